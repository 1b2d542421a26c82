//! How a log's chunks are compressed: a choice of file size against the
//! logger's time, which in lockstep paces the run (README, "The plant
//! engine"): zstd (level 1) is the smallest, LZ4 about 12 % cheaper and
//! 35 % larger, none about 40 % cheaper and ten times larger.

use serde::{Deserialize, Serialize};

/// Chunk compression of a log.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LogCompression {
    /// zstd at level 1 (the default).
    #[default]
    Zstd,
    /// LZ4 frames.
    Lz4,
    /// Uncompressed chunks.
    None,
}

impl LogCompression {
    /// Every choice, as spelled on the command line.
    pub const NAMES: [&'static str; 3] = ["zstd", "lz4", "none"];

    /// The name, as spelled on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Zstd => "zstd",
            Self::Lz4 => "lz4",
            Self::None => "none",
        }
    }

    /// Parses a name of [`LogCompression::NAMES`].
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "zstd" => Ok(Self::Zstd),
            "lz4" => Ok(Self::Lz4),
            "none" => Ok(Self::None),
            other => Err(format!(
                "{other:?} is not a log compression (one of: {})",
                Self::NAMES.join(", ")
            )),
        }
    }
}
