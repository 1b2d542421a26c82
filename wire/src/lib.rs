//! The wire contract between the testbed's processes.
//!
//! Where it sits: between every pair of processes. The plant publishes
//! [`JointState`], the trajectory [`ReferenceSample`], the controller
//! [`Command`] and [`ControllerDiagnostics`], the plant [`Timing`]; the
//! launcher sends [`Control`] and every node reports [`NodeStatus`]. All are
//! fixed-size `#[repr(C)]` values exchanged zero-copy over iceoryx2 shared
//! memory, each topic paired with an event service so receivers sleep until
//! data arrives.
//!
//! Rules every message follows: per-joint data lives in fixed arrays of
//! [`MAX_DOF`] entries with a `dof` field saying how many are used; every
//! sample starts with a [`Header`] carrying a sequence number, the sim time
//! in integer nanoseconds and a monotonic wall-clock timestamp; type names
//! carry a version (iceoryx2 only compares name, size and alignment, so a
//! changed layout must change the name).
//!
//! Services live under a per-run prefix ([`RunPrefix`]), so two runs, or two
//! tests, never see each other.
//!
//! Besides the messages and topics: the node protocol every process follows
//! ([`NodeLink`]: READY, START, DONE, STOP), the typed config file through
//! which the launcher hands each node its part of the plan
//! ([`write_config`], [`read_config`]), each data message's field list
//! ([`data_message!`], [`MessageFields`]) from which the log's codec is made,
//! each type's memory layout ([`all_layouts`]) from which other languages'
//! bindings are generated ([`bindings`]), the codes messages carry (the
//! plant's [`Effects`], the controller's [`Fault`]s), and absolute-deadline
//! sleeping ([`clock`]).

pub mod bindings;
pub mod clock;
mod config;
mod connections;
mod domain;
mod effects;
mod faults;
mod fields;
mod files;
mod layout;
mod leftovers;
mod messages;
mod node;
mod reference;
mod topics;

pub use config::{ConfigError, read_config, write_config};
pub use connections::{CONNECTION_FAILED, connection_failures};
pub use domain::DomainNodes;
pub use effects::Effects;
pub use faults::Fault;
pub use fields::{FieldRef, FieldSource, MessageFields};
pub use files::{MAX_TEXT_FILE_BYTES, MAX_URDF_BYTES, read_regular_file, read_text_file};
pub use iceoryx2::prelude::ZeroCopySend;
pub use layout::{
    FieldLayout, FieldType, TypeLayout, WireField, WireLayout, all_layouts, field_size,
};
pub use messages::*;
pub use node::{HEARTBEAT, Mode, NodeError, NodeLink, SILENT_AFTER, ns_to_s};
pub use reference::{ReferenceWindow, is_stale};
pub use topics::{
    Bus, Delivery, LOSSLESS_TIMEOUT, MAX_NODES, MAX_SUBSCRIBERS, RunPrefix, SUBSCRIBER_BUFFER,
    Topic, TopicPublisher, TopicSubscriber, WireError, monotonic_ns,
};

/// iceoryx2's own messages on stderr: only its errors unless `verbose`
/// (then its information too). `IOX2_LOG_LEVEL` in the environment still
/// decides when set.
pub fn set_ipc_log_level(verbose: bool) {
    use iceoryx2::prelude::{LogLevel, set_log_level, set_log_level_from_env_or};
    if verbose {
        set_log_level(LogLevel::Info);
    } else {
        set_log_level_from_env_or(LogLevel::Error);
    }
}
