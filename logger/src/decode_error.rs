//! The one error a logged message that does not decode gives, whatever
//! its encoding (JSON, CDR): each way it can fail as data.

use crate::msg_schema::SchemaError;

/// A logged message that does not decode: what is missing or wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    /// A CDR channel without a testbed_msgs schema.
    #[error("channel {topic} has no testbed_msgs schema to read its CDR by")]
    NoSchema {
        /// The channel's topic.
        topic: String,
    },
    /// This build's own schema for a message did not parse.
    #[error("{0}")]
    OwnSchema(#[from] SchemaError),
    /// The stored schema lacks a field every message needs.
    #[error("schema {schema} has no {field}")]
    SchemaLacks {
        /// The schema's name.
        schema: String,
        /// The field, as the schema would declare it.
        field: &'static str,
    },
    /// A joint field with more entries than a joint vector holds.
    #[error("field '{field}' has {entries} entries (at most {max})")]
    TooManyEntries {
        /// The field.
        field: String,
        /// Its entries.
        entries: usize,
        /// The most a joint vector holds.
        max: usize,
    },
    /// Bytes left after the schema's last field.
    #[error("the CDR message is longer than its schema {schema} says")]
    LongerThanSchema {
        /// The schema's name.
        schema: String,
    },
    /// The message ends inside a field.
    #[error("the CDR message ends inside its {field}")]
    Truncated {
        /// The field.
        field: String,
    },
    /// A CDR header other than little-endian CDR (the only one written).
    #[error("not little-endian CDR (encapsulation {:02x} {:02x})", encapsulation[0], encapsulation[1])]
    NotLittleEndianCdr {
        /// The header's first two bytes.
        encapsulation: [u8; 2],
    },
    /// Fewer bytes than a CDR header.
    #[error("shorter than a CDR header")]
    ShorterThanHeader,
    /// A sequence length past the message's end.
    #[error("its {field} claims {entries} entries, more than the message holds")]
    LengthPastEnd {
        /// The field.
        field: String,
        /// The length it claims.
        entries: usize,
    },
    /// A string field that is not UTF-8.
    #[error("its {field} is not UTF-8")]
    NotUtf8 {
        /// The field.
        field: String,
    },
    /// A time field out of range.
    #[error("its {field} is not a time ({sec} s {nsec} ns)")]
    NotATime {
        /// The field.
        field: String,
        /// Its seconds.
        sec: i32,
        /// Its nanoseconds.
        nsec: u32,
    },
    /// JSON, but not an object.
    #[error("not a JSON object")]
    NotJsonObject,
    /// Not JSON (the parser's message: its error is neither `Clone` nor
    /// comparable).
    #[error("not JSON ({0})")]
    NotJson(String),
    /// A field's value is missing or of the wrong kind.
    #[error("{0}")]
    Field(#[from] wire::FieldError),
    /// A controller's own diagnostics with another count than its run
    /// declared.
    #[error("{got} values where the run's controller_diagnostics declares {declared}")]
    DiagnosticsCount {
        /// Values in the message.
        got: usize,
        /// Values the run declared.
        declared: usize,
    },
    /// A message for another number of joints than the logged robot's.
    #[error("dof {dof} but the logged robot has {joints} joints")]
    Dof {
        /// The message's dof.
        dof: u32,
        /// The robot's joints.
        joints: usize,
    },
}
