//! The log's messages as ROS 2 sees them: CDR data ([`crate::cdr`]) with
//! `ros2msg` schema texts, as rosbag2 writes MCAP (the `ros2` profile).
//!
//! Each wire message is a message of the testbed's own package,
//! `testbed_msgs/msg/<Name>`, made from its field list
//! ([`wire::data_message!`]) like the JSON codec before it: the `.msg`
//! text, the encoder and the decoder all walk that list, so they cannot
//! drift apart. The fields follow a `std_msgs/Header` (stamp: the sample's
//! sim time) and the wire header's `seq` and `wall_ns`, in the wire's
//! order, with these types: `U32` → `uint32`, `U64` → `uint64`, `I64` →
//! `int64`, `F64` → `float64`, `J` → `float64[]` (one entry per joint in
//! use). The package is shipped in `logger/msg/testbed_msgs/`, generated
//! from here (a test keeps it equal).
//!
//! Beside them the log carries standard messages for the tools that know
//! only those: `sensor_msgs/msg/JointState` for the states and the
//! commands, `tf2_msgs/msg/TFMessage` for the arm's frames,
//! `visualization_msgs/msg/MarkerArray` for its stick figure and
//! `std_msgs/msg/String` for the model (`/robot_description`, latched);
//! and what rosbag2 reads besides: each channel's offered QoS and the
//! `rosbag2` metadata record ([`rosbag2_metadata`]).

use wire::FieldRef;

use crate::LogMessage;
use crate::cdr::CdrWriter;
use crate::msg_schema::{MsgSchema, SchemaError};

/// The testbed's message package.
pub const PACKAGE: &str = "testbed_msgs";

/// What separates a schema text's message from the messages it uses.
const SEPARATOR: &str =
    "================================================================================";

/// `builtin_interfaces/msg/Time`.
const TIME: &str = "int32 sec\nuint32 nanosec\n";
/// `std_msgs/msg/Header`.
const HEADER: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";

/// A schema text: `main`, then each used message as `MSG: name` after a
/// separator line (the `ros2msg` encoding rosbag2 writes).
fn with_deps(main: &str, deps: &[(&str, &str)]) -> String {
    let mut s = main.to_string();
    for (name, text) in deps {
        s.push_str(SEPARATOR);
        s.push_str("\nMSG: ");
        s.push_str(name);
        s.push('\n');
        s.push_str(text);
    }
    s
}

const HEADER_DEPS: [(&str, &str); 2] = [
    ("std_msgs/Header", HEADER),
    ("builtin_interfaces/Time", TIME),
];

/// The QoS a rosbag2 recording gives a topic, as its channel's
/// `offered_qos_profiles` (YAML in the numeric form of rosbag2's metadata
/// version 8, which Humble writes and, with the [`ROSBAG2_METADATA`]
/// record saying version 8, Jazzy reads): reliable, automatic liveliness,
/// no deadline, lifespan or lease (the largest durations, rmw's
/// "infinite"). A stream is volatile with the system's default history
/// (history 3, depth 0); a latched topic ([`ROBOT_DESCRIPTION_TOPIC`]) is
/// offered as robot_state_publisher offers `/robot_description`: keep last
/// 1, transient local (durability 1), so that a subscriber that joins late
/// (Foxglove's 3D panel, `ros2 bag play`'s listeners) gets it. `ros2 bag
/// play` re-offers each topic with it.
pub fn qos_profiles(latched: bool) -> String {
    let (history, depth, durability) = if latched { (1, 1, 1) } else { (3, 0, 2) };
    let infinite = "\n    sec: 2147483647\n    nsec: 4294967295";
    format!(
        "- history: {history}\n  depth: {depth}\n  reliability: 1\n  durability: {durability}\n  \
         deadline:{infinite}\n  lifespan:{infinite}\n  liveliness: 1\n  \
         liveliness_lease_duration:{infinite}\n  avoid_ros_namespace_conventions: false\n"
    )
}

/// The robot model as ROS 2 publishes it: the URDF text, latched.
pub const ROBOT_DESCRIPTION_TOPIC: &str = "/robot_description";

