//! The node protocol every process of a run follows, whatever its role:
//! create its ports, report READY on the status topic, wait for START
//! (which carries the wall-clock epoch of step 0), run, report DONE, and
//! exit when the launcher sends STOP. A node also stops by itself when its
//! launcher disappears or a SIGINT/SIGTERM arrives.

use std::time::Duration;

use crate::{
    Bus, BusError, CONNECTION_FAILED, RunPrefix, TopicPublisher, TopicSubscriber, monotonic_ns,
};
use wire::{
    CONTROL_START, CONTROL_STOP, Control, Delivery, HEARTBEAT, Header, Mode, NODE_DONE,
    NODE_FAILED, NODE_READY, NODE_RUNNING, NodeKind, NodeStatus,
};

/// Why a node stopped.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// The bus failed.
    #[error(transparent)]
    Wire(#[from] BusError),
    /// The launcher is gone.
    #[error("the launcher (pid {0}) is gone")]
    ParentGone(u32),
    /// The launcher sent STOP before the node finished.
    #[error("stopped by the launcher")]
    Stopped,
    /// Something arrived that the protocol does not allow.
    #[error("{0}")]
    Protocol(String),
}

/// One node's link to its run: the bus, and the status and control ports.
pub struct NodeLink {
    /// The node's connection to the run's shared memory.
    pub bus: Bus,
    kind: NodeKind,
    status: TopicPublisher<NodeStatus>,
    control: TopicSubscriber<Control>,
    parent_pid: Option<u32>,
    status_seq: u64,
    stop_seen: bool,
    stop_outcome: Option<u32>,
    mode: Mode,
    /// START seen by [`NodeLink::check`] before the node waited for it.
    pending_start: Option<Control>,
    /// The last state and step reported, repeated as the heartbeat.
    last_report: (u32, u64),
    last_report_ns: u64,
}

impl NodeLink {
    /// Connects node `kind` of a `mode` run to the run under `prefix`; with
    /// `parent_pid` the node stops once that process (its launcher) is gone.
    pub fn connect(
        kind: NodeKind,
        prefix: &RunPrefix,
        parent_pid: Option<u32>,
        mode: Mode,
    ) -> Result<Self, BusError> {
        let bus = Bus::new(prefix, kind.name())?;
        let status = bus.publisher(Delivery::DropWhenFull)?;
        let control = bus.subscriber()?;
        Ok(Self {
            bus,
            kind,
            status,
            control,
            parent_pid,
            status_seq: 0,
            stop_seen: false,
            stop_outcome: None,
            mode,
            pending_start: None,
            last_report: (0, 0),
            last_report_ns: 0,
        })
    }

    /// Publishes this node's state.
    pub fn report(&mut self, state: u32, step: u64) -> Result<(), NodeError> {
        let now = monotonic_ns();
        self.last_report = (state, step);
        self.last_report_ns = now;
        let msg = NodeStatus {
            header: Header {
                seq: self.status_seq,
                t_ns: 0,
                wall_ns: now,
            },
            node: self.kind as u32,
            state,
            pid: std::process::id(),
            reserved: 0,
            step,
        };
        self.status_seq += 1;
        self.status.send(msg)?;
        Ok(())
    }

    /// Errors if the launcher is gone, a termination signal arrived, or
    /// STOP was received; repeats the last status as a heartbeat when
    /// [`HEARTBEAT`] has passed since the last one (every node calls this
    /// in each of its waits, so a node that stops calling it is frozen).
    pub fn check(&mut self) -> Result<(), NodeError> {
        self.bus.wait(Duration::ZERO)?;
        if self.last_report_ns > 0
            && monotonic_ns().saturating_sub(self.last_report_ns) >= HEARTBEAT.as_nanos() as u64
        {
            let (state, step) = self.last_report;
            self.report(state, step)?;
        }
        if let Some(pid) = self.parent_pid
            && std::os::unix::process::parent_id() != pid
        {
            return Err(NodeError::ParentGone(pid));
        }
        while let Some(c) = self.control.receive()? {
            match c.command {
                CONTROL_STOP => {
                    self.stop_seen = true;
                    self.stop_outcome = Some(c.code);
                }
                // Kept for the wait for START: a check between its polls
                // must not swallow it (the run would stall at step 0).
                CONTROL_START => self.pending_start = Some(c),
                _ => {}
            }
        }
        if self.stop_seen {
            return Err(NodeError::Stopped);
        }
        Ok(())
    }

