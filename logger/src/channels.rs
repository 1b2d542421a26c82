//! The channels a run publishes, once: the MCAP log and the live view
//! both open exactly this list, so a live run and its log show the same
//! topics with the same schemas (and one Foxglove layout serves both).
//! Every channel carries CDR messages with a `ros2msg` schema ([`crate::ros2`]).

use crate::LogMessage;
use crate::obstacles::CONTACT_MARKER_TOPIC;
use crate::ros2;
use crate::scene::{SCENE_TOPIC, TRANSFORMS_TOPIC};

/// The message encoding of every channel.
pub const MESSAGE_ENCODING: &str = "cdr";
/// The schema encoding of every channel.
pub const SCHEMA_ENCODING: &str = "ros2msg";
/// The MCAP profile of a log.
pub const PROFILE: &str = "ros2";

/// The plant's true state as `sensor_msgs/msg/JointState`: position q,
/// velocity q̇, effort the torque applied.
pub const JOINT_STATES_TOPIC: &str = "/joint_states";
/// The controller's torque as `sensor_msgs/msg/JointState` (effort only).
pub const JOINT_COMMANDS_TOPIC: &str = "/joint_commands";

/// One channel: CDR messages of one ROS 2 type.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelSpec {
    /// Topic.
    pub topic: &'static str,
    /// Schema name: the ROS 2 type (`testbed_msgs/msg/JointState`).
    pub schema_name: String,
    /// The `ros2msg` schema text.
    pub schema: String,
}

impl ChannelSpec {
    /// The channel of a wire message.
    pub fn of<M: LogMessage>() -> Self {
        Self {
            topic: M::LOG_TOPIC,
            schema_name: ros2::type_name::<M>(),
            schema: ros2::schema_text::<M>(),
        }
    }

    /// The robot model's latched channel (`std_msgs/msg/String`).
    pub fn robot_description() -> Self {
        Self::standard(
            ros2::ROBOT_DESCRIPTION_TOPIC,
            ros2::STRING,
            ros2::string_schema(),
        )
    }

    fn standard(topic: &'static str, name: &str, schema: String) -> Self {
        Self {
            topic,
            schema_name: name.into(),
            schema,
        }
    }
}

/// Every channel of a run, in the order the log opens them: the wire's
/// logged messages ([`wire::logged_messages!`]), then the standard views.
pub fn channels() -> Vec<ChannelSpec> {
    macro_rules! logged {
        ($($ty:ident => $topic:ident, $channel:literal, $schema:literal;)*) => {
            vec![$(ChannelSpec::of::<wire::$ty>(),)*]
        };
    }
    let mut all = wire::logged_messages!(logged);
    all.extend([
        ChannelSpec::standard(
            JOINT_STATES_TOPIC,
            ros2::JOINT_STATE,
            ros2::joint_state_schema(),
        ),
        ChannelSpec::standard(
            JOINT_COMMANDS_TOPIC,
            ros2::JOINT_STATE,
            ros2::joint_state_schema(),
        ),
        ChannelSpec::standard(TRANSFORMS_TOPIC, ros2::TF_MESSAGE, ros2::tf_schema()),
        ChannelSpec::standard(SCENE_TOPIC, ros2::MARKER_ARRAY, ros2::marker_array_schema()),
        ChannelSpec::standard(
            CONTACT_MARKER_TOPIC,
            ros2::MARKER_ARRAY,
            ros2::marker_array_schema(),
        ),
        ChannelSpec::robot_description(),
    ]);
    all
}

/// Where the Python log reader keeps the schemas this build writes.
pub const PYTHON_SCHEMAS_PATH: &str = "python/testbed_controller/log_schemas.py";

/// The Python module that tells `testbed_controller.log` which schemas a
/// log of this build holds: topic → [schema name, `ros2msg` text] for every
/// channel. The reader refuses a log whose schemas differ before it decodes
/// anything, as this crate's reader reads only its own messages: a schema
/// of 5 M lines, one that says uint64 for uint32, an empty one or one
/// nested a thousand deep would otherwise be decoded into garbage, or not
/// in minutes.
pub fn python_schemas_module() -> String {
    let map: std::collections::BTreeMap<&str, (String, String)> = channels()
        .into_iter()
        .map(|c| (c.topic, (c.schema_name, c.schema)))
        .collect();
    // JSON's strings and arrays are Python literals too.
    let body = serde_json::to_string_pretty(&map).unwrap_or_default();
    format!(
        "\"\"\"The `ros2msg` schemas a log of this build of the testbed holds, per topic:\n\
         [schema name, schema text]. Generated from the Rust logger's channels\n\
         (`logger::python_schemas_module`); `cargo test -p logger --lib python_schemas`\n\
         checks it is current, `TESTBED_WRITE_DOCS=1` rewrites it.\"\"\"\n\n\
         SCHEMA_ENCODING = {SCHEMA_ENCODING:?}\n\
         MESSAGE_ENCODING = {MESSAGE_ENCODING:?}\n\n\
         SCHEMAS = {body}\n"
    )
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        clippy::expect_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// The committed Python module equals what this build writes (write it
    /// with `TESTBED_WRITE_DOCS=1`).
    #[test]
    fn committed_python_schemas_are_current() {
        let path = format!("{}/../{PYTHON_SCHEMAS_PATH}", env!("CARGO_MANIFEST_DIR"));
        let module = python_schemas_module();
        if std::env::var_os("TESTBED_WRITE_DOCS").is_some() {
            std::fs::write(&path, &module).unwrap();
        }
        let shipped = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            shipped == module,
            "{path} is stale: TESTBED_WRITE_DOCS=1 cargo test -p logger --lib python_schemas"
        );
        assert!(module.contains("\"/joint_state\": [\n    \"testbed_msgs/msg/JointState\""));
    }
}
