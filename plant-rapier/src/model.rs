//! A URDF arm read into a checked, engine-neutral description.
//!
//! Parsing and checking happen here, once, so that the Rapier builder only
//! ever sees a tree it can simulate, and every problem is reported with the
//! link or joint it concerns.

use std::collections::{HashMap, VecDeque};

use crate::PlantError;

/// A rigid transform from a URDF `<origin xyz rpy>`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Origin {
    /// Translation, m.
    pub xyz: [f64; 3],
    /// Fixed-axis roll, pitch, yaw, rad.
    pub rpy: [f64; 3],
}

/// How a joint moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis between limits.
    Revolute,
    /// Rotation about the axis without limits.
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// No motion: the child moves with the parent.
    Fixed,
}

impl JointKind {
    /// True for the kinds the controller drives.
    pub fn is_actuated(self) -> bool {
        !matches!(self, JointKind::Fixed)
    }

    /// The URDF spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
        }
    }
}

/// One link's mass properties.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkInfo {
    /// URDF link name.
    pub name: String,
    /// Mass, kg (0 for a link with no `<inertial>`).
    pub mass: f64,
    /// Pose of the inertial frame in the link frame.
    pub inertial_origin: Origin,
    /// Inertia tensor about the COM in the inertial frame, kg m²,
    /// as [ixx, ixy, ixz, iyy, iyz, izz].
    pub inertia: [f64; 6],
}

/// One joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointInfo {
    /// URDF joint name.
    pub name: String,
    /// Its kind.
    pub kind: JointKind,
    /// Index of the parent link in [`ArmModel::links`].
    pub parent: usize,
    /// Index of the child link.
    pub child: usize,
    /// Pose of the joint frame (= child link frame at q = 0) in the parent link frame.
    pub origin: Origin,
    /// Unit axis in the joint frame.
    pub axis: [f64; 3],
    /// Position limits (lower, upper) for revolute and prismatic joints.
    pub limits: Option<(f64, f64)>,
    /// Effort limit (N m or N) when the URDF gives a positive one.
    pub effort: Option<f64>,
}

/// A checked arm: a tree of links rooted at one fixed link.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmModel {
    /// The robot's name.
    pub name: String,
    /// Links in file order.
    pub links: Vec<LinkInfo>,
    /// Joints in file order.
    pub joints: Vec<JointInfo>,
    /// Index of the root link (fixed to the world).
    pub root: usize,
    /// Joint indices from the root outwards (parents before children).
    pub topological: Vec<usize>,
    /// Indices of the actuated joints, in file order: the joint order used
    /// everywhere in the testbed.
    pub actuated: Vec<usize>,
    /// Fixed joints folded into their parent link, described for users.
    pub merged: Vec<String>,
    /// Links folded away by a merge: where each one now sits, so that a
    /// scenario can still name it (a payload at a tool link, say).
    pub merged_links: Vec<MergedLink>,
}

/// A link that a fixed joint folded into another one.
#[derive(Debug, Clone, PartialEq)]
pub struct MergedLink {
    /// The URDF name of the folded link.
    pub name: String,
    /// Index of the link it is now part of.
    pub into: usize,
    /// Its frame in that link's frame.
    pub origin: Origin,
}

impl ArmModel {
    /// Parses and checks a URDF document.
    pub fn from_urdf_str(text: &str) -> Result<Self, PlantError> {
        let robot =
            urdf_rs::read_from_string(text).map_err(|e| PlantError::Parse(e.to_string()))?;
        Self::from_robot(&robot)
    }

    fn from_robot(robot: &urdf_rs::Robot) -> Result<Self, PlantError> {
        let mut index = HashMap::new();
        let mut links = Vec::with_capacity(robot.links.len());
        for (i, l) in robot.links.iter().enumerate() {
            if index.insert(l.name.clone(), i).is_some() {
                return Err(PlantError::Duplicate {
                    what: "link",
                    name: l.name.clone(),
                });
            }
            links.push(link_info(l)?);
        }
        if links.is_empty() {
            return Err(PlantError::NoLinks);
        }

        let mut joints = Vec::with_capacity(robot.joints.len());
        let mut parent_of: Vec<Option<usize>> = vec![None; links.len()];
        let mut joint_names = HashMap::new();
        for (ji, j) in robot.joints.iter().enumerate() {
            if joint_names.insert(j.name.clone(), ji).is_some() {
                return Err(PlantError::Duplicate {
                    what: "joint",
                    name: j.name.clone(),
                });
            }
            let info = joint_info(j, &index)?;
            if let Some(other) = parent_of[info.child] {
                return Err(PlantError::TwoParents {
                    link: links[info.child].name.clone(),
                    first: robot.joints[other].name.clone(),
                    second: j.name.clone(),
                });
            }
            parent_of[info.child] = Some(ji);
            joints.push(info);
        }

        let model = Self::assemble(robot.name.clone(), links, joints, Vec::new(), Vec::new())?;
        model.merge_fixed_joints()
    }

