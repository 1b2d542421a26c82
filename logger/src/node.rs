//! The logger process: subscribes to every data topic and writes the run's
//! MCAP log. It drains its buffers in batches every 10 ms, so it is never on
//! the critical path; in lockstep its full buffer holds the publishers back
//! (no sample is lost), in real time a sample it could not take shows as a
//! gap in sequence numbers, counted per topic in `testbed.log_stats`.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

use bus::{NodeError, NodeLink, TopicSubscriber};
use serde::{Deserialize, Serialize};
use wire::{
    Command, ContactState, ControllerDiagnostics, JointState, OwnDiagnostics, ReferenceSample,
    Timing,
};

use crate::live::{LiveConfig, LiveError};
use crate::outputs::Outputs;
use crate::{LogError, LogMessage, LogWriter, RUN_END, RunMetadata};

/// What the launcher hands the logger node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoggerNodeConfig {
    /// The MCAP file to write.
    pub out: PathBuf,
    /// The `testbed.run` record (its start time is set when the logger starts).
    pub metadata: RunMetadata,
    /// The robot's URDF, attached to the log (and drawn in 3D).
    pub urdf: String,
    /// Joints the scenario holds still, as the plant holds them.
    #[serde(default)]
    pub lock: arm_model::Locks,
    /// Chunk compression of the log.
    #[serde(default)]
    pub compression: crate::LogCompression,
    /// Serve the run live to Foxglove (`testbed run --live`).
    #[serde(default)]
    pub live: Option<LiveConfig>,
    /// A contact scenario's obstacles, for the 3D view.
    #[serde(default)]
    pub obstacles: Vec<crate::obstacles::DrawnObstacle>,
}

/// Why the logger node stopped.
#[derive(Debug, thiserror::Error)]
pub enum LoggerNodeError {
    /// The node protocol or the bus.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// The log could not be written.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The URDF does not load (the launcher checked it: a damaged config).
    #[error("the logger cannot load the robot: {0}")]
    Model(#[from] arm_model::ModelError),
    /// The live view did not start.
    #[error(transparent)]
    Live(#[from] LiveError),
}

impl From<bus::WireError> for LoggerNodeError {
    fn from(e: bus::WireError) -> Self {
        Self::Node(e.into())
    }
}

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
    /// Subscribes to the message's topic (the wire's binding table).
    fn new(link: &NodeLink) -> Result<Self, LoggerNodeError> {
        Ok(Self {
            sub: link.bus.polling_subscriber(<M as wire::Bound>::TOPIC)?,
            count: TopicCount::default(),
        })
    }

    fn drain(
        &mut self,
        mut take: impl FnMut(&M) -> Result<(), LogError>,
    ) -> Result<(), LoggerNodeError> {
        while let Some(m) = self.sub.receive()? {
            self.count.add(m.header().seq);
            take(&m)?;
        }
        let _ = self.sub.drain_events();
        Ok(())
    }

    fn stats(&self, out: &mut BTreeMap<String, String>) {
        let name = M::LOG_TOPIC.trim_start_matches('/');
        out.insert(format!("{name}.received"), self.count.received.to_string());
        out.insert(format!("{name}.dropped"), self.count.dropped.to_string());
    }
}

struct Subs {
    state: Sub<JointState>,
    reference: Sub<ReferenceSample>,
    command: Sub<Command>,
    diag: Sub<ControllerDiagnostics>,
    own: Sub<OwnDiagnostics>,
    timing: Sub<Timing>,
    contact: Sub<ContactState>,
}

impl Subs {
    fn drain(&mut self, out: &mut Outputs) -> Result<(), LoggerNodeError> {
        // Timing first. Drained last, it lost 19 samples right after its
        // buffer's 2048th, in 2 of 8 lockstep runs on a loaded machine, even
        // though its publisher is lossless (retry until delivered). The
        // logger counted them as dropped. Drained first, no run of 32 lost
        // any. The cause inside iceoryx2 is not found yet.
        self.timing.drain(|m| out.take(m))?;
        self.contact.drain(|m| out.take_contact(m))?;
        self.state.drain(|m| out.take_state(m))?;
        self.reference.drain(|m| out.take(m))?;
        self.command.drain(|m| out.take_command(m))?;
        self.diag.drain(|m| out.take(m))?;
        self.own.drain(|m| out.take(m))
    }

    fn stats(&self) -> BTreeMap<String, String> {
        let mut out = BTreeMap::new();
        self.state.stats(&mut out);
        self.reference.stats(&mut out);
        self.command.stats(&mut out);
        self.diag.stats(&mut out);
        self.own.stats(&mut out);
        self.timing.stats(&mut out);
        self.contact.stats(&mut out);
        out
    }
}

/// How the run ended, as the log's stats record it (`replay` warns on
/// anything but "finished").
fn run_end(link: &NodeLink, result: &Result<(), LoggerNodeError>) -> String {
    match (link.run_end(), result) {
        (Some(end), _) => end.describe(),
        (None, Err(LoggerNodeError::Node(NodeError::ParentGone(pid)))) => {
            format!("the launcher (pid {pid}) vanished")
        }
        (None, Err(e)) => format!("the logger stopped: {e}"),
        (None, Ok(())) => "unknown".into(),
    }
}

/// Runs the logger node to the end of the run.
pub fn run(link: &mut NodeLink, config: &LoggerNodeConfig) -> Result<(), LoggerNodeError> {
    let mut subs = Subs {
        state: Sub::new(link)?,
        reference: Sub::new(link)?,
        command: Sub::new(link)?,
        diag: Sub::new(link)?,
        own: Sub::new(link)?,
        timing: Sub::new(link)?,
        contact: Sub::new(link)?,
    };
    let model = arm_model::ArmModel::from_urdf_str_locked(&config.urdf, &config.lock)?;
    // The live view first: a taken port fails the run before anything is
    // written.
    let live = match &config.live {
        Some(live) => Some(crate::live::start(live, &crate::channels())?),
        None => None,
    };
    if let Some(l) = &live {
        // Said and kept, so a viewer can find a port the system chose.
        let addr = l.address();
        eprintln!("testbed node logger: live view at ws://{addr}");
        if let Some(dir) = config.out.parent()
            && let Err(e) = std::fs::write(dir.join("live-address.txt"), format!("ws://{addr}\n"))
        {
            eprintln!("testbed node logger: warning: cannot write live-address.txt: {e}");
        }
    }
    let mut meta = config.metadata.clone();
    meta.start_time_unix_ns = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64);
    let log = LogWriter::create_with(&config.out, &meta, &config.urdf, config.compression)?;
    let mut out = Outputs::open(log, &model, &config.obstacles, live)?;

    let started = link.ready_and_wait_for_start();
    let result: Result<(), LoggerNodeError> = match started {
        Ok(_) => loop {
            subs.drain(&mut out)?;
            out.flush_if_due()?;
            if let Err(e) = link.check() {
                break Err(e.into());
            }
            if let Err(e) = link.bus.wait(Duration::from_millis(10)) {
                break Err(e.into());
            }
        },
        Err(e) => Err(e.into()),
    };
    // STOP, a signal or a vanished launcher: in every case take what is
    // still buffered and finish the file properly.
    subs.drain(&mut out)?;
    let mut stats = subs.stats();
    stats.insert(RUN_END.into(), run_end(link, &result));
    out.finish(stats)?;
    match result {
        Err(LoggerNodeError::Node(NodeError::Stopped)) => Ok(()),
        other => other,
    }
}
