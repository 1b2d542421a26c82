//! A scenario that works on any arm: what `--robot PATH` runs when no
//! scenario file is given.
//!
//! Gripper and finger joints (and joints that move no mass) are locked, so
//! the controller drives the arm. Per joint: a smooth sinusoid about the
//! middle of its range, an envelope of about 0.25 rad, an initial state
//! outside the envelope so the deferred constraint is exercised, and gains
//! K1_i, K2_i chosen from what the plant reports (the controller itself
//! still gets no model; see [`crate::gains`]). A joint no gain holds at the
//! rate against the barrier term (a feather-light link) gets armature, or is
//! locked if it moves under 1 % of the arm's mass; [`ArmDefault`] says which
//! and why, with any gravity load beyond an effort limit.

use plant_rapier::{ArmModel, JointKind, Locks, PerJoint, PlantError};
use trajectory::{EnvelopeConfig, ReferenceConfig, Signal, Sinusoid};

use crate::gains::{GainChoice, choose_gains};
use crate::probe::Probe;
use crate::{Initial, Scenario};

/// Why a gripper or finger joint is locked (the start of its reason).
pub const GRIPPER_LOCK: &str = "a gripper or finger joint: the controller drives the arm";

/// Joint names that mark a gripper or a finger (compared in lower case).
const GRIPPER_WORDS: [&str; 6] = ["finger", "gripper", "grip", "hand", "jaw", "claw"];

/// The default scenario for an arm and why it is what it is.
#[derive(Debug, Clone)]
pub struct ArmDefault {
    /// The scenario.
    pub scenario: Scenario,
    /// Joints the scenario locks, with the reason.
    pub locked: Vec<(String, String)>,
    /// Armature the scenario adds per joint (kg m² or kg), with the reason.
    pub armature: Vec<(String, f64, String)>,
    /// The gains and the reasons for them.
    pub gains: GainChoice,
    /// What a user should know: loads beyond effort limits, joints the
    /// scenario could not hold, envelopes it widened.
    pub warnings: Vec<String>,
}

/// Whether a joint's name says it belongs to a gripper or a hand.
fn is_gripper(name: &str) -> bool {
    let lower = name.to_lowercase();
    GRIPPER_WORDS.iter().any(|w| lower.contains(w))
}

/// Where a locked joint is held: the middle of its range, or 0.
fn lock_position(limits: Option<(f64, f64)>) -> f64 {
    limits.map_or(0.0, |(lo, hi)| 0.5 * (lo + hi))
}

/// The joints the default scenario locks: grippers and fingers, and joints
/// that move no mass, as long as some joint is left to control.
fn default_locks(full: &ArmModel) -> Vec<(String, f64, String)> {
    let massless = full.joints_moving_no_mass();
    let mut locks: Vec<(String, f64, String)> = Vec::new();
    for &ji in &full.actuated {
        let j = &full.joints[ji];
        let why = if is_gripper(&j.name) {
            GRIPPER_LOCK
        } else if massless.contains(&j.name) {
            "it moves no mass, so its acceleration is undefined"
        } else {
            continue;
        };
        locks.push((j.name.clone(), lock_position(j.limits), why.to_string()));
    }
    if locks.len() == full.dof() {
        // Nothing would be left to control: lock nothing, and let the plant
        // say what it cannot simulate.
        locks.clear();
    }
    locks
}

/// The widest envelope offset a joint may be given: 1 rad, or 0.3 of
/// its half range.
fn kc_cap(model: &ArmModel) -> Vec<f64> {
    model
        .actuated
        .iter()
        .map(|&ji| {
            let half = model.joints[ji]
                .limits
                .map_or(f64::INFINITY, |(lo, hi)| 0.5 * (hi - lo));
            match model.joints[ji].kind {
                JointKind::Prismatic => (0.15 * half).min(PRISMATIC_KC_CAP_M),
                _ => (0.3 * half).min(1.0),
            }
        })
        .collect()
}

