"""The controller node: the node protocol and the loop around a `Controller`.

It follows what every testbed node does (READY, wait for START, run, DONE,
wait for STOP), takes the launcher's node arguments (`--prefix`, `--config`,
`--mode`, `--parent-pid`, CPU placement), and for every joint state takes
the reference sample by the testbed's one rule, calls the controller, and
publishes the command and the diagnostics of that step.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import sys
import time
import traceback
from typing import Optional, Sequence

import numpy as np

from . import wire
from .bus import Bus, ReferenceWindow, Terminated
from .controller import DIAGNOSTIC_FIELDS, Controller, Reference, RunInfo, State
from .placement import apply_placement


class Stopped(Exception):
    """The launcher sent STOP."""


class ProtocolError(Exception):
    """Something arrived that the node protocol does not allow, or the
    launcher is gone."""


class NodeLink:
    """This node's status and control ports."""

    def __init__(self, bus: Bus, mode: str, parent_pid: Optional[int]):
        self.bus = bus
        self.mode = mode
        self.parent_pid = parent_pid
        self.status = bus.publisher("status", lossless=False)
        self.control = bus.subscriber("control")
        self.status_seq = 0
        self.stopped = False
        self.last_report = (0, 0)
        self.last_report_ns = 0
        self.pending_start = None

    def report(self, state: int, step: int) -> None:
        self.last_report, self.last_report_ns = (state, step), time.monotonic_ns()
        msg = wire.NodeStatus()
        msg.header.seq = self.status_seq
        msg.header.wall_ns = self.last_report_ns
        msg.node = wire.NODE_KIND_CONTROLLER
        msg.state = state
        msg.pid = os.getpid()
        msg.step = step
        self.status_seq += 1
        self.status.send_copy(msg)

    def check(self) -> None:
        """Raises if SIGINT/SIGTERM came, the launcher is gone, or STOP came;
        repeats the last status as the heartbeat the launcher listens for."""
        self.bus.wait(0.0)
        if self.last_report_ns and time.monotonic_ns() - self.last_report_ns >= wire.HEARTBEAT_NS:
            self.report(*self.last_report)
        if self.parent_pid is not None and os.getppid() != self.parent_pid:
            raise ProtocolError(f"the launcher (pid {self.parent_pid}) is gone")
        while (c := self.control.receive()) is not None:
            if int(c["command"]) == wire.CONTROL_STOP:
                self.stopped = True
            elif int(c["command"]) == wire.CONTROL_START:
                # Kept for the wait for START: a check between its polls
                # must not swallow it.
                self.pending_start = c
        if self.stopped:
            raise Stopped()

    def ready_and_wait_for_start(self) -> None:
        self.report(wire.NODE_READY, 0)
        last = time.monotonic()
        want = wire.MODE_LOCKSTEP if self.mode == "lockstep" else wire.MODE_REALTIME
        while True:
            self.control.wait_event(0.05)
            self.control.drain_events()
            c, self.pending_start = self.pending_start, None
            if c is None:
                c = self.control.receive()
            if c is not None:
                command, code = int(c["command"]), int(c["code"])
                if command == wire.CONTROL_START and code != want:
                    self.report(wire.NODE_FAILED, 0)
                    raise ProtocolError(f"this node was started with --mode {self.mode} but the run is not")
                if command == wire.CONTROL_START:
                    self.report(wire.NODE_RUNNING, 0)
                    return
                if command == wire.CONTROL_STOP:
                    raise Stopped()
                raise ProtocolError(f"unknown control command {command}")
            self.check()
            if time.monotonic() - last > 0.5:
                self.report(wire.NODE_READY, 0)
                last = time.monotonic()

    def done_and_wait_for_stop(self, steps: int) -> None:
        self.report(wire.NODE_DONE, steps)
        while True:
            try:
                self.check()
            except Stopped:
                return
            self.control.wait_event(0.05)
            self.control.drain_events()


