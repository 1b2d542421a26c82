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
from .node import run

__all__ = ["Controller", "Reference", "RunInfo", "State", "run", "wire"]
__version__ = "0.1.0"