/// The largest reference amplitude of a prismatic joint, m: a mobile
/// base's ±1000 m rail is not swung over 300 m.
const PRISMATIC_AMPLITUDE_M: f64 = 0.25;
/// The default envelope of a prismatic joint at most, m.
const PRISMATIC_KC_M: f64 = 0.05;
/// The widest envelope a prismatic joint may be given, m.
const PRISMATIC_KC_CAP_M: f64 = 0.15;

/// Per joint: the reference about `offsets`, its amplitude times the
/// joint's factor in `amplitude` (by name; 1 if absent), the envelope
/// (offset `kc` when given), and the initial position.
fn shape(
    model: &ArmModel,
    offsets: &[f64],
    amplitude: &[(String, f64)],
    kc: Option<&[f64]>,
) -> (Vec<Signal>, Vec<Signal>, Vec<f64>) {
    let (mut reference, mut envelope, mut q0) = (Vec::new(), Vec::new(), Vec::new());
    for (i, &ji) in model.actuated.iter().enumerate() {
        let j = &model.joints[ji];
        let half = j.limits.map_or(f64::INFINITY, |(lo, hi)| 0.5 * (hi - lo));
        let center = offsets[i];
        let (amp, kc_default) = match j.kind {
            JointKind::Prismatic => (
                (0.3 * half).min(PRISMATIC_AMPLITUDE_M),
                (0.15 * half).min(PRISMATIC_KC_M),
            ),
            _ => ((0.3 * half).min(0.5), 0.25f64.min(0.3 * half)),
        };
        let factor = amplitude
            .iter()
            .find(|(n, _)| *n == j.name)
            .map_or(1.0, |a| a.1);
        let amp = amp * factor;
        let kc = kc.map_or(kc_default, |k| k[i]);
        let omega = 0.8 + 0.2 * (i % 3) as f64;
        // Alternate sin and cos so the joints do not all start at rest.
        let (sin, cos) = if i % 2 == 0 { (amp, 0.0) } else { (0.0, amp) };
        let r = Sinusoid {
            offset: center,
            sin,
            cos,
            omega,
        };
        let e = Sinusoid {
            offset: kc,
            sin: 0.2 * kc,
            cos: 0.0,
            omega: 0.5,
        };
        // Start 1.5 envelopes away from the reference: outside the bound,
        // inside the joint limits.
        let mut q = r.eval(0.0)[0] + 1.5 * e.eval(0.0)[0];
        if let Some((lo, hi)) = j.limits {
            let pad = 0.02 * (hi - lo);
            q = q.clamp(lo + pad, hi - pad);
        }
        reference.push(r.into());
        envelope.push(e.into());
        q0.push(q);
    }
    (reference, envelope, q0)
}

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
        let offsets = crate::posture::choose(&model)?;
        let (reference, envelope, q0) = shape(&model, &offsets, amplitude, None);
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
        s.initial.q = q0;
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
        };
        Ok((d, model))
    }
}

/// What a joint's armature is for, as `robot` says it.
fn armature_purpose(g: &crate::JointGain) -> String {
    match g.armature_for {
        Some(crate::ArmatureFor::Barrier) | None => format!(
            "against the barrier term (K_b Δt/K2 = {:.2} at the widest envelope its range allows)",
            g.barrier
        ),
        Some(crate::ArmatureFor::Load) => format!(
            "within its envelope against its load of {:.3} N m (K1 at most 0.2/Δt)",
            g.load
        ),
    }
}

