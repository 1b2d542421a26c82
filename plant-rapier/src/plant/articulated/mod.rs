//! The arm's equations of motion in joint coordinates, integrated with RK4:
//! M(q) q̈ + h(q, q̇) = τ, with URDF damping, dry friction and hard stops.
//! URDF damping is integrated exactly (exponential time differencing,
//! `exponential.rs`), so a damped light link takes one step per period;
//! a step whose damping is mild (h·tr(M⁻¹D) ≤ `MILD_DAMPING` over each
//! group of joints that couple) is plain RK4 with the damping explicit,
//! which needs no eigendecomposition, and otherwise only the stiffly
//! damped joints are solved in modes.
//!
//! Rapier steps a multibody through its whole pipeline (islands, constraint
//! assembly, a first-order integrator), which for an arm without colliders
//! costs most of a control period and needs substeps for accuracy. This
//! engine evaluates only what a serial or branched arm needs and integrates
//! with a fourth-order method, so one substep per millisecond is far more
//! accurate than Rapier's six. Mimic joints are reduced into their leader's
//! coordinate; dry friction and hard stops act as impulses at the end of a
//! substep, as Rapier's velocity constraints do.

mod constraints;
mod etdrk4;
mod exponential;
mod linalg;
mod mat3;
mod spatial;
mod tree;

use nalgebra::Vector3;

use crate::PlantError;
use arm_model::ArmModel;
use constraints::Impulses;
use etdrk4::Exponential;
use linalg::Cholesky;
use spatial::Inertia;
use tree::Tree;

/// How one full coordinate (controlled or mimic) follows the controlled ones:
/// q_full = multiplier · q[leader] + offset.
#[derive(Debug, Clone, Copy)]
struct Follow {
    leader: usize,
    multiplier: f64,
    offset: f64,
}

/// Where the arm is at one stage of an integrator step: `s` seconds into
/// the control period, the joints at (q, q̇), the drive's own states at `x`.
pub(crate) struct Stage<'a> {
    pub(crate) s: f64,
    pub(crate) q: &'a [f64],
    pub(crate) qd: &'a [f64],
    pub(crate) x: &'a [f64],
}

/// The generalised torque on the controlled joints: what the motors, the
/// disturbance and the friction model add. A drive may carry states of its
/// own (a series-elastic joint's motor), which the engine integrates with
/// the arm.
pub(crate) trait Drive {
    /// τ at `at` into `out` (length `dof`), and the rates of the drive's
    /// states into `dx` (the length of `at.x`).
    fn torque(&self, at: &Stage, out: &mut [f64], dx: &mut [f64]);
}

/// An arm in joint coordinates.
#[derive(Debug, Clone)]
pub(crate) struct Articulated {
    /// Controlled joint names, for errors.
    names: Vec<String>,
    tree: Tree,
    follow: Vec<Follow>,
    gravity: Vector3<f64>,
    /// Per controlled joint.
    armature: Vec<f64>,
    /// Per full coordinate: URDF viscous damping.
    damping: Vec<f64>,
    /// Per controlled joint: the URDF damping reduced onto it (Jᵀ D J is
    /// diagonal: each full coordinate follows one controlled joint).
    reduced_damping: Vec<f64>,
    impulses: Impulses,
    link_inertia: Vec<Inertia>,
    /// An upper bound on the fastest decay rate the scenario's friction
    /// slope gives the arm, 1/s: it acts through the explicit stages, which
    /// are stable and accurate while a substep times it stays ≤ 1. (URDF
    /// damping is integrated exactly and needs no bound.)
    damping_rate: f64,
    /// The exponential integrator's state, for an arm with URDF damping.
    exponential: Option<Box<Exponential>>,
    /// A bound on the fastest oscillation of the series-elastic joints,
    /// rad/s (0 without them): RK4 follows it while a substep times it
    /// stays ≤ `MAX_PHASE_STEP`.
    oscillation_rate: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    /// The drive's own states (series-elastic motors' angles and speeds).
    x: Vec<f64>,
    /// Substeps the last step took.
    substeps_taken: u32,
    scratch: Scratch,
}

