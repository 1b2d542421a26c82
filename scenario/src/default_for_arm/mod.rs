//! A scenario that works on any arm: what `--robot PATH` runs when no
//! scenario file is given.
//!
//! Gripper and finger joints (and joints that move no mass) are locked, so
//! the controller drives the arm. Per joint: a smooth sinusoid about the
//! middle of its range, an envelope of about 0.25 rad, an initial state
//! outside the envelope so the deferred constraint is exercised, and gains
//! K1_i, K2_i chosen from what the plant reports (the controller itself
//! still gets no model; see [`crate::gains`]). An arm whose file names a
//! home pose (an MJCF keyframe `home`) starts there, the reference placed
//! so that the start is as far outside the envelope. A joint no gain holds at the
//! rate against the barrier term (a feather-light link) gets armature, or is
//! locked if it moves under 1 % of the arm's mass; [`ArmDefault`] says which
//! and why, with any gravity load beyond an effort limit.

mod checks;
mod locks;
mod reference;
mod types;

use plant_rapier::{ArmModel, Locks, PerJoint, PlantError};
use trajectory::{EnvelopeConfig, ReferenceConfig};

use crate::gains::choose_gains;
use crate::{Initial, Scenario};
use checks::{
    REFERENCE_EFFORT_SHARE, armature_purpose, friction_beyond_effort, nothing_to_control,
    overloaded, too_weak, warnings, within_effort,
};
pub use locks::GRIPPER_LOCK;
use locks::{default_locks, lock_position};
use reference::{home_start, kc_cap, offsets_for_start, shape};
pub use types::ArmDefault;

/// A joint that moves less than this fraction of the arm's moving mass is a
/// placeholder: where no gain holds it, it is locked rather than given
/// armature.
const PLACEHOLDER_FRACTION: f64 = 0.01;

/// How many times the default scenario is re-chosen after adding armature
/// or locking a joint no gain holds.
const ADJUSTMENTS: usize = 4;

impl ArmDefault {
    /// The default scenario for the arm in `urdf` (see the module docs).
    pub fn new(urdf: &str) -> Result<Self, PlantError> {
        Self::with_locks(urdf, &Locks::new())
    }

    /// The default scenario with the joints of `user` locked where it says
    /// before anything else is chosen (`--set plant.lock.J=…`): the
    /// remedy for an arm of more joints than a sample carries.
    pub fn with_locks(urdf: &str, user: &Locks) -> Result<Self, PlantError> {
        let full = ArmModel::from_urdf_str(urdf)?;
        let mut chosen: Vec<(String, f64, String)> = user
            .iter()
            .map(|(n, p)| (n.clone(), *p, "locked as asked (plant.lock)".to_string()))
            .collect();
        chosen.extend(
            default_locks(&full)
                .into_iter()
                .filter(|(n, ..)| !user.contains_key(n)),
        );
        let mut armature: Vec<(String, f64, String)> = Vec::new();
        let mut amplitude: Vec<(String, f64)> = Vec::new();
        let mut attempt = 0;
        loop {
            let (d, model) = match Self::attempt(urdf, &chosen, &armature, &amplitude) {
                // A joint with no inertia about its axis (AL5D's wrist) has
                // no acceleration: lock it, as one that moves no mass is.
                Err(PlantError::SingularInertia { joint, .. })
                    if chosen.len() + 1 < full.dof() && !chosen.iter().any(|c| c.0 == joint) =>
                {
                    let limits =
                        (full.joints.iter().find(|j| j.name == joint)).and_then(|j| j.limits);
                    chosen.push((
                        joint,
                        lock_position(limits),
                        "nothing it moves has inertia about its axis (M(q) is singular there), so its acceleration is undefined".to_string(),
                    ));
                    continue;
                }
                other => other?,
            };
            if d.gains.stability_number >= 2.0 {
                // The gains aim for 1 everywhere checked: 2 is a failure of
                // the choice, never a run.
                return Err(PlantError::InvalidConfig {
                    key: "controller.k2 (the default)".into(),
                    value: format!(
                        "gains with Δt·λmax(K2^½ M⁻¹ K2^½) = {:.3} at a posture along the reference",
                        d.gains.stability_number
                    ),
                    need: "below 2 (the sampled loop's stability limit): write a scenario with lower k2 or a higher rate_hz".into(),
                });
            }
            let unheld = d.gains.unheld();
            attempt += 1;
            // A motor that cannot bring its joint in by T_c is locked even
            // after the last try: the swings were cut as far as they go.
            let weak = too_weak(&d, attempt > ADJUSTMENTS);
            if weak.len() == model.dof() {
                return Err(nothing_to_control(&weak));
            }
            if !weak.is_empty() {
                chosen.extend(weak);
                continue;
            }
            if attempt > ADJUSTMENTS {
                return Ok(d);
            }
            let overloaded = overloaded(&d);
            if !overloaded.is_empty() && overloaded.len() < model.dof() {
                chosen.extend(overloaded);
                continue;
            }
            let slower = within_effort(&d);
            if !slower.is_empty() {
                for (name, f) in slower {
                    match amplitude.iter_mut().find(|(n, _)| *n == name) {
                        Some(a) => a.1 *= f,
                        None => amplitude.push((name, f)),
                    }
                }
                continue;
            }
            if unheld.is_empty() {
                return Ok(d);
            }
            // Lock placeholders, give the others armature; then choose again.
            let controlled = model.dof();
            let mut locked_now = 0;
            for i in unheld {
                let g = &d.gains.joints[i];
                let ji = model.actuated[i];
                let moved = model.subtree_mass(model.joints[ji].child);
                let need = g.armature_needed.unwrap_or(0.0);
                if moved < PLACEHOLDER_FRACTION * full.moving_mass() && locked_now + 1 < controlled
                {
                    locked_now += 1;
                    chosen.push((
                        g.name.clone(),
                        lock_position(model.joints[ji].limits),
                        format!(
                            "a placeholder ({moved:.2e} kg moved, under {} % of the arm) that no gain holds at {} Hz {} (max M⁻¹_ii {:.3e}; it would need armature {need:.2e})",
                            100.0 * PLACEHOLDER_FRACTION,
                            d.scenario.rate_hz,
                            armature_purpose(g),
                            g.minv_diag
                        ),
                    ));
                } else if let Some(a) = armature.iter_mut().find(|(n, ..)| *n == g.name) {
                    a.1 += need;
                } else {
                    armature.push((
                        g.name.clone(),
                        need,
                        format!(
                            "no gain holds it at {} Hz {} (max M⁻¹_ii {:.3e}); real motors add armature, URDFs omit it",
                            d.scenario.rate_hz,
                            armature_purpose(g),
                            g.minv_diag
                        ),
                    ));
                }
            }
        }
    }

