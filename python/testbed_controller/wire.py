"""The testbed's wire contract: message layouts, topics and protocol codes.

Generated from the Rust definitions (crate `wire`) by

    cargo run --release -- bindings python --out python/testbed_controller/wire.py

Do not edit: a test of the Rust workspace fails when this file no longer
matches the Rust types, and importing it checks every size and offset.
"""

# fmt: off
import ctypes

MAX_DOF = 32  # joints a message carries
SUBSCRIBER_BUFFER = 2048  # samples a subscriber holds
MAX_SUBSCRIBERS = 4  # subscribers (and listeners) per topic
MAX_NODES = 10  # nodes per service
LOSSLESS_TIMEOUT_S = 10  # a lockstep publisher gives up on a full reader after this
HEARTBEAT_NS = 100000000  # a node repeats its status at least this often while it runs
SILENT_AFTER_S = 3  # the launcher names a node not heard from for this long
RUN_PREFIX_STEM = "tbrun"  # every run's shared-memory prefix starts so
STATE_FINAL = 1  # JointState.flags: the last state, no command expected
NONE_U64 = 18446744073709551615  # JointState.command_seq, Command.reference_t_ns: none
CONTROL_START = 1  # Control.command
CONTROL_STOP = 2  # Control.command
NODE_READY = 1  # NodeStatus.state
NODE_RUNNING = 2  # NodeStatus.state
NODE_DONE = 3  # NodeStatus.state
NODE_FAILED = 4  # NodeStatus.state
NODE_KIND_PLANT = 1  # NodeStatus.node
NODE_KIND_TRAJECTORY = 2  # NodeStatus.node
NODE_KIND_CONTROLLER = 3  # NodeStatus.node
NODE_KIND_LOGGER = 4  # NodeStatus.node
MODE_REALTIME = 1  # Control.code with START
MODE_LOCKSTEP = 2  # Control.code with START
RUN_END_FINISHED = 0  # Control.code with STOP
RUN_END_INTERRUPTED = 1  # Control.code with STOP
RUN_END_FAILED = 2  # Control.code with STOP
RUN_END_LOST_NODE_BASE = 10  # Control.code with STOP: this + the lost node's kind
FAULT_NON_FINITE_INPUT = 1  # Command.fault (0: none)
FAULT_WRONG_LENGTH = 2  # Command.fault (0: none)
FAULT_ENVELOPE_NOT_POSITIVE = 3  # Command.fault (0: none)
FAULT_NON_FINITE_OUTPUT = 4  # Command.fault (0: none)
FAULT_NO_REFERENCE = 5  # Command.fault (0: none)


class Header(ctypes.Structure):
    _fields_ = [
        ("seq", ctypes.c_uint64),
        ("t_ns", ctypes.c_uint64),
        ("wall_ns", ctypes.c_uint64),
    ]
    SIZE = 24
    ALIGN = 8
    OFFSETS = {"seq": 0, "t_ns": 8, "wall_ns": 16}
    JOINT_FIELDS = ()


