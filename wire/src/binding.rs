//! Where each message travels, declared once: its topic on the bus, its
//! channel and schema in the log, and the structure name other languages'
//! bindings give it. The bus, the logger, the log reader and the bindings
//! generator all take the pairing from here.

use crate::{MessageFields, Topic};

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

/// The logged messages, declared once: calls `$then!` with one row per
/// message (`Type => TopicVariant, "/channel", "schema";`, the type a
/// name in `wire`: a caller outside it writes `wire::$ty`), in the order
/// the log opens their channels. The wire binds them here ([`Bound`],
/// [`Logged`]); the logger subscribes to each and opens its channel, and
/// the log's reader decodes each ([`Logged`] is matched exhaustively), all
/// from this one list. A message added here is logged and read, or the
/// code that must handle it does not compile.
#[macro_export]
macro_rules! logged_messages {
    ($then:ident) => {
        $then! {
            JointState => JointState, "/joint_state", "testbed.JointState";
            ReferenceSample => Reference, "/reference", "testbed.Reference";
            Command => Command, "/command", "testbed.Command";
            ControllerDiagnostics => Diagnostics, "/controller/diagnostics", "testbed.ControllerDiagnostics";
            Timing => Timing, "/timing", "testbed.Timing";
            OwnDiagnostics => OwnDiagnostics, "/controller/own_diagnostics", "testbed.OwnDiagnostics";
            ContactState => Contact, "/contact", "testbed.ContactState";
        }
    };
}

macro_rules! bind_logged {
    ($($ty:ident => $topic:ident, $channel:literal, $schema:literal;)*) => {
        $(impl Bound for crate::$ty {
            const TOPIC: Topic = Topic::$topic;
            const CHANNEL: Option<&'static str> = Some($channel);
            const SCHEMA: &'static str = $schema;
            const STRUCT: &'static str = stringify!($ty);
        })*

        /// One logged message of any type ([`logged_messages!`]'s list).
        #[derive(Debug, Clone, Copy, PartialEq)]
        #[allow(
            clippy::large_enum_variant,
            reason = "one message at a time, on the stack: boxing would allocate for every sample logged or read"
        )]
        pub enum Logged {
            $(
                #[doc = concat!("A `", stringify!($ty), "` (", $channel, ").")]
                $ty(crate::$ty),
            )*
        }

        $(impl From<crate::$ty> for Logged {
            fn from(m: crate::$ty) -> Self {
                Self::$ty(m)
            }
        })*

        impl Logged {
            /// Every logged message's channel, in the list's order.
            pub const CHANNELS: &'static [&'static str] = &[$($channel),*];

            /// The message's header.
            pub fn header(&self) -> &crate::Header {
                match self {
                    $(Self::$ty(m) => &m.header,)*
                }
            }
        }
    };
}

logged_messages!(bind_logged);

/// The messages that stay on the bus (the nodes' protocol), never logged:
/// calls `$then!` with one row per message (`Type => TopicVariant,
/// "schema";`), as [`logged_messages!`] does.
#[macro_export]
macro_rules! unlogged_messages {
    ($then:ident) => {
        $then! {
            Control => Control, "testbed.Control";
            NodeStatus => Status, "testbed.NodeStatus";
        }
    };
}

macro_rules! bind_unlogged {
    ($($ty:ident => $topic:ident, $schema:literal;)*) => {
        $(impl Bound for crate::$ty {
            const TOPIC: Topic = Topic::$topic;
            const CHANNEL: Option<&'static str> = None;
            const SCHEMA: &'static str = $schema;
            const STRUCT: &'static str = stringify!($ty);
        })*
    };
}

unlogged_messages!(bind_unlogged);

/// The structure name of the message a topic carries ("" for none: the
/// wire's test checks every topic has one).
pub fn struct_of(topic: Topic) -> &'static str {
    macro_rules! logged {
        ($($ty:ident => $topic:ident, $channel:literal, $schema:literal;)*) => {
            [$((Topic::$topic, stringify!($ty)),)*]
        };
    }
    macro_rules! unlogged {
        ($($ty:ident => $topic:ident, $schema:literal;)*) => {
            [$((Topic::$topic, stringify!($ty)),)*]
        };
    }
    let (logged, unlogged) = (logged_messages!(logged), unlogged_messages!(unlogged));
    logged
        .iter()
        .chain(&unlogged)
        .find(|(t, _)| *t == topic)
        .map_or("", |(_, s)| s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_topic_carries_one_message() {
        let structs: Vec<&str> = Topic::ALL.iter().map(|t| struct_of(*t)).collect();
        assert!(structs.iter().all(|s| !s.is_empty()), "{structs:?}");
        let mut unique = structs.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), Topic::ALL.len(), "{structs:?}");
        assert_eq!(crate::JointState::CHANNEL, Some("/joint_state"));
        assert_eq!(<crate::Timing as Bound>::TOPIC, Topic::Timing);
    }
}
