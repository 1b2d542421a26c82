//! The one error a logged message that does not decode gives, whatever
//! its encoding (JSON, CDR).

/// A logged message that does not decode: what is missing or wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct DecodeError(pub String);

impl From<wire::FieldError> for DecodeError {
    fn from(e: wire::FieldError) -> Self {
        Self(e.to_string())
    }
}
