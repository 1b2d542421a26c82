//! Where each message travels, declared once: its topic on the bus, its
//! channel and schema in the log, and the structure name other languages'
//! bindings give it. The bus, the logger, the log reader and the bindings
//! generator all take the pairing from here.

use crate::{
    Command, ContactState, Control, ControllerDiagnostics, JointState, MessageFields, NodeStatus,
    OwnDiagnostics, ReferenceSample, Timing, Topic,
};

/// A message bound to its topic and its log channel.
pub trait Bound: MessageFields {
    /// The bus topic it is published on.
    const TOPIC: Topic;
    /// Its MCAP channel (topic) in the log; None: not logged.
    const CHANNEL: Option<&'static str>;
    /// Its MCAP schema name in the log (versionless: the log format's
    /// version is the run's `log_format`).
    const SCHEMA: &'static str;
    /// The structure's name in generated bindings.
    const STRUCT: &'static str;
}

macro_rules! bind {
    ($($ty:ident => $topic:ident, $channel:expr, $schema:literal;)*) => {
        $(impl Bound for $ty {
            const TOPIC: Topic = Topic::$topic;
            const CHANNEL: Option<&'static str> = $channel;
            const SCHEMA: &'static str = $schema;
            const STRUCT: &'static str = stringify!($ty);
        })*

        /// The structure name of the message a topic carries.
        pub fn struct_of(topic: Topic) -> &'static str {
            match topic {
                $(Topic::$topic => stringify!($ty),)*
            }
        }
    };
}

bind! {
    JointState => JointState, Some("/joint_state"), "testbed.JointState";
    ReferenceSample => Reference, Some("/reference"), "testbed.Reference";
    Command => Command, Some("/command"), "testbed.Command";
    ControllerDiagnostics => Diagnostics, Some("/controller/diagnostics"), "testbed.ControllerDiagnostics";
    OwnDiagnostics => OwnDiagnostics, Some("/controller/own_diagnostics"), "testbed.OwnDiagnostics";
    Timing => Timing, Some("/timing"), "testbed.Timing";
    ContactState => Contact, Some("/contact"), "testbed.ContactState";
    Control => Control, None, "testbed.Control";
    NodeStatus => Status, None, "testbed.NodeStatus";
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_topic_carries_one_message() {
        let structs: Vec<&str> = Topic::ALL.iter().map(|t| struct_of(*t)).collect();
        let mut unique = structs.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), Topic::ALL.len(), "{structs:?}");
        assert_eq!(JointState::CHANNEL, Some("/joint_state"));
        assert_eq!(<Timing as Bound>::TOPIC, Topic::Timing);
    }
}