/// The channel metadata of `topic` as rosbag2 writes it: its offered QoS
/// (latched for [`ROBOT_DESCRIPTION_TOPIC`]).
pub fn channel_metadata(topic: &str) -> std::collections::BTreeMap<String, String> {
    let qos = qos_profiles(topic == ROBOT_DESCRIPTION_TOPIC);
    std::collections::BTreeMap::from([("offered_qos_profiles".to_string(), qos)])
}

/// Name of the metadata record rosbag2's MCAP storage plugin reads the
/// bag's metadata from (`serialized_metadata`, YAML of its `BagMetadata`).
/// Without it Jazzy took the channels' QoS to be in version 9's text form
/// and read every one as "unknown".
pub const ROSBAG2_METADATA: &str = "rosbag2";
/// The `BagMetadata` version the record declares: 8, whose QoS profiles
/// are numeric, as [`qos_profiles`] writes them (9 spells them as words,
/// which Humble cannot read).
pub const BAG_METADATA_VERSION: u32 = 8;
/// The ROS 2 distribution the record names.
pub const ROS_DISTRO: &str = "jazzy";

/// One channel as the `rosbag2` record lists it.
#[derive(Debug, Clone, PartialEq)]
pub struct BagTopic {
    /// The topic.
    pub name: String,
    /// Its ROS 2 type (`sensor_msgs/msg/JointState`).
    pub type_name: String,
    /// Its message encoding (`cdr`).
    pub serialization_format: String,
    /// Its `offered_qos_profiles` (YAML text).
    pub offered_qos_profiles: String,
    /// Messages written on it.
    pub message_count: u64,
}

/// The `rosbag2` metadata record of a log named `file` (its file name)
/// whose messages span `start_ns..=end_ns` of log time: every key Jazzy's
/// `BagMetadata` decoder reads (version, storage_identifier, duration,
/// starting_time, message_count, topics_with_message_count,
/// compression_format, compression_mode, relative_file_paths, files,
/// custom_data, ros_distro) as `serialized_metadata`, and `ROS_DISTRO` as
/// Iron's plugin wrote it. Strings are YAML double-quoted scalars.
pub fn rosbag2_metadata(
    file: &str,
    topics: &[BagTopic],
    (start_ns, end_ns): (u64, u64),
) -> std::collections::BTreeMap<String, String> {
    let q = |s: &str| serde_json::Value::from(s).to_string();
    let duration = end_ns.saturating_sub(start_ns);
    let count: u64 = topics.iter().map(|t| t.message_count).sum();
    let mut y = format!(
        "version: {BAG_METADATA_VERSION}\nstorage_identifier: {}\nduration:\n  nanoseconds: {duration}\n\
         starting_time:\n  nanoseconds_since_epoch: {start_ns}\nmessage_count: {count}\n",
        q("mcap")
    );
    if topics.is_empty() {
        y.push_str("topics_with_message_count: []\n");
    } else {
        y.push_str("topics_with_message_count:\n");
    }
    for t in topics {
        y.push_str(&format!(
            "  - topic_metadata:\n      name: {}\n      type: {}\n      serialization_format: {}\n\
             \x20     offered_qos_profiles: {}\n      type_description_hash: \"\"\n    message_count: {}\n",
            q(&t.name),
            q(&t.type_name),
            q(&t.serialization_format),
            q(&t.offered_qos_profiles),
            t.message_count
        ));
    }
    y.push_str(&format!(
        "compression_format: \"\"\ncompression_mode: \"\"\nrelative_file_paths:\n  - {f}\nfiles:\n  - path: {f}\n\
         \x20   starting_time:\n      nanoseconds_since_epoch: {start_ns}\n    duration:\n      nanoseconds: {duration}\n\
         \x20   message_count: {count}\ncustom_data: {{}}\nros_distro: {}\n",
        q(ROS_DISTRO),
        f = q(file),
    ));
    std::collections::BTreeMap::from([
        ("serialized_metadata".to_string(), y),
        ("ROS_DISTRO".to_string(), ROS_DISTRO.to_string()),
    ])
}

/// `std_msgs/msg/String`.
pub const STRING: &str = "std_msgs/msg/String";

/// The schema of [`STRING`].
pub fn string_schema() -> String {
    "string data\n".to_string()
}

/// A `std_msgs/msg/String` holding `text`.
pub fn string_message(out: &mut Vec<u8>, text: &str) {
    CdrWriter::new(out).string(text);
}

