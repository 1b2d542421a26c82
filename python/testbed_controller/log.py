"""Read a run's log (`runs/<id>/run.mcap`) into numpy tables, one per topic.

    import testbed_controller.log as tlog
    log = tlog.read_log("runs/<id>/run.mcap")
    state = log["/joint_state"]           # dict of numpy arrays
    state["t"], state["q"][:, 0]          # sim time (s), joint 1's position
    diag = log["/controller/diagnostics"]
    own = log["/controller/own_diagnostics"]   # an external controller's own:
    own["integral"]                       # by declared name (rows x joints)
    log.run["joint_names"], log.stats     # the run's metadata and the logger's counts

Built on the official readers: `mcap` for the file and `mcap-ros2-support`
for the messages (CDR with `ros2msg` schemas, log format 3), so every field
is decoded by the same code ROS 2 tools use; nothing here knows the
testbed's message layouts beyond checking each channel's stored schema
against the ones this build writes (`log_schemas.py`) before a message is
decoded. A testbed message's schema is checked as the Rust reader checks
it: one over 64 KiB, whose field types differ from this build's (a uint64
where it writes a uint32), that has no header, or that defines types
beyond the header's, is refused with a ValueError naming the file, the
topic and the field. A standard message (markers, /tf, sensor_msgs) whose
schema is not this build's text (an older log's markers) is left out, and
`Log.skipped` says why: the Rust reader does not read those either.

Each table has a row per message, in log order: `log_time_ns`; `t_ns` and
`t` (seconds) from `header.stamp` when the message has one; every numeric
field (nested fields as `a.b`); per-joint `float64[]` fields as 2-D arrays
(rows × joints). A field whose rows differ in length (or that holds
strings or messages) is an object array. `to_dataframe` turns a table into
a pandas DataFrame (`q[0]`, `q[1]`, … for per-joint fields), if pandas is
installed.
"""

from __future__ import annotations

from typing import Dict, Iterable, List, Optional

import numpy as np

from .log_schemas import SCHEMAS

__all__ = ["Log", "read_log", "to_dataframe"]

#: The largest stored schema read (this build's largest is under 3 KiB).
MAX_SCHEMA_BYTES = 64 * 1024
#: Most fields a testbed message's schema may have (as the Rust reader).
MAX_SCHEMA_FIELDS = 256
#: The field types testbed messages use (as the Rust reader).
FIELD_TYPES = {"std_msgs/Header", "uint32", "uint64", "int64", "float64", "float64[]"}
_SEPARATOR = "=" * 80


class Log(dict):
    """Topic → table (a dict of numpy arrays), with the run's metadata."""

    def __init__(self, path: str):
        super().__init__()
        self.path = path
        #: The `testbed.run` metadata (scenario TOML, mode, joint names, ...).
        self.run: Dict[str, str] = {}
        #: The logger's counts (`testbed.log_stats`), empty if it never finished.
        self.stats: Dict[str, str] = {}
        #: ROS 2 type of each topic (`testbed_msgs/msg/JointState`, ...).
        self.types: Dict[str, str] = {}
        #: Topics left out, and why (a standard message whose stored
        #: schema is not this build's).
        self.skipped: Dict[str, str] = {}

    @property
    def log_format(self) -> int:
        return int(self.run.get("log_format", "1"))


def _is_message(x) -> bool:
    return hasattr(x, "__slots__") and not isinstance(x, (str, bytes))


def _flatten(msg, prefix: str, row: Dict[str, object]) -> None:
    for name in msg.__slots__:
        value = getattr(msg, name)
        key = prefix + name
        if _is_message(value):
            _flatten(value, key + ".", row)
        else:
            row[key] = value


def _column(values: List[object]) -> np.ndarray:
    first = values[0]
    if isinstance(first, bool):
        return np.array(values, dtype=bool)
    if isinstance(first, int):
        try:
            return np.array(values, dtype=np.int64)
        except OverflowError:
            return np.array(values, dtype=np.uint64)
    if isinstance(first, float):
        return np.array(values, dtype=np.float64)
    if isinstance(first, (list, tuple)) and all(
        isinstance(v, (list, tuple)) and len(v) == len(first) for v in values
    ):
        if all(isinstance(x, (int, float)) for v in values[:1] for x in v):
            return np.array(values, dtype=np.float64).reshape(len(values), len(first))
    out = np.empty(len(values), dtype=object)
    out[:] = values
    return out


def _table(rows: List[Dict[str, object]], log_times: List[int]) -> Dict[str, np.ndarray]:
    table: Dict[str, np.ndarray] = {"log_time_ns": np.array(log_times, dtype=np.int64)}
    if "header.stamp.sec" in rows[0]:
        t_ns = np.array(
            [r["header.stamp.sec"] * 1_000_000_000 + r["header.stamp.nanosec"] for r in rows],
            dtype=np.int64,
        )
        table["t_ns"] = t_ns
        table["t"] = t_ns / 1e9
    for key in rows[0]:
        table[key] = _column([r[key] for r in rows])
    return table


def _own_by_name() -> Dict[str, str]:
    return {name: text for name, text in SCHEMAS.values()}


def _fields(where: str, text: str) -> Dict[str, str]:
    """A testbed message's main fields (name -> type), checked as the Rust
    reader checks them (`logger/src/msg_schema.rs`)."""
    fields: Dict[str, str] = {}
    for number, raw in enumerate(text.split("\n"), 1):
        line = raw.split("#", 1)[0].strip()
        if line.startswith("===="):
            break
        if not line or "=" in line:
            continue
        words = line.split()
        if len(words) != 2:
            raise ValueError(f"{where}, line {number}: {line[:80]!r} is not a field (TYPE NAME)")
        ty, name = words
        if ty not in FIELD_TYPES:
            raise ValueError(
                f"{where}, field '{name[:80]}': type {ty[:80]} is not one testbed messages use "
                f"({', '.join(sorted(FIELD_TYPES))})"
            )
        if name in fields:
            raise ValueError(f"{where}: field '{name}' appears twice")
        fields[name] = ty
        if len(fields) > MAX_SCHEMA_FIELDS:
            raise ValueError(f"{where}: more than {MAX_SCHEMA_FIELDS} fields")
    return fields


