"""iceoryx2 ports on the testbed's topics, with the services' settings the
Rust nodes use (from the generated `wire` module), so a Python node opens or
creates exactly the services a Rust node would.

Every topic is a publish-subscribe service paired with an event service of
the same name; readers that block wait on the event, publishers notify it.
Messages are read through a numpy view of the received sample's shared
memory and written straight into a loaned sample (zero copy).
"""

from __future__ import annotations

import ctypes
from collections import deque
from typing import Optional

import iceoryx2 as iox2
import numpy as np

from . import wire


def dtype_of(structure: type) -> np.dtype:
    """The numpy view of a wire structure (same size, offsets and alignment)."""
    dt = np.dtype(structure)
    if dt.itemsize != structure.SIZE:
        raise RuntimeError(f"numpy lays out {structure.__name__} in {dt.itemsize} bytes, not {structure.SIZE}")
    return dt


def _view(address: int, structure: type, dt: np.dtype) -> np.ndarray:
    """A structured numpy scalar view of `structure` at `address`."""
    raw = (ctypes.c_char * structure.SIZE).from_address(address)
    return np.frombuffer(raw, dtype=dt)[0]


class Terminated(Exception):
    """SIGINT or SIGTERM arrived."""


class Bus:
    """One process's iceoryx2 node under the run's prefix."""

    def __init__(self, prefix: str, name: str):
        config = iox2.config.default()
        config.global_cfg.prefix = iox2.FileName.new(prefix)
        self.node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(name))
            .config(config)
            .signal_handling_mode(iox2.SignalHandlingMode.HandleTerminationRequests)
            .create(iox2.ServiceType.Ipc)
        )
        self._ports: list = []

    def wait(self, seconds: float) -> None:
        """Sleeps up to `seconds`; raises Terminated on SIGINT/SIGTERM."""
        try:
            self.node.wait(iox2.Duration.from_secs_f64(seconds))
        except iox2.NodeWaitFailure as e:
            if "Termination" in repr(e) or "Termination" in str(e):
                raise Terminated() from e
            # Interrupted by another signal (SIGCONT after Ctrl-Z): an early wake-up.

    def _service(self, topic: str):
        name, message, max_publishers, _, _ = wire.TOPICS[topic]
        return (
            self.node.service_builder(iox2.ServiceName.new(name))
            .publish_subscribe(message)
            .enable_safe_overflow(False)
            .history_size(0)
            .subscriber_max_buffer_size(wire.SUBSCRIBER_BUFFER)
            .max_publishers(max_publishers)
            .max_subscribers(wire.MAX_SUBSCRIBERS)
            .max_nodes(wire.MAX_NODES)
            .open_or_create()
        )

    def _event(self, topic: str):
        name, _, _, max_notifiers, _ = wire.TOPICS[topic]
        return (
            self.node.service_builder(iox2.ServiceName.new(name))
            .event()
            .max_notifiers(max_notifiers)
            .max_listeners(wire.MAX_SUBSCRIBERS)
            .max_nodes(wire.MAX_NODES)
            .open_or_create()
        )

    def publisher(self, topic: str, lossless: bool) -> "Publisher":
        """A publisher on `topic`: lossless waits for a full reader (lockstep),
        otherwise a full reader misses the sample (real time)."""
        strategy = (
            iox2.BackpressureStrategy.RetryUntilDelivered
            if lossless
            else iox2.BackpressureStrategy.DiscardData
        )
        port = self._service(topic).publisher_builder().backpressure_strategy(strategy).create()
        notifier = None
        if wire.TOPICS[topic][4]:
            notifier = self._event(topic).notifier_builder().create()
        p = Publisher(topic, port, notifier)
        self._ports.append(p)
        return p

    def subscriber(self, topic: str, listen: Optional[bool] = None) -> "Subscriber":
        """A subscriber on `topic`, with a listener when its readers block on it."""
        if listen is None:
            listen = wire.TOPICS[topic][4]
        port = self._service(topic).subscriber_builder().buffer_size(wire.SUBSCRIBER_BUFFER).create()
        listener = self._event(topic).listener_builder().create() if listen else None
        s = Subscriber(topic, port, listener)
        self._ports.append(s)
        return s

    def close(self) -> None:
        """Removes every port, then the node (iceoryx2 leaves files behind otherwise)."""
        for p in reversed(self._ports):
            p.close()
        self._ports.clear()
        node, self.node = self.node, None
        if node is not None and hasattr(node, "delete"):
            node.delete()
        del node