/// The `testbed_msgs/msg/<Name>` name of a wire message.
pub fn type_name<M: LogMessage>() -> String {
    format!("{PACKAGE}/msg/{}", msg_name::<M>())
}

/// The message's name in its package (`JointState`, `Reference`, …).
pub fn msg_name<M: LogMessage>() -> &'static str {
    let s = M::LOG_SCHEMA;
    s.rsplit('.').next().unwrap_or(s)
}

/// The `.msg` definition of a wire message, made from its field list.
pub fn msg_text<M: LogMessage>() -> String {
    let mut s = String::new();
    for line in wrap(M::ABOUT, 76) {
        s.push_str("# ");
        s.push_str(&line);
        s.push('\n');
    }
    s.push_str(
        "# Generated from the wire's field list (crate wire, data_message!): do not edit.\n\n",
    );
    s.push_str("std_msgs/Header header  # stamp: the sample's sim time; frame_id empty\n");
    s.push_str("uint64 seq  # sequence number (the control step for step-aligned topics)\n");
    s.push_str("uint64 wall_ns  # CLOCK_MONOTONIC when published, ns\n");
    M::default().visit(&mut |name, f| {
        let ty = match f {
            FieldRef::U32(_) => "uint32",
            FieldRef::U(_) => "uint64",
            FieldRef::I(_) => "int64",
            FieldRef::F(_) => "float64",
            FieldRef::J(_) | FieldRef::V(_) => "float64[]",
        };
        s.push_str(ty);
        s.push(' ');
        s.push_str(name);
        match f {
            FieldRef::J(_) => s.push_str("  # one entry per joint, in joint order"),
            // ContactState's values are poses, OwnDiagnostics' the
            // controller's own diagnostics (#48 item 17).
            FieldRef::V(_) if name == "objects" => s.push_str(
                "  # each free object's pose, world frame: x, y, z (m), then the quaternion x, y, z, w; 7 values per object",
            ),
            FieldRef::V(_) => s.push_str("  # the declared diagnostics' values, in order"),
            _ => {}
        }
        s.push('\n');
    });
    s
}

/// The `ros2msg` schema of a wire message: its definition and the
/// standard messages it uses.
pub fn schema_text<M: LogMessage>() -> String {
    with_deps(&msg_text::<M>(), &HEADER_DEPS)
}

/// The schema this build writes for `M`, read back as a field list.
pub fn msg_schema<M: LogMessage>() -> Result<MsgSchema, SchemaError> {
    MsgSchema::parse(&type_name::<M>(), schema_text::<M>().as_bytes())
}

fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split_whitespace() {
        let line = lines.last_mut().filter(|l| l.len() + word.len() < width);
        match line {
            Some(l) => {
                if !l.is_empty() {
                    l.push(' ');
                }
                l.push_str(word);
            }
            None => lines.push(word.to_string()),
        }
    }
    lines
}

/// Appends the message's CDR to `out`.
pub fn encode<M: LogMessage>(m: &M, out: &mut Vec<u8>) {
    let h = m.header();
    let mut w = CdrWriter::new(out);
    w.header(h.t_ns, "");
    w.u64(h.seq);
    w.u64(h.wall_ns);
    m.each_field(|_, f| match f {
        FieldRef::U32(x) => w.u32(x),
        FieldRef::U(x) => w.u64(x),
        FieldRef::I(x) => w.i64(x),
        FieldRef::F(x) => w.f64(x),
        FieldRef::J(xs) | FieldRef::V(xs) => w.f64s(xs),
    });
}

/// `sensor_msgs/msg/JointState`.
pub const JOINT_STATE: &str = "sensor_msgs/msg/JointState";

/// The schema of [`JOINT_STATE`].
pub fn joint_state_schema() -> String {
    with_deps(
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
        &HEADER_DEPS,
    )
}

/// A `sensor_msgs/msg/JointState` stamped `t_ns`.
pub fn joint_state(
    out: &mut Vec<u8>,
    t_ns: u64,
    names: &[String],
    position: &[f64],
    velocity: &[f64],
    effort: &[f64],
) {
    let mut w = CdrWriter::new(out);
    w.header(t_ns, "");
    w.len(names.len());
    for n in names {
        w.string(n);
    }
    w.f64s(position);
    w.f64s(velocity);
    w.f64s(effort);
}

