"""The generated wire module against ctypes and numpy."""

import ctypes
import unittest

import numpy as np

from testbed_controller import wire
from testbed_controller.bus import dtype_of


class WireLayout(unittest.TestCase):
    def test_every_structure_has_rusts_size_alignment_and_offsets(self):
        for name in wire.STRUCTURES:
            s = getattr(wire, name)
            self.assertEqual(ctypes.sizeof(s), s.SIZE, name)
            self.assertEqual(ctypes.alignment(s), s.ALIGN, name)
            for field, offset in s.OFFSETS.items():
                self.assertEqual(getattr(s, field).offset, offset, f"{name}.{field}")

    def test_numpy_views_match_ctypes(self):
        for name in wire.STRUCTURES:
            s = getattr(wire, name)
            dt = dtype_of(s)
            self.assertEqual(dt.itemsize, s.SIZE, name)
            for field, offset in s.OFFSETS.items():
                self.assertEqual(dt.fields[field][1], offset, f"{name}.{field}")

    def test_a_value_written_with_ctypes_reads_back_through_numpy(self):
        m = wire.JointState()
        m.header.t_ns = 123_000_000
        m.dof = 2
        m.q_measured[1] = -0.25
        view = np.frombuffer(bytes(m), dtype=dtype_of(wire.JointState))[0]
        self.assertEqual(int(view["header"]["t_ns"]), 123_000_000)
        self.assertEqual(float(view["q_measured"][1]), -0.25)

    def test_topics_name_their_messages_and_versions(self):
        name, message, pubs, notifiers, waiters = wire.TOPICS["command"]
        self.assertEqual(name, "testbed/command")
        self.assertIs(message, wire.Command)
        self.assertTrue(message.type_name().startswith("testbed.Command.v"))
        self.assertTrue(waiters)
        self.assertGreaterEqual(notifiers, pubs)
        self.assertFalse(wire.TOPICS["reference"][4])


if __name__ == "__main__":
    unittest.main()
