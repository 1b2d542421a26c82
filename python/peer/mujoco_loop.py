"""The loop a user would write instead of the testbed: one Python process, a
numpy controller (the paper's law of python/examples/nac.py, written from
SPEC) driving a MuJoCo plant loaded from the same URDF, RK4 with substeps.

    python3 python/peer/mujoco_loop.py CONFIG.json

CONFIG is what `testbed bench --peer` writes: the URDF path, the period and
step count, the initial state, the reference and envelope sinusoids and the
controller's resolved parameters. Prints one JSON line: the loop's wall time
(model loading and imports excluded), the steps and the final state.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "examples"))

import testbed_controller as tc  # noqa: E402
from nac import PaperLaw  # noqa: E402


def sinusoids(joints: list[dict], t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value, rate and acceleration of offset + sin·sin(ωt) + cos·cos(ωt)."""
    v, d, dd = [], [], []
    for j in joints:
        w, s, c = j.get("omega", 0.0), j.get("sin", 0.0), j.get("cos", 0.0)
        sw, cw = math.sin(w * t), math.cos(w * t)
        v.append(j.get("offset", 0.0) + s * sw + c * cw)
        d.append(w * (s * cw - c * sw))
        dd.append(-w * w * (s * sw + c * cw))
    return np.array(v), np.array(d), np.array(dd)


def load(urdf: str, period: float, substeps: int) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_path(urdf)
    model.opt.timestep = period / substeps
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    # The testbed's arm has no colliders: no contacts here either.
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    return model, mujoco.MjData(model)


def main(path: str) -> int:
    with open(path, encoding="utf-8") as f:
        cfg = json.load(f)
    if cfg["envelope"].get("from_limits"):
        raise SystemExit("peer: an envelope from the joint limits is not supported")
    period, steps, substeps = cfg["period_s"], cfg["steps"], cfg["substeps"]
    model, data = load(cfg["urdf"], period, substeps)
    n = cfg["controller"]["dof"]
    if model.nv != n:
        raise SystemExit(f"peer: MuJoCo sees {model.nv} joints, the scenario {n}")
    data.qpos[:] = cfg["initial"]["q"]
    data.qvel[:] = cfg["initial"]["qd"]
    mujoco.mj_forward(model, data)
    law = PaperLaw()
    c = cfg["controller"]
    law.setup(tc.RunInfo(dof=n, period_ns=c["period_ns"], mode="lockstep", params=c["params"]))
    reference, envelope = cfg["reference"]["joints"], cfg["envelope"]["joints"]
    worst = np.zeros(n)
    start = time.perf_counter()
    for k in range(steps):
        t = k * period
        q_d, qd_d, qdd_d = sinusoids(reference, t)
        kc, kc_dot, _ = sinusoids(envelope, t)
        state = tc.State(seq=k, t_ns=round(t * 1e9), t=t, q=data.qpos.copy(), qd=data.qvel.copy())
        tau = law.step(state, tc.Reference(q_d, qd_d, qdd_d, kc, kc_dot))
        if t >= c["params"]["tc"]:
            worst = np.maximum(worst, np.abs(state.q - q_d))
        data.ctrl[:] = 0.0
        data.qfrc_applied[:] = np.where(np.isfinite(tau), tau, 0.0)
        for _ in range(substeps):
            mujoco.mj_step(model, data)
    wall = time.perf_counter() - start
    print(json.dumps({"wall_s": wall, "steps": steps, "max_abs_error_after_tc": worst.tolist()}))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit("usage: mujoco_loop.py CONFIG.json")
    sys.exit(main(sys.argv[1]))
