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
use wire::Logged;

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
    /// A contact scenario's free objects' shapes, in order, for the 3D
    /// view (their poses come with the contact samples).
    #[serde(default)]
    pub objects: Vec<crate::obstacles::DrawnShape>,
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

impl From<bus::BusError> for LoggerNodeError {
    fn from(e: bus::BusError) -> Self {
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

/// A subscription to one logged message, whatever its type.
trait Drain {
    /// Takes every sample waiting into `out`.
    fn drain(&mut self, out: &mut Outputs) -> Result<(), LoggerNodeError>;
    /// Its counts, for the log's stats.
    fn stats(&self, out: &mut BTreeMap<String, String>);
    /// Its topic.
    fn topic(&self) -> wire::Topic;
}

impl<M> Drain for Sub<M>
where
    M: LogMessage + Into<Logged> + std::fmt::Debug + wire::ZeroCopySend + 'static,
{
    fn drain(&mut self, out: &mut Outputs) -> Result<(), LoggerNodeError> {
        while let Some(m) = self.sub.receive()? {
            self.count.add(m.header().seq);
            out.take_logged(&m.into())?;
        }
        let _ = self.sub.drain_events();
        Ok(())
    }

    fn stats(&self, out: &mut BTreeMap<String, String>) {
        let name = M::LOG_TOPIC.trim_start_matches('/');
        out.insert(format!("{name}.received"), self.count.received.to_string());
        out.insert(format!("{name}.dropped"), self.count.dropped.to_string());
    }

    fn topic(&self) -> wire::Topic {
        M::TOPIC
    }
}

/// A subscription to each of the wire's logged messages
/// ([`wire::logged_messages!`]).
struct Subs(Vec<Box<dyn Drain>>);

impl Subs {
    fn new(link: &NodeLink) -> Result<Self, LoggerNodeError> {
        macro_rules! subscribe {
            ($($ty:ident => $topic:ident, $channel:literal, $schema:literal;)*) => {
                vec![$(Box::new(Sub::<wire::$ty> {
                    sub: link.bus.polling_subscriber()?,
                    count: TopicCount::default(),
                }) as Box<dyn Drain>,)*]
            };
        }
        let mut subs = wire::logged_messages!(subscribe);
        // Timing first. Drained last, it lost 19 samples right after its
        // buffer's 2048th, in 2 of 8 lockstep runs on a loaded machine, even
        // though its publisher is lossless (retry until delivered). The
        // logger counted them as dropped. Drained first, no run of 32 lost
        // any. The cause inside iceoryx2 is not found yet.
        subs.sort_by_key(|s| s.topic() != wire::Topic::Timing);
        Ok(Self(subs))
    }

    fn drain(&mut self, out: &mut Outputs) -> Result<(), LoggerNodeError> {
        self.0.iter_mut().try_for_each(|s| s.drain(out))
    }

    fn stats(&self) -> BTreeMap<String, String> {
        let mut out = BTreeMap::new();
        for s in &self.0 {
            s.stats(&mut out);
        }
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
    let mut subs = Subs::new(link)?;
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
    let mut out = Outputs::open(
        log,
        (&model, &config.urdf),
        (&config.obstacles, &config.objects),
        live,
    )?;

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