class Publisher:
    """Writes one message type straight into loaned shared memory."""

    def __init__(self, topic: str, port, notifier):
        self.topic = topic
        self.structure = wire.TOPICS[topic][1]
        self.dtype = dtype_of(self.structure)
        self.port = port
        self.notifier = notifier

    def loan(self):
        """A loaned sample and a zeroed numpy view of its payload to fill."""
        sample = self.port.loan_uninit()
        view = _view(sample.payload_ptr, self.structure, self.dtype)
        ctypes.memset(sample.payload_ptr, 0, self.structure.SIZE)
        return sample, view

    def send(self, sample) -> None:
        """Sends a sample filled through its view, and wakes the listeners."""
        sample.assume_init().send()
        if self.notifier is not None:
            self.notifier.notify()

    def send_copy(self, message) -> None:
        """Sends a ctypes message (for the rare control messages)."""
        self.port.send_copy(message)
        if self.notifier is not None:
            self.notifier.notify()

    def close(self) -> None:
        for port in (self.port, self.notifier):
            if port is not None:
                port.delete()
        self.port = self.notifier = None


class Subscriber:
    """Receives one message type; each sample is copied out and released at once."""

    def __init__(self, topic: str, port, listener):
        self.topic = topic
        self.structure = wire.TOPICS[topic][1]
        self.dtype = dtype_of(self.structure)
        self.port = port
        self.listener = listener
        self.last_header = b""

    def receive(self) -> Optional[np.void]:
        """The next buffered message as a structured numpy record, or None.
        A copy of the message before it (same header: a send a signal
        interrupted and the publisher made again) is dropped."""
        while True:
            sample = self.port.receive()
            if sample is None:
                return None
            record = _view(sample.payload_ptr, self.structure, self.dtype).copy()
            sample.delete()
            header = record["header"].tobytes()
            if header != self.last_header:
                self.last_header = header
                return record

    def wait_event(self, seconds: float) -> bool:
        """Blocks until a wake-up or `seconds`; True if one came."""
        if self.listener is None:
            return False
        try:
            woken = self.listener.timed_wait(iox2.Duration.from_secs_f64(seconds))
        except iox2.ListenerWaitError:
            # A signal cut the wait short (Ctrl-Z and `fg`): an early wake-up.
            return False
        return len(woken) > 0

    def drain_events(self) -> None:
        """Consumes pending wake-ups."""
        if self.listener is not None:
            self.listener.try_wait()

    def close(self) -> None:
        for port in (self.port, self.listener):
            if port is not None:
                port.delete()
        self.port = self.listener = None


class ReferenceWindow:
    """The testbed's one rule for which reference sample a state uses: the
    newest at or before the state's sim time; in lockstep, only once that
    choice is final (a sample at or after the state's time has arrived).
    A sample older than the one due on the reference grid (or none) is a
    stale reference; `stale` counts them, as the Rust window does."""

    def __init__(self, bus: Bus, lockstep: bool, period_ns: int):
        self.sub = bus.subscriber("reference", listen=False)
        self.recent: deque = deque()
        self.wait_for_final = lockstep
        self.period_ns = max(int(period_ns), 1)
        self.stale = 0

    def _arrive(self, r) -> None:
        t = int(r["header"]["t_ns"])
        if not self.recent or int(self.recent[-1]["header"]["t_ns"]) <= t:
            self.recent.append(r)
        else:
            items = sorted([*self.recent, r], key=lambda x: int(x["header"]["t_ns"]))
            self.recent = deque(items)

    def take(self, t_ns: int, idle) -> Optional[np.void]:
        """The sample for `t_ns`; `idle()` runs while lockstep waits for it."""
        while True:
            while (r := self.sub.receive()) is not None:
                self._arrive(r)
            settled = bool(self.recent) and int(self.recent[-1]["header"]["t_ns"]) >= t_ns
            if settled or not self.wait_for_final:
                picked = self._pick(t_ns)
                due = t_ns // self.period_ns * self.period_ns
                if picked is None or int(picked["header"]["t_ns"]) < due:
                    self.stale += 1
                return picked
            idle()

    def _pick(self, t_ns: int) -> Optional[np.void]:
        recent = self.recent
        while len(recent) > 1 and int(recent[1]["header"]["t_ns"]) <= t_ns:
            recent.popleft()
        if recent and int(recent[0]["header"]["t_ns"]) <= t_ns:
            return recent[0]
        return None
