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
}

impl NodeStates {
    pub(super) fn read(
        &mut self,
        status: &bus::TopicSubscriber<NodeStatus>,
    ) -> Result<(), RunError> {
        while let Some(s) = status.receive()? {
            let Some(kind) = NodeKind::from_u32(s.node) else {
                continue;
            };
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