class JointState(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("dof", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("q", ctypes.c_double * MAX_DOF),
        ("qd", ctypes.c_double * MAX_DOF),
        ("q_measured", ctypes.c_double * MAX_DOF),
        ("qd_measured", ctypes.c_double * MAX_DOF),
        ("tau_applied", ctypes.c_double * MAX_DOF),
        ("disturbance", ctypes.c_double * MAX_DOF),
        ("effects", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("deadline_misses", ctypes.c_uint64),
        ("command_seq", ctypes.c_uint64),
        ("applied_wall_ns", ctypes.c_uint64),
    ]
    SIZE = 1600
    ALIGN = 8
    OFFSETS = {"header": 0, "dof": 24, "flags": 28, "q": 32, "qd": 288, "q_measured": 544, "qd_measured": 800, "tau_applied": 1056, "disturbance": 1312, "effects": 1568, "reserved": 1572, "deadline_misses": 1576, "command_seq": 1584, "applied_wall_ns": 1592}
    JOINT_FIELDS = ("q", "qd", "q_measured", "qd_measured", "tau_applied", "disturbance")

    @staticmethod
    def type_name() -> str:
        return "testbed.JointState.v4"


class ReferenceSample(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("dof", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("q_d", ctypes.c_double * MAX_DOF),
        ("qd_d", ctypes.c_double * MAX_DOF),
        ("qdd_d", ctypes.c_double * MAX_DOF),
        ("kc", ctypes.c_double * MAX_DOF),
        ("kc_dot", ctypes.c_double * MAX_DOF),
    ]
    SIZE = 1312
    ALIGN = 8
    OFFSETS = {"header": 0, "dof": 24, "reserved": 28, "q_d": 32, "qd_d": 288, "qdd_d": 544, "kc": 800, "kc_dot": 1056}
    JOINT_FIELDS = ("q_d", "qd_d", "qdd_d", "kc", "kc_dot")

    @staticmethod
    def type_name() -> str:
        return "testbed.Reference.v2"


class Command(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("dof", ctypes.c_uint32),
        ("fault", ctypes.c_uint32),
        ("tau", ctypes.c_double * MAX_DOF),
        ("state_wall_ns", ctypes.c_uint64),
        ("compute_ns", ctypes.c_uint64),
        ("started_wall_ns", ctypes.c_uint64),
        ("reference_t_ns", ctypes.c_uint64),
        ("stale_references", ctypes.c_uint64),
    ]
    SIZE = 328
    ALIGN = 8
    OFFSETS = {"header": 0, "dof": 24, "fault": 28, "tau": 32, "state_wall_ns": 288, "compute_ns": 296, "started_wall_ns": 304, "reference_t_ns": 312, "stale_references": 320}
    JOINT_FIELDS = ("tau",)

    @staticmethod
    def type_name() -> str:
        return "testbed.Command.v3"


class ControllerDiagnostics(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("dof", ctypes.c_uint32),
        ("fault", ctypes.c_uint32),
        ("barrier_breached", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("compute_ns", ctypes.c_uint64),
        ("gamma", ctypes.c_double),
        ("gamma_dot", ctypes.c_double),
        ("j_hat", ctypes.c_double),
        ("delta", ctypes.c_double),
        ("r", ctypes.c_double),
        ("wc_norm", ctypes.c_double),
        ("q_d", ctypes.c_double * MAX_DOF),
        ("qd_d", ctypes.c_double * MAX_DOF),
        ("qdd_d", ctypes.c_double * MAX_DOF),
        ("kc_in", ctypes.c_double * MAX_DOF),
        ("kc_dot", ctypes.c_double * MAX_DOF),
        ("z1", ctypes.c_double * MAX_DOF),
        ("z1g", ctypes.c_double * MAX_DOF),
        ("z2", ctypes.c_double * MAX_DOF),
        ("alpha", ctypes.c_double * MAX_DOF),
        ("kc", ctypes.c_double * MAX_DOF),
        ("d", ctypes.c_double * MAX_DOF),
        ("tau", ctypes.c_double * MAX_DOF),
        ("tau_actor", ctypes.c_double * MAX_DOF),
        ("tau_feedback", ctypes.c_double * MAX_DOF),
        ("tau_barrier", ctypes.c_double * MAX_DOF),
        ("tau_model", ctypes.c_double * MAX_DOF),
        ("wa_norm", ctypes.c_double * MAX_DOF),
    ]
    SIZE = 4448
    ALIGN = 8
    OFFSETS = {"header": 0, "dof": 24, "fault": 28, "barrier_breached": 32, "reserved": 36, "compute_ns": 40, "gamma": 48, "gamma_dot": 56, "j_hat": 64, "delta": 72, "r": 80, "wc_norm": 88, "q_d": 96, "qd_d": 352, "qdd_d": 608, "kc_in": 864, "kc_dot": 1120, "z1": 1376, "z1g": 1632, "z2": 1888, "alpha": 2144, "kc": 2400, "d": 2656, "tau": 2912, "tau_actor": 3168, "tau_feedback": 3424, "tau_barrier": 3680, "tau_model": 3936, "wa_norm": 4192}
    JOINT_FIELDS = ("q_d", "qd_d", "qdd_d", "kc_in", "kc_dot", "z1", "z1g", "z2", "alpha", "kc", "d", "tau", "tau_actor", "tau_feedback", "tau_barrier", "tau_model", "wa_norm")

    @staticmethod
    def type_name() -> str:
        return "testbed.ControllerDiagnostics.v3"


class Timing(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("wake_late_ns", ctypes.c_int64),
        ("period_ns", ctypes.c_int64),
        ("round_trip_ns", ctypes.c_int64),
        ("controller_compute_ns", ctypes.c_int64),
        ("deadline_missed", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("deadline_misses", ctypes.c_uint64),
        ("floor_late_wakeups", ctypes.c_uint64),
    ]
    SIZE = 80
    ALIGN = 8
    OFFSETS = {"header": 0, "wake_late_ns": 24, "period_ns": 32, "round_trip_ns": 40, "controller_compute_ns": 48, "deadline_missed": 56, "reserved": 60, "deadline_misses": 64, "floor_late_wakeups": 72}
    JOINT_FIELDS = ()

    @staticmethod
    def type_name() -> str:
        return "testbed.Timing.v2"


class OwnDiagnostics(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("count", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("values", ctypes.c_double * MAX_DOF),
    ]
    SIZE = 288
    ALIGN = 8
    OFFSETS = {"header": 0, "count": 24, "reserved": 28, "values": 32}
    JOINT_FIELDS = ("values",)

    @staticmethod
    def type_name() -> str:
        return "testbed.OwnDiagnostics.v1"


class ContactState(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("points", ctypes.c_uint32),
        ("count", ctypes.c_uint32),
        ("force", ctypes.c_double),
        ("point_x", ctypes.c_double),
        ("point_y", ctypes.c_double),
        ("point_z", ctypes.c_double),
        ("objects", ctypes.c_double * MAX_DOF),
    ]
    SIZE = 320
    ALIGN = 8
    OFFSETS = {"header": 0, "points": 24, "count": 28, "force": 32, "point_x": 40, "point_y": 48, "point_z": 56, "objects": 64}
    JOINT_FIELDS = ("objects",)

    @staticmethod
    def type_name() -> str:
        return "testbed.ContactState.v2"


class Control(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("command", ctypes.c_uint32),
        ("code", ctypes.c_uint32),
        ("epoch_wall_ns", ctypes.c_uint64),
    ]
    SIZE = 40
    ALIGN = 8
    OFFSETS = {"header": 0, "command": 24, "code": 28, "epoch_wall_ns": 32}
    JOINT_FIELDS = ()

    @staticmethod
    def type_name() -> str:
        return "testbed.Control.v2"


class NodeStatus(ctypes.Structure):
    _fields_ = [
        ("header", Header),
        ("node", ctypes.c_uint32),
        ("state", ctypes.c_uint32),
        ("pid", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("step", ctypes.c_uint64),
    ]
    SIZE = 48
    ALIGN = 8
    OFFSETS = {"header": 0, "node": 24, "state": 28, "pid": 32, "reserved": 36, "step": 40}
    JOINT_FIELDS = ()

    @staticmethod
    def type_name() -> str:
        return "testbed.NodeStatus.v1"


# Topic name -> (service name, message type, max publishers, max notifiers,
# whether readers block on its events). Every service lives under the run's prefix.
TOPICS = {
    "joint_state": ("testbed/joint_state", JointState, 1, 2, True),
    "reference": ("testbed/reference", ReferenceSample, 1, 2, False),
    "command": ("testbed/command", Command, 1, 2, True),
    "diagnostics": ("testbed/diagnostics", ControllerDiagnostics, 1, 2, False),
    "own_diagnostics": ("testbed/own_diagnostics", OwnDiagnostics, 1, 2, False),
    "timing": ("testbed/timing", Timing, 1, 2, False),
    "contact": ("testbed/contact", ContactState, 1, 2, False),
    "control": ("testbed/control", Control, 1, 2, True),
    "status": ("testbed/status", NodeStatus, 8, 8, True),
}

STRUCTURES = ("Header", "JointState", "ReferenceSample", "Command", "ControllerDiagnostics", "Timing", "OwnDiagnostics", "ContactState", "Control", "NodeStatus")


def _check_layouts() -> None:
    for name in STRUCTURES:
        s = globals()[name]
        if ctypes.sizeof(s) != s.SIZE or ctypes.alignment(s) != s.ALIGN:
            raise ImportError(
                f"{name}: ctypes lays it out in {ctypes.sizeof(s)} bytes aligned to "
                f"{ctypes.alignment(s)}, Rust in {s.SIZE} aligned to {s.ALIGN}"
            )
        for field, offset in s.OFFSETS.items():
            if getattr(s, field).offset != offset:
                raise ImportError(f"{name}.{field}: ctypes offset {getattr(s, field).offset}, Rust {offset}")


_check_layouts()
