"""CPU placement the launcher asks of a node: pinning, SCHED_FIFO, locked
memory. What the system refuses is reported, never fatal (as for the Rust
nodes)."""

from __future__ import annotations

import ctypes
import ctypes.util
import os
from typing import Optional

_MCL_CURRENT, _MCL_FUTURE = 1, 2


def apply_placement(cpus: Optional[str], fifo: Optional[int], lock_memory: bool) -> list[str]:
    """Applies what was asked; returns one sentence per refusal."""
    refused = []
    if cpus:
        try:
            os.sched_setaffinity(0, {int(c) for c in cpus.split(",")})
        except (OSError, ValueError) as e:
            refused.append(f"pinning to CPUs {cpus}: {e}")
    if fifo is not None:
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(fifo))
        except OSError as e:
            refused.append(f"SCHED_FIFO priority {fifo}: {e}")
    if lock_memory:
        libc = ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True)
        if libc.mlockall(_MCL_CURRENT | _MCL_FUTURE) != 0:
            refused.append(f"locking memory: {os.strerror(ctypes.get_errno())}")
    return refused
