//! Point-to-point moves through waypoints: each segment a minimum-jerk
//! (quintic) curve from rest to rest, with a dwell at each waypoint.

use serde::{Deserialize, Serialize};

use crate::TrajectoryError;

/// The arm's posture `q` at time `t`, held for `dwell_s` before the move to
/// the next waypoint starts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Waypoint {
    /// Arrival time, s.
    pub t: f64,
    /// Joint positions, one per joint.
    pub q: Vec<f64>,
    /// How long to stay, s (default 0).
    #[serde(default)]
    pub dwell_s: f64,
}

/// The largest |q| of a waypoint, rad or m: past any joint's travel.
pub const MAX_POSITION: f64 = 1e3;

/// Checks `points`: finite, one position per joint, each move with time to
/// happen. Returns the number of joints.
pub(crate) fn validate(points: &[Waypoint]) -> Result<usize, TrajectoryError> {
    let invalid = |k: usize, key: &str, reason: String| TrajectoryError::Invalid {
        field: format!("reference.waypoints[{k}].{key}"),
        reason,
    };
    let Some(first) = points.first() else {
        return Err(invalid(0, "t", "no waypoint: give at least one".into()));
    };
    let dof = first.q.len();
    if dof == 0 {
        return Err(invalid(0, "q", "no joint position given".into()));
    }
    for (k, p) in points.iter().enumerate() {
        if p.q.len() != dof {
            return Err(invalid(
                k,
                "q",
                format!("{} positions, but waypoint 0 has {dof}", p.q.len()),
            ));
        }
        for (name, v) in [("t", p.t), ("dwell_s", p.dwell_s)]
            .into_iter()
            .chain(p.q.iter().map(|v| ("q", *v)))
        {
            if !v.is_finite() {
                return Err(TrajectoryError::NotFinite {
                    field: format!("reference.waypoints[{k}].{name}"),
                    value: v,
                });
            }
        }
        // Finite is not enough: q = 1e300 passed and overflowed every step.
        if let Some(v) = p.q.iter().find(|v| v.abs() > MAX_POSITION) {
            return Err(invalid(
                k,
                "q",
                format!("{v:e} is out of range: positions must be from -1000 to 1000 (rad or m)"),
            ));
        }
        for (name, v) in [("t", p.t), ("dwell_s", p.dwell_s)] {
            if v.abs() > crate::samples::MAX_TIME_S {
                return Err(invalid(
                    k,
                    name,
                    format!("{v:e} is out of range: times must be from -1e6 to 1e6 s"),
                ));
            }
        }
        if p.dwell_s < 0.0 {
            return Err(invalid(k, "dwell_s", format!("{} is negative", p.dwell_s)));
        }
        if k > 0 {
            let leave = points[k - 1].t + points[k - 1].dwell_s;
            if p.t <= leave {
                return Err(invalid(
                    k,
                    "t",
                    format!(
                        "{} is not after the previous waypoint's departure at {leave} s (its t plus dwell_s): a move needs time",
                        p.t
                    ),
                ));
            }
            // A 1 ns move's quintic has accelerations of 1e18 rad/s².
            if p.t - leave < crate::samples::MIN_TIME_STEP_S {
                return Err(invalid(
                    k,
                    "t",
                    format!(
                        "{} is {:e} s after the previous waypoint's departure at {leave} s: a move needs at least 1e-6 s",
                        p.t,
                        p.t - leave
                    ),
                ));
            }
        }
    }
    Ok(dof)
}

/// The value, rate and acceleration of joint `i` at `t`.
pub(crate) fn eval(points: &[Waypoint], i: usize, t: f64) -> [f64; 3] {
    // The segment whose move (departure → arrival) contains t, if any.
    let next = points.partition_point(|p| p.t <= t);
    if next == 0 {
        return [points[0].q[i], 0.0, 0.0];
    }
    let Some(to) = points.get(next) else {
        return [points[next - 1].q[i], 0.0, 0.0];
    };
    let from = &points[next - 1];
    let start = from.t + from.dwell_s;
    if t <= start {
        return [from.q[i], 0.0, 0.0];
    }
    let d = to.t - start;
    let tau = (t - start) / d;
    let delta = to.q[i] - from.q[i];
    let (t2, t3) = (tau * tau, tau * tau * tau);
    [
        from.q[i] + delta * t3 * (10.0 - 15.0 * tau + 6.0 * t2),
        delta / d * 30.0 * t2 * (1.0 - 2.0 * tau + t2),
        delta / (d * d) * 60.0 * tau * (1.0 - 3.0 * tau + 2.0 * t2),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wp(t: f64, q: f64, dwell_s: f64) -> Waypoint {
        Waypoint {
            t,
            q: vec![q],
            dwell_s,
        }
    }

    #[test]
    fn moves_rest_to_rest_and_dwell() {
        let p = [wp(0.0, 0.0, 0.5), wp(2.5, 1.0, 1.0), wp(4.5, -1.0, 0.0)];
        assert_eq!(validate(&p).unwrap(), 1);
        assert_eq!(eval(&p, 0, 0.3), [0.0, 0.0, 0.0]);
        // Half-way through the first move: half-way there, at peak speed.
        let mid = eval(&p, 0, 1.5);
        assert!((mid[0] - 0.5).abs() < 1e-12 && (mid[1] - 1.875 / 2.0).abs() < 1e-12);
        assert_eq!(eval(&p, 0, 3.0), [1.0, 0.0, 0.0]);
        assert_eq!(eval(&p, 0, 9.0), [-1.0, 0.0, 0.0]);
        // C² at the joins: derivatives match finite differences.
        for &t in &[0.5, 1.0, 2.49, 3.5, 4.0, 4.49] {
            let h = 1e-6;
            let fd = (eval(&p, 0, t + h)[0] - eval(&p, 0, t - h)[0]) / (2.0 * h);
            assert!((eval(&p, 0, t)[1] - fd).abs() < 1e-5, "t = {t}");
        }
    }

    #[test]
    fn bad_waypoints_are_named() {
        let e = validate(&[wp(0.0, 0.0, 1.0), wp(1.0, 1.0, 0.0)]).unwrap_err();
        assert!(e.to_string().starts_with("reference.waypoints[1].t"), "{e}");
        let mut two = vec![wp(0.0, 0.0, 0.0), wp(1.0, 1.0, 0.0)];
        two[1].q.push(0.0);
        let e = validate(&two).unwrap_err();
        assert!(
            e.to_string().contains("2 positions, but waypoint 0 has 1"),
            "{e}"
        );
    }

    /// Issue 48 item 10 (N12): a waypoint at q = 1e300, or a move of 1 ns,
    /// passed "finite, after the previous one" and then faulted on every
    /// step; they are refused by key, value and range, and the edges are
    /// taken.
    #[test]
    fn waypoints_beyond_physical_bounds_are_refused() {
        let e = validate(&[wp(0.0, 0.0, 0.0), wp(1.0, 1e300, 0.0)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("reference.waypoints[1].q")
                && e.contains("1e300")
                && e.contains("from -1000 to 1000"),
            "{e}"
        );
        let e = validate(&[wp(0.0, 0.0, 1.0), wp(1.0 + 1e-9, 1.0, 0.0)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("reference.waypoints[1].t") && e.contains("at least 1e-6 s"),
            "{e}"
        );
        let e = validate(&[wp(0.0, 0.0, 0.0), wp(1e300, 1.0, 0.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("from -1e6 to 1e6 s"), "{e}");
        validate(&[wp(0.0, -1e3, 0.0), wp(1e-6, 1e3, 0.0)]).unwrap();
    }
}
