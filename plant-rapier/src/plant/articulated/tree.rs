//! The arm as a kinematic tree in joint coordinates, and its two dynamics
//! terms: the joint-space inertia M(q) by the composite-rigid-body algorithm
//! and the bias h(q, q̇) = C(q, q̇) q̇ + G(q) by recursive Newton–Euler
//! (Featherstone 2008, §5.3 and §6.2), in link frames with spatial algebra.
//! `arm_model::dynamics` is a separate world-frame Newton–Euler the
//! controller's laws use; the tests compare the two.

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

use super::spatial::{Force, Inertia, Motion, Xform};
use arm_model::{ArmModel, JointKind, LinkInfo};

/// One joint of the tree, parents before children.
#[derive(Debug, Clone)]
struct Joint {
    /// The joint that moves the parent link (None: the fixed root).
    parent: Option<usize>,
    /// The child link's index in the model.
    link: usize,
    /// Parent link frame → joint frame at q = 0 (the URDF origin).
    origin: Xform,
    /// Unit axis in the joint frame, and the motion subspace it spans.
    axis: Vector3<f64>,
    subspace: Motion,
    prismatic: bool,
    /// The joint's coordinate (None for a fixed joint).
    coord: Option<usize>,
}

/// The tree with its scratch space, allocated once.
#[derive(Debug, Clone)]
pub(super) struct Tree {
    joints: Vec<Joint>,
    /// Each link's spatial inertia in its own frame (payload included).
    inertia: Vec<Inertia>,
    /// Number of coordinates (controlled and mimic).
    nf: usize,
    // Scratch, one entry per joint.
    xup: Vec<Xform>,
    vel: Vec<Motion>,
    acc: Vec<Motion>,
    force: Vec<Force>,
    composite: Vec<Inertia>,
}

fn xform_of(o: &arm_model::Origin) -> Xform {
    let iso = arm_model::iso(o);
    let rot = iso.rotation.to_rotation_matrix();
    Xform {
        e: rot.matrix().transpose(),
        r: iso.translation.vector,
    }
}

/// A link's spatial inertia in its frame from its URDF `<inertial>`.
pub(super) fn link_inertia(link: &LinkInfo) -> Inertia {
    let [ixx, ixy, ixz, iyy, iyz, izz] = link.inertia;
    let tensor = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
    let frame = arm_model::iso(&link.inertial_origin);
    let r = frame.rotation.to_rotation_matrix();
    let in_link = r.matrix() * tensor * r.matrix().transpose();
    Inertia::from_com(link.mass, frame.translation.vector, in_link)
}

impl Tree {
    /// The tree of `model`: coordinate i < dof() is controlled joint i,
    /// dof() + k is mimic joint k.
    pub(super) fn new(model: &ArmModel) -> Self {
        let n = model.dof();
        let coord_of = |ji: usize| {
            model.actuated.iter().position(|&a| a == ji).or_else(|| {
                model
                    .mimic
                    .iter()
                    .position(|m| m.joint == ji)
                    .map(|k| n + k)
            })
        };
        let mut joint_of_link = vec![None; model.links.len()];
        let mut joints = Vec::with_capacity(model.topological.len());
        for &ji in &model.topological {
            let j = &model.joints[ji];
            let axis = Vector3::new(j.axis[0], j.axis[1], j.axis[2]);
            let axis = if axis.norm() > 0.0 {
                axis.normalize()
            } else {
                axis
            };
            let prismatic = j.kind == JointKind::Prismatic;
            let subspace = if prismatic {
                Motion {
                    w: Vector3::zeros(),
                    v: axis,
                }
            } else {
                Motion {
                    w: axis,
                    v: Vector3::zeros(),
                }
            };
            joint_of_link[j.child] = Some(joints.len());
            joints.push(Joint {
                parent: joint_of_link[j.parent],
                link: j.child,
                origin: xform_of(&j.origin),
                axis,
                subspace,
                prismatic,
                coord: if j.kind == JointKind::Fixed {
                    None
                } else {
                    coord_of(ji)
                },
            });
        }
        let nj = joints.len();
        Self {
            joints,
            inertia: model.links.iter().map(link_inertia).collect(),
            nf: n + model.mimic.len(),
            xup: vec![Xform::IDENTITY; nj],
            vel: vec![Motion::ZERO; nj],
            acc: vec![Motion::ZERO; nj],
            force: vec![Force::ZERO; nj],
            composite: vec![Inertia::ZERO; nj],
        }
    }

    /// Number of coordinates, controlled and mimic.
    pub(super) fn coords(&self) -> usize {
        self.nf
    }

    /// The coordinates in tree order (parents before children).
    pub(super) fn coords_in_order(&self) -> Vec<usize> {
        self.joints.iter().filter_map(|j| j.coord).collect()
    }

