//! The wire contract between the testbed's processes.
//!
//! Where it sits: between every pair of processes. The plant publishes
//! [`JointState`], the trajectory [`ReferenceSample`], the controller
//! [`Command`] and [`ControllerDiagnostics`] (an external controller also
//! its [`OwnDiagnostics`]), the plant [`Timing`] (and [`ContactState`] when
//! its links touch obstacles); the
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
//! Besides the messages and topics: the node protocol's constants
//! ([`Mode`], [`HEARTBEAT`], [`SILENT_AFTER`]), the reference rule
//! ([`is_stale`]), each data message's field list
//! ([`data_message!`], [`MessageFields`]) from which the log's codec is made,
//! each type's memory layout ([`all_layouts`]) from which other languages'
//! bindings are generated ([`bindings`]), the codes messages carry (the
//! plant's [`Effects`], the controller's [`Fault`]s). This crate is the
//! contract only: it opens no port and starts no thread. The runtime that
//! puts these messages on iceoryx2 shared memory (ports, the node protocol,
//! run prefixes, clocks) is the `bus` crate.

mod binding;
pub mod bindings;
mod effects;
mod faults;
mod fields;
mod files;
mod layout;
mod messages;
mod names;
mod own;
mod protocol;
mod reference_rule;
mod topic;

pub use binding::{Bound, Logged, struct_of};
pub use effects::Effects;
pub use faults::Fault;
pub use fields::{FieldError, FieldRef, FieldSource, MessageFields};
pub use files::{
    MAX_TEXT_FILE_BYTES, MAX_URDF_BYTES, open_regular_file, read_regular_file, read_text_file,
};
pub use iceoryx2::prelude::ZeroCopySend;
pub use layout::{
    FieldLayout, FieldType, TypeLayout, WireField, WireLayout, all_layouts, field_size,
};
pub use messages::*;
pub use names::{describe_char, forbidden_name_char};
pub use own::{OwnLayout, OwnLayoutError, OwnShape, is_diagnostic_name};
pub use protocol::{HEARTBEAT, Mode, SILENT_AFTER, UnknownMode, ns_to_s};
pub use reference_rule::is_stale;
pub use topic::{
    Delivery, LOSSLESS_TIMEOUT, MAX_NODES, MAX_SUBSCRIBERS, RUN_PREFIX_STEM, SUBSCRIBER_BUFFER,
    Topic,
};
