//! The position gain a torque-limited joint can follow (the default
//! scenario's gains, [`crate::gains`]).
//!
//! The law's velocity loop asks for q̇ = −K1 z1. A joint whose motor can
//! accelerate it by at most a beyond its load reaches that line from rest
//! at an error E and must then decelerate at K1 q̇ = K1² z1; where K1² E > a
//! it cannot, crosses the line at full torque and swings back and forth
//! about the reference (Fetch's 0.32 N m head pan under a 87 N m base,
//! kicked 0.4 rad out, swung ±0.95 rad for 4 s at the paper's K1 = 15).
//! K1 ≤ √(a/E) keeps the joint on the line. E is the start's distance
//! from the reference, which grows with the envelope (the start is 1.5
//! envelopes out).
//!
//! The bound only lowers the paper's K1 = 15 where the joint's load needs
//! less: where the load needs more, holding it within the envelope comes
//! first (xarm7's elbow needs 60 and keeps it; lowering it to the bound
//! and widening the envelope instead made its error ten times larger).

/// What a joint's motor allows: its acceleration beyond the load and how
/// far from the reference it starts.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MotorBound {
    /// (effort − load) · min M⁻¹_ii, rad/s².
    pub accel: f64,
    /// The start's distance from the reference per unit of envelope.
    start_per_kc: f64,
}

impl MotorBound {
    /// The bound of a joint with effort limit `effort`, load `load` (N m),
    /// smallest M⁻¹_ii `minv_low`, starting `start_error` from the
    /// reference with envelope `kc`; none where the motor has no limit, no
    /// room beyond the load, or the joint starts on the reference.
    pub fn new(
        effort: Option<f64>,
        load: f64,
        minv_low: f64,
        start_error: f64,
        kc: f64,
    ) -> Option<Self> {
        let accel = (effort? - load) * minv_low;
        let start_per_kc = start_error / kc;
        (accel.is_finite() && accel > 0.0 && start_per_kc.is_finite() && start_per_kc > 0.0)
            .then_some(Self {
                accel,
                start_per_kc,
            })
    }

    /// The largest K1 the motor follows with envelope `kc`: √(a/E).
    pub fn k1_at(&self, kc: f64) -> f64 {
        (self.accel / (self.start_per_kc * kc)).sqrt()
    }

    /// The start's distance from the reference with envelope `kc`, rad.
    pub fn start_error(&self, kc: f64) -> f64 {
        self.start_per_kc * kc
    }

    /// The least time in which the motor brings the joint from its start
    /// into an envelope of offset `kc`, whose smallest value is `low` of
    /// it: accelerate half the way and brake the other, 2√(d/a), s.
    pub fn entry_time(&self, kc: f64, low: f64) -> f64 {
        let d = (self.start_error(kc) - low * kc).max(0.0);
        2.0 * (d / self.accel).sqrt()
    }
}

/// The smallest K1 a joint is given (what it gets when its load needs
/// less), and the motor bound when that is what sets it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct K1Floor {
    /// K1 at least, 1/s.
    pub k1: f64,
    /// The motor's bound, when lower than the paper's gain.
    pub motor: Option<MotorBound>,
    /// The envelope the floor is for.
    pub envelope: f64,
}

impl K1Floor {
    /// The floor with envelope `envelope`: the paper's `k1_min`, or the
    /// motor's bound where that is lower. It never lowers K1 below what
    /// the load needs: the envelope holds the load first.
    pub fn at(k1_min: f64, motor: Option<MotorBound>, envelope: f64) -> Self {
        match motor {
            Some(b) if b.k1_at(envelope) < k1_min => Self {
                k1: b.k1_at(envelope),
                motor: Some(b),
                envelope,
            },
            _ => Self {
                k1: k1_min,
                motor: None,
                envelope,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_weak_motor_lowers_the_floor_of_k1() {
        // Fetch's head pan: 0.32 N m, 0.09 N m of load, M⁻¹ 21, 0.375 rad out.
        let b = MotorBound::new(Some(0.32), 0.09, 21.0, 0.375, 0.25).unwrap();
        assert!((b.k1_at(0.25) - (0.23f64 * 21.0 / 0.375).sqrt()).abs() < 1e-12);
        // A wider envelope starts further out: a lower bound.
        assert!((b.start_error(0.5) - 0.75).abs() < 1e-12);
        assert!(b.k1_at(0.5) < b.k1_at(0.25));
        // From 0.375 rad out into an envelope whose least is 0.2 rad.
        let t = b.entry_time(0.25, 0.8);
        assert!((t - 2.0 * (0.175 / b.accel).sqrt()).abs() < 1e-12);
        let floor = K1Floor::at(15.0, Some(b), 0.25);
        assert_eq!(floor.k1, b.k1_at(0.25));
        assert!(floor.motor.is_some());
        // No bound without a limit, room or distance to cover.
        assert!(MotorBound::new(None, 0.09, 21.0, 0.375, 0.25).is_none());
        assert!(MotorBound::new(Some(0.05), 0.09, 21.0, 0.375, 0.25).is_none());
        assert!(MotorBound::new(Some(0.32), 0.09, 21.0, 0.0, 0.25).is_none());
        // A strong motor (√(290/0.375) = 27.8) leaves the paper's 15.
        let strong = MotorBound::new(Some(300.0), 10.0, 1.0, 0.375, 0.25);
        let floor = K1Floor::at(15.0, strong, 0.25);
        assert_eq!((floor.k1, floor.motor.is_none()), (15.0, true));
    }
}