/// The largest phase a substep may advance the fastest elastic oscillation
/// by: RK4's phase error is then ~(0.2)⁵/120 ≈ 3e-6 rad per substep and
/// its amplitude error ~(0.2)⁶/144 ≈ 4e-7, far below any physical damping.
const MAX_PHASE_STEP: f64 = 0.2;

/// The most substeps a period takes: the count is capped here, and a
/// scenario that needs more is refused before it runs.
pub(crate) const MAX_SUBSTEPS: f64 = 1e6;

/// What a period of the articulated engine needs, uncapped.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SubstepNeed {
    /// Substeps the explicit damping (friction slope, spring damping over
    /// motor inertia) needs.
    pub(crate) damped: f64,
    /// Substeps the fastest elastic oscillation needs.
    pub(crate) oscillating: f64,
    /// The damping bound, 1/s.
    pub(crate) damping_rate: f64,
    /// The oscillation bound, rad/s.
    pub(crate) oscillation_rate: f64,
}

/// Buffers for one evaluation and the RK4 stages, allocated once.
#[derive(Debug, Clone)]
struct Scratch {
    qf: Vec<f64>,
    qdf: Vec<f64>,
    hf: Vec<f64>,
    mf: Vec<f64>,
    tau: Vec<f64>,
    chol: Cholesky,
    q0: Vec<f64>,
    qd0: Vec<f64>,
    k_q: [Vec<f64>; 4],
    k_qd: [Vec<f64>; 4],
    x0: Vec<f64>,
    k_x: [Vec<f64>; 4],
}

/// What the engine needs from the model beyond its tree.
pub(crate) struct Setup<'a> {
    pub(crate) gravity: [f64; 3],
    pub(crate) armature: &'a [f64],
    pub(crate) urdf_dynamics: bool,
    /// Viscous damping the plant adds per controlled joint (the friction
    /// model's slope at rest), for the substep bound.
    pub(crate) extra_damping: &'a [f64],
    /// The series-elastic joints, for the substep bound.
    pub(crate) springs: Springs<'a>,
}

/// The series-elastic transmissions: per controlled joint, the stiffness
/// and damping (0 where rigid), the largest stiffness and damping per motor
/// inertia, and the drive's state count (0 without them).
pub(crate) struct Springs<'a> {
    pub(crate) stiffness: &'a [f64],
    pub(crate) damping: &'a [f64],
    pub(crate) per_motor_inertia: (f64, f64),
    pub(crate) states: usize,
}

