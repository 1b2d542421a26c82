//! Reading a run log, as far as it goes.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mcap::records::Record;

use super::{DecodeError, LogError, RUN_METADATA, STATS_METADATA, URDF_ATTACHMENT};
use crate::msg_schema::MsgSchema;

/// What a log holds besides its messages.
#[derive(Debug, Clone, Default)]
pub struct LogContents {
    /// The file.
    pub path: PathBuf,
    /// The `testbed.run` metadata.
    pub run: BTreeMap<String, String>,
    /// The logger's counts (`testbed.log_stats`), absent if it never finished.
    pub stats: Option<BTreeMap<String, String>>,
    /// The robot's URDF.
    pub urdf: Option<String>,
    /// Messages read.
    pub messages: u64,
    /// The file ended with its footer (the logger finished it).
    pub complete: bool,
    /// Why reading stopped early, if it did.
    pub cut_short: Option<String>,
    /// Why the log's integrity cannot be checked, if it cannot: its data
    /// section's checksum is 0 (MCAP's "not computed", which other writers
    /// leave) or it has no DataEnd record. A record changed after writing
    /// would then go unseen, so such a log is never judged clean.
    pub unchecked: Option<String>,
    /// What is wrong after the footer, if anything: the closing magic cut
    /// or changed. Every record was read, so the run's data are whole;
    /// the file is still not as the logger left it (#60 item 8).
    pub end_damaged: Option<String>,
}

impl LogContents {
    /// How the run ended, as the logger recorded it (None: the logger
    /// never finished the file, or the log predates the record).
    pub fn run_end(&self) -> Option<&str> {
        self.stats.as_ref()?.get(crate::RUN_END).map(String::as_str)
    }

    /// The log's format ([`crate::LOG_FORMAT`]); 1 for a log that predates
    /// the record, None when the record is not a number.
    pub fn log_format(&self) -> Option<u32> {
        self.run
            .get("log_format")
            .map_or(Some(1), |v| v.parse().ok())
    }

    /// Samples the logger could not take, summed over topics (None if the
    /// logger never finished the file).
    pub fn logger_dropped(&self) -> Option<u64> {
        self.stats.as_ref().map(|stats| {
            stats
                .iter()
                .filter(|(k, _)| k.ends_with(".dropped"))
                .filter_map(|(_, v)| v.parse::<u64>().ok())
                .sum()
        })
    }
}

/// Why a message handler stopped reading a log.
#[derive(Debug, thiserror::Error)]
pub enum MessageError {
    /// The message does not decode, or does not fit the run: the log is
    /// read up to it, and `cut_short` says why.
    #[error(transparent)]
    Malformed(#[from] DecodeError),
    /// The handler itself failed (writing a CSV, say): reading stops with
    /// this error.
    #[error(transparent)]
    Sink(#[from] std::io::Error),
}

/// How a channel's messages are encoded: JSON (log formats 1 and 2) or CDR
/// (format 3). [`crate::Decode::decode_as`] decodes either.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// JSON text (`json`).
    Json,
    /// Little-endian CDR (`cdr`).
    Cdr,
}

impl Encoding {
    /// The encoding of an MCAP channel's `message_encoding`.
    pub fn of(message_encoding: &str) -> Option<Self> {
        match message_encoding {
            "json" => Some(Self::Json),
            "cdr" => Some(Self::Cdr),
            _ => None,
        }
    }
}

/// One message of a log, as the reader hands it over: its channel's topic,
/// encoding and stored schema, and its data ([`crate::decode_logged`]
/// decodes a testbed message by that schema).
#[derive(Debug, Clone, Copy)]
pub struct RawMessage<'a> {
    /// The channel's topic.
    pub topic: &'a str,
    /// The channel's message encoding.
    pub encoding: Encoding,
    /// The channel's schema, for a testbed message in CDR (None for JSON
    /// and for the standard views).
    pub schema: Option<&'a MsgSchema>,
    /// The message's bytes.
    pub data: &'a [u8],
}

