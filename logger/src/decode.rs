//! A logged message back from its data, whatever the log's format: JSON
//! (formats 1 and 2, [`crate::json`]) or CDR (format 3, [`crate::ros2`]).

use crate::decode_error::DecodeError;
use crate::json::LogMessage;
use crate::reader::{Encoding, RawMessage};
use wire::Logged;

/// Every logged message decodes from either encoding.
pub trait Decode: LogMessage {
    /// The message back from a log's data in `encoding` (JSON in log
    /// formats 1 and 2, CDR from format 3).
    fn decode_as(encoding: Encoding, data: &[u8]) -> Result<Self, DecodeError> {
        match encoding {
            Encoding::Json => Self::parse(data),
            Encoding::Cdr => crate::cdr_decode::decode(data),
        }
    }
}

impl<M: LogMessage> Decode for M {}

/// A logged message from the log's message: decoded by the schema its
/// log stores (CDR) or by field name (JSON); None for a channel that is
/// not one of the wire's logged messages (the standard views: `/tf`,
/// `/joint_states`, the markers).
pub fn decode_logged(m: &RawMessage<'_>) -> Result<Option<Logged>, DecodeError> {
    macro_rules! arms {
        ($($ty:ident => $topic:ident, $channel:literal, $schema:literal;)*) => {
            match m.topic {
                $($channel => decode_one::<wire::$ty>(m).map(Logged::from),)*
                _ => return Ok(None),
            }
        };
    }
    wire::logged_messages!(arms).map(Some)
}

fn decode_one<M: LogMessage>(m: &RawMessage<'_>) -> Result<M, DecodeError> {
    match (m.encoding, m.schema) {
        (Encoding::Json, _) => M::parse(m.data),
        (Encoding::Cdr, Some(schema)) => crate::cdr_decode::decode_by(schema, m.data),
        (Encoding::Cdr, None) => Err(DecodeError::NoSchema {
            topic: m.topic.to_string(),
        }),
    }
}