impl Articulated {
    /// The arm of `model` at rest at q = 0.
    pub(crate) fn new(model: &ArmModel, setup: &Setup) -> Result<Self, PlantError> {
        let n = model.dof();
        let tree = Tree::new(model);
        let nf = tree.coords();
        let follow: Vec<Follow> = (0..n)
            .map(|i| Follow {
                leader: i,
                multiplier: 1.0,
                offset: 0.0,
            })
            .chain(model.mimic.iter().map(|m| Follow {
                leader: m.leader,
                multiplier: m.multiplier,
                offset: m.offset,
            }))
            .collect();
        let moving: Vec<usize> = model.moving_joints().collect();
        let of = |f: fn(&arm_model::JointInfo) -> f64| -> Vec<f64> {
            moving
                .iter()
                .map(|&ji| {
                    if setup.urdf_dynamics {
                        f(&model.joints[ji])
                    } else {
                        0.0
                    }
                })
                .collect()
        };
        let limits = moving.iter().map(|&ji| model.joints[ji].limits).collect();
        let damping = of(|j| j.damping);
        let mut reduced_damping = vec![0.0; n];
        for (f, d) in follow.iter().zip(&damping) {
            reduced_damping[f.leader] += f.multiplier * f.multiplier * d;
        }
        let chol = mass_structure(&tree, &follow, n);
        // The drive's states are integrated by RK4 alone: with them, URDF
        // damping is explicit, its rate in the substep bound.
        let springs = &setup.springs;
        let exponential = (springs.states == 0 && reduced_damping.iter().any(|d| *d > 0.0))
            .then(|| Box::new(Exponential::new(&chol, n)));
        let mut arm = Self {
            names: model.joint_names(),
            impulses: Impulses::new(of(|j| j.friction), limits, n),
            damping,
            reduced_damping,
            exponential,
            link_inertia: model.links.iter().map(tree::link_inertia).collect(),
            tree,
            follow,
            gravity: Vector3::from(setup.gravity),
            armature: setup.armature.to_vec(),
            damping_rate: 0.0,
            oscillation_rate: 0.0,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            x: vec![0.0; springs.states],
            substeps_taken: 0,
            scratch: Scratch {
                qf: vec![0.0; nf],
                qdf: vec![0.0; nf],
                hf: vec![0.0; nf],
                mf: vec![0.0; nf * nf],
                tau: vec![0.0; n],
                chol,
                q0: vec![0.0; n],
                qd0: vec![0.0; n],
                k_q: std::array::from_fn(|_| vec![0.0; n]),
                k_qd: std::array::from_fn(|_| vec![0.0; n]),
                x0: vec![0.0; springs.states],
                k_x: std::array::from_fn(|_| vec![0.0; springs.states]),
            },
        };
        // A singular M at the start is a model no step can integrate.
        let (q, qd) = (arm.q.clone(), arm.qd.clone());
        arm.factor_mass(&q, &qd)?;
        arm.damping_rate = arm.rate_of(setup.extra_damping);
        if springs.states > 0 {
            // The coupled motor–link system's rates are at most twice the
            // motors' and the links' own (|a − b|² ≤ 2|a|² + 2|b|²).
            let (k_b, d_b) = springs.per_motor_inertia;
            let urdf = arm.reduced_damping.clone();
            arm.damping_rate += arm.rate_of(&urdf) + 2.0 * (d_b + arm.rate_of(springs.damping));
            arm.oscillation_rate = (2.0 * (k_b + arm.rate_of(springs.stiffness))).sqrt();
        }
        Ok(arm)
    }

    /// Joint positions and velocities.
    pub(crate) fn state(&self) -> (&[f64], &[f64]) {
        (&self.q, &self.qd)
    }

    /// Puts the arm at `q`, `qd`.
    pub(crate) fn set_state(&mut self, q: &[f64], qd: &[f64]) {
        self.q.copy_from_slice(q);
        self.qd.copy_from_slice(qd);
    }

    /// The drive's own states (empty without them).
    pub(crate) fn extra_state(&self) -> &[f64] {
        &self.x
    }

    /// The drive's own states, to set.
    pub(crate) fn extra_state_mut(&mut self) -> &mut [f64] {
        &mut self.x
    }

    /// M(q) with armature (row-major) into `inertia`, and the bias
    /// h(q, q̇) with URDF damping into `bias`, at the current state in the
    /// controlled joints' coordinates: what the arm computes before it
    /// solves for q̈. Err where M(q) is singular (naming the joint).
    pub(crate) fn inertia_and_bias(
        &mut self,
        inertia: &mut [f64],
        bias: &mut [f64],
    ) -> Result<(), PlantError> {
        let (q, qd) = (self.q.clone(), self.qd.clone());
        self.factor_mass(&q, &qd)?;
        let s = &self.scratch;
        inertia.copy_from_slice(s.chol.matrix());
        bias.iter_mut().for_each(|b| *b = 0.0);
        for (k, f) in self.follow.iter().enumerate() {
            bias[f.leader] += f.multiplier * (s.hf[k] + self.damping[k] * s.qdf[k]);
        }
        Ok(())
    }

    /// Adds a point mass to link `link` at `point` (its frame), replacing
    /// an earlier one there.
    pub(crate) fn attach_point_mass(&mut self, link: usize, point: [f64; 3], mass: f64) -> bool {
        let Some(base) = self.link_inertia.get(link) else {
            return false;
        };
        let payload = Inertia::from_com(mass, Vector3::from(point), nalgebra::Matrix3::zeros());
        self.tree.set_link_inertia(link, base.add(&payload));
        true
    }