    /// nf × nf (row-major): whether M's entry for two coordinates can be
    /// non-zero, i.e. one moves the other's joint (same branch).
    pub(super) fn coupling(&self) -> Vec<bool> {
        let nf = self.nf;
        let mut out = vec![false; nf * nf];
        for (i, j) in self.joints.iter().enumerate() {
            let Some(ci) = j.coord else { continue };
            out[ci * nf + ci] = true;
            let mut k = i;
            while let Some(p) = self.joints[k].parent {
                k = p;
                if let Some(ck) = self.joints[k].coord {
                    out[ci * nf + ck] = true;
                    out[ck * nf + ci] = true;
                }
            }
        }
        out
    }

    /// Sets link `link`'s spatial inertia (a payload added to it).
    pub(super) fn set_link_inertia(&mut self, link: usize, inertia: Inertia) {
        self.inertia[link] = inertia;
    }

    /// The bias h(q, q̇) into `h` and M(q) into `m` (row-major nf × nf,
    /// zeroed before the first call and used for nothing else), for full
    /// coordinates `q`, `qd` and gravity `g` in the root frame.
    pub(super) fn dynamics(
        &mut self,
        q: &[f64],
        qd: &[f64],
        g: Vector3<f64>,
        h: &mut [f64],
        m: &mut [f64],
    ) {
        self.forward(q, qd, g);
        self.backward(h);
        self.mass_matrix(m);
    }

    /// Link transforms, velocities and bias accelerations, root to leaves.
    /// Gravity enters as the root accelerating upwards (Featherstone's trick).
    fn forward(&mut self, q: &[f64], qd: &[f64], g: Vector3<f64>) {
        let root_acc = Motion {
            w: Vector3::zeros(),
            v: -g,
        };
        for (i, j) in self.joints.iter().enumerate() {
            let (qi, qdi) = j.coord.map_or((0.0, 0.0), |c| (q[c], qd[c]));
            let motion = if j.prismatic {
                Xform {
                    e: Matrix3::identity(),
                    r: j.axis * qi,
                }
            } else {
                let rot = Rotation3::from_axis_angle(&Unit::new_unchecked(j.axis), qi);
                Xform {
                    e: rot.matrix().transpose(),
                    r: Vector3::zeros(),
                }
            };
            let x = j.origin.then(motion);
            let vj = j.subspace.scaled(qdi);
            let (vp, ap) = match j.parent {
                Some(p) => (self.vel[p], self.acc[p]),
                None => (Motion::ZERO, root_acc),
            };
            let v = x.motion(vp).add(vj);
            self.acc[i] = x.motion(ap).add(v.cross_motion(vj));
            self.vel[i] = v;
            self.xup[i] = x;
            let inertia = &self.inertia[j.link];
            self.force[i] = inertia
                .apply(self.acc[i])
                .add(v.cross_force(inertia.apply(v)));
        }
    }

    /// Joint forces from the link forces, leaves to root: the bias.
    fn backward(&mut self, h: &mut [f64]) {
        for i in (0..self.joints.len()).rev() {
            let j = &self.joints[i];
            if let Some(c) = j.coord {
                h[c] = j.subspace.dot(self.force[i]);
            }
            if let Some(p) = j.parent {
                let back = self.xup[i].force_back(self.force[i]);
                self.force[p] = self.force[p].add(back);
            }
        }
    }

    /// The composite-rigid-body algorithm on the transforms of `forward`.
    /// It writes every entry where two coordinates share a branch (the
    /// same ones each call); the others are zero and left alone, so `m`
    /// must start zeroed and serve only this tree.
    fn mass_matrix(&mut self, m: &mut [f64]) {
        let nf = self.nf;
        for (c, j) in self.composite.iter_mut().zip(&self.joints) {
            *c = self.inertia[j.link];
        }
        for i in (0..self.joints.len()).rev() {
            if let Some(p) = self.joints[i].parent {
                let back = self.xup[i].inertia_back(&self.composite[i]);
                self.composite[p] = self.composite[p].add(&back);
            }
            let Some(ci) = self.joints[i].coord else {
                continue;
            };
            let mut f = self.composite[i].apply(self.joints[i].subspace);
            m[ci * nf + ci] = self.joints[i].subspace.dot(f);
            let mut k = i;
            while let Some(p) = self.joints[k].parent {
                f = self.xup[k].force_back(f);
                k = p;
                if let Some(ck) = self.joints[k].coord {
                    let mik = self.joints[k].subspace.dot(f);
                    m[ci * nf + ck] = mik;
                    m[ck * nf + ci] = mik;
                }
            }
        }
    }
}
