//! One run's nodes create their ports one at a time.
//!
//! iceoryx2 connects a new port to the ports already registered when it is
//! created, and the older side opens that connection lazily on its next
//! send or receive. When two processes create counterpart ports at the
//! same moment, neither sees the other at creation and both create the
//! connection lazily after START, concurrently; iceoryx2 0.10 then
//! sometimes leaves the pair unconnected and only warns (a lockstep log
//! once held no commands at all, 1 run in about 400 under load). Holding
//! this lock from [`crate::NodeLink::connect`] until READY makes every
//! connection be created by exactly one side, while the other is idle.

use std::fs::{File, OpenOptions};
use std::path::PathBuf;

use crate::{RunPrefix, WireError};

/// The lock file's name after the run prefix (in `/dev/shm`, beside the
/// run's shared memory, and removed with its domain).
const SUFFIX: &str = "ports.lock";

impl RunPrefix {
    /// The run's port-creation lock file.
    pub(crate) fn ports_lock_path(&self) -> PathBuf {
        PathBuf::from("/dev/shm").join(format!("{}{SUFFIX}", self.as_str()))
    }

    /// Whether `file_name` is a run's port-creation lock file.
    pub(crate) fn is_ports_lock(file_name: &str) -> bool {
        file_name.starts_with(RunPrefix::STEM) && file_name.ends_with(SUFFIX)
    }
}

/// Held while a node creates its ports; released when dropped (or when
/// the process dies: it is an `flock`).
#[derive(Debug)]
pub(crate) struct PortsLock {
    _file: File,
}

impl PortsLock {
    /// Blocks until this process is the only one of the run creating ports.
    pub(crate) fn acquire(prefix: &RunPrefix) -> Result<Self, WireError> {
        let path = prefix.ports_lock_path();
        let fail = |cause: std::io::Error| WireError::Ipc {
            what: "lock port creation",
            topic: path.display().to_string(),
            cause: cause.to_string(),
        };
        let file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(fail)?;
        file.lock().map_err(fail)?;
        Ok(Self { _file: file })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_second_holder_waits_for_the_first() {
        let prefix = RunPrefix::unique();
        let first = PortsLock::acquire(&prefix).unwrap();
        let path = prefix.ports_lock_path();
        let other = File::options().write(true).open(&path).unwrap();
        assert!(matches!(
            other.try_lock(),
            Err(std::fs::TryLockError::WouldBlock)
        ));
        drop(first);
        other.try_lock().unwrap();
        assert!(RunPrefix::is_ports_lock(
            &path.file_name().unwrap().to_string_lossy()
        ));
        std::fs::remove_file(path).unwrap();
    }
}
