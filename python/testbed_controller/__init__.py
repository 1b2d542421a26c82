"""Write a testbed controller in Python.

Subclass `Controller`, implement `step(state, ref) -> tau`, and call
`run(MyController())` at the bottom of your script; then

    testbed run --controller-cmd "python3 my_controller.py"

runs it as the controller node of the stack: same iceoryx2 topics, zero
copy, in real time or lockstep. The message layouts (`wire`) are generated
from the Rust definitions.
"""

from . import wire
from .controller import Controller, Reference, RunInfo, State


def __getattr__(name):
    # `run` needs iceoryx2; reading a log (`testbed_controller.log`) needs
    # only numpy and the MCAP readers, so the bus is imported on first use.
    if name == "run":
        try:
            from .node import run
        except ModuleNotFoundError as e:
            if e.name != "iceoryx2":
                raise
            raise ModuleNotFoundError(
                "testbed_controller.run speaks iceoryx2 0.10.0, which is not installed: "
                "pip install 'rl-deferred-testbed[bus]' (or iceoryx2==0.10.0)",
                name="iceoryx2") from e
        return run
    raise AttributeError(f"module 'testbed_controller' has no attribute {name!r}")


__all__ = ["Controller", "Reference", "RunInfo", "State", "run", "wire"]
__version__ = "0.1.0"