    /// Finds the root, orders the joints from it, and lists the actuated ones.
    fn assemble(
        name: String,
        links: Vec<LinkInfo>,
        joints: Vec<JointInfo>,
        merged: Vec<String>,
        merged_links: Vec<MergedLink>,
    ) -> Result<Self, PlantError> {
        let mut parent_of: Vec<Option<usize>> = vec![None; links.len()];
        for (ji, j) in joints.iter().enumerate() {
            parent_of[j.child] = Some(ji);
        }
        let roots: Vec<usize> = (0..links.len())
            .filter(|&i| parent_of[i].is_none())
            .collect();
        let root = match roots.as_slice() {
            [r] => *r,
            [] => return Err(PlantError::NoRoot),
            many => {
                return Err(PlantError::ManyRoots(
                    many.iter().map(|&i| links[i].name.clone()).collect(),
                ));
            }
        };

        // Breadth-first from the root; a link never reached sits on a cycle.
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); links.len()];
        for (ji, j) in joints.iter().enumerate() {
            children[j.parent].push(ji);
        }
        let mut topological = Vec::with_capacity(joints.len());
        let mut reached = vec![false; links.len()];
        reached[root] = true;
        let mut queue = VecDeque::from([root]);
        while let Some(link) = queue.pop_front() {
            for &ji in &children[link] {
                let child = joints[ji].child;
                if !reached[child] {
                    reached[child] = true;
                    topological.push(ji);
                    queue.push_back(child);
                }
            }
        }
        if let Some(i) = reached.iter().position(|r| !r) {
            return Err(PlantError::Cycle {
                link: links[i].name.clone(),
            });
        }

        let actuated: Vec<usize> = (0..joints.len())
            .filter(|&i| joints[i].kind.is_actuated())
            .collect();
        if actuated.is_empty() {
            return Err(PlantError::NoActuatedJoints);
        }
        Ok(Self {
            name,
            links,
            joints,
            root,
            topological,
            actuated,
            merged,
            merged_links,
        })
    }

    /// Folds every fixed joint into its parent: the child's mass joins the
    /// parent link's, and the child's own joints hang from the parent. The
    /// plant then simulates only bodies that move independently.
    fn merge_fixed_joints(mut self) -> Result<Self, PlantError> {
        while let Some(ji) = self.joints.iter().position(|j| j.kind == JointKind::Fixed) {
            let j = self.joints.remove(ji);
            let (parent, child) = (j.parent, j.child);
            let t = iso(&j.origin);
            let child_link = self.links[child].clone();
            merge_mass(&mut self.links[parent], &child_link, &t);
            for k in &mut self.joints {
                if k.parent == child {
                    k.parent = parent;
                    k.origin = origin_of(&(t * iso(&k.origin)));
                }
            }
            self.merged.push(format!(
                "{} ({} into {})",
                j.name, child_link.name, self.links[parent].name
            ));
            for m in &mut self.merged_links {
                if m.into == child {
                    m.into = parent;
                    m.origin = origin_of(&(t * iso(&m.origin)));
                }
            }
            self.merged_links.push(MergedLink {
                name: child_link.name.clone(),
                into: parent,
                origin: j.origin,
            });
            // Drop the child link and renumber.
            self.links.remove(child);
            for k in &mut self.joints {
                if k.parent > child {
                    k.parent -= 1;
                }
                if k.child > child {
                    k.child -= 1;
                }
            }
            for m in &mut self.merged_links {
                if m.into > child {
                    m.into -= 1;
                }
            }
        }
        let model = Self::assemble(
            self.name,
            self.links,
            self.joints,
            self.merged,
            self.merged_links,
        )?;
        // A joint must move some mass, or its acceleration is undefined.
        for &ji in &model.actuated {
            let j = &model.joints[ji];
            if model.subtree_mass(j.child) <= 0.0 {
                return Err(PlantError::BadInertia {
                    link: model.links[j.child].name.clone(),
                    reason: format!(
                        "joint '{}' moves this link, but it and everything it carries have no mass",
                        j.name
                    ),
                });
            }
        }
        Ok(model)
    }

    fn subtree_mass(&self, link: usize) -> f64 {
        self.links[link].mass
            + self
                .joints
                .iter()
                .filter(|j| j.parent == link)
                .map(|j| self.subtree_mass(j.child))
                .sum::<f64>()
    }

    /// The link called `name` (a merged one too): the index of the body it
    /// is part of and its frame in that body's link frame.
    pub fn locate_link(&self, name: &str) -> Option<(usize, Origin)> {
        if let Some(i) = self.links.iter().position(|l| l.name == name) {
            return Some((i, Origin::default()));
        }
        self.merged_links
            .iter()
            .find(|m| m.name == name)
            .map(|m| (m.into, m.origin))
    }

    /// Names of every link a scenario may name: the URDF's, merged ones included.
    pub fn link_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.links.iter().map(|l| l.name.clone()).collect();
        names.extend(self.merged_links.iter().map(|m| m.name.clone()));
        names
    }

    /// Number of actuated joints.
    pub fn dof(&self) -> usize {
        self.actuated.len()
    }

    /// Names of the actuated joints, in order.
    pub fn joint_names(&self) -> Vec<String> {
        self.actuated
            .iter()
            .map(|&i| self.joints[i].name.clone())
            .collect()
    }

    /// Total mass of the links that move (every link but the root).
    pub fn moving_mass(&self) -> f64 {
        self.links
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != self.root)
            .map(|(_, l)| l.mass)
            .sum()
    }
}

