//! The motors behind the joints (`[plant.actuator]`): the torque each gives
//! over a period, in closed form, and the torque its transmission passes
//! to the link. A series-elastic joint's motor angle and speed are states
//! the engine integrates with the arm (the drive's extra states: all n
//! angles, then all n speeds).

use crate::JointActuator;

/// Every joint's motor, and its torque over the current period.
#[derive(Debug, Clone)]
pub(super) struct Motors {
    joints: Vec<JointActuator>,
    /// The motor torque at the period's start.
    start: Vec<f64>,
    /// The command it moves towards over the period (after saturation).
    target: Vec<f64>,
    lags: bool,
    elastic: bool,
}

impl Motors {
    pub(super) fn new(joints: Vec<JointActuator>) -> Self {
        let n = joints.len();
        Self {
            lags: joints.iter().any(JointActuator::lags),
            elastic: joints.iter().any(|j| j.spring.is_some()),
            joints,
            start: vec![0.0; n],
            target: vec![0.0; n],
        }
    }

    /// The number of states the engine integrates for the motors: each
    /// joint's motor angle and speed when any joint is elastic.
    pub(super) fn extra_states(&self) -> usize {
        if self.elastic {
            2 * self.joints.len()
        } else {
            0
        }
    }

    /// Each joint's actuator.
    pub(super) fn joints(&self) -> &[JointActuator] {
        &self.joints
    }

    /// Starts a period in which the motors are told `command`.
    pub(super) fn begin(&mut self, command: &[f64]) {
        self.target.copy_from_slice(command);
        if !self.lags {
            self.start.copy_from_slice(command);
        }
    }

    /// Motor i's torque `s` seconds into the period.
    pub(super) fn torque_at(&self, i: usize, s: f64) -> f64 {
        let j = &self.joints[i];
        response(
            self.start[i],
            self.target[i],
            j.time_constant,
            j.slew_rate,
            s,
        )
        .0
    }

    /// Each motor's mean torque over a period of `dt` into `out`.
    pub(super) fn mean_into(&self, dt: f64, out: &mut [f64]) {
        if !self.lags {
            // Exactly the command, not its integral over dt divided by dt.
            out.copy_from_slice(&self.target);
            return;
        }
        for (i, (o, j)) in out.iter_mut().zip(&self.joints).enumerate() {
            *o = response(
                self.start[i],
                self.target[i],
                j.time_constant,
                j.slew_rate,
                dt,
            )
            .1 / dt;
        }
    }

    /// Ends a period of `dt`: the next one starts where this one ended.
    pub(super) fn end(&mut self, dt: f64) {
        if self.lags {
            for i in 0..self.start.len() {
                self.start[i] = self.torque_at(i, dt);
            }
        }
    }

    /// The torque on joint i's link and, for an elastic joint, its motor's
    /// acceleration, at the link's (q, q̇), the motor states `x` and time `s`
    /// into the period.
    pub(super) fn drive(&self, i: usize, s: f64, q: f64, qd: f64, x: &[f64]) -> (f64, f64) {
        let j = &self.joints[i];
        let motor = self.torque_at(i, s);
        match &j.spring {
            // Not `motor + 0.0`: a torque of −0 stays −0, as without motors.
            None if j.cogging.is_empty() => (motor, 0.0),
            None => (motor + j.cogging_at(q), 0.0),
            Some(spring) => {
                let n = self.joints.len();
                let (theta, theta_dot) = (x[i], x[n + i]);
                let link = spring.torque(theta - q, theta_dot - qd);
                let accel = (motor + j.cogging_at(theta) - link) / spring.motor_inertia;
                (link, accel)
            }
        }
    }

    /// Puts every motor where its link is, its spring unloaded, into `x`.
    pub(super) fn rest_at(&self, q: &[f64], qd: &[f64], x: &mut [f64]) {
        if self.elastic {
            let n = q.len();
            x[..n].copy_from_slice(q);
            x[n..].copy_from_slice(qd);
        }
    }
}

/// A motor torque that starts at `from` and is told `to`, moving through a
/// first-order lag of time constant `tc` (0: none) no faster than `slew`
/// (infinite: no limit): its value at `s` and its integral over [0, s].
///
/// While the lag would move faster than the slew limit, the torque ramps
/// at the limit; once the gap is down to slew·tc, it decays exponentially.
pub(crate) fn response(from: f64, to: f64, tc: f64, slew: f64, s: f64) -> (f64, f64) {
    let gap = (to - from).abs();
    let sign = (to - from).signum();
    if gap == 0.0 {
        return (to, to * s);
    }
    // The gap below which the lag moves slower than the slew limit.
    let lag_gap = if slew.is_infinite() {
        f64::INFINITY
    } else {
        slew * tc
    };
    let ramp_end = if gap > lag_gap {
        (gap - lag_gap) / slew
    } else {
        0.0
    };
    if ramp_end > 0.0 && s <= ramp_end {
        return (from + sign * slew * s, from * s + sign * slew * s * s / 2.0);
    }
    // (Not slew · 0 when there is no ramp: the slew may be infinite.)
    let ramped = if ramp_end > 0.0 {
        from * ramp_end + sign * slew * ramp_end * ramp_end / 2.0
    } else {
        0.0
    };
    let (u, left) = (s - ramp_end, gap.min(lag_gap));
    if tc == 0.0 {
        return (to, ramped + to * u);
    }
    // −expm1(−u/tc) = 1 − e^(−u/tc), exact for small u.
    let decayed = -(-u / tc).exp_m1();
    (
        to - sign * left * (1.0 - decayed),
        ramped + to * u - sign * left * tc * decayed,
    )
}

#[cfg(test)]
mod tests {
    use super::response;

    #[test]
    fn a_lag_alone_is_the_exponential() {
        let (v, int) = response(0.0, 2.0, 0.1, f64::INFINITY, 0.3);
        let e = (-3.0f64).exp();
        assert!((v - 2.0 * (1.0 - e)).abs() < 1e-15);
        assert!((int - 2.0 * (0.3 - 0.1 * (1.0 - e))).abs() < 1e-15);
    }

    #[test]
    fn a_slew_limit_alone_is_a_ramp_then_the_command() {
        assert_eq!(response(1.0, -1.0, 0.0, 10.0, 0.1), (0.0, 0.05));
        let (v, int) = response(1.0, -1.0, 0.0, 10.0, 0.5);
        assert_eq!(v, -1.0);
        // Ramp 1 → −1 over 0.2 s (integral 0), then −1 for 0.3 s.
        assert!((int + 0.3).abs() < 1e-15);
    }

    #[test]
    fn lag_and_slew_ramp_until_the_lag_is_slower() {
        // Gap 10, slew 20, tc 0.1: ramp until the gap is 2 (0.4 s), then
        // decay from a gap of 2 at 20 N m/s, continuous in value and rate.
        let (v, _) = response(0.0, 10.0, 0.1, 20.0, 0.4);
        assert!((v - 8.0).abs() < 1e-12);
        let h = 1e-7;
        let (a, _) = response(0.0, 10.0, 0.1, 20.0, 0.4 + h);
        assert!(((a - v) / h - 20.0).abs() < 1e-4);
        let (w, _) = response(0.0, 10.0, 0.1, 20.0, 0.5);
        assert!((w - (10.0 - 2.0 * (-1.0f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn nothing_set_follows_at_once() {
        assert_eq!(response(3.0, 5.0, 0.0, f64::INFINITY, 0.2), (5.0, 1.0));
    }
}