/// Called for every message of a log, in file order.
pub type OnMessage<'a> = &'a mut dyn FnMut(&RawMessage<'_>) -> Result<(), MessageError>;

/// The package of testbed's own messages: their stored schemas are read.
const OWN_SCHEMAS: &str = "testbed_msgs/";

/// One channel of the log, as its record and its schema's said.
struct ChannelInfo {
    topic: String,
    encoding: Result<Encoding, String>,
    /// A testbed message's schema in CDR, read (or why it cannot be).
    schema: Option<Result<Arc<MsgSchema>, String>>,
}

/// Reads `path` record by record, calling `on_message(topic, data)` (if
/// given) for every message in file order. A truncated or unfinished file is
/// read up to its last whole record; `cut_short` then says why it ended.
///
/// The file is read one top-level record at a time (a chunk is about a
/// megabyte), so memory stays the same whatever the log's length.
pub fn read_log(path: &Path, on_message: Option<OnMessage<'_>>) -> Result<LogContents, LogError> {
    stream(path, on_message, false)
}

/// The run's metadata and URDF of the log at `path`: the records before its
/// first message (where the logger writes them), without unpacking the
/// rest. Only `run` and `urdf` are read.
pub fn read_log_head(path: &Path) -> Result<LogContents, LogError> {
    stream(path, None, true)
}

/// [`read`] over the file at `path`, record by record: each top-level
/// record's framing is checked (as [`crate::scan::sound_prefix`] does for a
/// whole buffer) before its bytes are handed on.
fn stream(
    path: &Path,
    mut on_message: Option<OnMessage<'_>>,
    head_only: bool,
) -> Result<LogContents, LogError> {
    use std::io::Read;
    let p = path.display().to_string();
    let io = |cause| LogError::Io {
        path: p.clone(),
        cause,
    };
    let file = wire::open_regular_file(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let mut file = std::io::BufReader::with_capacity(1 << 20, file);
    let mut magic = [0u8; 8];
    if file.read_exact(&mut magic).is_err() || magic != *mcap::MAGIC {
        return Err(LogError::NotATestbedLog {
            path: p,
            reason: "not an MCAP file (no MCAP magic at the start)".into(),
        });
    }
    let mut walk = Walk::new(path);
    let mut at = magic.len() as u64;
    let mut part = Vec::new();
    // The data section's checksum covers every record before DataEnd, those
    // outside the chunks (channels, the run's metadata, the URDF) too: a
    // changed byte there once turned a degraded log into a clean one.
    let mut data_crc = crc32fast::Hasher::new();
    data_crc.update(&magic);
    while at < len {
        let rest = len - at;
        let mut header = [0u8; 9];
        if rest < 9 || file.read_exact(&mut header).is_err() {
            walk.damaged = Some(format!("the file ends inside a record header at byte {at}"));
            break;
        }
        let op = header[0];
        let mut l8 = [0u8; 8];
        l8.copy_from_slice(&header[1..]);
        let body_len = u64::from_le_bytes(l8);
        if body_len > rest - 9 || body_len > crate::scan::MAX_CHUNK_BYTES {
            walk.damaged = Some(format!(
                "the record at byte {at} (opcode {op:#04x}) claims {body_len} bytes but {} remain: \
                 the file is cut short or damaged",
                rest - 9
            ));
            break;
        }
        part.clear();
        part.extend_from_slice(mcap::MAGIC);
        part.extend_from_slice(&header);
        let start = part.len();
        part.resize(start + body_len as usize, 0);
        file.read_exact(&mut part[start..]).map_err(io)?;
        if op == crate::scan::OP_CHUNK
            && let Some(why) = crate::scan::check_chunk(&part[start..])
        {
            walk.damaged = Some(format!("the chunk at byte {at} is damaged: {why}"));
            break;
        }
        if op == OP_DATA_END {
            if let Some(why) = data_crc_differs(&part[start..], &data_crc) {
                walk.damaged = Some(why);
                break;
            }
            walk.data_end = Some(stored_crc(&part[start..]));
        } else if !head_only {
            data_crc.update(&part[mcap::MAGIC.len()..]);
        }
        if walk.feed(
            crate::records::Records::part(&part),
            &mut on_message,
            head_only,
        )? {
            break;
        }
        at += 9 + body_len;
        if op == crate::scan::OP_FOOTER {
            let mut tail = Vec::new();
            // At most the magic and a byte more: the rest is not read.
            (&mut file)
                .take(mcap::MAGIC.len() as u64 + 1)
                .read_to_end(&mut tail)
                .map_err(io)?;
            walk.out.end_damaged = end_damage(&tail, len - at);
            break;
        }
    }
    walk.finish(head_only)
}

/// What is wrong with the `tail` of a file after its footer (`left`
/// bytes in all): None when it is exactly MCAP's closing magic.
fn end_damage(tail: &[u8], left: u64) -> Option<String> {
    let magic = mcap::MAGIC;
    if tail == magic && left == magic.len() as u64 {
        return None;
    }
    Some(if left < magic.len() as u64 {
        format!(
            "the file is cut: it ends {left} bytes after the footer, inside the closing magic \
             ({} bytes)",
            magic.len()
        )
    } else if !tail.starts_with(magic) {
        "the closing magic after the footer is wrong: the file's last bytes were changed".into()
    } else {
        format!(
            "{} bytes follow the closing magic: something was appended",
            left - magic.len() as u64
        )
    })
}

/// The DataEnd record's opcode.
const OP_DATA_END: u8 = 0x0F;

/// The data section's checksum a DataEnd record's `body` holds (0: not
/// computed, or a body too short to hold one).
fn stored_crc(body: &[u8]) -> u32 {
    body.get(..4)
        .and_then(|b| b.try_into().ok())
        .map_or(0, u32::from_le_bytes)
}

/// Why the data section's checksum in DataEnd's `body` does not match
/// `crc` (None when it does, or when the writer left it 0: not computed,
/// which [`Walk::finish`] reports as a log that cannot be checked).
fn data_crc_differs(body: &[u8], crc: &crc32fast::Hasher) -> Option<String> {
    let stored = u32::from_le_bytes(body.get(..4)?.try_into().ok()?);
    let computed = crc.clone().finalize();
    (stored != 0 && stored != computed).then(|| {
        format!(
            "the data section's checksum does not match ({computed:#010x}, the log says \
             {stored:#010x}): a record was changed after it was written (a channel, the \
             run's metadata, the URDF or a chunk)"
        )
    })
}

/// [`read_log`] of a log already in memory (`path` names it in messages).
pub fn read_log_bytes(
    buf: &[u8],
    path: &Path,
    on_message: Option<OnMessage<'_>>,
) -> Result<LogContents, LogError> {
    read(buf, path, on_message, false)
}

fn read(
    buf: &[u8],
    path: &Path,
    mut on_message: Option<OnMessage<'_>>,
    head_only: bool,
) -> Result<LogContents, LogError> {
    if !buf.starts_with(mcap::MAGIC) {
        return Err(LogError::NotATestbedLog {
            path: path.display().to_string(),
            reason: "not an MCAP file (no MCAP magic at the start)".into(),
        });
    }
    let mut walk = Walk::new(path);
    // Only the soundly framed part goes to the reader (see `scan`).
    let (end, damaged) = crate::scan::sound_prefix(buf);
    walk.damaged = damaged;
    // The `mcap` reader checks a non-zero checksum; a zero one is noted.
    walk.data_end = crate::scan::find_record(&buf[..end], OP_DATA_END).map(stored_crc);
    walk.feed(
        crate::records::Records::new(&buf[..end]),
        &mut on_message,
        head_only,
    )?;
    if let Some((_, after)) = crate::scan::locate(&buf[..end], crate::scan::OP_FOOTER) {
        let tail = &buf[after..buf.len().min(after + mcap::MAGIC.len() + 1)];
        walk.out.end_damaged = end_damage(tail, (buf.len() - after) as u64);
    }
    walk.finish(head_only)
}

/// What a log has said so far, record by record.
struct Walk {
    out: LogContents,
    p: String,
    topics: HashMap<u16, ChannelInfo>,
    /// The testbed messages' schemas by id, read.
    schemas: HashMap<u16, Result<Arc<MsgSchema>, String>>,
    /// Where the framing stopped being sound, if it did.
    damaged: Option<String>,
    /// The data section's checksum its DataEnd record holds (None: no
    /// DataEnd read).
    data_end: Option<u32>,
}

impl Walk {
    fn new(path: &Path) -> Self {
        Self {
            out: LogContents {
                path: path.to_path_buf(),
                ..LogContents::default()
            },
            p: path.display().to_string(),
            topics: HashMap::new(),
            schemas: HashMap::new(),
            damaged: None,
            data_end: None,
        }
    }

    /// Takes `records`; true when reading is to stop.
    fn feed(
        &mut self,
        records: crate::records::Records<'_>,
        on_message: &mut Option<OnMessage<'_>>,
        head_only: bool,
    ) -> Result<bool, LogError> {
        let out = &mut self.out;
        for record in records {
            let record = match record {
                Ok(r) => r,
                Err(e) => {
                    out.cut_short = Some(if e.is_checksum() {
                        format!(
                            "a chunk is damaged (its checksum does not match: {e}); it and what follows are left out"
                        )
                    } else {
                        format!("the file ends inside a record ({e})")
                    });
                    return Ok(true);
                }
            };
            match record {
                Record::Schema { header, data }
                    if header.name.starts_with(OWN_SCHEMAS) && header.encoding == "ros2msg" =>
                {
                    let read = MsgSchema::parse(&header.name, &data)
                        .map(Arc::new)
                        .map_err(|e| e.to_string());
                    self.schemas.insert(header.id, read);
                }
                Record::Channel(c) => {
                    let encoding = Encoding::of(&c.message_encoding).ok_or(c.message_encoding);
                    let schema = match encoding {
                        Ok(Encoding::Cdr) => self.schemas.get(&c.schema_id).cloned(),
                        _ => None,
                    };
                    let info = ChannelInfo {
                        topic: c.topic,
                        encoding,
                        schema,
                    };
                    self.topics.insert(c.id, info);
                }
                Record::Message { .. } if head_only => return Ok(true),
                Record::Message { header, data } => {
                    let channel = self.topics.get(&header.channel_id);
                    if let (Some(channel), Some(handler)) = (channel, on_message.as_mut())
                        && let Some(why) = deliver(handler, channel, &data, &self.p)?
                    {
                        out.cut_short = Some(why);
                        return Ok(true);
                    }
                    out.messages += 1;
                }
                Record::Metadata(m) if m.name == RUN_METADATA => out.run = m.metadata,
                Record::Metadata(m) if m.name == STATS_METADATA => out.stats = Some(m.metadata),
                Record::Attachment { header, data, .. } if header.name == URDF_ATTACHMENT => {
                    // Refused here, by name, rather than handed on: a 60 MB
                    // attachment took 101 s to be refused by the URDF
                    // reader's diagnosis (#48 item 8).
                    if data.len() > arm_model::MAX_URDF_BYTES {
                        return Err(LogError::NotATestbedLog {
                            path: self.p.clone(),
                            reason: format!(
                                "its {URDF_ATTACHMENT} attachment is {} bytes, over the cap of \
                                 {} bytes on a URDF (arm_model::MAX_URDF_BYTES)",
                                data.len(),
                                arm_model::MAX_URDF_BYTES
                            ),
                        });
                    }
                    out.urdf = Some(String::from_utf8_lossy(&data).to_string());
                }
                Record::Footer(_) => out.complete = true,
                _ => {}
            }
        }
        Ok(false)
    }

    fn finish(mut self, head_only: bool) -> Result<LogContents, LogError> {
        let out = &mut self.out;
        if let Some(why) = self.damaged
            && out.cut_short.is_none()
        {
            out.cut_short = Some(why);
        }
        if out.run.is_empty() {
            return Err(LogError::NotATestbedLog {
                path: self.p,
                reason: "no testbed.run metadata: not a log written by testbed".into(),
            });
        }
        if !out.complete && out.cut_short.is_none() && !head_only {
            out.cut_short = Some("the logger never finished the file (no footer)".into());
        }
        if out.cut_short.is_none() && !head_only {
            out.unchecked = match self.data_end {
                // testbed's logger always computes it (0 by chance: once in 2³²).
                Some(0) => Some(
                    "its data section's checksum is 0 (MCAP's \"not computed\", as Python's \
                     mcap writer leaves it; testbed's logger always computes it), so a record \
                     changed after writing would go unseen"
                        .into(),
                ),
                Some(_) => None,
                None => Some(
                    "it has no DataEnd record, so no checksum covers its data section and a \
                     record changed after writing would go unseen"
                        .into(),
                ),
            };
        }
        Ok(self.out)
    }
}

/// Hands one message to the handler: None when it took it, Some(why) when
/// the log is to be read no further, an error when the handler failed.
fn deliver(
    handler: &mut OnMessage<'_>,
    channel: &ChannelInfo,
    data: &[u8],
    path: &str,
) -> Result<Option<String>, LogError> {
    let topic = channel.topic.as_str();
    let encoding = match &channel.encoding {
        Ok(enc) => *enc,
        Err(other) => {
            return Ok(Some(format!(
                "channel {topic} holds {other:?} messages, which testbed does not read"
            )));
        }
    };
    let schema = match &channel.schema {
        Some(Ok(schema)) => Some(schema.as_ref()),
        Some(Err(why)) => {
            return Ok(Some(format!(
                "channel {topic}'s stored schema cannot be read: {why}"
            )));
        }
        None => None,
    };
    let message = RawMessage {
        topic,
        encoding,
        schema,
        data,
    };
    match handler(&message) {
        Ok(()) => Ok(None),
        Err(MessageError::Malformed(e)) => Ok(Some(format!("a {topic} message is malformed: {e}"))),
        Err(MessageError::Sink(cause)) => Err(LogError::Sink {
            path: path.to_string(),
            topic: topic.to_string(),
            cause,
        }),
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// Every input the fuzzer found a crash with (fuzz/regressions/log) is
    /// read to a named error or a cut-short log, without a huge allocation.
    #[test]
    fn fuzz_regressions_read_without_a_crash() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/regressions/log");
        let mut seen = 0;
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let buf = std::fs::read(e.path()).unwrap();
            // Every message decoded as JSON, as a reader of the log does.
            let mut count = |m: &RawMessage<'_>| {
                match m.encoding {
                    Encoding::Json => drop(crate::json_object::JsonObject::parse(m.data)?),
                    Encoding::Cdr => crate::check_message(m.encoding, m.data)?,
                }
                Ok(())
            };
            match read_log_bytes(&buf, &e.path(), Some(&mut count)) {
                Ok(c) => assert!(c.cut_short.is_some(), "{}", e.path().display()),
                Err(err) => assert!(!err.to_string().is_empty()),
            }
            seen += 1;
        }
        assert!(
            seen >= 2,
            "the regression inputs are missing from {}",
            dir.display()
        );
    }

    /// A format-3 log with bytes flipped here and there is read to a named
    /// error or as far as it goes, and no message decoder panics on what
    /// the reader hands it (the fuzzer's `log` target does this at length).
    #[test]
    fn damaged_cdr_logs_read_without_a_crash() {
        let dir = std::env::temp_dir().join(format!("testbed-cdr-dmg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.mcap");
        let meta = crate::RunMetadata::default();
        let mut w =
            crate::LogWriter::create_with(&path, &meta, "<robot/>", crate::LogCompression::None)
                .unwrap();
        for k in 0..40u64 {
            let mut s = wire::JointState {
                dof: 2,
                ..wire::JointState::default()
            };
            s.header.seq = k;
            s.q[0] = k as f64;
            w.write(&s).unwrap();
            let mut d = wire::ControllerDiagnostics {
                dof: 2,
                ..wire::ControllerDiagnostics::default()
            };
            d.header.seq = k;
            w.write(&d).unwrap();
        }
        w.finish(BTreeMap::new()).unwrap();
        let good = std::fs::read(&path).unwrap();
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for _ in 0..3000 {
            let mut buf = good.clone();
            for _ in 0..1 + next() % 4 {
                let at = (next() % buf.len() as u64) as usize;
                buf[at] = next() as u8;
            }
            let mut decode = |m: &RawMessage<'_>| {
                if crate::decode_logged(m)?.is_none() {
                    crate::check_message(m.encoding, m.data)?;
                }
                Ok(())
            };
            let _ = read_log_bytes(&buf, &path, Some(&mut decode));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The head is the metadata and URDF, read without the messages; the
    /// full read hands every message's JSON to the handler.
    #[test]
    fn the_head_holds_the_run_and_the_urdf() {
        let dir = std::env::temp_dir().join(format!("testbed-head-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.mcap");
        let meta = crate::RunMetadata {
            run_id: "head".into(),
            ..crate::RunMetadata::default()
        };
        let mut w = crate::LogWriter::create(&path, &meta, "<robot name='r'/>").unwrap();
        for k in 0..3u64 {
            let mut s = wire::JointState::default();
            s.header.seq = k;
            w.write(&s).unwrap();
        }
        w.finish(BTreeMap::new()).unwrap();

        let head = read_log_head(&path).unwrap();
        assert_eq!(head.run.get("run_id").map(String::as_str), Some("head"));
        assert_eq!(head.urdf.as_deref(), Some("<robot name='r'/>"));
        assert_eq!((head.messages, head.complete), (0, false));
        assert!(head.cut_short.is_none());

        let mut seqs = Vec::new();
        let mut take = |m: &RawMessage<'_>| {
            assert_eq!(m.encoding, Encoding::Cdr);
            // A standard message (the model on /robot_description) is
            // only checked, so its schema is not kept.
            let own = m.topic != crate::ros2::ROBOT_DESCRIPTION_TOPIC;
            assert_eq!(
                m.schema.is_some(),
                own,
                "a testbed message's schema is read"
            );
            if let Some(wire::Logged::JointState(s)) = crate::decode_logged(m)? {
                seqs.push(s.header.seq);
            }
            Ok(())
        };
        let all = read_log(&path, Some(&mut take)).unwrap();
        // The three states and the model on /robot_description.
        assert_eq!((all.messages, all.complete), (4, true));
        assert_eq!(seqs, [0, 1, 2]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A URDF attachment over the URDF cap is refused by name with the cap,
    /// by the head and the full read alike (#48 item 8).
    #[test]
    fn a_urdf_attachment_over_the_cap_is_refused() {
        let dir = std::env::temp_dir().join(format!("testbed-bigurdf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.mcap");
        let big = format!("<robot>{}</robot>", " ".repeat(arm_model::MAX_URDF_BYTES));
        let w = crate::LogWriter::create(&path, &crate::RunMetadata::default(), &big).unwrap();
        w.finish(BTreeMap::new()).unwrap();
        let want = format!(
            "its robot.urdf attachment is {} bytes, over the cap of {} bytes",
            big.len(),
            arm_model::MAX_URDF_BYTES
        );
        let head = read_log_head(&path).unwrap_err().to_string();
        assert!(head.contains(&want), "{head}");
        let all = read_log(&path, None).unwrap_err().to_string();
        assert!(all.contains(&want), "{all}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