pub(crate) fn iso(o: &Origin) -> nalgebra::Isometry3<f64> {
    nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(o.xyz[0], o.xyz[1], o.xyz[2]),
        nalgebra::UnitQuaternion::from_euler_angles(o.rpy[0], o.rpy[1], o.rpy[2]),
    )
}

fn origin_of(t: &nalgebra::Isometry3<f64>) -> Origin {
    let (r, p, y) = t.rotation.euler_angles();
    let v = t.translation.vector;
    Origin {
        xyz: [v.x, v.y, v.z],
        rpy: [r, p, y],
    }
}

/// The tensor about the COM in link axes, and the COM, of a link.
fn link_inertia(l: &LinkInfo) -> (nalgebra::Matrix3<f64>, nalgebra::Vector3<f64>) {
    let [ixx, ixy, ixz, iyy, iyz, izz] = l.inertia;
    let i = nalgebra::Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
    let t = iso(&l.inertial_origin);
    let r = t.rotation.to_rotation_matrix();
    (
        r.matrix() * i * r.matrix().transpose(),
        t.translation.vector,
    )
}

/// Adds `child`, placed at `t` in `parent`'s frame, to `parent`'s mass properties.
fn merge_mass(parent: &mut LinkInfo, child: &LinkInfo, t: &nalgebra::Isometry3<f64>) {
    let m = parent.mass + child.mass;
    if child.mass == 0.0 || m == 0.0 {
        return;
    }
    let (ip, cp) = link_inertia(parent);
    let (ic, cc) = link_inertia(child);
    let r = t.rotation.to_rotation_matrix();
    let ic = r.matrix() * ic * r.matrix().transpose();
    let cc = t * nalgebra::Point3::from(cc);
    let c = (parent.mass * cp + child.mass * cc.coords) / m;
    // Parallel-axis theorem for each part about the combined COM.
    let shift = |mass: f64, d: nalgebra::Vector3<f64>| {
        mass * (d.dot(&d) * nalgebra::Matrix3::identity() - d * d.transpose())
    };
    let i = ip + shift(parent.mass, cp - c) + ic + shift(child.mass, cc.coords - c);
    parent.mass = m;
    parent.inertial_origin = Origin {
        xyz: [c.x, c.y, c.z],
        rpy: [0.0; 3],
    };
    parent.inertia = [
        i[(0, 0)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 1)],
        i[(1, 2)],
        i[(2, 2)],
    ];
}

fn finite(field: String, v: f64) -> Result<f64, PlantError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(PlantError::NotFinite { field, value: v })
    }
}

fn origin(field: &str, o: &urdf_rs::Pose) -> Result<Origin, PlantError> {
    let mut out = Origin {
        xyz: [0.0; 3],
        rpy: [0.0; 3],
    };
    for k in 0..3 {
        out.xyz[k] = finite(format!("{field} origin xyz"), o.xyz.0[k])?;
        out.rpy[k] = finite(format!("{field} origin rpy"), o.rpy.0[k])?;
    }
    Ok(out)
}