    /// The substeps a period of `dt` takes when the scenario asks for
    /// `substeps`: more only where stiff scenario friction needs them.
    pub(crate) fn substeps_for(&self, dt: f64, substeps: u32) -> u32 {
        let need = self.substeps_needed(dt);
        substeps.max(need.damped.max(need.oscillating).min(MAX_SUBSTEPS) as u32)
    }

    /// The substeps a period of `dt` needs for accuracy, uncapped (so a
    /// scenario past [`MAX_SUBSTEPS`] can be refused rather than run
    /// inaccurately), and the rates they come from.
    pub(crate) fn substeps_needed(&self, dt: f64) -> SubstepNeed {
        SubstepNeed {
            // The friction slope acts through the explicit stages.
            damped: (dt * self.damping_rate).ceil(),
            oscillating: (dt * self.oscillation_rate / MAX_PHASE_STEP).ceil(),
            damping_rate: self.damping_rate,
            oscillation_rate: self.oscillation_rate,
        }
    }

    /// Advances by `dt` in `substeps` steps (RK4, or ETDRK4 with URDF
    /// damping) with the torque `drive`.
    pub(crate) fn step(
        &mut self,
        drive: &dyn Drive,
        dt: f64,
        substeps: u32,
    ) -> Result<(), PlantError> {
        let substeps = self.substeps_for(dt, substeps);
        let h = dt / f64::from(substeps);
        self.substeps_taken = 0;
        for k in 0..substeps {
            // A blown-up state stays blown up: the rest of the period's
            // substeps (up to a million) would only carry NaN along.
            if !self.finite() {
                self.blown_up();
                break;
            }
            let s0 = f64::from(k) * h;
            match self.exponential.take() {
                Some(mut x) => {
                    self.etdrk4(&mut x, drive, s0, h);
                    self.exponential = Some(x);
                }
                None => self.rk4(drive, s0, h, false),
            }
            self.constrain(h);
            self.substeps_taken += 1;
        }
        Ok(())
    }

    /// Whether q, q̇ and the drive's states are all finite.
    fn finite(&self) -> bool {
        self.q
            .iter()
            .chain(&self.qd)
            .chain(&self.x)
            .all(|v| v.is_finite())
    }

    /// Substeps the last [`Self::step`] took (fewer than its count once
    /// the state went non-finite).
    pub(crate) fn substeps_taken(&self) -> u32 {
        self.substeps_taken
    }

    /// Marks the state non-finite, as a blown-up run is reported.
    fn blown_up(&mut self) {
        self.q.iter_mut().for_each(|v| *v = f64::NAN);
        self.qd.iter_mut().for_each(|v| *v = f64::NAN);
    }

    /// One RK4 step of `h` from `s0` into the period, the drive's states
    /// with it; `factored`: the inertia at the start is the one factored
    /// last.
    fn rk4(&mut self, drive: &dyn Drive, s0: f64, h: f64, factored: bool) {
        let s = &mut self.scratch;
        s.q0.copy_from_slice(&self.q);
        s.qd0.copy_from_slice(&self.qd);
        s.x0.copy_from_slice(&self.x);
        for stage in 0..4 {
            let frac = [0.0, 0.5, 0.5, 1.0][stage];
            let (mut q, mut qd) = (std::mem::take(&mut self.q), std::mem::take(&mut self.qd));
            let mut x = std::mem::take(&mut self.x);
            if stage > 0 {
                let s = &self.scratch;
                for i in 0..q.len() {
                    q[i] = s.q0[i] + frac * h * s.k_q[stage - 1][i];
                    qd[i] = s.qd0[i] + frac * h * s.k_qd[stage - 1][i];
                }
                for (i, xi) in x.iter_mut().enumerate() {
                    *xi = s.x0[i] + frac * h * s.k_x[stage - 1][i];
                }
            }
            let mut qdd = std::mem::take(&mut self.scratch.k_qd[stage]);
            let mut dx = std::mem::take(&mut self.scratch.k_x[stage]);
            let at = Stage {
                s: s0 + frac * h,
                q: &q,
                qd: &qd,
                x: &x,
            };
            if stage == 0 && factored {
                self.accelerate_factored(drive, &at, &mut qdd, &mut dx);
            } else {
                self.acceleration(drive, &at, &mut qdd, &mut dx);
            }
            self.scratch.k_qd[stage] = qdd;
            self.scratch.k_x[stage] = dx;
            self.scratch.k_q[stage].copy_from_slice(&qd);
            (self.q, self.qd, self.x) = (q, qd, x);
        }
        let s = &self.scratch;
        for i in 0..self.armature.len() {
            let dq = s.k_q[0][i] + 2.0 * (s.k_q[1][i] + s.k_q[2][i]) + s.k_q[3][i];
            let dqd = s.k_qd[0][i] + 2.0 * (s.k_qd[1][i] + s.k_qd[2][i]) + s.k_qd[3][i];
            self.q[i] = s.q0[i] + h / 6.0 * dq;
            self.qd[i] = s.qd0[i] + h / 6.0 * dqd;
        }
        for (i, x) in self.x.iter_mut().enumerate() {
            let dx = s.k_x[0][i] + 2.0 * (s.k_x[1][i] + s.k_x[2][i]) + s.k_x[3][i];
            *x = s.x0[i] + h / 6.0 * dx;
        }
    }