/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: &str = "tf2_msgs/msg/TFMessage";

const VECTOR3: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION: &str = "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";

/// The schema of [`TF_MESSAGE`].
pub fn tf_schema() -> String {
    with_deps(
        "geometry_msgs/TransformStamped[] transforms\n",
        &[
            (
                "geometry_msgs/TransformStamped",
                "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
            ),
            (
                "geometry_msgs/Transform",
                "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
            ),
            ("geometry_msgs/Vector3", VECTOR3),
            ("geometry_msgs/Quaternion", QUATERNION),
            HEADER_DEPS[0],
            HEADER_DEPS[1],
        ],
    )
}

/// A rigid transform: translation x, y, z and rotation x, y, z, w.
pub type Pose = ([f64; 3], [f64; 4]);

/// The fixed frame: the URDF's root link sits at its origin.
pub const WORLD_FRAME: &str = "world";

/// A rigid transform as translation and quaternion (x, y, z, w).
pub(crate) fn parts(p: &nalgebra::Isometry3<f64>) -> Pose {
    let (t, r) = (p.translation.vector, p.rotation);
    ([t.x, t.y, t.z], [r.i, r.j, r.k, r.w])
}

/// A `tf2_msgs/msg/TFMessage`: each `(parent, child, pose)`, stamped `t_ns`.
pub fn tf_message<'a>(
    out: &mut Vec<u8>,
    t_ns: u64,
    frames: impl ExactSizeIterator<Item = (&'a str, &'a str, Pose)>,
) {
    let mut w = CdrWriter::new(out);
    w.len(frames.len());
    for (parent, child, (t, r)) in frames {
        w.header(t_ns, parent);
        w.string(child);
        for x in t.into_iter().chain(r) {
            w.f64(x);
        }
    }
}

/// `visualization_msgs/msg/MarkerArray`.
pub const MARKER_ARRAY: &str = "visualization_msgs/msg/MarkerArray";

/// The schema of [`MARKER_ARRAY`]: the marker of ROS 2 Humble and later
/// (with the texture, UV and mesh-file fields that Foxy's lacks, whose
/// layout Humble's subscribers cannot read), from
/// `visualization_msgs/msg/Marker.msg` of ros2/common_interfaces 4.2.
pub fn marker_array_schema() -> String {
    with_deps(
        "visualization_msgs/Marker[] markers\n",
        &[
            (
                "visualization_msgs/Marker",
                "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\n\
                 int32 ADD=0\nint32 DELETE=2\n\
                 std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
                 geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
                 builtin_interfaces/Duration lifetime\nbool frame_locked\n\
                 geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\n\
                 string texture_resource\nsensor_msgs/CompressedImage texture\n\
                 visualization_msgs/UVCoordinate[] uv_coordinates\n\
                 string text\nstring mesh_resource\nvisualization_msgs/MeshFile mesh_file\n\
                 bool mesh_use_embedded_materials\n",
            ),
            (
                "sensor_msgs/CompressedImage",
                "std_msgs/Header header\nstring format\nuint8[] data\n",
            ),
            ("visualization_msgs/UVCoordinate", "float32 u\nfloat32 v\n"),
            (
                "visualization_msgs/MeshFile",
                "string filename\nuint8[] data\n",
            ),
            (
                "geometry_msgs/Pose",
                "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
            ),
            ("geometry_msgs/Point", VECTOR3),
            ("geometry_msgs/Vector3", VECTOR3),
            ("geometry_msgs/Quaternion", QUATERNION),
            (
                "std_msgs/ColorRGBA",
                "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
            ),
            ("builtin_interfaces/Duration", TIME),
            HEADER_DEPS[0],
            HEADER_DEPS[1],
        ],
    )
}

/// One shape of the stick figure, locked to its frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// The frame it rides on (also its namespace).
    pub frame: String,
    /// Unique within the frame.
    pub id: i32,
    /// `Marker.SPHERE` (2) or `Marker.CYLINDER` (3).
    pub kind: i32,
    /// Its pose in the frame.
    pub pose: Pose,
    /// Its size along x, y, z.
    pub scale: [f64; 3],
    /// r, g, b, a.
    pub color: [f32; 4],
    /// How long it shows after its stamp, ns (0: until replaced).
    pub lifetime_ns: u64,
}