def _definitions(text: str) -> str:
    """The types a schema defines after its main message."""
    at = text.find(_SEPARATOR)
    return text[at:] if at >= 0 else ""


def _check_schema(path: str, topic: str, schema, own: Dict[str, str]) -> Optional[str]:
    """Refuses a stored schema this reader cannot trust to decode (see the
    module's docstring); None if it reads, or why a standard message's
    channel is left out."""
    name = schema.name if schema is not None else ""
    where = f"{path}: channel {topic} (schema {name[:80] or 'none'})"
    if schema is None or schema.encoding != "ros2msg":
        raise ValueError(f"{where}: a log of format 3 stores ros2msg schemas")
    if len(schema.data) > MAX_SCHEMA_BYTES:
        raise ValueError(
            f"{where}: the schema is {len(schema.data)} bytes (at most {MAX_SCHEMA_BYTES})"
        )
    try:
        text = schema.data.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError(f"{where}: the schema is not UTF-8 text") from None
    mine = own.get(name)
    if mine == text:
        return None
    if not name.startswith("testbed_msgs/"):
        return f"schema {name[:80]} is not the one this build writes: left out"
    if mine is None:
        raise ValueError(f"{where}: not a testbed message this build knows")
    # An older or newer testbed message: read by its own fields, as long
    # as each field this build also has keeps its type.
    fields = _fields(where, text)
    if "header" not in fields:
        raise ValueError(f"{where}: the schema has no std_msgs/Header header")
    if _definitions(text) != _definitions(mine):
        raise ValueError(f"{where}: the schema defines types beyond std_msgs/Header's")
    for field, ty in _fields(name, mine).items():
        if field in fields and fields[field] != ty:
            raise ValueError(
                f"{where}, field '{field}': {fields[field]} in the log, {ty} in this build"
            )
    return None


def read_log(path: str, topics: Optional[Iterable[str]] = None) -> Log:
    """Every message of the log at `path` (or of `topics` only), decoded by
    the official ROS 2 decoder, as one table per topic. A log of format 1 or
    2 (JSON messages) is refused: `testbed replay --csv` reads those."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    log = Log(path)
    rows: Dict[str, List[Dict[str, object]]] = {}
    times: Dict[str, List[int]] = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for record in reader.iter_metadata():
            if record.name == "testbed.run":
                log.run = dict(record.metadata)
            elif record.name == "testbed.log_stats":
                log.stats = dict(record.metadata)
        if log.log_format < 3:
            raise ValueError(
                f"{path} is a log of format {log.log_format} (JSON messages); "
                "read it with `testbed replay --csv`"
            )
        wanted = list(topics) if topics is not None else None
        own = _own_by_name()
        factory = DecoderFactory()
        decoders: Dict[int, object] = {}
        for schema, channel, message in reader.iter_messages(topics=wanted, log_time_order=False):
            if channel.topic in log.skipped:
                continue
            decode = decoders.get(channel.id)
            if decode is None:
                why = _check_schema(path, channel.topic, schema, own)
                if why is not None:
                    log.skipped[channel.topic] = why
                    continue
                decode = factory.decoder_for(channel.message_encoding, schema)
                if decode is None:
                    raise ValueError(
                        f"{path}: channel {channel.topic}: no decoder for "
                        f"{channel.message_encoding!r} messages"
                    )
                decoders[channel.id] = decode
            log.types.setdefault(channel.topic, schema.name)
            row: Dict[str, object] = {}
            _flatten(decode(message.data), "", row)
            rows.setdefault(channel.topic, []).append(row)
            times.setdefault(channel.topic, []).append(message.log_time)
    for topic, r in rows.items():
        log[topic] = _table(r, times[topic])
    _name_own_values(log)
    return log


OWN_TOPIC = "/controller/own_diagnostics"


def _name_own_values(log: Log) -> None:
    """Adds each declared own diagnostic (metadata `controller_diagnostics`,
    `name:shape,…`) to its table by name, cut from the `values` rows."""
    table = log.get(OWN_TOPIC)
    layout = [e.split(":", 1) for e in log.run.get("controller_diagnostics", "").split(",") if e]
    if table is None or not layout or "values" not in table:
        return
    values = table["values"]
    if values.dtype == object:
        raise ValueError(f"{log.path}: {OWN_TOPIC} rows differ in length")
    # count = dof x (per-joint ones) + (scalars): no joint name is parsed.
    per_joint = sum(shape == "joints" for _, shape in layout)
    scalars = len(layout) - per_joint
    dof = (values.shape[1] - scalars) // per_joint if per_joint else 0
    at = 0
    for name, shape in layout:
        size = dof if shape == "joints" else 1
        part = values[:, at : at + size]
        table[name] = part if shape == "joints" else part[:, 0]
        at += size


def to_dataframe(table: Dict[str, np.ndarray]):
    """A table as a pandas DataFrame: per-joint arrays become `name[i]` columns."""
    import pandas as pd

    cols: Dict[str, np.ndarray] = {}
    for key, v in table.items():
        if v.ndim == 2:
            for i in range(v.shape[1]):
                cols[f"{key}[{i}]"] = v[:, i]
        else:
            cols[key] = v
    return pd.DataFrame(cols)
