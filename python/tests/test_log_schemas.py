"""The log reader checks each channel's stored schema before it decodes a
message (#48 item 4): this build's schemas read; a testbed message from an
older build (a field fewer) reads; a field whose type changed, a schema
without a header, a 5 MB schema, a deeply nested one and an unknown
testbed message are refused, naming the file, the topic and the field; a
standard message whose schema is not this build's is left out and said."""

import os
import tempfile
import unittest

from mcap.writer import Writer as RawWriter
from mcap_ros2.writer import Writer

from testbed_controller.log import MAX_SCHEMA_BYTES, read_log
from testbed_controller.log_schemas import SCHEMAS

TOPIC = "/command"
NAME, TEXT = SCHEMAS[TOPIC]


def command(seq: int) -> dict:
    return {
        "header": {"stamp": {"sec": 0, "nanosec": seq * 1_000_000}, "frame_id": ""},
        "seq": seq,
        "wall_ns": 0,
        "dof": 2,
        "fault": 0,
        "tau": [1.0, 2.0],
        "state_wall_ns": 0,
        "compute_ns": 0,
        "started_wall_ns": 0,
        "reference_t_ns": 0,
        "stale_references": 0,
    }


class LogSchemas(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)

    def log(self, name: str, text: str, message=command, topic: str = TOPIC) -> str:
        """A log of three messages on `topic` under the schema (`name`,
        `text`), each encoded with this build's schema (a hostile schema is
        stored, never parsed, by the writer)."""
        encoded = os.path.join(self.dir.name, "encoded.mcap")
        with open(encoded, "wb") as f:
            w = Writer(f)
            schema = w.register_msgdef(NAME, TEXT)
            for seq in range(3):
                w.write_message(TOPIC, schema, message(seq), seq)
            w.finish()
        from mcap.reader import make_reader

        with open(encoded, "rb") as f:
            payloads = [m.data for _, _, m in make_reader(f).iter_messages()]
        path = os.path.join(self.dir.name, "run.mcap")
        with open(path, "wb") as f:
            w = RawWriter(f)
            w.start(profile="ros2", library="test")
            w.add_metadata("testbed.run", {"log_format": "3"})
            sid = w.register_schema(name, "ros2msg", text.encode())
            cid = w.register_channel(topic, "cdr", sid)
            for seq, data in enumerate(payloads):
                w.add_message(cid, seq, data, seq, seq)
            w.finish()
        return path

    def refused(self, path: str, *words: str) -> str:
        with self.assertRaises(ValueError) as e:
            read_log(path)
        text = str(e.exception)
        for w in (path, TOPIC) + words:
            self.assertIn(w, text)
        return text

    def test_this_builds_schema_reads(self):
        log = read_log(self.log(NAME, TEXT))
        self.assertEqual(log[TOPIC]["tau"].shape, (3, 2))
        self.assertEqual(list(log[TOPIC]["seq"]), [0, 1, 2])

    def test_an_older_testbed_message_with_a_field_fewer_reads(self):
        older = TEXT.replace("uint64 stale_references\n", "")
        self.assertNotEqual(older, TEXT)

        def message(seq):
            m = command(seq)
            del m["stale_references"]
            return m

        log = read_log(self.log(NAME, older, message))
        self.assertNotIn("stale_references", log[TOPIC])
        self.assertEqual(list(log[TOPIC]["dof"]), [2, 2, 2])

    def test_a_field_whose_type_changed_is_refused(self):
        wider = TEXT.replace("uint32 dof", "uint64 dof")
        self.refused(self.log(NAME, wider), "field 'dof'", "uint64 in the log, uint32")

    def test_a_schema_without_fields_is_refused(self):
        self.refused(self.log(NAME, ""), "no std_msgs/Header header")

    def test_a_schema_of_5_mb_is_refused_before_it_is_parsed(self):
        huge = TEXT + "uint32 X=1\n" * (5 * 1024 * 1024 // 11)
        self.refused(self.log(NAME, huge), f"at most {MAX_SCHEMA_BYTES}")

    def test_a_deeply_nested_schema_is_refused(self):
        depth = 500  # under the size bound; deep enough for a RecursionError
        text = "std_msgs/Header header\nT0 a\n"
        for k in range(depth):
            nxt = f"T{k + 1} a\n" if k + 1 < depth else "uint32 x\n"
            text += "=" * 80 + f"\nMSG: testbed_msgs/T{k}\n{nxt}"
        self.refused(self.log(NAME, text), "type T0 is not one testbed messages use")

    def test_a_standard_message_of_another_schema_is_left_out_and_said(self):
        text = "float64 x\n"
        log = read_log(self.log("geometry_msgs/msg/Foo", text))
        self.assertNotIn(TOPIC, log)
        self.assertIn("not the one this build writes", log.skipped[TOPIC])

    def test_an_unknown_testbed_message_is_refused(self):
        self.refused(self.log("testbed_msgs/msg/Foo", TEXT), "not a testbed message this build knows")


if __name__ == "__main__":
    unittest.main()
