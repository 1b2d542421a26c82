//! The channels a run publishes, once: the MCAP log and the live view
//! both open exactly this list, so a live run and its log show the same
//! topics with the same schemas (and one Foxglove layout serves both).

use serde_json::Value;
use wire::{Command, ControllerDiagnostics, JointState, ReferenceSample, Timing};

use crate::LogMessage;
use crate::scene::{
    SCENE_SCHEMA, SCENE_TOPIC, TRANSFORMS_SCHEMA, TRANSFORMS_TOPIC, scene_schema, transforms_schema,
};

/// One channel: JSON messages with a JSON schema.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelSpec {
    /// Topic.
    pub topic: &'static str,
    /// Schema name.
    pub schema_name: &'static str,
    /// The JSON schema.
    pub schema: Value,
}

impl ChannelSpec {
    /// The channel of a wire message.
    pub fn of<M: LogMessage>() -> Self {
        Self {
            topic: M::LOG_TOPIC,
            schema_name: M::LOG_SCHEMA,
            schema: M::schema(),
        }
    }
}

/// Every channel of a run, in the order the log opens them.
pub fn channels() -> Vec<ChannelSpec> {
    vec![
        ChannelSpec::of::<JointState>(),
        ChannelSpec::of::<ReferenceSample>(),
        ChannelSpec::of::<Command>(),
        ChannelSpec::of::<ControllerDiagnostics>(),
        ChannelSpec::of::<Timing>(),
        ChannelSpec {
            topic: TRANSFORMS_TOPIC,
            schema_name: TRANSFORMS_SCHEMA,
            schema: transforms_schema(),
        },
        ChannelSpec {
            topic: SCENE_TOPIC,
            schema_name: SCENE_SCHEMA,
            schema: scene_schema(),
        },
    ]
}
