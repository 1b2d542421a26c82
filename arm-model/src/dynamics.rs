//! Rigid-body dynamics of an [`ArmModel`] by recursive Newton–Euler, written
//! from the model's kinematic and inertial data only (nothing of Rapier's).
//!
//! One evaluation gives τ = M(q) q̈ + C(q, q̇) q̇ + G(q) in the controlled
//! joints' coordinates, mimic couplings included (the generalised force
//! Jᵀ τ_full of the whole tree, J the coupling's Jacobian). That is all a
//! model-based law needs: computed torque is one call with q̈ = v, gravity
//! one call with q̇ = q̈ = 0. Joint damping and friction are not in it: they
//! are what a controller's model usually lacks. A joint's own armature
//! (MJCF's; a URDF has none) is: it is part of M(q), as in MuJoCo.

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion, Vector3};

use crate::{ArmModel, JointKind, iso};

/// Gravity, m/s² (URDF is z-up).
pub const GRAVITY: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

/// One moving joint, in the order of the forward pass.
#[derive(Debug, Clone)]
struct Step {
    parent: usize,
    child: usize,
    /// Index into the full coordinates (controlled, then mimic).
    coord: usize,
    prismatic: bool,
    origin: Isometry3<f64>,
    axis: Vector3<f64>,
}

/// One moving link's mass properties in its link frame.
#[derive(Debug, Clone)]
struct Body {
    link: usize,
    mass: f64,
    com: Point3<f64>,
    /// Inertia about the COM, in the link frame.
    inertia: Matrix3<f64>,
}

/// The dynamics of one arm, with scratch space allocated once.
#[derive(Debug, Clone)]
pub struct Dynamics {
    n: usize,
    steps: Vec<Step>,
    bodies: Vec<Body>,
    /// (follower coordinate, leader, multiplier, offset) of each mimic joint.
    mimic: Vec<(usize, usize, f64, f64)>,
    /// Each moving joint's armature (rotor inertia), by full coordinate:
    /// a torque armature · q̈ of its own, on M's diagonal.
    armature: Vec<f64>,
    // Scratch.
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    pose: Vec<Isometry3<f64>>,
    w: Vec<Vector3<f64>>,
    wd: Vec<Vector3<f64>>,
    a: Vec<Vector3<f64>>,
    axis_w: Vec<Vector3<f64>>,
    f: Vec<Vector3<f64>>,
    m: Vec<Vector3<f64>>,
    tau_full: Vec<f64>,
    tau: Vec<f64>,
}

impl Dynamics {
    /// The dynamics of `model` with every link's mass and inertia scaled by
    /// `mass_scale` (1: the URDF's; 0.8: a model 20 % light).
    pub fn new(model: &ArmModel, mass_scale: f64) -> Self {
        let moving: Vec<usize> = model.moving_joints().collect();
        let coord_of = |ji: usize| moving.iter().position(|&m| m == ji);
        let steps = model
            .topological
            .iter()
            .filter_map(|&ji| {
                let j = &model.joints[ji];
                Some(Step {
                    parent: j.parent,
                    child: j.child,
                    coord: coord_of(ji)?,
                    prismatic: j.kind == JointKind::Prismatic,
                    origin: iso(&j.origin),
                    axis: Vector3::new(j.axis[0], j.axis[1], j.axis[2]),
                })
            })
            .collect();
        let bodies = model
            .links
            .iter()
            .enumerate()
            .filter(|(i, l)| *i != model.root && l.mass > 0.0)
            .map(|(i, l)| {
                let io = iso(&l.inertial_origin);
                let [ixx, ixy, ixz, iyy, iyz, izz] = l.inertia;
                let local = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
                let rot = io.rotation.to_rotation_matrix();
                Body {
                    link: i,
                    mass: mass_scale * l.mass,
                    com: Point3::from(io.translation.vector),
                    inertia: mass_scale * (rot.matrix() * local * rot.matrix().transpose()),
                }
            })
            .collect();
        let n = model.dof();
        let mimic = model
            .mimic
            .iter()
            .enumerate()
            .map(|(i, c)| (n + i, c.leader, c.multiplier, c.offset))
            .collect();
        let armature = moving.iter().map(|&ji| model.joints[ji].armature).collect();
        let (nl, nf) = (model.links.len(), moving.len());
        Self {
            n,
            steps,
            bodies,
            mimic,
            armature,
            q: vec![0.0; nf],
            qd: vec![0.0; nf],
            qdd: vec![0.0; nf],
            pose: vec![Isometry3::identity(); nl],
            w: vec![Vector3::zeros(); nl],
            wd: vec![Vector3::zeros(); nl],
            a: vec![Vector3::zeros(); nl],
            axis_w: vec![Vector3::zeros(); nl],
            f: vec![Vector3::zeros(); nl],
            m: vec![Vector3::zeros(); nl],
            tau_full: vec![0.0; nf],
            tau: vec![0.0; n],
        }
    }

