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
    ]);
    all
}
