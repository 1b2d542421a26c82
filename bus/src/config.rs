//! The launcher's validated plan, handed to each node as one typed file:
//! the launcher writes a role's config as JSON, the node reads the same
//! type back. A failure either way is an error naming the file.

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

/// Why a node's config could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read or written.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// The file is not the config this node takes.
    #[error("{path}: not a valid node config: {cause}")]
    Json {
        /// The file.
        path: String,
        /// The parser's message.
        cause: serde_json::Error,
    },
}

/// Writes `config` to `path` as JSON.
pub fn write_config<T: Serialize>(path: &Path, config: &T) -> Result<(), ConfigError> {
    let p = path.display().to_string();
    let text = serde_json::to_vec_pretty(config).map_err(|cause| ConfigError::Json {
        path: p.clone(),
        cause,
    })?;
    std::fs::write(path, text).map_err(|cause| ConfigError::Io { path: p, cause })
}

/// Configs larger than this are refused unread: the largest holds a URDF
/// ([`wire::MAX_URDF_BYTES`]) and the scenario.
pub const MAX_CONFIG_BYTES: u64 = 4 * wire::MAX_URDF_BYTES;

/// Reads a config written by [`write_config`]: a regular file of at most
/// `MAX_CONFIG_BYTES` (`/dev/zero` once read until memory ran out).
pub fn read_config<T: DeserializeOwned>(path: &Path) -> Result<T, ConfigError> {
    let p = path.display().to_string();
    let text =
        wire::read_regular_file(path, Some(MAX_CONFIG_BYTES)).map_err(|cause| ConfigError::Io {
            path: p.clone(),
            cause,
        })?;
    serde_json::from_slice(&text).map_err(|cause| ConfigError::Json { path: p, cause })
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct C {
        a: f64,
        b: Vec<u64>,
    }

    #[test]
    fn a_config_round_trips_and_bad_files_name_the_path() {
        let dir = std::env::temp_dir().join(format!("wire-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("c.json");
        let c = C {
            a: 0.1 + 0.2,
            b: vec![1, 2],
        };
        write_config(&f, &c).unwrap();
        assert_eq!(read_config::<C>(&f).unwrap(), c);
        std::fs::write(&f, "{\"a\": 1.0, \"b\": [], \"zz\": 0}").unwrap();
        let e = read_config::<C>(&f).unwrap_err().to_string();
        assert!(e.contains("c.json") && e.contains("zz"), "{e}");
        let e = read_config::<C>(&dir.join("none.json")).unwrap_err();
        assert!(e.to_string().contains("none.json"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
