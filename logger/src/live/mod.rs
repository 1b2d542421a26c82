//! The live view (`testbed run --live`): while the run goes, the logger
//! serves the run's channels (the same list, topics and schemas as the log,
//! [`crate::channels`]) over the Foxglove WebSocket protocol with the
//! `foxglove` crate. Only the logger process does this, and only when asked:
//! without `--live` nothing of it runs and no tokio runtime exists; a build
//! without the `live` feature (the fuzz targets) has no foxglove at all.

use std::collections::BTreeMap;
use std::net::SocketAddr;

use serde::{Deserialize, Serialize};

use crate::ChannelSpec;

#[cfg(feature = "live")]
mod front;
#[cfg(feature = "live")]
mod guard;
#[cfg(feature = "live")]
mod server;
#[cfg(feature = "live")]
mod shared;

/// The port Foxglove's own examples use, and its app's default.
pub const DEFAULT_PORT: u16 = 8765;
/// Most samples per topic and second of sim time sent live.
pub const DEFAULT_RATE_HZ: f64 = 50.0;
/// Most viewers connected at once: each costs the logger a queue.
pub const DEFAULT_MAX_CLIENTS: usize = 8;
/// The most `--live-clients` may ask for.
pub const MAX_CLIENTS_LIMIT: usize = 64;

/// What the launcher hands the logger for a live run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LiveConfig {
    /// Where to listen.
    pub addr: SocketAddr,
    /// Most samples per topic and second of sim time sent live (the log
    /// keeps every one).
    pub rate_hz: f64,
    /// Most clients connected at once; the next is refused (HTTP 503).
    #[serde(default = "default_max_clients")]
    pub max_clients: usize,
}

fn default_max_clients() -> usize {
    DEFAULT_MAX_CLIENTS
}

/// Why the live view could not start.
#[derive(Debug, thiserror::Error)]
pub enum LiveError {
    /// The address is taken or not ours to listen on.
    #[error("the live view cannot listen on {addr}: {cause}")]
    Listen {
        /// The address.
        addr: SocketAddr,
        /// The cause, as the server gives it.
        cause: String,
    },
    /// A channel could not be opened.
    #[error("the live view cannot open channel {topic}: {cause}")]
    Channel {
        /// The topic.
        topic: &'static str,
        /// The cause.
        cause: String,
    },
    /// This build has no live view (the logger crate without `live`).
    #[error("this build has no live view (the logger crate's `live` feature is off)")]
    NotBuilt,
    /// The client limit is out of range.
    #[error("live max_clients must be 1 to {MAX_CLIENTS_LIMIT}, got {0}")]
    Clients(usize),
    /// The rate is not a positive number.
    #[error("live rate_hz must be a positive number, got {0}")]
    Rate(f64),
}

/// A running live view, as the logger drives it.
pub trait LiveView {
    /// Offers one message of `topic` (its CDR, as logged) stamped `t_ns`:
    /// sent if its topic is due and someone subscribed, skipped otherwise.
    fn offer(&mut self, topic: &str, t_ns: u64, data: &[u8]);
    /// The address the server listens on (the port chosen when asked for 0).
    fn address(&self) -> std::net::SocketAddr;
    /// Stops the server; what was sent, for the log's stats record.
    fn finish(self: Box<Self>) -> BTreeMap<String, String>;
}

/// Starts the live view on `config.addr` with `channels` (the first one's
/// samples drive the viewer's clock).
pub fn start(
    config: &LiveConfig,
    channels: &[ChannelSpec],
) -> Result<Box<dyn LiveView>, LiveError> {
    if !(config.rate_hz.is_finite() && config.rate_hz > 0.0) {
        return Err(LiveError::Rate(config.rate_hz));
    }
    if !(1..=MAX_CLIENTS_LIMIT).contains(&config.max_clients) {
        return Err(LiveError::Clients(config.max_clients));
    }
    #[cfg(feature = "live")]
    return Ok(Box::new(server::Live::start(config, channels)?));
    #[cfg(not(feature = "live"))]
    {
        let _ = channels;
        Err(LiveError::NotBuilt)
    }
}