def parse_args(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    p = argparse.ArgumentParser(description="A testbed controller node written in Python.")
    p.add_argument("--prefix", required=True, help="the run's shared-memory prefix")
    p.add_argument("--config", required=True, help="the controller's config (JSON) the launcher wrote")
    p.add_argument("--mode", required=True, choices=["realtime", "lockstep"])
    p.add_argument("--parent-pid", type=int, default=None, help="stop when this process is gone")
    p.add_argument("--cpus", default=None, help="pin to these CPUs (comma-separated)")
    p.add_argument("--fifo", type=int, default=None, help="SCHED_FIFO priority")
    p.add_argument("--lock-memory", action="store_true", help="lock memory (mlockall)")
    p.add_argument("--verbose", action="store_true")
    return p.parse_args(argv)


def read_run_info(path: str, mode: str) -> RunInfo:
    try:
        with open(path, encoding="utf-8") as f:
            cfg = json.load(f)
        return RunInfo(
            dof=int(cfg["dof"]),
            period_ns=int(cfg["period_ns"]),
            mode=mode,
            params=dict(cfg["params"]),
            reference_period_ns=int(cfg.get("reference_period_ns", 0)),
            own=dict(cfg.get("own_params", {})),
            own_diagnostics=parse_own_layout(cfg.get("own_diagnostics", "")),
        )
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise SystemExit(f"controller: cannot read the config {path}: {e!r}") from e


def parse_own_layout(text: str) -> tuple:
    """`name:shape,…` (the launcher's layout of the own diagnostics) as pairs."""
    pairs = tuple(tuple(e.split(":", 1)) for e in text.split(",") if e)
    for p in pairs:
        if len(p) != 2 or p[1] not in ("scalar", "joints"):
            raise ValueError(f"own_diagnostics entry {':'.join(p)!r} is not name:scalar or name:joints")
    return pairs


class Loop:
    """Per-step work: state in, controller, command and diagnostics out."""

    def __init__(self, controller: Controller, info: RunInfo, bus: Bus, link: NodeLink):
        lockstep = info.mode == "lockstep"
        self.c = controller
        self.n = info.dof
        self.link = link
        self.states = bus.subscriber("joint_state")
        self.refs = ReferenceWindow(bus, lockstep, info.reference_period_ns or info.period_ns)
        self.commands = bus.publisher("command", lossless=lockstep)
        self.diags = bus.publisher("diagnostics", lossless=lockstep)
        self.own_layout = info.own_diagnostics
        self.own_names = frozenset(name for name, _ in self.own_layout)
        self.own = bus.publisher("own_diagnostics", lossless=lockstep) if self.own_layout else None
        self.idle = lambda: (bus.wait(0.001), link.check())

    def run(self) -> int:
        """Handles states until the final one; returns how many."""
        handled = 0
        while True:
            finished = False
            while (s := self.states.receive()) is not None:
                if int(s["flags"]) & wire.STATE_FINAL:
                    finished = True
                    continue
                self.step(s)
                handled += 1
                # Inside the loop: a controller slower than the plant finds
                # the next state waiting and never leaves it.
                if handled % 256 == 0:
                    self.link.check()
            if finished:
                return handled
            if not self.states.wait_event(0.1):
                self.link.check()
            self.states.drain_events()

    def step(self, s) -> None:
        started_wall_ns = time.monotonic_ns()
        started = time.perf_counter_ns()
        n = self.n
        h = s["header"]
        t_ns = int(h["t_ns"])
        r = self.refs.take(t_ns, self.idle)
        state = State(
            seq=int(h["seq"]), t_ns=t_ns, t=t_ns / 1e9, q=s["q_measured"][:n].copy(), qd=s["qd_measured"][:n].copy()
        )
        fault, tau, extra = self.compute(state, r)
        compute_ns = time.perf_counter_ns() - started
        wall_ns = time.monotonic_ns()
        sample, m = self.commands.loan()
        m["header"] = (h["seq"], t_ns, wall_ns)
        m["dof"] = n
        m["fault"] = fault
        m["tau"][:n] = tau
        m["state_wall_ns"] = h["wall_ns"]
        m["compute_ns"] = compute_ns
        m["started_wall_ns"] = started_wall_ns
        m["reference_t_ns"] = wire.NONE_U64 if r is None else int(r["header"]["t_ns"])
        m["stale_references"] = self.refs.stale
        self.commands.send(sample)
        self.publish_diagnostics(h, wall_ns, compute_ns, state, r, fault, tau, extra)
        if self.own is not None:
            self.publish_own(h, wall_ns, extra)

    def compute(self, state: State, r) -> tuple:
        """(fault, tau, extra diagnostics) of one step."""
        n = self.n
        zero = np.zeros(n)
        if r is None:
            return wire.FAULT_NO_REFERENCE, zero, None
        ref = Reference(
            q_d=r["q_d"][:n].copy(),
            qd_d=r["qd_d"][:n].copy(),
            qdd_d=r["qdd_d"][:n].copy(),
            kc=r["kc"][:n].copy(),
            kc_dot=r["kc_dot"][:n].copy(),
        )
        inputs = np.concatenate((state.q, state.qd, ref.q_d, ref.qd_d, ref.qdd_d, ref.kc, ref.kc_dot))
        if not np.isfinite(inputs).all():
            return wire.FAULT_NON_FINITE_INPUT, zero, None
        if (ref.kc <= 0).any():
            return wire.FAULT_ENVELOPE_NOT_POSITIVE, zero, None
        tau = np.asarray(self.c.step(state, ref), dtype=float)
        if tau.shape != (n,):
            raise ValueError(f"{type(self.c).__name__}.step returned a torque of shape {tau.shape}, not ({n},)")
        extra = self.c.diagnostics()
        if not np.isfinite(tau).all():
            return wire.FAULT_NON_FINITE_OUTPUT, zero, extra
        return 0, tau, extra

    def publish_diagnostics(self, h, wall_ns, compute_ns, state, r, fault, tau, extra) -> None:
        n = self.n
        sample, d = self.diags.loan()
        d["header"] = (h["seq"], h["t_ns"], wall_ns)
        d["dof"] = n
        d["fault"] = fault
        d["compute_ns"] = compute_ns
        d["gamma"] = 1.0
        if r is not None:
            for field in ("q_d", "qd_d", "qdd_d", "kc_dot"):
                d[field] = r[field]
            d["kc_in"] = r["kc"]
            d["kc"] = r["kc"]
            e = state.q - r["q_d"][:n]
            d["z1"][:n] = e
            d["z1g"][:n] = e
            d["z2"][:n] = state.qd - r["qd_d"][:n]
            d["alpha"][:n] = r["qd_d"][:n]
            d["d"][:n] = r["kc"][:n] * r["kc"][:n] - e * e
        d["tau"][:n] = tau
        d["tau_feedback"][:n] = tau
        own = self.own_names
        for key, value in (extra or {}).items():
            if key in own:
                continue
            if key not in DIAGNOSTIC_FIELDS:
                raise KeyError(
                    f"{type(self.c).__name__}.diagnostics() names '{key}', neither a ControllerDiagnostics field "
                    f"nor one of its own_diagnostics ({', '.join(sorted(own)) or 'none declared'})"
                )
            if key in wire.ControllerDiagnostics.JOINT_FIELDS:
                d[key][:n] = value
            else:
                d[key] = value
        self.diags.send(sample)

    def publish_own(self, h, wall_ns, extra) -> None:
        """The declared diagnostics' values, in the launcher's order; NaN on a
        step the controller was not asked (a fault before `step`)."""
        n = self.n
        sample, o = self.own.loan()
        o["header"] = (h["seq"], h["t_ns"], wall_ns)
        at = 0
        for name, shape in self.own_layout:
            size = n if shape == "joints" else 1
            if extra is None:
                value = np.full(size, np.nan)
            elif name not in extra:
                raise KeyError(f"{type(self.c).__name__}.diagnostics() gives no '{name}' (declared in own_diagnostics)")
            else:
                value = np.asarray(extra[name], dtype=float).reshape(-1)
                if value.size != size:
                    raise ValueError(
                        f"{type(self.c).__name__}.diagnostics()['{name}'] has {value.size} values; "
                        f"its shape '{shape}' takes {size}"
                    )
            o["values"][at : at + size] = value
            at += size
        o["count"] = at
        self.own.send(sample)


def run(controller: Controller, argv: Optional[Sequence[str]] = None) -> None:
    """Runs `controller` as the run's controller node; exits the process."""
    sys.exit(main(controller, argv))


def die_with_parent(parent_pid: Optional[int]) -> None:
    """Ends this process when the launcher dies, even in the middle of a
    `step()` that never returns (the periodic check of the launcher cannot
    run then): the kernel sends SIGKILL (Linux), and the next run removes
    what this process left in shared memory."""
    if parent_pid is None or not sys.platform.startswith("linux"):
        return
    import ctypes
    import signal

    pr_set_pdeathsig = 1
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0)
    try:
        os.kill(parent_pid, 0)
    except ProcessLookupError:
        raise SystemExit(f"controller: the launcher (pid {parent_pid}) is gone") from None


