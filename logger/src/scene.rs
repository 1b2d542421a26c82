//! The arm in 3D for Foxglove's 3D panel and RViz: every link frame as a
//! `tf2_msgs/msg/TFMessage` (the `/tf` of ROS 2) in the URDF's tree (each
//! link in its parent link's frame, the root in `world`; links that fixed
//! or locked joints folded into another one included, each under its own
//! parent in the file at its joint's place), and a stick figure (a
//! cylinder from each link frame to the next joint, a sphere at each joint)
//! as a `visualization_msgs/msg/MarkerArray` whose markers ride on those
//! frames. The poses come from the URDF by the same forward kinematics as
//! the dynamics ([`arm_model::dynamics::Dynamics::link_poses`]).

use arm_model::dynamics::Dynamics;
use arm_model::{ArmModel, iso};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::obstacles::DrawnObstacle;
pub use crate::ros2::WORLD_FRAME;
use crate::ros2::{self, Marker, Pose, parts};

/// Topic of the link frames (ROS 2's).
pub const TRANSFORMS_TOPIC: &str = "/tf";
/// Topic of the arm's geometry.
pub const SCENE_TOPIC: &str = "/arm/scene";
/// A cylinder of the stick figure, in its link's frame.
#[derive(Debug, Clone)]
struct Bone {
    link: usize,
    to: Vector3<f64>,
}

/// The arm's frames and figure.
#[derive(Debug, Clone)]
pub struct ArmScene {
    dynamics: Dynamics,
    links: Vec<String>,
    /// Each model link's parent frame (None: the root): the URDF parent's
    /// name, the model link that frame is part of, and the frame's pose in
    /// that link (identity unless the parent was folded away: panda's
    /// fingers hang from panda_hand, which is part of panda_link7).
    parents: Vec<Option<(String, usize, Isometry3<f64>)>>,
    /// Links folded into another: (name, its parent link in the URDF, its
    /// pose there). The parent is the URDF's, folded or not, so that /tf is
    /// the file's tree (panda_hand under panda_link8, not the panda_link7
    /// both are part of).
    folded: Vec<(String, String, Isometry3<f64>)>,
    bones: Vec<Bone>,
    radius: f64,
    /// A contact scenario's obstacles, drawn in the world frame.
    obstacles: Vec<DrawnObstacle>,
}

/// One transform of `/tf`: the parent frame, the child frame, the child's
/// pose in the parent.
pub type Frame<'a> = (&'a str, &'a str, Pose);

impl ArmScene {
    /// The scene of `model`: a bone from each link frame to each joint it
    /// carries; a link that carries none (the tool end) gets a bone to twice
    /// its centre of mass, about where a uniform link ends.
    pub fn new(model: &ArmModel) -> Self {
        let mut bones: Vec<Bone> = model
            .joints
            .iter()
            .map(|j| Bone {
                link: j.parent,
                to: iso(&j.origin).translation.vector,
            })
            .collect();
        for (i, l) in model.links.iter().enumerate() {
            if i != model.root && !model.joints.iter().any(|j| j.parent == i) {
                let com = iso(&l.inertial_origin).translation.vector;
                bones.push(Bone {
                    link: i,
                    to: com * 2.0,
                });
            }
        }
        bones.retain(|b| b.to.norm() > 1e-6);
        let longest = bones.iter().map(|b| b.to.norm()).fold(0.0, f64::max);
        let mut parents = vec![None; model.links.len()];
        for j in &model.joints {
            let folded_parent = model
                .tree_parents
                .get(&model.links[j.child].name)
                .and_then(|p| model.merged_links.iter().find(|m| &m.name == p))
                .filter(|m| m.into == j.parent);
            parents[j.child] = Some(match folded_parent {
                Some(m) => (m.name.clone(), m.into, iso(&m.origin)),
                None => (
                    model.links[j.parent].name.clone(),
                    j.parent,
                    Isometry3::identity(),
                ),
            });
        }
        let folded = model
            .merged_links
            .iter()
            .map(|m| (m.name.clone(), m.parent.clone(), iso(&m.joint_origin)))
            .collect();
        Self {
            dynamics: Dynamics::new(model, 1.0),
            links: model.links.iter().map(|l| l.name.clone()).collect(),
            parents,
            folded,
            bones,
            radius: (0.08 * longest).clamp(0.005, 0.05),
            obstacles: Vec::new(),
        }
    }

