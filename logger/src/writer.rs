//! Writing a run log.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::channels::{ChannelSpec, MESSAGE_ENCODING, PROFILE, SCHEMA_ENCODING};
use super::compression::LogCompression;
use super::json::LogMessage;
use super::mcap_out::McapOut;
use super::{LogError, RUN_METADATA, STATS_METADATA, URDF_ATTACHMENT};

/// A chunk is closed at least this often, so a crash loses at most this
/// much wall time of data (an unfinished MCAP file loses only its open chunk).
const FLUSH_EVERY: Duration = Duration::from_millis(500);
/// The zstd level of the chunks (negative: zstd's fast levels).
pub const ZSTD_LEVEL: i32 = -1;
/// Chunks are also closed when they reach this size (uncompressed).
const CHUNK_BYTES: usize = 1 << 20;

/// What the `testbed.run` metadata record says.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunMetadata {
    /// Run id (the run folder's name).
    pub run_id: String,
    /// "realtime" or "lockstep".
    pub mode: String,
    /// Control rate, Hz.
    pub rate_hz: f64,
    /// The scenario as it ran (TOML).
    pub scenario_toml: String,
    /// Where the scenario came from.
    pub scenario_source: String,
    /// The robot's label.
    pub robot: String,
    /// Joint names, in order.
    pub joint_names: Vec<String>,
    /// Wall-clock start, ns since the Unix epoch.
    pub start_time_unix_ns: u64,
    /// The seed of every random effect.
    pub seed: u64,
    /// The plant effects the scenario turns on, by name.
    pub plant_effects: Vec<String>,
    /// K1_i and K2_i per joint, as `[a, b, …]`.
    pub k1: String,
    /// K2_i per joint.
    pub k2: String,
    /// Locked joints as `name=position`, with what they mimic.
    pub locked_joints: String,
    /// Mimic joints as `name=multiplier*leader+offset`.
    pub mimic_joints: String,
    /// Whether URDF damping and friction act.
    pub urdf_dynamics: bool,
    /// The control law (`nac`, `pd`, `ctc`, …).
    pub law: String,
    /// Whether the law uses the URDF's model (M, C, G).
    pub model_based: bool,
    /// The law's parameters as `key=value` pairs.
    pub law_parameters: String,
    /// The user's command that ran as the controller node (`testbed run
    /// --controller-cmd`); empty for the testbed's own controller.
    #[serde(default)]
    pub controller_cmd: String,
    /// The law that command declared (`CMD --describe`); empty when it
    /// declared none or the testbed's own controller ran.
    #[serde(default)]
    pub controller_name: String,
    /// Its own parameters as `key=value` pairs.
    #[serde(default)]
    pub controller_params: String,
    /// Its own diagnostics as `name:shape` pairs ([`wire::OwnLayout`]): what
    /// the `/controller/own_diagnostics` values are, in order.
    #[serde(default)]
    pub controller_diagnostics: String,
}

/// The log format this logger writes, recorded as `log_format` in the
/// `testbed.run` metadata (a log without it is format 1). Format 2 adds the
/// data path's stamps: `JointState.command_seq` and `applied_wall_ns`,
/// `Command.started_wall_ns`, `reference_t_ns` and `stale_references`.
/// Format 3 is the ROS 2 one: the `ros2` profile, CDR messages and
/// `ros2msg` schemas ([`crate::ros2`]) instead of JSON with JSON schemas.
pub const LOG_FORMAT: u32 = 3;

impl RunMetadata {
    /// The `testbed.run` record: every field as text (lists joined by
    /// commas), from the struct's own serde form, plus the log format and
    /// the software that wrote it.
    fn to_map(&self) -> Result<BTreeMap<String, String>, serde_json::Error> {
        let serde_json::Value::Object(fields) = serde_json::to_value(self)? else {
            unreachable!("a struct serialises to an object");
        };
        let text = |v: serde_json::Value| match v {
            serde_json::Value::String(s) => s,
            serde_json::Value::Array(items) => items
                .into_iter()
                .map(|i| i.as_str().map_or_else(|| i.to_string(), String::from))
                .collect::<Vec<_>>()
                .join(","),
            other => other.to_string(),
        };
        let mut map: BTreeMap<String, String> =
            fields.into_iter().map(|(k, v)| (k, text(v))).collect();
        map.insert("log_format".into(), LOG_FORMAT.to_string());
        map.insert(
            "software".into(),
            format!("testbed {}", env!("CARGO_PKG_VERSION")),
        );
        Ok(map)
    }
}