    /// q̈ = M⁻¹ (τ − h − D q̇) at `at`, and the drive's state rates. A state
    /// that has blown up (the torque of a diverging law) has no inertia to
    /// factor: its acceleration is NaN, and the run reports the non-finite
    /// state, as it does with Rapier.
    fn acceleration(&mut self, drive: &dyn Drive, at: &Stage, qdd: &mut [f64], dx: &mut [f64]) {
        if self.factor_mass(at.q, at.qd).is_err() {
            qdd.iter_mut()
                .chain(dx.iter_mut())
                .for_each(|x| *x = f64::NAN);
            return;
        }
        self.accelerate_factored(drive, at, qdd, dx);
    }

    /// [`Self::acceleration`] at the state `factor_mass` was last called at.
    fn accelerate_factored(
        &mut self,
        drive: &dyn Drive,
        at: &Stage,
        qdd: &mut [f64],
        dx: &mut [f64],
    ) {
        let s = &mut self.scratch;
        drive.torque(at, &mut s.tau, dx);
        for (k, f) in self.follow.iter().enumerate() {
            let damping = self.damping[k] * s.qdf[k];
            s.tau[f.leader] -= f.multiplier * (s.hf[k] + damping);
        }
        qdd.copy_from_slice(&s.tau);
        s.chol.solve(qdd);
    }

    /// Evaluates the tree at (q, q̇) and factors the reduced M(q) + armature.
    fn factor_mass(&mut self, q: &[f64], qd: &[f64]) -> Result<(), PlantError> {
        let s = &mut self.scratch;
        for (k, f) in self.follow.iter().enumerate() {
            s.qf[k] = f.multiplier * q[f.leader] + f.offset;
            s.qdf[k] = f.multiplier * qd[f.leader];
        }
        self.tree
            .dynamics(&s.qf, &s.qdf, self.gravity, &mut s.hf, &mut s.mf);
        let nf = self.follow.len();
        let m = s.chol.matrix_mut();
        let n = self.armature.len();
        if nf == n {
            // No mimic joint: the coordinates are the joints.
            m.copy_from_slice(&s.mf);
        } else {
            m.iter_mut().for_each(|x| *x = 0.0);
            for (k, fk) in self.follow.iter().enumerate() {
                for (l, fl) in self.follow.iter().enumerate() {
                    m[fk.leader * n + fl.leader] +=
                        fk.multiplier * fl.multiplier * s.mf[k * nf + l];
                }
            }
        }
        for (i, a) in self.armature.iter().enumerate() {
            m[i * n + i] += a;
        }
        let names = &self.names;
        s.chol.factor().map_err(|row| PlantError::SingularInertia {
            joint: names.get(row).map_or("?", String::as_str).to_string(),
            q: q.to_vec(),
        })
    }

