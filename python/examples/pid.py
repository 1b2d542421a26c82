"""A PID controller in Python with a parameter of its own: the testbed's
`pd` law plus an integral term, τ = −K2 (K1 e + ė) − ki K2 ∫e dt, with K1
and K2 from the scenario's [controller] table and `ki` from its
[external] table (default 2.0).

    testbed run --controller-cmd "python3 python/examples/pid.py"
    testbed run --controller-cmd "python3 python/examples/pid.py" --scenario my.toml
        # my.toml:  [external]
        #           ki = 5.0

The log and the summary name the law `pid` with its `ki`; its integral
∫e dt is a diagnostic of its own (the log's /controller/own_diagnostics
channel, the CSV's own.integral<i> columns, the summary's last and largest
values); what it prints is in the run folder (nodes/controller.log).
"""

import numpy as np

import testbed_controller as tc


class PID(tc.Controller):
    name = "pid"
    params = {"ki": 2.0}
    own_diagnostics = {"integral": "joints"}

    def setup(self, run: tc.RunInfo) -> None:
        self.k1 = run.gain("k1")
        self.k2 = run.gain("k2")
        self.ki = float(run.own["ki"])
        self.dt = run.dt
        self.integral = np.zeros(run.dof)
        print(f"pid: ki = {self.ki}, {run.dof} joints at {1 / self.dt:.0f} Hz")

    def step(self, state: tc.State, ref: tc.Reference) -> np.ndarray:
        e = state.q - ref.q_d
        ed = state.qd - ref.qd_d
        self.integral += e * self.dt
        return -self.k2 * (self.k1 * e + ed) - self.ki * self.k2 * self.integral

    def diagnostics(self) -> dict:
        return {"integral": self.integral}


if __name__ == "__main__":
    tc.run(PID())