    /// The scene with a contact scenario's obstacles drawn beside the arm.
    pub fn with_obstacles(mut self, obstacles: &[DrawnObstacle]) -> Self {
        self.obstacles = obstacles.to_vec();
        self
    }

    /// Every link's frame in its parent's at joint positions `q` (one
    /// entry per controlled joint): the model's links from their joints,
    /// then the folded links at their fixed places. A root link named
    /// `world` is the world frame itself.
    pub fn frames(&mut self, q: &[f64]) -> Vec<Frame<'_>> {
        let poses = self.dynamics.link_poses(q);
        let mut out: Vec<Frame<'_>> = Vec::with_capacity(self.links.len() + self.folded.len());
        for (i, name) in self.links.iter().enumerate() {
            let (parent, pose) = match &self.parents[i] {
                Some((p, k, at)) => (p.as_str(), (poses[*k] * *at).inverse() * poses[i]),
                None if name == WORLD_FRAME => continue,
                None => (WORLD_FRAME, poses[i]),
            };
            out.push((parent, name.as_str(), parts(&pose)));
        }
        for (name, parent, pose) in &self.folded {
            out.push((parent.as_str(), name.as_str(), parts(pose)));
        }
        out
    }

    /// [`ArmScene::frames`] as a `tf2_msgs/msg/TFMessage` stamped `t_ns`,
    /// appended to `out`.
    pub fn transforms(&mut self, out: &mut Vec<u8>, t_ns: u64, q: &[f64]) {
        let frames = self.frames(q);
        ros2::tf_message(out, t_ns, frames.into_iter());
    }

    /// The stick figure: per link a sphere at its origin and a cylinder
    /// along each bone, each locked to the link's frame, so it moves with
    /// the transforms without being sent again.
    pub fn markers(&self) -> Vec<Marker> {
        let d = 2.0 * self.radius;
        let mut out = Vec::new();
        for (i, name) in self.links.iter().enumerate() {
            out.push(Marker {
                frame: name.clone(),
                id: 0,
                kind: SPHERE,
                pose: parts(&Isometry3::identity()),
                scale: [1.5 * d; 3],
                color: [0.2, 0.2, 0.2, 1.0],
                lifetime_ns: 0,
            });
            for (k, b) in self.bones.iter().filter(|b| b.link == i).enumerate() {
                out.push(Marker {
                    frame: name.clone(),
                    id: k as i32 + 1,
                    kind: CYLINDER,
                    pose: parts(&cylinder_pose(b.to)),
                    scale: [d, d, b.to.norm()],
                    color: color(i),
                    lifetime_ns: 0,
                });
            }
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            out.push(o.marker(i as i32));
        }
        out
    }

    /// [`ArmScene::markers`] as a `visualization_msgs/msg/MarkerArray`
    /// stamped `t_ns`, appended to `out`.
    pub fn scene(&self, out: &mut Vec<u8>, t_ns: u64) {
        ros2::marker_array(out, t_ns, &self.markers());
    }
}

/// `visualization_msgs/Marker.SPHERE`.
const SPHERE: i32 = 2;
/// `visualization_msgs/Marker.CYLINDER`.
const CYLINDER: i32 = 3;

/// A cylinder (the marker's axis: z, centred) from the frame's origin to `to`.
fn cylinder_pose(to: Vector3<f64>) -> Isometry3<f64> {
    let rotation = UnitQuaternion::rotation_between(&Vector3::z(), &to).unwrap_or_else(|| {
        // Only for `to` along -z (rotation_between has no unique answer).
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    });
    Isometry3::from_parts((to / 2.0).into(), rotation)
}