fn link_info(l: &urdf_rs::Link) -> Result<LinkInfo, PlantError> {
    let field = format!("link '{}'", l.name);
    let mass = finite(format!("{field} mass"), l.inertial.mass.value)?;
    if mass < 0.0 {
        return Err(PlantError::BadInertia {
            link: l.name.clone(),
            reason: format!("mass {mass} is negative"),
        });
    }
    let i = &l.inertial.inertia;
    let inertia = [i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz];
    for v in inertia {
        finite(format!("{field} inertia"), v)?;
    }
    check_inertia(&l.name, mass, &inertia)?;
    Ok(LinkInfo {
        name: l.name.clone(),
        mass,
        inertial_origin: origin(&format!("{field} inertial"), &l.inertial.origin)?,
        inertia,
    })
}

/// A physical inertia tensor is positive semi-definite and its principal
/// moments obey the triangle inequality; a link with mass must have some
/// rotational inertia too (it is an extended body).
fn check_inertia(link: &str, mass: f64, i: &[f64; 6]) -> Result<(), PlantError> {
    let bad = |reason: String| {
        Err(PlantError::BadInertia {
            link: link.to_string(),
            reason,
        })
    };
    let [ixx, ixy, ixz, iyy, iyz, izz] = *i;
    if mass == 0.0 {
        if i.iter().any(|v| *v != 0.0) {
            return bad("inertia given for a link of zero mass".into());
        }
        return Ok(());
    }
    let m = nalgebra::Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
    let mut ev: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
    ev.sort_by(f64::total_cmp);
    let scale = ev[2].abs().max(f64::MIN_POSITIVE);
    if ev[0] <= 1e-12 * scale {
        return bad(format!(
            "the inertia tensor is not positive definite (principal moments {:.3e}, {:.3e}, {:.3e})",
            ev[0], ev[1], ev[2]
        ));
    }
    if ev[0] + ev[1] < ev[2] * (1.0 - 1e-9) {
        return bad(format!(
            "principal moments {:.3e}, {:.3e}, {:.3e} break the triangle inequality",
            ev[0], ev[1], ev[2]
        ));
    }
    Ok(())
}

