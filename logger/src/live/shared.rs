//! What the relay's threads (`front.rs`) and the guard (`guard.rs`) share
//! with the logger: the stop flag, the counts, the open connections.

use std::collections::{HashMap, HashSet};
use std::net::TcpStream;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64};

/// What the accept thread, the connections and the guard share with the
/// logger.
pub(super) struct Shared {
    pub(super) stop: AtomicBool,
    pub(super) max_clients: usize,
    pub(super) refused: AtomicU64,
    pub(super) accepted: AtomicU64,
    /// Connections to the server's port that the relay did not make, cut.
    pub(super) bypassed: AtomicU64,
    /// Open client connections by number, kept to cut them at the end.
    pub(super) open: Mutex<HashMap<u64, TcpStream>>,
    /// Local ports of the relay's own connections to the server.
    pub(super) relayed: Mutex<HashSet<u16>>,
}

impl Shared {
    pub(super) fn open(&self) -> std::sync::MutexGuard<'_, HashMap<u64, TcpStream>> {
        self.open.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(super) fn relayed(&self) -> std::sync::MutexGuard<'_, HashSet<u16>> {
        self.relayed.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The relay's connections to the server, by local port.
    pub(super) fn relayed_ports(&self) -> HashSet<u16> {
        self.relayed().clone()
    }
}
