"""The node loop's handling of what a controller returns (no bus needed)."""

import unittest

import numpy as np

import testbed_controller as tc
from testbed_controller import wire
from testbed_controller.bus import dtype_of
from testbed_controller.node import Loop, parse_own_layout


def reference(n, kc=0.5):
    r = np.zeros(1, dtype=dtype_of(wire.ReferenceSample))[0]
    r["kc"][:n] = kc
    return r


class Fixed(tc.Controller):
    def __init__(self, tau):
        self.tau = tau

    def step(self, state, ref):
        return self.tau


def loop_for(controller, n=2):
    loop = Loop.__new__(Loop)  # the per-step logic alone, without ports
    loop.c, loop.n = controller, n
    return loop


def state(n=2):
    return tc.State(seq=0, t_ns=0, t=0.0, q=np.zeros(n), qd=np.zeros(n))


class LoopFaults(unittest.TestCase):
    def test_a_finite_torque_passes(self):
        fault, tau, _ = loop_for(Fixed(np.array([1.0, -2.0]))).compute(state(), reference(2))
        self.assertEqual(fault, 0)
        np.testing.assert_array_equal(tau, [1.0, -2.0])

    def test_a_non_finite_torque_becomes_zero_with_the_fault(self):
        fault, tau, _ = loop_for(Fixed(np.array([np.nan, 1.0]))).compute(state(), reference(2))
        self.assertEqual(fault, wire.FAULT_NON_FINITE_OUTPUT)
        np.testing.assert_array_equal(tau, [0.0, 0.0])

    def test_no_reference_and_a_bad_envelope_are_faults_without_a_step(self):
        loop = loop_for(Fixed(None))
        self.assertEqual(loop.compute(state(), None)[0], wire.FAULT_NO_REFERENCE)
        self.assertEqual(loop.compute(state(), reference(2, kc=0.0))[0], wire.FAULT_ENVELOPE_NOT_POSITIVE)

    def test_a_torque_of_the_wrong_shape_is_an_error_naming_the_controller(self):
        with self.assertRaisesRegex(ValueError, "Fixed.step returned a torque of shape"):
            loop_for(Fixed(np.zeros(3))).compute(state(), reference(2))

    def test_gains_resolve_one_number_or_one_per_joint(self):
        run = tc.RunInfo(dof=2, period_ns=1_000_000, mode="lockstep", params={"k1": 15.0, "k2": [1.0, 2.0]})
        np.testing.assert_array_equal(run.gain("k1"), [15.0, 15.0])
        np.testing.assert_array_equal(run.gain("k2"), [1.0, 2.0])
        self.assertEqual(run.dt, 1e-3)
        bad = tc.RunInfo(dof=3, period_ns=1, mode="lockstep", params={"k2": [1.0, 2.0]})
        with self.assertRaisesRegex(ValueError, "2 entries for 3 joints"):
            bad.gain("k2")


class Port:
    """A publisher's stand-in: loans a zeroed message, keeps what is sent."""

    def __init__(self, structure):
        self.dtype = dtype_of(structure)
        self.sent = []

    def loan(self):
        view = np.zeros(1, dtype=self.dtype)[0]
        return view, view

    def send(self, sample):
        self.sent.append(sample)


class OwnDiagnostics(unittest.TestCase):
    def own_loop(self, layout="integral:joints,windup:scalar"):
        loop = loop_for(Fixed(None))
        loop.own_layout = parse_own_layout(layout)
        loop.own_names = frozenset(name for name, _ in loop.own_layout)
        loop.own = Port(wire.OwnDiagnostics)
        loop.diags = Port(wire.ControllerDiagnostics)
        return loop

    def header(self):
        return {"seq": 4, "t_ns": 4_000_000, "wall_ns": 7}

    def test_values_follow_the_launchers_layout(self):
        loop = self.own_loop()
        loop.publish_own(self.header(), 9, {"windup": 0.5, "integral": np.array([1.0, 2.0])})
        o = loop.own.sent[0]
        self.assertEqual(int(o["count"]), 3)
        np.testing.assert_array_equal(o["values"][:4], [1.0, 2.0, 0.5, 0.0])
        self.assertEqual(int(o["header"]["seq"]), 4)

    def test_a_step_without_diagnostics_publishes_nan(self):
        loop = self.own_loop()
        loop.publish_own(self.header(), 9, None)
        self.assertTrue(np.isnan(loop.own.sent[0]["values"][:3]).all())

    def test_missing_or_misshapen_values_are_named(self):
        loop = self.own_loop()
        with self.assertRaisesRegex(KeyError, "gives no 'windup'"):
            loop.publish_own(self.header(), 9, {"integral": np.zeros(2)})
        with self.assertRaisesRegex(ValueError, r"\['integral'\] has 3 values; its shape 'joints' takes 2"):
            loop.publish_own(self.header(), 9, {"integral": np.zeros(3), "windup": 0.0})

    def test_an_undeclared_diagnostic_is_named_with_the_declared_ones(self):
        loop = self.own_loop()
        with self.assertRaisesRegex(KeyError, "names 'my_integral', neither .* \\(integral, windup\\)"):
            loop.publish_diagnostics(self.header(), 9, 0, state(), None, 0, np.zeros(2), {"my_integral": 1.0})

    def test_a_bad_layout_is_refused(self):
        with self.assertRaisesRegex(ValueError, "not name:scalar or name:joints"):
            parse_own_layout("x:vector")

    def test_describe_declares_the_diagnostics(self):
        class PID(tc.Controller):
            name = "pid"
            own_diagnostics = {"integral": "joints"}

        self.assertEqual(PID().describe()["diagnostics"], {"integral": "joints"})


if __name__ == "__main__":
    unittest.main()