fn joint_info(j: &urdf_rs::Joint, index: &HashMap<String, usize>) -> Result<JointInfo, PlantError> {
    use urdf_rs::JointType as T;
    let kind = match j.joint_type {
        T::Revolute => JointKind::Revolute,
        T::Continuous => JointKind::Continuous,
        T::Prismatic => JointKind::Prismatic,
        T::Fixed => JointKind::Fixed,
        T::Floating | T::Planar | T::Spherical => {
            return Err(PlantError::UnsupportedJoint {
                joint: j.name.clone(),
                kind: format!("{:?}", j.joint_type).to_lowercase(),
            });
        }
    };
    if j.mimic.is_some() {
        return Err(PlantError::Mimic {
            joint: j.name.clone(),
        });
    }
    let link = |name: &str, role: &'static str| {
        index
            .get(name)
            .copied()
            .ok_or_else(|| PlantError::MissingLink {
                joint: j.name.clone(),
                role,
                link: name.to_string(),
            })
    };
    let parent = link(&j.parent.link, "parent")?;
    let child = link(&j.child.link, "child")?;
    if parent == child {
        return Err(PlantError::Cycle {
            link: j.child.link.clone(),
        });
    }
    let field = format!("joint '{}'", j.name);
    let mut axis = [0.0; 3];
    for (k, a) in axis.iter_mut().enumerate() {
        *a = finite(format!("{field} axis"), j.axis.xyz.0[k])?;
    }
    let norm = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
    if kind.is_actuated() {
        if norm < 1e-9 {
            return Err(PlantError::ZeroAxis {
                joint: j.name.clone(),
            });
        }
        axis.iter_mut().for_each(|a| *a /= norm);
    }
    let lower = finite(format!("{field} limit lower"), j.limit.lower)?;
    let upper = finite(format!("{field} limit upper"), j.limit.upper)?;
    let effort = finite(format!("{field} limit effort"), j.limit.effort)?;
    // A revolute or prismatic joint without a usable <limit> (lower = upper,
    // as urdf-rs fills a missing one) moves freely rather than being locked.
    let limits = match kind {
        JointKind::Revolute | JointKind::Prismatic if lower < upper => Some((lower, upper)),
        JointKind::Revolute | JointKind::Prismatic if lower > upper => {
            return Err(PlantError::BadLimits {
                joint: j.name.clone(),
                lower,
                upper,
            });
        }
        _ => None,
    };
    Ok(JointInfo {
        name: j.name.clone(),
        kind,
        parent,
        child,
        origin: origin(&field, &j.origin)?,
        axis,
        limits,
        effort: (kind.is_actuated() && effort > 0.0).then_some(effort),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arm(joints: &str, links: &str) -> String {
        format!(
            r#"<robot name="t">
  <link name="base"/>
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  {links}
  {joints}
</robot>"#
        )
    }

    const J1: &str = r#"<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>"#;

    fn err(text: &str) -> String {
        ArmModel::from_urdf_str(text).unwrap_err().to_string()
    }

    #[test]
    fn the_two_link_arm_reads_as_specified() {
        let m = ArmModel::from_urdf_str(crate::TWO_LINK_URDF).unwrap();
        assert_eq!(m.joint_names(), ["joint1", "joint2"]);
        assert_eq!(m.links[m.root].name, "base_link");
        assert!((m.moving_mass() - 2.85).abs() < 1e-12);
        assert_eq!(m.joints[0].axis, [0.0, -1.0, 0.0]);
        assert_eq!(m.joints[1].origin.xyz, [0.35, 0.0, 0.0]);
    }

    /// The 0.2 kg tool on a fixed joint 0.2 m along link3 (0.5 kg, COM at
    /// 0.1 m, I = 0.5·0.2²/12 about it) folds into link3 by the parallel-axis theorem.
    #[test]
    fn fixed_joint_mass_merges_into_the_parent() {
        let m =
            ArmModel::from_urdf_str(include_str!("../../robots/three_link_planar.urdf")).unwrap();
        assert_eq!(m.dof(), 3);
        assert!(m.links.iter().all(|l| l.name != "tool"));
        let l3 = m.links.iter().find(|l| l.name == "link3").unwrap();
        let c = (0.5 * 0.1 + 0.2 * 0.2) / 0.7;
        assert!((l3.mass - 0.7).abs() < 1e-12);
        assert!((l3.inertial_origin.xyz[0] - c).abs() < 1e-12);
        let i_rod = 0.00166667; // 0.5·0.2²/12 as the URDF writes it
        let iyy = i_rod + 0.5 * (0.1 - c) * (0.1 - c) + 0.0001 + 0.2 * (0.2 - c) * (0.2 - c);
        assert!(
            (l3.inertia[3] - iyy).abs() < 1e-9,
            "{} vs {iyy}",
            l3.inertia[3]
        );
        assert_eq!(m.merged, ["tool_mount (tool into link3)"]);
    }

    #[test]
    fn a_joint_that_moves_no_mass_is_refused() {
        let j2 = J1
            .replace("j1", "j2")
            .replace("base", "a")
            .replace("<child link=\"a\"/>", "<child link=\"b\"/>");
        let e = err(&arm(&format!("{J1}{j2}"), "<link name=\"b\"/>"));
        assert!(
            e.contains("joint 'j2' moves this link") && e.contains("no mass"),
            "{e}"
        );
    }

    #[test]
    fn malformed_urdfs_are_named_errors() {
        assert!(err("not xml at all").starts_with("not a valid URDF"));
        let missing = J1.replace("<child link=\"a\"/>", "<child link=\"ghost\"/>");
        assert_eq!(
            err(&arm(&missing, "")),
            "joint 'j1': child link 'ghost' does not exist"
        );
        let floating =
            r#"<joint name="free" type="floating"><parent link="base"/><child link="a"/></joint>"#;
        assert!(err(&arm(floating, "")).contains("joint 'free' is floating"));
        let mimic = J1.replace("</joint>", "<mimic joint=\"j0\"/></joint>");
        assert!(err(&arm(&mimic, "")).contains("<mimic>"));
        let neg = r#"<link name="b"><inertial><mass value="-1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>"#;
        let jb = J1.replace("j1", "j2").replace("\"a\"", "\"b\"");
        assert_eq!(
            err(&arm(&format!("{J1}{jb}"), neg)),
            "link 'b': mass -1 is negative"
        );
        let tri = r#"<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.5"/></inertial></link>"#;
        assert!(err(&arm(&format!("{J1}{jb}"), tri)).contains("triangle inequality"));
        let loop_ = J1.replace("j1", "back").replace(
            "<parent link=\"base\"/><child link=\"a\"/>",
            "<parent link=\"a\"/><child link=\"base\"/>",
        );
        assert!(err(&arm(&format!("{J1}{loop_}"), "")).contains("loop"));
        let bad = J1.replace("lower=\"-1\" upper=\"1\"", "lower=\"1\" upper=\"-1\"");
        assert!(err(&arm(&bad, "")).contains("limit lower 1 is above upper -1"));
        let nan = J1.replace("0 0 1", "0 NaN 1");
        assert!(err(&arm(&nan, "")).contains("joint 'j1' axis"));
        assert!(err(&arm("", "")).contains("several root links"));
    }
}
