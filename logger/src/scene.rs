//! The arm in 3D for Foxglove's 3D panel: every link frame as a
//! `foxglove.FrameTransforms` message, and a stick figure (a cylinder from
//! each link frame to the next joint, a sphere at each joint) as a
//! `foxglove.SceneUpdate` whose entities ride on those frames. Both are JSON
//! with a JSON schema of the fields written (a subset of Foxglove's), like
//! every other channel. The poses come from the URDF by the same forward
//! kinematics as the dynamics ([`arm_model::dynamics::Dynamics::link_poses`]).

use arm_model::dynamics::Dynamics;
use arm_model::{ArmModel, iso};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use serde_json::{Value, json};

/// Topic of the link frames.
pub const TRANSFORMS_TOPIC: &str = "/arm/transforms";
/// Schema of [`TRANSFORMS_TOPIC`] (Foxglove's well-known name).
pub const TRANSFORMS_SCHEMA: &str = "foxglove.FrameTransforms";
/// Topic of the arm's geometry.
pub const SCENE_TOPIC: &str = "/arm/scene";
/// Schema of [`SCENE_TOPIC`].
pub const SCENE_SCHEMA: &str = "foxglove.SceneUpdate";
/// The fixed frame: the URDF's root link sits at its origin.
pub const WORLD_FRAME: &str = "world";

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
    bones: Vec<Bone>,
    radius: f64,
}

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
        Self {
            dynamics: Dynamics::new(model, 1.0),
            links: model.links.iter().map(|l| l.name.clone()).collect(),
            bones,
            radius: (0.08 * longest).clamp(0.005, 0.05),
        }
    }

    /// Every link's frame in the world at joint positions `q` (one entry
    /// per controlled joint), stamped `t_ns`.
    pub fn transforms(&mut self, t_ns: u64, q: &[f64]) -> Value {
        let stamp = time(t_ns);
        let poses = self.dynamics.link_poses(q);
        let transforms: Vec<Value> = self
            .links
            .iter()
            .zip(poses)
            .map(|(name, pose)| {
                let (translation, rotation) = parts(pose);
                json!({
                    "timestamp": stamp,
                    "parent_frame_id": WORLD_FRAME,
                    "child_frame_id": name,
                    "translation": translation,
                    "rotation": rotation,
                })
            })
            .collect();
        json!({ "transforms": transforms })
    }

    /// The stick figure: one entity per link, locked to its frame, so it
    /// moves with the transforms without being sent again.
    pub fn scene(&self, t_ns: u64) -> Value {
        let stamp = time(t_ns);
        let d = 2.0 * self.radius;
        let entities: Vec<Value> = self
            .links
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let cylinders: Vec<Value> = self
                    .bones
                    .iter()
                    .filter(|b| b.link == i)
                    .map(|b| {
                        json!({
                            "pose": pose(&cylinder_pose(b.to)),
                            "size": {"x": d, "y": d, "z": b.to.norm()},
                            "bottom_scale": 1.0,
                            "top_scale": 1.0,
                            "color": color(i),
                        })
                    })
                    .collect();
                json!({
                    "timestamp": stamp,
                    "frame_id": name,
                    "id": name,
                    "lifetime": {"sec": 0, "nsec": 0},
                    "frame_locked": true,
                    "cylinders": cylinders,
                    "spheres": [{
                        "pose": pose(&Isometry3::identity()),
                        "size": {"x": 1.5 * d, "y": 1.5 * d, "z": 1.5 * d},
                        "color": {"r": 0.2, "g": 0.2, "b": 0.2, "a": 1.0},
                    }],
                })
            })
            .collect();
        json!({ "deletions": [], "entities": entities })
    }
}

/// A cylinder (Foxglove's axis: z, centred) from the frame's origin to `to`.
fn cylinder_pose(to: Vector3<f64>) -> Isometry3<f64> {
    let rotation = UnitQuaternion::rotation_between(&Vector3::z(), &to).unwrap_or_else(|| {
        // Only for `to` along -z (rotation_between has no unique answer).
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    });
    Isometry3::from_parts((to / 2.0).into(), rotation)
}

/// A rigid transform as Foxglove's Vector3 and Quaternion.
fn parts(p: &Isometry3<f64>) -> (Value, Value) {
    let (t, r) = (p.translation.vector, p.rotation);
    (
        json!({"x": t.x, "y": t.y, "z": t.z}),
        json!({"x": r.i, "y": r.j, "z": r.k, "w": r.w}),
    )
}

fn pose(p: &Isometry3<f64>) -> Value {
    let (position, orientation) = parts(p);
    json!({"position": position, "orientation": orientation})
}

/// Alternating link colours, so that neighbours stand apart.
fn color(link: usize) -> Value {
    if link.is_multiple_of(2) {
        json!({"r": 0.95, "g": 0.55, "b": 0.1, "a": 1.0})
    } else {
        json!({"r": 0.25, "g": 0.5, "b": 0.9, "a": 1.0})
    }
}

fn time(t_ns: u64) -> Value {
    json!({"sec": t_ns / 1_000_000_000, "nsec": t_ns % 1_000_000_000})
}