    /// One choice of the default scenario with `chosen` locked and
    /// `armature` added: the scenario and the model it runs.
    fn attempt(
        urdf: &str,
        chosen: &[(String, f64, String)],
        armature: &[(String, f64, String)],
        amplitude: &[(String, f64)],
    ) -> Result<(Self, ArmModel), PlantError> {
        let lock: Locks = chosen.iter().map(|(n, p, _)| (n.clone(), *p)).collect();
        let model = ArmModel::from_urdf_str_locked(urdf, &lock)?;
        // An MJCF arm starts at its keyframe `home` (the reference placed
        // to start it outside the envelope); a URDF's start is chosen.
        let home = home_start(&model);
        let offsets = match &home {
            Some(h) => offsets_for_start(&model, h, amplitude),
            None => crate::posture::choose(&model)?,
        };
        let (reference, envelope, q0) = shape(&model, &offsets, amplitude, None);
        let q0 = home.clone().unwrap_or(q0);
        let n = q0.len();
        let mut s = Scenario {
            name: format!("default for {}", model.name),
            duration_s: 10.0,
            reference: ReferenceConfig {
                joints: reference,
                waypoints: Vec::new(),
                file: None,
                samples: None,
                rate_hz: None,
                horizon_s: trajectory::DEFAULT_HORIZON_S,
            },
            envelope: EnvelopeConfig {
                joints: envelope,
                from_limits: false,
                file: None,
                samples: None,
            },
            initial: Initial {
                q: q0,
                qd: vec![0.0; n],
            },
            ..Scenario::default()
        };
        s.plant.lock = lock;
        let stuck = friction_beyond_effort(&model);
        if stuck.is_some() {
            s.plant.urdf_dynamics = false;
        }
        let per_joint: Vec<f64> = model
            .joint_names()
            .iter()
            .map(|name| {
                armature
                    .iter()
                    .find(|(n, ..)| n == name)
                    .map_or(0.0, |a| a.1)
            })
            .collect();
        if per_joint.iter().any(|a| *a > 0.0) {
            s.plant.armature = PerJoint::Each(per_joint.clone());
        }
        let gains = choose_gains(&model, &s, &kc_cap(&model))?;
        let (_, envelope, q0) = shape(&model, &offsets, amplitude, Some(&gains.envelope));
        s.envelope.joints = envelope;
        let from_home = home.is_some();
        s.initial.q = home.unwrap_or(q0);
        s.rate_hz = gains.rate_hz;
        s.controller.k1 = controller::Gain::Each(gains.joints.iter().map(|g| g.k1).collect());
        s.controller.k2 = controller::Gain::Each(gains.joints.iter().map(|g| g.k2).collect());
        let mut warnings = warnings(&model, &offsets, &per_joint, &gains)?;
        warnings.extend(stuck);
        for (name, f) in amplitude.iter().filter(|(_, f)| *f < 1.0) {
            warnings.push(format!(
                "joint '{name}': reference swing cut to {f:.3} of the default's: it needed more than {:.0} % of the joint's effort limit",
                100.0 * REFERENCE_EFFORT_SHARE
            ));
        }
        let d = Self {
            scenario: s,
            locked: chosen
                .iter()
                .map(|(n, _, why)| (n.clone(), why.clone()))
                .collect(),
            armature: armature
                .iter()
                .map(|(n, a, why)| (n.clone(), *a, why.clone()))
                .collect(),
            gains,
            warnings,
            from_home,
        };
        Ok((d, model))
    }
}

impl ArmDefault {
    /// What this default changes of the arm and why, and what it warns
    /// about, one sentence each (what `sim` and `run` say before a run).
    pub fn changes(&self) -> Vec<String> {
        let locked = self.locked.iter().map(|(name, why)| {
            let at = self.scenario.plant.lock.get(name).copied().unwrap_or(0.0);
            format!("locked {name} at {at:.4}: {why}")
        });
        let armature = self.armature.iter().map(|(name, a, why)| {
            format!("armature {a:.3e} added to {name} ([plant] armature): {why}")
        });
        locked
            .chain(armature)
            .chain(self.warnings.iter().cloned())
            .collect()
    }
}

impl Scenario {
    /// The default scenario for the arm in `urdf` (see the module docs).
    pub fn for_arm(urdf: &str) -> Result<Self, PlantError> {
        ArmDefault::new(urdf).map(|d| d.scenario)
    }

    /// [`Scenario::for_arm`] with the joints of `locks` locked first.
    pub fn for_arm_locked(urdf: &str, locks: &Locks) -> Result<Self, PlantError> {
        ArmDefault::with_locks(urdf, locks).map(|d| d.scenario)
    }
}