    /// The largest trace of a group's block of M⁻¹ E at the factored
    /// posture, E the scenario's friction slope `extra` per joint: an upper
    /// bound on the largest eigenvalue of M⁻¹ E, since E is positive
    /// semi-definite and M⁻¹ block diagonal over the groups.
    fn rate_of(&self, extra: &[f64]) -> f64 {
        let (mut x, mut shares) = (vec![0.0; extra.len()], vec![0.0; extra.len()]);
        exponential::damping_shares(&self.scratch.chol, extra, &mut x, &mut shares)
    }

    /// Dry friction and hard stops as impulses at the end of a substep
    /// (none on a state that has blown up).
    fn constrain(&mut self, h: f64) {
        if !self.impulses.needed(&self.follow, &self.q) {
            return;
        }
        let (mut q, mut qd) = (std::mem::take(&mut self.q), std::mem::take(&mut self.qd));
        // The inertia at the end of the substep serves a passed stop, and
        // friction where no modes give the damped response (from M₀).
        let modal = self.exponential.as_deref().is_some_and(|x| x.modal);
        let end_inertia = !modal || self.impulses.stop_passed(&self.follow, &q);
        let finite = q.iter().chain(&qd).all(|v| v.is_finite());
        if finite && (!end_inertia || self.factor_mass(&q, &qd).is_ok()) {
            let chol = &self.scratch.chol;
            let modes = (self.exponential.as_deref())
                .filter(|x| x.modal)
                .map(|x| &x.modes);
            self.impulses
                .apply(&self.follow, chol, modes, &mut q, &mut qd, h);
        }
        (self.q, self.qd) = (q, qd);
    }
}

/// The inertia's factorisation for the arm's branches: joints eliminated
/// children first, coupled where a coordinate following one is on the
/// same branch as a coordinate following the other.
fn mass_structure(tree: &Tree, follow: &[Follow], n: usize) -> Cholesky {
    let nf = follow.len();
    let full = tree.coupling();
    let mut coupled = vec![false; n * n];
    for (k, fk) in follow.iter().enumerate() {
        for (l, fl) in follow.iter().enumerate() {
            if full[k * nf + l] {
                coupled[fk.leader * n + fl.leader] = true;
            }
        }
    }
    let mut order: Vec<usize> = tree
        .coords_in_order()
        .into_iter()
        .filter(|&c| c < n)
        .collect();
    order.reverse();
    if order.len() != n {
        // Not every joint on the tree: no structure to rely on.
        order = (0..n).collect();
        coupled.iter_mut().for_each(|c| *c = true);
    }
    Cholesky::with_structure(order, |i, j| coupled[i * n + j])
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// A torque past any the state can hold: q̈ overflows within a substep.
    struct Overflow;

    impl Drive for Overflow {
        fn torque(&self, _: &Stage, out: &mut [f64], _: &mut [f64]) {
            out.iter_mut().for_each(|t| *t = f64::MAX);
        }
    }

    fn two_link() -> Articulated {
        let model = ArmModel::from_urdf_str(arm_model::TWO_LINK_URDF).unwrap();
        let setup = Setup {
            gravity: [0.0, 0.0, -9.81],
            armature: &[0.0, 0.0],
            urdf_dynamics: true,
            extra_damping: &[0.0, 0.0],
            springs: Springs {
                stiffness: &[0.0, 0.0],
                damping: &[0.0, 0.0],
                per_motor_inertia: (0.0, 0.0),
                states: 0,
            },
        };
        Articulated::new(&model, &setup).unwrap()
    }

    /// Issue 48 item 7: a state that went non-finite took every remaining
    /// substep of its period (up to a million) carrying NaN. Substepping
    /// stops at once: a period that starts blown up takes none, one that
    /// blows up takes the substeps up to it, and the state reads NaN.
    #[test]
    fn substepping_stops_once_the_state_is_not_finite() {
        let mut arm = two_link();
        arm.set_state(&[f64::NAN, 0.0], &[0.0, 0.0]);
        arm.step(&Overflow, 1e-3, 1000).unwrap();
        assert_eq!(arm.substeps_taken(), 0);
        let mut arm = two_link();
        arm.step(&Overflow, 1e-3, 1000).unwrap();
        assert!(arm.substeps_taken() <= 2, "{}", arm.substeps_taken());
        assert!(arm.state().0.iter().all(|q| q.is_nan()));
    }
}