    /// Number of controlled joints.
    pub fn dof(&self) -> usize {
        self.n
    }

    /// τ = M(q) q̈ + C(q, q̇) q̇ + G(q) for the controlled joints. Slices
    /// have one entry per controlled joint (checked by the caller).
    pub fn inverse(&mut self, q: &[f64], qd: &[f64], qdd: &[f64]) -> &[f64] {
        self.expand(q, Some((qd, qdd)));
        self.solve()
    }

    /// G(q): the torque that holds the arm still at q.
    pub fn gravity(&mut self, q: &[f64]) -> &[f64] {
        self.expand(q, None);
        self.solve()
    }

    /// Every link frame's pose in the world (the root link's frame) at q,
    /// indexed like the model's links: the forward kinematics of the same
    /// tree the dynamics walk (the live view draws the arm with it).
    pub fn link_poses(&mut self, q: &[f64]) -> &[Isometry3<f64>] {
        self.expand(q, None);
        self.forward_pass();
        &self.pose
    }

    fn solve(&mut self) -> &[f64] {
        self.forward_pass();
        self.backward_pass();
        for (t, (a, qdd)) in self
            .tau_full
            .iter_mut()
            .zip(self.armature.iter().zip(&self.qdd))
        {
            *t += a * qdd;
        }
        let n = self.n;
        self.tau.copy_from_slice(&self.tau_full[..n]);
        for &(k, leader, mult, _) in &self.mimic {
            self.tau[leader] += mult * self.tau_full[k];
        }
        &self.tau
    }

    /// The coordinates of every moving joint from the controlled ones
    /// (rates zero when `rates` is None).
    fn expand(&mut self, q: &[f64], rates: Option<(&[f64], &[f64])>) {
        let n = self.n;
        self.q[..n].copy_from_slice(q);
        match rates {
            Some((qd, qdd)) => {
                self.qd[..n].copy_from_slice(qd);
                self.qdd[..n].copy_from_slice(qdd);
            }
            None => {
                self.qd.iter_mut().for_each(|x| *x = 0.0);
                self.qdd.iter_mut().for_each(|x| *x = 0.0);
            }
        }
        for &(k, leader, mult, offset) in &self.mimic {
            self.q[k] = mult * q[leader] + offset;
            self.qd[k] = mult * self.qd[leader];
            self.qdd[k] = mult * self.qdd[leader];
        }
    }