/// A `visualization_msgs/msg/MarkerArray` of `markers`, stamped `t_ns`.
pub fn marker_array(out: &mut Vec<u8>, t_ns: u64, markers: &[Marker]) {
    let mut w = CdrWriter::new(out);
    w.len(markers.len());
    for m in markers {
        w.header(t_ns, &m.frame);
        w.string(&m.frame);
        w.i32(m.id);
        w.i32(m.kind);
        w.i32(0);
        for x in m.pose.0.into_iter().chain(m.pose.1).chain(m.scale) {
            w.f64(x);
        }
        for c in m.color {
            w.f32(c);
        }
        w.time(m.lifetime_ns);
        w.u8(1);
        w.len(0);
        w.len(0);
        // texture_resource, texture (a CompressedImage: header, format,
        // data), uv_coordinates: none.
        w.string("");
        w.header(0, "");
        w.string("");
        w.len(0);
        w.len(0);
        w.string("");
        w.string("");
        // mesh_file: filename, data.
        w.string("");
        w.len(0);
        w.u8(0);
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;
    use crate::cdr_decode::decode;
    use wire::{Command, ControllerDiagnostics, JointState, Timing};
    use wire::{Header, MAX_DOF};

    #[test]
    fn every_field_round_trips_bit_for_bit() {
        let mut s = JointState {
            header: Header {
                seq: 7,
                t_ns: 7_000_000_123,
                wall_ns: u64::MAX - 3,
            },
            dof: 3,
            flags: 1,
            effects: 0x1ff,
            deadline_misses: 4,
            command_seq: wire::NONE_U64,
            applied_wall_ns: 99,
            ..JointState::default()
        };
        s.q[0] = 0.1 + 0.2;
        s.q[1] = -1e-300;
        s.qd[0] = f64::NAN;
        s.disturbance[2] = f64::INFINITY;
        let mut out = Vec::new();
        encode(&s, &mut out);
        let back: JointState = decode(&out).unwrap();
        assert_eq!(back.header, s.header);
        for (a, b) in back.q.iter().zip(&s.q).chain(back.qd.iter().zip(&s.qd)) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        assert_eq!(back.disturbance, s.disturbance);
        assert_eq!(
            (back.command_seq, back.effects, back.flags),
            (s.command_seq, s.effects, s.flags)
        );
        let t = Timing {
            round_trip_ns: -1,
            deadline_missed: 1,
            ..Timing::default()
        };
        out.clear();
        encode(&t, &mut out);
        assert_eq!(decode::<Timing>(&out).unwrap(), t);
        let d = ControllerDiagnostics {
            dof: MAX_DOF as u32,
            gamma: 0.25,
            tau: [1.5; MAX_DOF],
            ..ControllerDiagnostics::default()
        };
        out.clear();
        encode(&d, &mut out);
        assert_eq!(decode::<ControllerDiagnostics>(&out).unwrap(), d);
    }

    #[test]
    fn a_short_or_long_message_is_an_error() {
        let mut out = Vec::new();
        encode(&Command::default(), &mut out);
        for cut in [0, 3, 10, out.len() - 1] {
            assert!(decode::<Command>(&out[..cut]).is_err(), "{cut}");
        }
        out.extend([1; 8]);
        assert!(matches!(
            decode::<Command>(&out).unwrap_err(),
            crate::DecodeError::LongerThanSchema { .. }
        ));
        // A JointState's bytes are not a Timing.
        out.clear();
        encode(&JointState::default(), &mut out);
        assert!(decode::<Timing>(&out).is_err());
    }

    #[test]
    fn msg_texts_list_every_field_with_its_type() {
        let text = msg_text::<JointState>();
        assert!(text.contains("\nfloat64[] q_measured  #"), "{text}");
        assert!(text.contains("\nuint32 dof\n"), "{text}");
        assert!(text.contains("\nuint64 command_seq\n"), "{text}");
        assert!(!text.contains("reserved"));
        assert!(msg_text::<Timing>().contains("\nint64 round_trip_ns\n"));
        assert_eq!(
            type_name::<wire::ReferenceSample>(),
            "testbed_msgs/msg/Reference"
        );
        let schema = schema_text::<Command>();
        assert!(schema.contains(&format!("{SEPARATOR}\nMSG: std_msgs/Header\n")));
    }
}