    /// How the launcher said the run ended, once STOP arrived.
    pub fn run_end(&self) -> Option<wire::RunEnd> {
        self.stop_outcome.map(wire::RunEnd::from_code)
    }

    /// Reports READY and blocks until START; returns the epoch of step 0.
    /// A node whose ports iceoryx2 could not all connect fails here.
    pub fn ready_and_wait_for_start(&mut self) -> Result<u64, NodeError> {
        let failed = crate::connection_failures();
        if failed > 0 {
            self.report(NODE_FAILED, 0)?;
            return Err(NodeError::Protocol(format!(
                "{CONNECTION_FAILED} {failed} pair(s) of ports while creating them"
            )));
        }
        self.report(NODE_READY, 0)?;
        let mut last_report = monotonic_ns();
        loop {
            self.control.wait_event(Duration::from_millis(50))?;
            self.control.drain_events()?;
            let next = match self.pending_start.take() {
                Some(c) => Some(c),
                None => self.control.receive()?,
            };
            if let Some(c) = next {
                match c.command {
                    CONTROL_START if c.code != self.mode.code() => {
                        // Say so, so that the launcher fails the run at once.
                        self.report(NODE_FAILED, 0)?;
                        return Err(NodeError::Protocol(format!(
                            "this node was started with --mode {} but the run is {}",
                            self.mode.as_str(),
                            if c.code == Mode::Lockstep.code() {
                                "lockstep"
                            } else {
                                "realtime"
                            }
                        )));
                    }
                    CONTROL_START => {
                        self.report(NODE_RUNNING, 0)?;
                        return Ok(c.epoch_wall_ns);
                    }
                    CONTROL_STOP => {
                        self.stop_outcome = Some(c.code);
                        return Err(NodeError::Stopped);
                    }
                    other => {
                        return Err(NodeError::Protocol(format!(
                            "unknown control command {other}"
                        )));
                    }
                }
            }
            self.check()?;
            // READY again now and then, in case the launcher connected late.
            if monotonic_ns() - last_report > 500_000_000 {
                self.report(NODE_READY, 0)?;
                last_report = monotonic_ns();
            }
        }
    }

    /// Reports DONE and waits for STOP (or the launcher's disappearance).
    pub fn done_and_wait_for_stop(&mut self, steps: u64) -> Result<(), NodeError> {
        self.report(NODE_DONE, steps)?;
        loop {
            match self.check() {
                Err(NodeError::Stopped) => return Ok(()),
                Err(e) => return Err(e),
                Ok(()) => {}
            }
            self.control.wait_event(Duration::from_millis(50))?;
            self.control.drain_events()?;
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn a_prefix_names_its_launcher_and_run_ends_round_trip() {
        let p = crate::RunPrefix::unique();
        assert_eq!(p.launcher_pid(), Some(std::process::id()));
        assert_eq!(
            crate::RunPrefix::parse("other").unwrap().launcher_pid(),
            None
        );
        for end in [
            wire::RunEnd::Finished,
            wire::RunEnd::Interrupted,
            wire::RunEnd::Failed,
            wire::RunEnd::LostNode(wire::NodeKind::Plant),
            wire::RunEnd::LostNode(wire::NodeKind::Logger),
        ] {
            assert_eq!(wire::RunEnd::from_code(end.code()), end);
        }
        assert_eq!(
            wire::RunEnd::LostNode(wire::NodeKind::Plant).describe(),
            "lost the plant"
        );
        assert_ne!(Mode::Lockstep.code(), Mode::Realtime.code());
    }
}
