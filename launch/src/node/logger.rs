//! The logger process: subscribes to every data topic and writes the run's
//! MCAP log. It drains its buffers in batches every 10 ms, so it is never on
//! the critical path; in lockstep its full buffer holds the publishers back
//! (no sample is lost), in real time a sample it could not take shows as a
//! gap in sequence numbers, counted per topic in `testbed.log_stats`.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Duration;

use wire::{
    Command, ControllerDiagnostics, JointState, ReferenceSample, Timing, Topic, TopicSubscriber,
};

use super::{NodeContext, NodeError};
use crate::log::{LogMessage, LogWriter, RunMetadata};

/// Counts for one topic.
#[derive(Debug, Default, Clone, Copy)]
struct TopicCount {
    received: u64,
    dropped: u64,
    next_seq: u64,
}

impl TopicCount {
    fn add(&mut self, seq: u64) {
        self.received += 1;
        if seq > self.next_seq {
            self.dropped += seq - self.next_seq;
        }
        self.next_seq = self.next_seq.max(seq + 1);
    }
}

struct Sub<M: LogMessage + std::fmt::Debug + wire::ZeroCopySend + 'static> {
    sub: TopicSubscriber<M>,
    count: TopicCount,
}

impl<M: LogMessage + std::fmt::Debug + wire::ZeroCopySend + 'static> Sub<M> {
    fn new(ctx: &NodeContext, topic: Topic) -> Result<Self, NodeError> {
        Ok(Self {
            sub: ctx.bus.polling_subscriber(topic)?,
            count: TopicCount::default(),
        })
    }

    fn drain(&mut self, log: &mut LogWriter) -> Result<(), NodeError> {
        while let Some(m) = self.sub.receive()? {
            self.count.add(m.header().seq);
            log.write(&m)
                .map_err(|e| NodeError::Protocol(e.to_string()))?;
        }
        let _ = self.sub.drain_events();
        Ok(())
    }

    fn stats(&self, out: &mut BTreeMap<String, String>) {
        let name = M::TOPIC.trim_start_matches('/');
        out.insert(format!("{name}.received"), self.count.received.to_string());
        out.insert(format!("{name}.dropped"), self.count.dropped.to_string());
    }
}

struct Subs {
    state: Sub<JointState>,
    reference: Sub<ReferenceSample>,
    command: Sub<Command>,
    diag: Sub<ControllerDiagnostics>,
    timing: Sub<Timing>,
}

impl Subs {
    fn drain(&mut self, log: &mut LogWriter) -> Result<(), NodeError> {
        self.state.drain(log)?;
        self.reference.drain(log)?;
        self.command.drain(log)?;
        self.diag.drain(log)?;
        self.timing.drain(log)
    }

    fn stats(&self) -> BTreeMap<String, String> {
        let mut out = BTreeMap::new();
        self.state.stats(&mut out);
        self.reference.stats(&mut out);
        self.command.stats(&mut out);
        self.diag.stats(&mut out);
        self.timing.stats(&mut out);
        out
    }
}

/// Runs the logger node, writing to `out`.
pub fn run(ctx: &mut NodeContext, out: &Path, meta: RunMetadata) -> Result<(), NodeError> {
    let log_err = |e: crate::log::LogError| NodeError::Protocol(e.to_string());
    let mut subs = Subs {
        state: Sub::new(ctx, Topic::JointState)?,
        reference: Sub::new(ctx, Topic::Reference)?,
        command: Sub::new(ctx, Topic::Command)?,
        diag: Sub::new(ctx, Topic::Diagnostics)?,
        timing: Sub::new(ctx, Topic::Timing)?,
    };
    let mut log = LogWriter::create(out, &meta, &ctx.plan.robot.urdf).map_err(log_err)?;
    // Every channel exists from the start, even if a topic stays silent.
    log.add_channel::<JointState>().map_err(log_err)?;
    log.add_channel::<ReferenceSample>().map_err(log_err)?;
    log.add_channel::<Command>().map_err(log_err)?;
    log.add_channel::<ControllerDiagnostics>()
        .map_err(log_err)?;
    log.add_channel::<Timing>().map_err(log_err)?;
    log.flush().map_err(log_err)?;

    let started = ctx.ready_and_wait_for_start();
    let result = match started {
        Ok(_) => loop {
            subs.drain(&mut log)?;
            log.flush_if_due().map_err(log_err)?;
            if let Err(e) = ctx.check() {
                break Err(e);
            }
            if let Err(e) = ctx.bus.wait(Duration::from_millis(10)) {
                break Err(e.into());
            }
        },
        Err(e) => Err(e),
    };
    // STOP, a signal or a vanished launcher: in every case take what is
    // still buffered and finish the file properly.
    subs.drain(&mut log)?;
    let stats = subs.stats();
    log.finish(stats).map_err(log_err)?;
    match result {
        Err(NodeError::Stopped) => Ok(()),
        other => other,
    }
}
