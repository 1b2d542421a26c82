"""The testbed in process: the Rust core of `testbed sim` as a Python module.

    import testbed
    rows, summary = testbed.sim("paper")               # as `testbed sim --scenario paper`
    robot = testbed.Robot("iiwa14")                    # a shipped robot (or a URDF): M(q), C(q, q̇)q̇, G(q)
    law = testbed.Law("nac")                           # a built-in law, stepped by hand
    table = testbed.compare("ur5_randomised", seeds=5) # `testbed compare --json`
    env = gymnasium.make("testbed/ArmTracking-v0")     # the Gymnasium environment

docs/python.md has the whole interface.
"""

from ._native import (  # noqa: F401  (the public interface)
    LAWS,
    MAX_DOF,
    ROBOTS,
    SCENARIOS,
    EnvCore,
    Law,
    Robot,
    TestbedError,
    VecEnvCore,
    compare,
    scenario_file,
    scenario_toml,
    search_space,
    sim,
)
from .env import ArmTrackingEnv, ArmTrackingVecEnv, observation_names  # noqa: F401
from .policy import LinearPolicy  # noqa: F401

ENV_ID = "testbed/ArmTracking-v0"


def read_log(path, topics=None):
    """A run's MCAP log as tables of numpy arrays (one per topic); the
    reader of `testbed_controller.log`, which needs the `mcap` and
    `mcap-ros2-support` packages."""
    from testbed_controller.log import read_log as _read

    return _read(path, topics=topics)


def _register():
    import gymnasium

    if ENV_ID not in gymnasium.registry:
        gymnasium.register(
            id=ENV_ID,
            entry_point="testbed.env:ArmTrackingEnv",
            vector_entry_point="testbed.env:ArmTrackingVecEnv",
            disable_env_checker=False,
        )


_register()