/// An open log.
pub struct LogWriter {
    writer: McapOut,
    path: PathBuf,
    /// Topic, channel id and last sequence number of each open channel: a
    /// handful, searched by the topic's address first (every caller passes
    /// the same constants), which costs less than hashing it per message.
    channels: Vec<(&'static str, u16, u32)>,
    last_flush: Instant,
    /// One message's CDR, reused from message to message.
    scratch: Vec<u8>,
}

impl LogWriter {
    /// Creates the file (zstd chunks) and writes the run's metadata and the URDF.
    pub fn create(path: &Path, meta: &RunMetadata, urdf: &str) -> Result<Self, LogError> {
        Self::create_with(path, meta, urdf, LogCompression::Zstd)
    }

    /// [`LogWriter::create`] with chunks compressed as `compression` says.
    pub fn create_with(
        path: &Path,
        meta: &RunMetadata,
        urdf: &str,
        compression: LogCompression,
    ) -> Result<Self, LogError> {
        let p = path.display().to_string();
        let file = open_new(path).map_err(|cause| LogError::Io {
            path: p.clone(),
            cause,
        })?;
        let io = |cause| LogError::Io {
            path: p.clone(),
            cause,
        };
        // zstd's first fast level (`zstd --fast=1`), not its default 3:
        // compressing is the logger's largest cost, and on the doubles of a
        // run (which no level squeezes much) level -1 is twice as fast as
        // level 1 for a file 3 % larger (results.md).
        let mut writer = McapOut::create(
            file,
            PROFILE,
            &format!("testbed {}", env!("CARGO_PKG_VERSION")),
            compression,
            ZSTD_LEVEL,
        )
        .map_err(io)?;
        let map = meta.to_map().map_err(|cause| LogError::Encode {
            path: p.clone(),
            topic: RUN_METADATA,
            cause,
        })?;
        writer.metadata(RUN_METADATA, &map).map_err(io)?;
        writer
            .attach(
                0,
                meta.start_time_unix_ns,
                URDF_ATTACHMENT,
                "application/xml",
                urdf.as_bytes(),
            )
            .map_err(io)?;
        let mut log = Self {
            writer,
            path: path.to_path_buf(),
            channels: Vec::new(),
            last_flush: Instant::now(),
            scratch: Vec::with_capacity(4096),
        };
        // The model on its latched topic, once, at the run's start: where
        // Foxglove's 3D panel and robot_state_publisher look for it.
        log.add_channel_spec(&ChannelSpec::robot_description())?;
        let mut data = Vec::with_capacity(urdf.len() + 16);
        crate::ros2::string_message(&mut data, urdf);
        log.write_raw(
            crate::ros2::ROBOT_DESCRIPTION_TOPIC,
            0,
            meta.start_time_unix_ns,
            &data,
        )?;
        Ok(log)
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn err(&self) -> impl Fn(std::io::Error) -> LogError + '_ {
        |cause| LogError::Io {
            path: self.path.display().to_string(),
            cause,
        }
    }

    /// Registers the channel of `M` (done on first write otherwise).
    pub fn add_channel<M: LogMessage>(&mut self) -> Result<u16, LogError> {
        match self.find(M::LOG_TOPIC) {
            Some(i) => Ok(self.channels[i].1),
            None => self.add_channel_spec(&ChannelSpec::of::<M>()),
        }
    }

    /// Registers a channel (once: a topic registered before keeps its id).
    pub fn add_channel_spec(&mut self, spec: &ChannelSpec) -> Result<u16, LogError> {
        if let Some(i) = self.find(spec.topic) {
            return Ok(self.channels[i].1);
        }
        let schema_id = self
            .writer
            .add_schema(&spec.schema_name, SCHEMA_ENCODING, spec.schema.as_bytes())
            .map_err(self.err())?;
        let id = self
            .writer
            .add_channel(
                schema_id,
                spec.topic,
                MESSAGE_ENCODING,
                &crate::ros2::channel_metadata(spec.topic),
            )
            .map_err(self.err())?;
        self.channels.push((spec.topic, id, 0));
        Ok(id)
    }

    fn find(&self, topic: &str) -> Option<usize> {
        let same = |t: &&str| std::ptr::eq(*t, topic);
        (self.channels.iter().position(|c| same(&c.0)))
            .or_else(|| self.channels.iter().position(|c| c.0 == topic))
    }

    /// Appends one message; gives back its CDR (for the live view).
    pub fn write<M: LogMessage>(&mut self, msg: &M) -> Result<&[u8], LogError> {
        self.add_channel::<M>()?;
        let h = msg.header();
        let mut data = std::mem::take(&mut self.scratch);
        data.clear();
        crate::ros2::encode(msg, &mut data);
        let res = self.write_raw(M::LOG_TOPIC, h.t_ns, h.wall_ns, &data);
        self.scratch = data;
        res.map(|()| self.scratch.as_slice())
    }