/// Alternating link colours, so that neighbours stand apart.
fn color(link: usize) -> [f32; 4] {
    if link.is_multiple_of(2) {
        [0.95, 0.55, 0.1, 1.0]
    } else {
        [0.25, 0.5, 0.9, 1.0]
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// The elbow's frame sits at the end of link 1 (0.35 m along it), and
    /// link 2's bone ends where the link does (twice its COM, 0.31 m).
    #[test]
    fn frames_and_bones_follow_the_urdf() {
        let model = ArmModel::from_urdf_str(arm_model::TWO_LINK_URDF).unwrap();
        let mut scene = ArmScene::new(&model);
        let frames = scene.frames(&[0.0, 0.0]);
        let elbow = frames.iter().find(|(_, n, _)| *n == "link2").unwrap();
        assert_eq!(elbow.0, "link1");
        assert!((elbow.2.0[0] - 0.35).abs() < 1e-12);
        let root = frames.iter().find(|(p, _, _)| *p == WORLD_FRAME).unwrap();
        assert_eq!(
            frames.iter().filter(|f| f.0 == WORLD_FRAME).count(),
            1,
            "{root:?}"
        );
        let markers = scene.markers();
        let link2 = markers
            .iter()
            .find(|m| m.frame == "link2" && m.kind == CYLINDER)
            .unwrap();
        assert!((link2.scale[2] - 0.31).abs() < 1e-12, "{link2:?}");
        // A cylinder along +x: its centre halfway, its z axis turned onto x.
        let c = cylinder_pose(Vector3::new(0.31, 0.0, 0.0));
        assert!((c.translation.vector.x - 0.155).abs() < 1e-12);
        assert!((c.rotation * Vector3::z() - Vector3::x()).norm() < 1e-12);
        let down = cylinder_pose(Vector3::new(0.0, 0.0, -1.0));
        assert!((down.rotation * Vector3::z() + Vector3::z()).norm() < 1e-12);
    }
}

#[cfg(test)]
mod tree_tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    fn attribute_values(urdf: &str, tag: &str) -> Vec<String> {
        urdf.split(&format!("<{tag} name=\""))
            .skip(1)
            .map(|s| s.split('"').next().unwrap().to_string())
            .collect()
    }

    /// #39 row 14: `/tf` is the URDF's whole tree: every link once, each
    /// in its parent's frame, down from `world`.
    #[test]
    fn every_urdf_link_is_a_frame_of_one_tree() {
        let urdf = include_str!("../../robots/panda.urdf");
        let model = ArmModel::from_urdf_str(urdf).unwrap();
        let mut scene = ArmScene::new(&model);
        let q = vec![0.3; model.dof()];
        let frames: Vec<(String, String)> = scene
            .frames(&q)
            .into_iter()
            .map(|(p, c, _)| (p.to_string(), c.to_string()))
            .collect();
        let mut children: Vec<&str> = frames.iter().map(|f| f.1.as_str()).collect();
        children.sort_unstable();
        let mut links = attribute_values(urdf, "link");
        links.retain(|l| l != WORLD_FRAME);
        links.sort_unstable();
        assert_eq!(children, links);
        // Every parent is the world or another frame: one connected tree.
        for (parent, child) in &frames {
            assert!(
                parent == WORLD_FRAME || frames.iter().any(|f| &f.1 == parent),
                "{child}'s parent {parent} is no frame"
            );
        }
        assert_eq!(frames.iter().filter(|f| f.0 == WORLD_FRAME).count(), 1);
    }

    /// #48 item 17: each frame hangs from its parent in the URDF, fixed
    /// and locked joints included (panda_hand, its TCP and fingers were
    /// all put on panda_link7, the link they are folded into), at its
    /// joint's own origin.
    #[test]
    fn every_frame_hangs_from_its_urdf_parent() {
        let urdf = include_str!("../../robots/panda.urdf");
        // Every joint's (child, parent) as the file says.
        let joints: Vec<(String, String)> = urdf
            .split("<joint ")
            .skip(1)
            .map(|j| {
                let attr = |tag: &str| {
                    let at = j.find(&format!("<{tag} link=\"")).unwrap() + tag.len() + 8;
                    j[at..].split('"').next().unwrap().to_string()
                };
                (attr("child"), attr("parent"))
            })
            .collect();
        for locks in [
            arm_model::Locks::new(),
            arm_model::Locks::from([("panda_finger_joint1".to_string(), 0.02)]),
        ] {
            let model = ArmModel::from_urdf_str_locked(urdf, &locks).unwrap();
            let mut scene = ArmScene::new(&model);
            let q = vec![0.3; model.dof()];
            let frames = scene.frames(&q);
            for (child, parent) in &joints {
                let f = frames.iter().find(|f| f.1 == child.as_str()).unwrap();
                assert_eq!(f.0, parent.as_str(), "{child} ({} locks)", locks.len());
            }
            let hand = frames.iter().find(|f| f.1 == "panda_hand").unwrap();
            // panda_hand_joint: rpy 0 0 -pi/4 on panda_link8, no offset.
            assert!(hand.2.0.iter().all(|x| x.abs() < 1e-12), "{hand:?}");
            let tcp = frames.iter().find(|f| f.1 == "panda_hand_tcp").unwrap();
            assert!((tcp.2.0[2] - 0.1034).abs() < 1e-12, "{tcp:?}");
        }
    }
}
