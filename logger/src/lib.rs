//! The run log: one MCAP file per run that explains itself, and the
//! logger process that writes it.
//!
//! Where it sits: at the end of the data flow. The logger node
//! ([`node::run`]) subscribes to every data topic and writes what it
//! receives; `testbed replay` and the launcher's summary read the file
//! back ([`read_log`]). Nothing here steps the loop.
//!
//! The file follows MCAP's `ros2` profile, as rosbag2 writes it: channels
//! carry CDR messages with `ros2msg` schemas ([`ros2`]), so ROS 2 tools,
//! Foxglove, PlotJuggler and the official `mcap` readers decode every
//! field; chunks are zstd-compressed (LZ4 or none on request). Each
//! message's log time is its sim time and its publish time the sample's
//! wall timestamp. Logs of formats 1 and 2 (JSON messages with JSON
//! schemas) are still read: the reader hands each message's encoding with
//! it ([`Encoding`]). A metadata
//! record `testbed.run` holds the scenario (full TOML), run id, mode, rate,
//! software version and start time; the robot's URDF is an attachment; a
//! last metadata record `testbed.log_stats` counts what the logger received
//! and what it could not take.
//!
//! Besides the wire's topics, the logger derives the arm's link frames and
//! a stick figure for Foxglove's 3D panel ([`scene`]); with `--live` it also
//! serves every channel over the Foxglove WebSocket protocol ([`live`]).
//! Log and live view open one channel list ([`channels`]), and
//! [`foxglove_layout`] lays them out for either.

pub mod cdr;
pub mod cdr_decode;
mod channels;
mod compression;
mod decode;
mod decode_error;
mod json;
mod json_object;
mod layout;
pub mod live;
mod mcap_out;
pub mod msg_schema;
pub mod node;
pub mod obstacles;
mod outputs;
mod reader;
mod records;
pub mod ros2;
mod scan;
pub mod scene;
mod writer;

pub use channels::{
    ChannelSpec, JOINT_COMMANDS_TOPIC, JOINT_STATES_TOPIC, MESSAGE_ENCODING, PROFILE,
    PYTHON_SCHEMAS_PATH, SCHEMA_ENCODING, channels, python_schemas_module,
};
pub use compression::{LogCompression, UnknownCompression};
pub use decode::{Decode, decode_logged};
pub use decode_error::DecodeError;
pub use json::LogMessage;
pub use json_object::JsonObject;
pub use layout::foxglove_layout;
pub use reader::{
    Encoding, LogContents, MessageError, OnMessage, RawMessage, read_log, read_log_bytes,
    read_log_head,
};
pub use writer::{LOG_FORMAT, LogWriter, RunMetadata, ZSTD_LEVEL};

/// Checks a message nothing decodes further (the arm's frames and figure,
/// the standard views): JSON text, or CDR with its header.
pub fn check_message(encoding: Encoding, data: &[u8]) -> Result<(), DecodeError> {
    match encoding {
        Encoding::Json => JsonObject::check(data),
        Encoding::Cdr => cdr::CdrReader::new(data).map(|_| ()),
    }
}

/// Name of the metadata record that describes the run.
pub const RUN_METADATA: &str = "testbed.run";
/// Name of the metadata record with the logger's counts.
pub const STATS_METADATA: &str = "testbed.log_stats";
/// The key of [`STATS_METADATA`] that says how the run ended
/// ("finished", "interrupted", "lost the plant", …).
pub const RUN_END: &str = "run_end";
/// Name of the URDF attachment.
pub const URDF_ATTACHMENT: &str = "robot.urdf";

/// Why a log could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// File system.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// The MCAP library.
    #[error("{path}: {cause}")]
    Mcap {
        /// The file.
        path: String,
        /// The cause.
        cause: mcap::McapError,
    },
    /// A message could not be encoded.
    #[error("{path}: cannot encode a {topic} message: {cause}")]
    Encode {
        /// The file.
        path: String,
        /// The message's topic.
        topic: &'static str,
        /// The cause.
        cause: serde_json::Error,
    },
    /// A message for a channel the writer never opened (a bug of the
    /// caller, reported rather than written to a wrong channel).
    #[error("{path}: no channel {topic} was opened before its first message")]
    UnknownChannel {
        /// The file.
        path: String,
        /// The topic.
        topic: &'static str,
    },
    /// The handler of a message failed while reading.
    #[error("reading {path} ({topic}): {cause}")]
    Sink {
        /// The file.
        path: String,
        /// The message's topic.
        topic: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// The file is readable MCAP but not a testbed log.
    #[error("{path}: {reason}")]
    NotATestbedLog {
        /// The file.
        path: String,
        /// What is missing or wrong.
        reason: String,
    },
}

impl LogError {
    /// An error of the mcap library about `path`. Its I/O errors (a full
    /// disk among them) are shown as such: the library's own text for them
    /// ("I/O error from writing, or reading a compression stream") hides
    /// the cause.
    pub fn mcap(path: &str, cause: mcap::McapError) -> Self {
        match cause {
            mcap::McapError::Io(cause) => LogError::Io {
                path: path.to_string(),
                cause,
            },
            cause => LogError::Mcap {
                path: path.to_string(),
                cause,
            },
        }
    }
}