fn object(title: &str, props: Value) -> Value {
    let required: Vec<&String> = props
        .as_object()
        .map(|o| o.keys().collect())
        .unwrap_or_default();
    json!({"title": title, "type": "object", "properties": props, "required": required})
}

fn numbers(title: &str, keys: &[&str]) -> Value {
    let props: serde_json::Map<String, Value> = keys
        .iter()
        .map(|k| (k.to_string(), json!({"type": "number"})))
        .collect();
    object(title, Value::Object(props))
}

fn time_schema() -> Value {
    object(
        "time",
        json!({
            "sec": {"type": "integer", "minimum": 0},
            "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999},
        }),
    )
}

fn pose_schema() -> Value {
    object(
        "foxglove.Pose",
        json!({
            "position": numbers("foxglove.Vector3", &["x", "y", "z"]),
            "orientation": numbers("foxglove.Quaternion", &["x", "y", "z", "w"]),
        }),
    )
}

fn array(items: Value) -> Value {
    json!({"type": "array", "items": items})
}

/// The JSON schema of [`ArmScene::transforms`].
pub fn transforms_schema() -> Value {
    let transform = object(
        "foxglove.FrameTransform",
        json!({
            "timestamp": time_schema(),
            "parent_frame_id": {"type": "string"},
            "child_frame_id": {"type": "string"},
            "translation": numbers("foxglove.Vector3", &["x", "y", "z"]),
            "rotation": numbers("foxglove.Quaternion", &["x", "y", "z", "w"]),
        }),
    );
    let mut s = object(TRANSFORMS_SCHEMA, json!({ "transforms": array(transform) }));
    s["description"] = "Every link frame of the arm in the world frame".into();
    s
}

/// The JSON schema of [`ArmScene::scene`].
pub fn scene_schema() -> Value {
    let vec3 = || numbers("foxglove.Vector3", &["x", "y", "z"]);
    let rgba = || numbers("foxglove.Color", &["r", "g", "b", "a"]);
    let cylinder = object(
        "foxglove.CylinderPrimitive",
        json!({
            "pose": pose_schema(),
            "size": vec3(),
            "bottom_scale": {"type": "number"},
            "top_scale": {"type": "number"},
            "color": rgba(),
        }),
    );
    let sphere = object(
        "foxglove.SpherePrimitive",
        json!({"pose": pose_schema(), "size": vec3(), "color": rgba()}),
    );
    let mut lifetime = time_schema();
    lifetime["title"] = "duration".into();
    let entity = object(
        "foxglove.SceneEntity",
        json!({
            "timestamp": time_schema(),
            "frame_id": {"type": "string"},
            "id": {"type": "string"},
            "lifetime": lifetime,
            "frame_locked": {"type": "boolean"},
            "cylinders": array(cylinder),
            "spheres": array(sphere),
        }),
    );
    let mut s = object(
        SCENE_SCHEMA,
        json!({"deletions": array(json!({"type": "object"})), "entities": array(entity)}),
    );
    s["description"] = "The arm as a stick figure, one entity per link frame".into();
    s
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn validate(schema: &Value, msg: &Value) {
        let v = jsonschema::validator_for(schema).unwrap();
        if let Err(e) = v.validate(msg) {
            panic!("{msg} does not match its schema: {e}");
        }
    }

    #[test]
    fn messages_match_their_schemas() {
        let model = ArmModel::from_urdf_str(arm_model::TWO_LINK_URDF).unwrap();
        let mut scene = ArmScene::new(&model);
        validate(
            &transforms_schema(),
            &scene.transforms(1_500_000_000, &[0.3, -0.2]),
        );
        validate(&scene_schema(), &scene.scene(0));
    }

    /// The elbow's frame sits at the end of link 1 (0.35 m along it), and
    /// link 2's bone ends where the link does (twice its COM, 0.31 m).
    #[test]
    fn frames_and_bones_follow_the_urdf() {
        let model = ArmModel::from_urdf_str(arm_model::TWO_LINK_URDF).unwrap();
        let mut scene = ArmScene::new(&model);
        let tf = scene.transforms(0, &[0.0, 0.0]);
        let elbow = tf["transforms"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["child_frame_id"] == "link2")
            .unwrap();
        assert!((elbow["translation"]["x"].as_f64().unwrap() - 0.35).abs() < 1e-12);
        let s = scene.scene(0);
        let link2 = s["entities"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["frame_id"] == "link2")
            .unwrap();
        let len = link2["cylinders"][0]["size"]["z"].as_f64().unwrap();
        assert!((len - 0.31).abs() < 1e-12, "{len}");
        // A cylinder along +x: its centre halfway, its z axis turned onto x.
        let c = cylinder_pose(Vector3::new(0.31, 0.0, 0.0));
        assert!((c.translation.vector.x - 0.155).abs() < 1e-12);
        assert!((c.rotation * Vector3::z() - Vector3::x()).norm() < 1e-12);
        let down = cylinder_pose(Vector3::new(0.0, 0.0, -1.0));
        assert!((down.rotation * Vector3::z() + Vector3::z()).norm() < 1e-12);
    }
}