    /// Poses, angular velocities and accelerations, and frame-origin
    /// accelerations of every link, in the world frame.
    fn forward_pass(&mut self) {
        for s in &self.steps {
            let (p, c, k) = (s.parent, s.child, s.coord);
            let (q, qd, qdd) = (self.q[k], self.qd[k], self.qdd[k]);
            let motion = if s.prismatic {
                Isometry3::from_parts(Translation3::from(s.axis * q), UnitQuaternion::identity())
            } else {
                Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_scaled_axis(s.axis * q),
                )
            };
            self.pose[c] = self.pose[p] * s.origin * motion;
            let z = self.pose[c].rotation * s.axis;
            self.axis_w[c] = z;
            let r = self.pose[c].translation.vector - self.pose[p].translation.vector;
            let (wp, wdp) = (self.w[p], self.wd[p]);
            let a_carried = self.a[p] + wdp.cross(&r) + wp.cross(&wp.cross(&r));
            if s.prismatic {
                self.w[c] = wp;
                self.wd[c] = wdp;
                self.a[c] = a_carried + z * qdd + 2.0 * wp.cross(&(z * qd));
            } else {
                self.w[c] = wp + z * qd;
                self.wd[c] = wdp + z * qdd + wp.cross(&(z * qd));
                self.a[c] = a_carried;
            }
        }
    }

    /// Force and moment (about each link frame's origin) that each joint
    /// must supply, summed from the leaves, projected on the joint axes.
    fn backward_pass(&mut self) {
        self.f.iter_mut().for_each(|v| *v = Vector3::zeros());
        self.m.iter_mut().for_each(|v| *v = Vector3::zeros());
        for b in &self.bodies {
            let li = b.link;
            let pose = &self.pose[li];
            let rc = pose.rotation * b.com.coords;
            let rot = pose.rotation.to_rotation_matrix();
            let i_w = rot.matrix() * b.inertia * rot.matrix().transpose();
            let (w, wd) = (self.w[li], self.wd[li]);
            let a_com = self.a[li] + wd.cross(&rc) + w.cross(&w.cross(&rc));
            let fi = b.mass * (a_com - GRAVITY);
            self.f[li] = fi;
            self.m[li] = rc.cross(&fi) + i_w * wd + w.cross(&(i_w * w));
        }
        for s in self.steps.iter().rev() {
            let (p, c) = (s.parent, s.child);
            let z = self.axis_w[c];
            self.tau_full[s.coord] = if s.prismatic {
                self.f[c].dot(&z)
            } else {
                self.m[c].dot(&z)
            };
            let r = self.pose[c].translation.vector - self.pose[p].translation.vector;
            let (fc, mc) = (self.f[c], self.m[c]);
            self.f[p] += fc;
            self.m[p] += mc + r.cross(&fc);
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;
    use crate::TWO_LINK_URDF;

    /// The two-link arm's closed-form dynamics (SPEC §1) at a few states.
    #[test]
    fn two_link_matches_the_closed_form() {
        let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
        let mut d = Dynamics::new(&model, 1.0);
        // Point masses at the link ends would be the textbook form; read the
        // URDF's numbers instead and check M's symmetry and G by energy.
        let q = [0.3, -0.7];
        let g = d.gravity(&q).to_vec();
        let h = 1e-6;
        let pe = |q: &[f64]| potential(&model, q);
        for i in 0..2 {
            let mut qp = q;
            let mut qm = q;
            qp[i] += h;
            qm[i] -= h;
            let fd = (pe(&qp) - pe(&qm)) / (2.0 * h);
            assert!((g[i] - fd).abs() < 1e-6, "G[{i}] {} vs dV/dq {fd}", g[i]);
        }
        let m = mass_matrix(&mut d, &q);
        assert!((m[0][1] - m[1][0]).abs() < 1e-12);
        assert!(m[0][0] > 0.0 && m[1][1] > 0.0 && m[0][0] * m[1][1] > m[0][1] * m[0][1]);
    }

    #[test]
    fn mass_scale_scales_every_term() {
        let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
        let mut full = Dynamics::new(&model, 1.0);
        let mut light = Dynamics::new(&model, 0.8);
        let (q, qd, qdd) = ([0.2, 0.4], [1.0, -2.0], [0.5, 3.0]);
        let a = full.inverse(&q, &qd, &qdd).to_vec();
        let b = light.inverse(&q, &qd, &qdd).to_vec();
        for i in 0..2 {
            assert!((b[i] - 0.8 * a[i]).abs() < 1e-12 * a[i].abs().max(1.0));
        }
    }

    fn mass_matrix(d: &mut Dynamics, q: &[f64]) -> Vec<Vec<f64>> {
        let n = d.dof();
        let g = d.gravity(q).to_vec();
        (0..n)
            .map(|j| {
                let mut e = vec![0.0; n];
                e[j] = 1.0;
                let col = d.inverse(q, &vec![0.0; n], &e).to_vec();
                col.iter().zip(&g).map(|(c, g)| c - g).collect()
            })
            .collect()
    }

    /// Potential energy −Σ m gᵀ p_com, by forward kinematics of its own.
    fn potential(model: &ArmModel, q: &[f64]) -> f64 {
        let mut pose = vec![Isometry3::identity(); model.links.len()];
        for &ji in &model.topological {
            let j = &model.joints[ji];
            let k = model.actuated.iter().position(|&a| a == ji).unwrap();
            let ax = Vector3::new(j.axis[0], j.axis[1], j.axis[2]);
            pose[j.child] =
                pose[j.parent] * iso(&j.origin) * UnitQuaternion::from_scaled_axis(ax * q[k]);
        }
        model
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let p = pose[i] * Point3::from(iso(&l.inertial_origin).translation.vector);
                -l.mass * GRAVITY.dot(&p.coords)
            })
            .sum()
    }
}
