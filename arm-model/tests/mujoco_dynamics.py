"""MuJoCo's own dynamics of an MJCF file at given states, for
arm-model/tests/mujoco.rs to compare the testbed's with.

    python mujoco_dynamics.py MODEL.xml STATES.json

STATES.json: {"names": [joint, ...], "states": [{"q", "qd", "tau"}, ...]},
every vector in the order of "names" (the testbed's joint order). Prints
JSON {"M": [...], "bias": [...], "qacc": [...]} per state in that order:
Mesh geoms are removed first (see without_meshes). M from mj_fullM (armature included; MuJoCo 4 signature), bias = qfrc_bias (C q̇ + G), and the
accelerations mj_forward gives under tau with joint damping on and every
constraint (joint limits, dry friction `frictionloss`, contacts) and the
actuators off. What the testbed names and does not apply is off here too:
joint springs (stiffness), body gravcomp and the model's own <option
gravity> (gravity is the testbed's default, as a scenario's).
"""

import json
import sys

import mujoco
import numpy as np


def without_meshes(model_path):
    """The model with its mesh geoms and mesh assets removed: meshes are
    not shipped (only the MJCF is), and the testbed reads an arm only when
    no moving body takes its mass from a mesh (each such body has an
    <inertial>, or its meshes weigh nothing), so they change no dynamics.
    A body welded to the world may weigh its meshes; it moves nothing."""
    spec = mujoco.MjSpec.from_file(model_path)
    for g in list(spec.geoms):
        # A geom naming a mesh is a mesh whatever its written type (MuJoCo
        # infers the type from `mesh`).
        if g.type == mujoco.mjtGeom.mjGEOM_MESH or g.meshname:
            spec.delete(g)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    # Textures are image files not shipped either; they only colour.
    for g in spec.geoms:
        g.material = ""
    for site in spec.sites:
        site.material = ""
    for asset in list(spec.materials) + list(spec.textures):
        spec.delete(asset)
    return spec.compile()


def joint(m, name):
    """MuJoCo's joint `name`; an unnamed one by the testbed's name for it,
    BODY_jointK (the body's K-th joint)."""
    try:
        return m.joint(name)
    except KeyError:
        body, _, k = name.rpartition("_joint")
        return m.joint(int(m.body(body).jntadr[0]) + int(k))


def main(model_path, states_path):
    m = without_meshes(model_path)
    # frictionloss and limits are constraints in MuJoCo; the comparison is
    # of the smooth dynamics, so they are off (the testbed's are elsewhere).
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    # Gravity is the scenario's in the testbed (the model's <option
    # gravity> is noted, not applied); the comparison is at its default.
    m.opt.gravity[:] = (0.0, 0.0, -9.81)
    m.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_GRAVITY)
    # gravcomp and joint springs are named by the testbed and not applied.
    m.body_gravcomp[:] = 0.0
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_SPRING
    # A position servo pushes even at ctrl 0; the torque is tau alone.
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_ACTUATION
    d = mujoco.MjData(m)
    with open(states_path) as f:
        spec = json.load(f)
    joints = [joint(m, n) for n in spec["names"]]
    qadr = [int(j.qposadr[0]) for j in joints]
    vadr = [int(j.dofadr[0]) for j in joints]
    if len(joints) != m.nv:
        sys.exit(f"{len(joints)} joints named for {m.nv} MuJoCo dofs")
    out = []
    for s in spec["states"]:
        d.qpos[:] = m.qpos0
        d.qpos[qadr] = s["q"]
        d.qvel[:] = 0
        d.qvel[vadr] = s["qd"]
        d.qfrc_applied[:] = 0
        d.qfrc_applied[vadr] = s["tau"]
        mujoco.mj_forward(m, d)
        full = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, full)
        out.append(
            {
                "M": full[np.ix_(vadr, vadr)].tolist(),
                "bias": d.qfrc_bias[vadr].tolist(),
                "qacc": d.qacc[vadr].tolist(),
            }
        )
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