def main(controller: Controller, argv: Optional[Sequence[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv == ["--describe"]:
        # The launcher asks before the run; a controller that declares no
        # name says so by failing, and runs unnamed.
        if not controller.name:
            return 1
        print(json.dumps(controller.describe()))
        return 0
    args = parse_args(argv)
    die_with_parent(args.parent_pid)
    for refused in apply_placement(args.cpus, args.fifo, args.lock_memory):
        print(f"controller: warning: {refused}", file=sys.stderr)
    info = read_run_info(args.config, args.mode)
    controller.setup(info)
    bus = Bus(args.prefix, "controller")
    link = None
    try:
        link = NodeLink(bus, args.mode, args.parent_pid)
        loop = Loop(controller, info, bus, link)
        # Everything made so far (numpy, iceoryx2, the controller) lives for
        # the whole run: out of the collector's sight, a full collection no
        # longer walks it (tens of ms, a burst of missed deadlines at 1 kHz).
        gc.collect()
        gc.freeze()
        link.ready_and_wait_for_start()
        handled = loop.run()
        link.done_and_wait_for_stop(handled)
        return 0
    except Stopped:
        return 0
    except Terminated:
        print("controller: interrupted by a termination request", file=sys.stderr)
        return 130
    except ProtocolError as e:
        print(f"controller: error: {e}", file=sys.stderr)
        return 1
    except Exception:
        traceback.print_exc()
        if link is not None:
            try:
                link.report(wire.NODE_FAILED, 0)
            except Exception:  # the bus itself may be what failed
                pass
        return 1
    finally:
        bus.close()
