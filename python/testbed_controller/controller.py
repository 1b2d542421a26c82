"""The controller API: what a Python controller implements, and what it is given.

Subclass `Controller` and implement `step`; `testbed_controller.run` does
the rest (the node protocol, the loop, the messages, timing and faults).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from . import wire


@dataclass(frozen=True)
class RunInfo:
    """What the launcher tells the controller about the run."""

    #: Controlled joints.
    dof: int
    #: Control period, ns (the plant holds each torque this long).
    period_ns: int
    #: "realtime" or "lockstep".
    mode: str
    #: The scenario's `[controller]` table as the launcher resolved it
    #: (law, tc, k1, k2, beta, …: SPEC §11), defaults filled in.
    params: dict = field(default_factory=dict)
    #: Period of the reference samples, ns (0: the control period): which
    #: sample is due at a state's time.
    reference_period_ns: int = 0
    #: This controller's own parameters: its declared `params` with the
    #: scenario's `[external]` table over them (checked by the launcher).
    own: dict = field(default_factory=dict)
    #: Its own diagnostics as the launcher laid them out: (name, shape)
    #: pairs, shape "scalar" or "joints", in the order they are published.
    own_diagnostics: tuple = ()

    @property
    def dt(self) -> float:
        """The control period, s."""
        return self.period_ns / 1e9

    def gain(self, key: str) -> np.ndarray:
        """A per-joint gain (`k1`, `k2`): one number for every joint or a list."""
        value = self.params[key]
        if isinstance(value, (int, float)):
            return np.full(self.dof, float(value))
        g = np.asarray(value, dtype=float)
        if g.shape != (self.dof,):
            raise ValueError(f"controller.{key} has {g.size} entries for {self.dof} joints")
        return g


@dataclass(frozen=True)
class State:
    """The measured joint state the controller acts on."""

    #: Step number k.
    seq: int
    #: Sim time t_k, ns and s.
    t_ns: int
    t: float
    #: Measured positions and velocities (noise and quantisation included).
    q: np.ndarray
    qd: np.ndarray


@dataclass(frozen=True)
class Reference:
    """The reference sample for the state's time."""

    q_d: np.ndarray
    qd_d: np.ndarray
    qdd_d: np.ndarray
    kc: np.ndarray
    kc_dot: np.ndarray


class Controller:
    """A control law. Implement `step`; the others are optional.

    Declare what the law is, and the launcher names it in the log and the
    summary, takes its parameters from the scenario's `[external]` table
    (checked against these, by name and kind), and logs its own
    diagnostics on a channel of their own (`/controller/own_diagnostics`),
    in the CSV (`own.NAME` columns) and in the summary:

        class PID(Controller):
            name = "pid"
            params = {"ki": 2.0}      # defaults; run.own["ki"] in setup()
            own_diagnostics = {"integral": "joints"}   # or "scalar"
    """

    #: The law's name (1 to 40 of a-z, 0-9, '-', '_'); "" declares nothing.
    name: str = ""
    #: Its own parameters and their defaults (numbers, booleans, strings, lists).
    params: dict = {}
    #: Its own diagnostics: name (a-z, 0-9, '_', starting with a letter) →
    #: "scalar" (one number a step) or "joints" (one per joint); at most 32
    #: numbers a step in all. `diagnostics()` gives their values each step.
    own_diagnostics: dict = {}

    def describe(self) -> dict:
        """What `--describe` prints: the law's name, parameters and diagnostics."""
        return {"name": self.name, "params": dict(self.params), "diagnostics": dict(self.own_diagnostics)}

    def setup(self, run: RunInfo) -> None:
        """Called once before the first step."""

    def step(self, state: State, ref: Reference) -> np.ndarray:
        """The torque for this state: a float array of `run.dof` entries.

        A non-finite torque is never sent: the step then publishes zero
        torque with the fault flag, as the testbed's own laws do.
        """
        raise NotImplementedError

    def diagnostics(self) -> Optional[dict[str, Any]]:
        """Diagnostics of the step just made: by ControllerDiagnostics field
        name (`z1`, `z2`, `alpha`, `tau_actor`, `gamma`, `j_hat`, …), which go
        to the log beside the defaults (errors, envelope, torque), and every
        name declared in `own_diagnostics` (a number, or `dof` numbers)."""
        return None


#: Fields of ControllerDiagnostics a controller may set.
DIAGNOSTIC_FIELDS = frozenset(
    name for name, _ in wire.ControllerDiagnostics._fields_ if name not in ("header", "reserved")
)
