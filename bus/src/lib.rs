//! The runtime of the wire contract: how a process of a run talks to the
//! others over iceoryx2 shared memory.
//!
//! Where it sits: under every node and the launcher, above `wire` (which
//! says *what* is exchanged). [`Bus`] opens a run's topics under its
//! per-run prefix ([`RunPrefix`], so two runs or two tests never see each
//! other) as [`TopicPublisher`]s and [`TopicSubscriber`]s with the QoS the
//! contract fixes; [`NodeLink`] is the node protocol every process follows
//! (READY, START, DONE, STOP); [`write_config`] and [`read_config`] carry
//! each node its part of the plan; [`ReferenceWindow`] applies the
//! contract's reference rule; [`clock`] sleeps to absolute deadlines and
//! measures the timer floor; the rest cleans up what killed runs leave.

pub mod clock;
mod config;
mod connections;
mod domain;
mod leftovers;
mod node;
mod reference;
mod shm_space;
mod topics;

pub use config::{ConfigError, read_config, write_config};
pub use connections::{CONNECTION_FAILED, connection_failures};
pub use domain::DomainNodes;
pub use node::{NodeError, NodeLink};
pub use reference::ReferenceWindow;
pub use shm_space::{SHM_DIR, SHM_NEEDED_BYTES, shm_free_bytes, shm_too_small};
pub use topics::{Bus, BusError, RunPrefix, TopicPublisher, TopicSubscriber, monotonic_ns};

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