    /// Appends one message already encoded (CDR) to a registered channel.
    pub fn write_raw(
        &mut self,
        topic: &'static str,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), LogError> {
        let Some(i) = self.find(topic) else {
            return Err(LogError::UnknownChannel {
                path: self.path.display().to_string(),
                topic,
            });
        };
        let (_, id, seq) = &mut self.channels[i];
        *seq = seq.wrapping_add(1);
        self.writer.message(*id, *seq, log_time, publish_time, data);
        if self.writer.chunk_len() >= CHUNK_BYTES {
            let res = self.writer.close_chunk();
            res.map_err(self.err())?;
        }
        Ok(())
    }

    /// Closes the open chunk if it is older than the flush period.
    pub fn flush_if_due(&mut self) -> Result<(), LogError> {
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.flush()?;
        }
        Ok(())
    }

    /// Closes the open chunk and pushes it to the file.
    pub fn flush(&mut self) -> Result<(), LogError> {
        self.last_flush = Instant::now();
        let res = self.writer.close_chunk().and_then(|()| self.writer.flush());
        res.map_err(self.err())
    }

    /// Writes the `rosbag2` and `testbed.log_stats` records, the summary
    /// and the footer.
    pub fn finish(mut self, stats: BTreeMap<String, String>) -> Result<(), LogError> {
        let res = self.writer.close_chunk();
        res.map_err(self.err())?;
        let (topics, span) = self.writer.bag_topics();
        let file = self
            .path
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default();
        let bag = crate::ros2::rosbag2_metadata(&file, &topics, span);
        let res = self
            .writer
            .metadata(crate::ros2::ROSBAG2_METADATA, &bag)
            .and_then(|()| self.writer.metadata(STATS_METADATA, &stats));
        res.map_err(self.err())?;
        let path = self.path.display().to_string();
        self.writer
            .finish()
            .map_err(|cause| LogError::Io { path, cause })
    }
}

/// Opens `path` for a new log: never an existing file (a finished run's
/// log must not be truncated by a logger started again with its config),
/// but a device such as /dev/null or /dev/full is written as it is.
fn open_new(path: &Path) -> std::io::Result<File> {
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
    {
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            let regular = std::fs::metadata(path).is_ok_and(|m| m.is_file());
            if regular {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::AlreadyExists,
                    "the file exists: a log is never overwritten (remove it or name another)",
                ));
            }
            std::fs::OpenOptions::new().write(true).open(path)
        }
        other => other,
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// #39 row 3: an existing log is never opened for writing.
    #[test]
    fn an_existing_log_is_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.mcap");
        std::fs::write(&path, b"a finished run").unwrap();
        let err = LogWriter::create(&path, &RunMetadata::default(), "<robot/>")
            .err()
            .unwrap()
            .to_string();
        assert!(
            err.contains("run.mcap") && err.contains("never overwritten"),
            "{err}"
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"a finished run");
    }

    /// A full disk (#18 row 12): the error says so and names the file,
    /// whether it strikes a record written at once or a compressed chunk.
    #[test]
    fn a_full_disk_is_named_as_such() {
        let full = Path::new("/dev/full");
        let meta = RunMetadata::default();
        // The URDF attachment goes straight to the file, past the buffer.
        let err = LogWriter::create(full, &meta, &"x".repeat(1 << 20))
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("/dev/full"), "{err}");
        assert!(err.contains("No space left on device"), "{err}");
        // A chunk of messages, compressed, then flushed (if the small
        // start fitted in the buffer).
        let err = match LogWriter::create(full, &meta, "<robot/>") {
            Err(e) => e.to_string(),
            Ok(mut w) => {
                let mut err = None;
                for k in 0..20_000u64 {
                    let mut s = wire::JointState::default();
                    s.header.seq = k;
                    s.dof = 12;
                    s.q = [k as f64 * 1e-3; wire::MAX_DOF];
                    let r = w
                        .write(&s)
                        .map(|_| ())
                        .and_then(|()| if k % 1000 == 999 { w.flush() } else { Ok(()) });
                    if let Err(e) = r {
                        err = Some(e.to_string());
                        break;
                    }
                }
                err.unwrap_or_else(|| w.finish(BTreeMap::new()).err().unwrap().to_string())
            }
        };
        assert!(err.contains("No space left on device"), "{err}");
    }
}
