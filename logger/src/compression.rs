//! How a log's chunks are compressed: a choice of file size against the
//! logger's CPU. On a run's CDR (mostly doubles) zstd's fast level -1 makes
//! the smallest files of the three, LZ4 files about a third larger, none
//! files about two and a half times larger; compressing is then about half
//! of the logger's CPU, and none the cheapest (results.md, "Logs in the
//! ROS 2 format").

use serde::{Deserialize, Serialize};

/// Chunk compression of a log.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LogCompression {
    /// zstd at its fast level -1 ([`crate::ZSTD_LEVEL`]; the default).
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
    pub fn parse(s: &str) -> Result<Self, UnknownCompression> {
        match s {
            "zstd" => Ok(Self::Zstd),
            "lz4" => Ok(Self::Lz4),
            "none" => Ok(Self::None),
            other => Err(UnknownCompression(other.into())),
        }
    }
}

/// A name that is not a [`LogCompression`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownCompression(pub String);

impl std::fmt::Display for UnknownCompression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names = LogCompression::NAMES.join(", ");
        write!(f, "{:?} is not a log compression (one of: {names})", self.0)
    }
}

impl std::error::Error for UnknownCompression {}
