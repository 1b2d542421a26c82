"""Read a run's log with the official ROS 2 decoders, one table per topic.

    python3 python/examples/read_log.py runs/<id>/run.mcap          # rows and fields per topic
    python3 python/examples/read_log.py runs/<id>/run.mcap --json   # the same as JSON (the tests use it)
"""

import json
import sys

import testbed_controller.log as tlog


def main() -> int:
    args = sys.argv[1:]
    if not args:
        print(__doc__, file=sys.stderr)
        return 2
    log = tlog.read_log(args[0])
    if "--json" in args:
        out = {
            "log_format": log.log_format,
            "rows": {t: len(table["log_time_ns"]) for t, table in log.items()},
            "types": log.types,
            "dof": len(log.run.get("joint_names", "").split(",")),
            "q_shape": list(log["/joint_state"]["q"].shape),
            "last_t": float(log["/joint_state"]["t"][-1]),
        }
        print(json.dumps(out))
        return 0
    print(f"{log.path}: log format {log.log_format}, robot {log.run.get('robot')}")
    for topic, table in log.items():
        rows = len(table["log_time_ns"])
        print(f"{topic} ({log.types[topic]}): {rows} rows")
        for name, col in table.items():
            print(f"    {name}: {col.dtype} {col.shape}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
