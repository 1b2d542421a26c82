//! What the launcher has heard from each node on the status topic: who is
//! ready, who is done, the plant's progress, and when each was last heard
//! (the heartbeat that tells a silent node).

use std::time::{Duration, Instant};

use wire::{NODE_DONE, NODE_FAILED, NODE_READY, NodeKind, NodeStatus};

use super::{NODES, RunError};

/// What the status topic has said so far.
#[derive(Default)]
pub(super) struct NodeStates {
    pub(super) ready: Vec<NodeKind>,
    pub(super) done: Vec<NodeKind>,
    pub(super) plant_step: u64,
    /// When each node was last heard from (any status: its heartbeat).
    heard: Vec<(NodeKind, Instant)>,
    /// When the launcher last looked, to tell its own pause from theirs.
    looked: Option<Instant>,
    /// The process (group leader) each node is: a status naming a node is
    /// taken only from it or its group. A node started by hand is bound to
    /// the first process that speaks for it.
    pids: Vec<(NodeKind, u32)>,
    /// Statuses refused, said once.
    refused: Vec<(NodeKind, u32)>,
}

impl NodeStates {
    /// For nodes whose processes are `pids` (the launcher's children).
    pub(super) fn with_pids(pids: Vec<(NodeKind, u32)>) -> Self {
        Self {
            pids,
            ..Self::default()
        }
    }

    /// Whether a status naming `kind` may come from `pid` (a controller
    /// once published "plant done" and ended a run early, blamed on the
    /// plant).
    fn speaks_for(&mut self, kind: NodeKind, pid: u32) -> bool {
        match self.pids.iter().find(|(k, _)| *k == kind) {
            Some((_, leader)) => pid == *leader || process_group(pid) == Some(*leader),
            None => {
                self.pids.push((kind, pid));
                true
            }
        }
    }

    pub(super) fn read(
        &mut self,
        status: &bus::TopicSubscriber<NodeStatus>,
    ) -> Result<(), RunError> {
        while let Some(s) = status.receive()? {
            let Some(kind) = NodeKind::from_u32(s.node) else {
                continue;
            };
            if !self.speaks_for(kind, s.pid) {
                if !self.refused.contains(&(kind, s.pid)) {
                    self.refused.push((kind, s.pid));
                    eprintln!(
                        "testbed: warning: ignored a status naming the {} from process {}, \
                         which is not that node",
                        kind.name(),
                        s.pid
                    );
                }
                continue;
            }
            if kind == NodeKind::Plant {
                self.plant_step = self.plant_step.max(s.step);
            }
            match self.heard.iter_mut().find(|(k, _)| *k == kind) {
                Some((_, at)) => *at = Instant::now(),
                None => self.heard.push((kind, Instant::now())),
            }
            let list = match s.state {
                NODE_READY => &mut self.ready,
                NODE_DONE => &mut self.done,
                NODE_FAILED => {
                    return Err(RunError::NodeFailed {
                        node: kind.name(),
                        how: "reported a failure".into(),
                        stderr: String::new(),
                    });
                }
                _ => continue,
            };
            if !list.contains(&kind) {
                list.push(kind);
            }
        }
        let _ = status.drain_events();
        Ok(())
    }

    /// The node heard from least recently, if that was longer ago than
    /// `limit`. A pause of the launcher itself (Ctrl-Z and `fg` of the whole
    /// run, a paused VM) silences nobody: every node is then heard anew.
    pub(super) fn silent(&mut self, limit: Duration) -> Option<NodeKind> {
        let now = Instant::now();
        if self
            .looked
            .replace(now)
            .is_some_and(|l| now - l > Duration::from_secs(1))
        {
            self.heard.iter_mut().for_each(|(_, at)| *at = now);
        }
        let (kind, at) = NODES
            .iter()
            .map(|k| {
                let at = self.heard.iter().find(|(h, _)| h == k).map(|(_, at)| *at);
                (*k, at.unwrap_or(now))
            })
            .min_by_key(|(_, at)| *at)?;
        (now - at > limit).then_some(kind)
    }
}

/// The process group of `pid` (field 5 of /proc/<pid>/stat).
fn process_group(pid: u32) -> Option<u32> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces.
    let rest = &stat[stat.rfind(')')? + 1..];
    rest.split_whitespace().nth(2)?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// #31 row 12: a status naming a node is taken only from that node's
    /// process or its group; a hand-started node is bound to its first.
    #[test]
    fn a_status_is_taken_only_from_the_node_it_names() {
        let me = std::process::id();
        let group = process_group(me).unwrap_or(me);
        let mut n = NodeStates::with_pids(vec![(NodeKind::Plant, 1), (NodeKind::Logger, group)]);
        assert!(
            !n.speaks_for(NodeKind::Plant, me),
            "pid 1 is not this test's group"
        );
        assert!(
            n.speaks_for(NodeKind::Logger, me),
            "a member of the logger's group"
        );
        assert!(n.speaks_for(NodeKind::Trajectory, 4242));
        assert!(!n.speaks_for(NodeKind::Trajectory, 4243));
    }
}
