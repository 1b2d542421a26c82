//! A run's shared-memory domain and its removal.
//!
//! Each run uses its own iceoryx2 prefix. iceoryx2 removes a node's files
//! when the node is dropped (or, for a killed process, when a later node
//! cleans up after it), but keeps one small management segment per prefix
//! forever. With a fresh prefix per run those would pile up, so the
//! launcher removes its domain at the end of the run, and removes domains
//! that killed launchers left behind when it starts.

use std::time::{Duration, SystemTime};

use iceoryx2::prelude::*;

use crate::topics::{BusError, RunPrefix};

/// A domain whose segment is younger than this may belong to a run that is
/// still starting up (its first node not yet registered), so it is left alone.
const STALE_AFTER: Duration = Duration::from_secs(60);

/// What is known about a domain's nodes.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct DomainNodes {
    /// Nodes whose process is alive.
    pub alive: u32,
    /// Dead nodes whose leftovers were removed.
    pub cleaned: u32,
}

impl RunPrefix {
    /// Removes the leftovers of dead nodes in this domain and counts the live ones.
    pub fn clean_dead_nodes(&self) -> Result<DomainNodes, BusError> {
        let config = self.config()?;
        let mut nodes = DomainNodes::default();
        Node::<ipc::Service>::list(&config, |state| {
            match state {
                NodeState::Alive(_) => nodes.alive += 1,
                NodeState::Dead(view) => {
                    if view.try_remove_stale_resources().is_ok() {
                        nodes.cleaned += 1;
                    }
                }
                // A node being created or of another user: count it as in use.
                NodeState::Inaccessible(_) | NodeState::Undefined(_) => nodes.alive += 1,
            }
            CallbackProgression::Continue
        })
        .map_err(|e| BusError::Ipc {
            what: "list nodes",
            topic: self.as_str().to_string(),
            cause: format!("{e:?}"),
        })?;
        Ok(nodes)
    }

    /// Removes this domain from shared memory if no node of it is alive.
    /// Returns true if it was removed.
    pub fn remove_domain_if_unused(&self) -> Result<bool, BusError> {
        if self.clean_dead_nodes()?.alive > 0 {
            return Ok(false);
        }
        let config = self.config()?;
        // SAFETY: iceoryx2 requires that no process uses the domain while its
        // management segment is removed. The prefix is unique to one run
        // (process id and start time), and the listing above found no live
        // node in it: every process of that run has ended.
        #[allow(
            unsafe_code,
            reason = "iceoryx2 removes a dead run's domain only this way; SAFETY above"
        )]
        let removed =
            unsafe { iceoryx2::testing::remove_global_mgmt_segment::<ipc::Service>(&config) };
        removed.map_err(|e| BusError::Ipc {
            what: "remove domain",
            topic: self.as_str().to_string(),
            cause: format!("{e:?}"),
        })
    }

    /// Domains of earlier runs found in shared memory (their management
    /// segment is older than a minute), excluding `except`.
    pub fn stale_domains(except: &RunPrefix) -> Vec<RunPrefix> {
        let Ok(entries) = std::fs::read_dir("/dev/shm") else {
            return Vec::new();
        };
        let now = SystemTime::now();
        let mut found: Vec<RunPrefix> = Vec::new();
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().to_string();
            if !name.starts_with(RunPrefix::STEM) || !name.ends_with(".global_mgmt") {
                continue;
            }
            let Some(end) = name.find('_') else { continue };
            let Ok(prefix) = RunPrefix::parse(&name[..=end]) else {
                continue;
            };
            let old = entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|m| now.duration_since(m).ok())
                .is_some_and(|age| age > STALE_AFTER);
            // A domain whose launcher is gone is stale at once; one whose
            // pid is alive (maybe reused) only after STALE_AFTER.
            let orphaned = prefix
                .launcher_pid()
                .is_some_and(|pid| !std::path::Path::new(&format!("/proc/{pid}")).exists());
            if (old || orphaned) && prefix != *except && !found.contains(&prefix) {
                found.push(prefix);
            }
        }
        found
    }
}