/// Joints that gravity alone loads beyond their effort limit somewhere
/// along the default reference (a humanoid's 30 N m waist under a 30 kg
/// chest, a mobile base's suspension): no controller holds them, so they
/// are locked where the reference would hold them, and the rest of the arm
/// is controlled. Locks to add, with the reason.
fn overloaded(d: &ArmDefault) -> Vec<(String, f64, String)> {
    d.gains
        .joints
        .iter()
        .zip(&d.scenario.reference.joints)
        .filter_map(|(g, r)| {
            let e = g.effort?;
            (g.gravity > e).then(|| {
                (
                    g.name.clone(),
                    r.offset,
                    format!(
                        "gravity alone loads it with up to {:.1} N m along the reference, beyond its effort limit {e} N m: no controller holds it",
                        g.gravity
                    ),
                )
            })
        })
        .collect()
}

/// Joints whose URDF dry friction is at least their effort limit (Drake's
/// Allegro hand lists 10 N m of friction on 0.7 N m motors): no motor moves
/// them, so the default turns URDF dynamics off, and says why.
fn friction_beyond_effort(model: &ArmModel) -> Option<String> {
    let stuck: Vec<String> = model
        .moving_joints()
        .map(|ji| &model.joints[ji])
        .filter(|j| j.effort.is_some_and(|e| j.friction >= e))
        .map(|j| {
            format!(
                "{} ({} N m ≥ {} N m)",
                j.name,
                j.friction,
                j.effort.unwrap_or(0.0)
            )
        })
        .collect();
    (!stuck.is_empty()).then(|| {
        format!(
            "the URDF's dry friction is at least the effort limit on {}: no motor could move them, so the default turns URDF damping and friction off ([plant] urdf_dynamics = false)",
            stuck.join(", ")
        )
    })
}

/// The share of a joint's effort its reference may need: the rest is the
/// controller's to correct with.
const REFERENCE_EFFORT_SHARE: f64 = 0.7;

/// Joints whose reference needs more than [`REFERENCE_EFFORT_SHARE`] of
/// their effort limit: the factor to scale their reference's amplitude by.
/// Where gravity alone leaves room, the motion's load scales with the
/// amplitude, so the factor fits it; where gravity along the swing takes
/// the room (a long arm swung away from upright), the swing is halved,
/// which brings it back towards the posture chosen to unload it.
fn within_effort(d: &ArmDefault) -> Vec<(String, f64)> {
    d.gains
        .joints
        .iter()
        .filter_map(|g| {
            let share = REFERENCE_EFFORT_SHARE * g.effort?;
            let (room, motion) = (share - g.gravity, g.load - g.gravity);
            if g.load <= share {
                None
            } else if room > 0.0 {
                Some((g.name.clone(), room / motion))
            } else {
                Some((g.name.clone(), 0.5))
            }
        })
        .collect()
}

/// What `testbed robot` should say about the default scenario beyond its
/// numbers: gravity beyond a motor's effort at the posture the reference
/// swings about, joints no gain holds, envelopes widened.
fn warnings(
    model: &ArmModel,
    offsets: &[f64],
    armature: &[f64],
    gains: &GainChoice,
) -> Result<Vec<String>, PlantError> {
    let mut out = Vec::new();
    let probe = Probe::at(model, offsets, armature)?;
    for (i, &ji) in model.actuated.iter().enumerate() {
        let j = &model.joints[ji];
        let g = probe.gravity[i].abs();
        if let Some(e) = j.effort
            && g > e
        {
            out.push(format!(
                "joint '{}': gravity alone loads it with {g:.1} N m at the default posture, beyond its effort limit {e} N m: it cannot hold the arm up and every step will saturate (check the URDF's masses and effort limits, or set [plant] effort_limit)",
                j.name
            ));
        }
    }
    for j in &gains.joints {
        if let Some(a) = j.armature_needed {
            out.push(format!(
                "joint '{}': no gain holds it at {} Hz {} even with the armature added (it needs {a:.2e} more); lock it in [plant.lock] or raise rate_hz",
                j.name,
                gains.rate_hz,
                armature_purpose(j)
            ));
        }
        if let Some(why) = &j.envelope_reason {
            out.push(format!("joint '{}': envelope widened for {why}", j.name));
        }
    }
    Ok(out)
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
