//! A log that is damaged, cut, reordered or not the whole run is never read
//! as `clean`: `replay` names what is wrong, keeps every step it can, and
//! exits as `run` does for its verdict.

use std::collections::BTreeMap;
use std::path::Path;

use mcap::records::Record;

use crate::util::{lockstep_log, lockstep_log as a_log, ok, testbed};

/// Rows 3 and 4, logs: a Header claiming u64::MAX bytes and a chunk asking
/// for 4.28 GB are named, never a panic or a huge allocation.
#[test]
fn damaged_record_lengths_in_a_log_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let log = a_log(dir.path());
    let good = std::fs::read(&log).unwrap();
    // The Header record: opcode at byte 8, its length at 9..17.
    let mut bad = good.clone();
    bad[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
    let f = dir.path().join("header.mcap");
    std::fs::write(&f, &bad).unwrap();
    let out = testbed().arg("replay").arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("header.mcap") && e.contains("testbed.run metadata"),
        "{e}"
    );
    // The first chunk's uncompressed size: walk the records to it.
    let mut at = 8;
    while good[at] != 0x06 {
        at += 9 + u64::from_le_bytes(good[at + 1..at + 9].try_into().unwrap()) as usize;
    }
    let mut bad = good.clone();
    bad[at + 9 + 16..at + 9 + 24].copy_from_slice(&4_280_000_000u64.to_le_bytes());
    let f = dir.path().join("chunk.mcap");
    std::fs::write(&f, &bad).unwrap();
    let out = testbed().arg("replay").arg(&f).output().unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    // Read as far as it goes (invalid, exit 4) or not at all (1).
    assert!(matches!(out.status.code(), Some(1 | 4)), "{e}");
    assert!(e.contains("4280000000 bytes uncompressed"), "{e}");
}

/// #18 row 5: a finished run's log says so and replays without a warning.
#[test]
fn a_finished_run_is_recorded_as_finished() {
    let dir = tempfile::tempdir().unwrap();
    let log = a_log(dir.path());
    let s: serde_json::Value =
        serde_json::from_slice(&ok(testbed().arg("replay").arg("--json").arg(&log)).stdout)
            .unwrap();
    assert!(s.get("warning").is_none(), "{s}");
    assert_eq!(s["run_end"], "finished");
    let text = std::fs::read(&log).unwrap();
    let needle = b"run_end";
    assert!(text.windows(needle.len()).any(|w| w == needle));
}

/// #31 row 13: a byte changed anywhere in a log either changes nothing or is
/// said: checksums are checked, so no damaged chunk silently changes the
/// figures (10 of 400 such mutations once did).
#[test]
fn a_damaged_log_never_silently_changes_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    let out = crate::util::ok(
        testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--duration",
                "1",
                "--json",
                "--runs-dir",
            ])
            .arg(dir.path()),
    );
    let run: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let log = std::path::PathBuf::from(run["log"].as_str().unwrap());
    let bytes = std::fs::read(&log).unwrap();
    let figures = |s: &serde_json::Value| {
        (
            s["steps"].clone(),
            s["joints"].clone(),
            s["metrics"].clone(),
        )
    };
    let original = figures(&run);
    let damaged = dir.path().join("damaged.mcap");
    let mut silent = Vec::new();
    for k in 1..60 {
        let at = bytes.len() * k / 60;
        let mut b = bytes.clone();
        b[at] ^= 0x20;
        std::fs::write(&damaged, &b).unwrap();
        let out = testbed()
            .args(["replay", "--json"])
            .arg(&damaged)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "byte {at}: {err}");
        let Ok(s) = serde_json::from_slice::<serde_json::Value>(&out.stdout) else {
            continue; // refused with a named error
        };
        if figures(&s) != original && s["warning"].is_null() {
            silent.push(at);
        }
    }
    assert!(
        silent.is_empty(),
        "bytes {silent:?} changed the summary silently"
    );
}

/// #31 row 20: `--verify` of a log with no complete step is refused, not
/// reported as a difference of 0.
#[test]
fn verify_refuses_a_log_with_no_step() {
    let dir = tempfile::tempdir().unwrap();
    let out = crate::util::ok(
        testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--duration",
                "0.2",
                "--json",
                "--runs-dir",
            ])
            .arg(dir.path()),
    );
    let run: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let bytes = std::fs::read(run["log"].as_str().unwrap()).unwrap();
    // The head of the log only: its metadata and URDF, no message.
    let cut = dir.path().join("head.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    let err = crate::util::fails(testbed().args(["replay", "--verify"]).arg(&cut));
    assert!(err.contains("no step to re-drive"), "{err}");
}

/// #39 row 1: a byte changed in a record outside the chunks (the run's
/// metadata, a channel) makes the log invalid: the data section's
/// checksum covers them.
#[test]
fn a_changed_record_outside_the_chunks_makes_the_log_invalid() {
    let dir = tempfile::tempdir().unwrap();
    let log = a_log(dir.path());
    let bytes = std::fs::read(&log).unwrap();
    let find = |needle: &[u8]| {
        bytes
            .windows(needle.len())
            .position(|w| w == needle)
            .unwrap()
    };
    let clean = json_of(testbed().args(["replay", "--json"]).arg(&log));
    assert_ne!(clean["timing"]["verdict"], "invalid", "{clean}");
    // The first copies are in the data section: the run's metadata (its
    // scenario text) and the /joint_states channel.
    for needle in [&b"duration_s"[..], &b"/joint_states"[..]] {
        let mut b = bytes.clone();
        b[find(needle) + 1] ^= 0x01;
        let damaged = dir.path().join("damaged.mcap");
        std::fs::write(&damaged, &b).unwrap();
        let out = testbed()
            .args(["replay", "--json"])
            .arg(&damaged)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        // Either the analysis says the log is invalid, or (the run's
        // metadata no longer reads) the error says why.
        match serde_json::from_slice::<serde_json::Value>(&out.stdout) {
            Ok(s) => {
                assert_eq!(s["timing"]["verdict"], "invalid", "{s}");
                assert!(s.to_string().contains("checksum does not match"), "{s}");
            }
            Err(_) => {
                assert!(
                    !out.status.success() && err.contains("checksum does not match"),
                    "{err}"
                );
            }
        }
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// The JSON a command printed, whatever its exit code.
fn json_of(cmd: &mut std::process::Command) -> serde_json::Value {
    let out = cmd.output().unwrap();
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}", String::from_utf8_lossy(&out.stderr));
    })
}

/// Copies the MCAP log `from` to `to` record by record with `mcap`'s own
/// writer, as a tool that edits logs does: only the messages of topics
/// `keep` accepts, the logger's counts of the others left out too when
/// `drop_counts`, every `thin`-th message of topic `thin.0` dropped, and
/// the data section's checksum computed only when `data_crc`, and every
/// message of topic `replace.0` holding `replace.1` instead of its data.
fn rewrite(
    from: &Path,
    to: &Path,
    keep: &dyn Fn(&str) -> bool,
    drop_counts: bool,
    thin: Option<(&str, u32)>,
    data_crc: bool,
    replace: Option<(&str, &[u8])>,
) {
    let bytes = std::fs::read(from).unwrap();
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .calculate_data_section_crc(data_crc)
        .create(std::io::BufWriter::new(std::fs::File::create(to).unwrap()))
        .unwrap();
    let (mut schemas, mut channels) = (BTreeMap::new(), BTreeMap::new());
    let mut seen = 0u32;
    for record in mcap::read::ChunkFlattener::new(&bytes).unwrap() {
        match record.unwrap() {
            Record::Schema { header, data } => {
                let id = w.add_schema(&header.name, &header.encoding, &data).unwrap();
                schemas.insert(header.id, id);
            }
            Record::Channel(c) if keep(&c.topic) => {
                let id = w
                    .add_channel(
                        schemas[&c.schema_id],
                        &c.topic,
                        &c.message_encoding,
                        &c.metadata,
                    )
                    .unwrap();
                channels.insert(c.id, (id, c.topic));
            }
            Record::Message { mut header, data } => {
                let Some((id, topic)) = channels.get(&header.channel_id) else {
                    continue;
                };
                if let Some((t, every)) = thin
                    && t == topic
                {
                    seen += 1;
                    if seen.is_multiple_of(every) {
                        continue;
                    }
                }
                header.channel_id = *id;
                let data = match replace {
                    Some((t, with)) if t == topic => with.to_vec().into(),
                    _ => data,
                };
                w.write_to_known_channel(&header, &data).unwrap();
            }
            Record::Metadata(mut m) => {
                if drop_counts && m.name == "testbed.log_stats" {
                    m.metadata.retain(|k, _| {
                        let name = k.rsplit_once('.').map_or(k.as_str(), |(n, _)| n);
                        keep(&format!("/{name}"))
                    });
                }
                w.write_metadata(&m).unwrap();
            }
            Record::Attachment { header, data, .. } => w
                .attach(&mcap::Attachment {
                    log_time: header.log_time,
                    create_time: header.create_time,
                    name: header.name,
                    media_type: header.media_type,
                    data,
                })
                .unwrap(),
            _ => {}
        }
    }
    w.finish().unwrap();
}

/// `replay ARGS LOG`: its exit code, its JSON summary (if it printed
/// one) and its stderr.
fn replay(args: &[&str], log: &Path) -> (Option<i32>, Option<serde_json::Value>, String) {
    let out = testbed()
        .arg("replay")
        .args(args)
        .arg(log)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!err.contains("panicked"), "{err}");
    (
        out.status.code(),
        serde_json::from_slice(&out.stdout).ok(),
        err,
    )
}

/// Item 1 (D2): a log rewritten without /timing, without /command, or
/// with only the states and diagnostics (so its rows are all complete)
/// replays `invalid` with exit 4, naming the topics, with and without
/// `--verify`; so does a log holding fewer messages than the logger
/// received. The rewrite itself, keeping everything, stays clean.
#[test]
fn a_log_without_whole_topics_replays_invalid() {
    let dir = tempfile::tempdir().unwrap();
    let log = lockstep_log(dir.path());
    let copy = dir.path().join("copy.mcap");
    rewrite(&log, &copy, &|_| true, true, None, true, None);
    let (code, s, err) = replay(&["--json", "--verify"], &copy);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(s.unwrap()["timing"]["verdict"], "clean");

    let only_rows = ["/joint_state", "/controller/diagnostics"];
    // What the rewrite keeps, and the topics then missing.
    type Case<'a> = (&'a dyn Fn(&str) -> bool, &'a [&'a str]);
    let cases: [Case<'_>; 3] = [
        (&|t| t != "/timing", &["/timing"]),
        (&|t| t != "/command", &["/command"]),
        (
            &|t| only_rows.contains(&t),
            &["/reference", "/command", "/timing"],
        ),
    ];
    for (keep, missing) in cases {
        let cut = dir.path().join("cut.mcap");
        rewrite(&log, &cut, keep, true, None, true, None);
        for args in [&["--json"][..], &["--json", "--verify"]] {
            let (code, s, err) = replay(args, &cut);
            assert_ne!(code, Some(0), "{missing:?} {args:?}: {err}");
            let said = match s {
                Some(s) => {
                    assert_eq!(s["timing"]["verdict"], "invalid", "{s}");
                    assert_eq!(code, Some(4), "{err}");
                    s["timing"]["reasons"].to_string()
                }
                // --verify without /command has nothing to re-drive.
                None => err,
            };
            assert!(said.contains("the log is not the whole run"), "{said}");
            for topic in missing {
                assert!(said.contains(topic), "{topic} not named: {said}");
            }
        }
    }
    // Every 7th /timing message gone, the logger's counts kept.
    let thin = dir.path().join("thin.mcap");
    rewrite(
        &log,
        &thin,
        &|_| true,
        false,
        Some(("/timing", 7)),
        true,
        None,
    );
    let (code, s, err) = replay(&["--json"], &thin);
    assert_eq!(code, Some(4), "{err}");
    let reasons = s.unwrap()["timing"]["reasons"].to_string();
    assert!(
        reasons.contains("/timing messages where the logger received 300"),
        "{reasons}"
    );
}

/// #60 item 8: a malformed message on a topic no step is read from
/// (`/robot_description`) is skipped and named, every step recovered; a
/// log whose last byte is cut, or whose closing magic was changed, says
/// so. Each is `degraded` (exit 3), never clean and never a lost log.
#[test]
fn damage_no_step_depends_on_is_named_and_the_steps_kept() {
    let dir = tempfile::tempdir().unwrap();
    let log = lockstep_log(dir.path());
    let bad = dir.path().join("bad.mcap");
    let garbage: &[u8] = b"\x07garbag";
    rewrite(
        &log,
        &bad,
        &|_| true,
        true,
        None,
        true,
        Some(("/robot_description", garbage)),
    );
    let bytes = std::fs::read(&log).unwrap();
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() - 1]).unwrap();
    let mut changed = bytes.clone();
    *changed.last_mut().unwrap() ^= 0xff;
    let magic = dir.path().join("magic.mcap");
    std::fs::write(&magic, &changed).unwrap();
    for (file, said) in [
        (&bad, "1 /robot_description message(s) skipped: malformed"),
        (&cut, "the file is cut"),
        (&magic, "the closing magic after the footer is wrong"),
    ] {
        let (code, s, err) = replay(&["--json", "--verify"], file);
        let s = s.unwrap_or_else(|| panic!("{}: no summary: {err}", file.display()));
        assert_eq!(s["timing"]["verdict"], "degraded", "{s}");
        assert_eq!(code, Some(3), "{err}");
        assert_eq!(s["missing_rows"], 0, "{s}");
        let reasons = s["timing"]["reasons"].to_string();
        assert!(reasons.contains(said), "{said}: {reasons}");
    }
}

/// Item 1: a data section whose checksum is 0 (MCAP's "not computed", as
/// Python's mcap writer leaves it) does not turn the integrity check off:
/// the log is said to be one that cannot be checked, never clean.
#[test]
fn a_log_without_a_data_checksum_cannot_be_checked() {
    let dir = tempfile::tempdir().unwrap();
    let log = lockstep_log(dir.path());
    let copy = dir.path().join("no-crc.mcap");
    rewrite(&log, &copy, &|_| true, false, None, false, None);
    let (code, s, err) = replay(&["--json"], &copy);
    assert_eq!(code, Some(4), "{err}");
    let s = s.unwrap();
    assert_eq!(s["timing"]["verdict"], "invalid", "{s}");
    let reasons = s["timing"]["reasons"].to_string();
    assert!(
        reasons.contains("the log cannot be checked") && reasons.contains("checksum is 0"),
        "{reasons}"
    );
    assert!(err.contains("verdict is invalid (exit status 4)"), "{err}");
}

/// Copies the MCAP log `from` to `to` with every message of `topic`
/// written after all the others, as a tool that writes one channel at a
/// time would: the log is whole, only its order changes.
fn rewrite_with_topic_last(from: &Path, to: &Path, topic: &str) {
    let bytes = std::fs::read(from).unwrap();
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .create(std::io::BufWriter::new(std::fs::File::create(to).unwrap()))
        .unwrap();
    let (mut schemas, mut channels) = (BTreeMap::new(), BTreeMap::new());
    let mut held = Vec::new();
    let mut metadata = Vec::new();
    for record in mcap::read::ChunkFlattener::new(&bytes).unwrap() {
        match record.unwrap() {
            Record::Schema { header, data } => {
                let id = w.add_schema(&header.name, &header.encoding, &data).unwrap();
                schemas.insert(header.id, id);
            }
            Record::Channel(c) => {
                let id = w
                    .add_channel(
                        schemas[&c.schema_id],
                        &c.topic,
                        &c.message_encoding,
                        &c.metadata,
                    )
                    .unwrap();
                channels.insert(c.id, (id, c.topic));
            }
            Record::Message { mut header, data } => {
                let (id, t) = &channels[&header.channel_id];
                header.channel_id = *id;
                if t == topic {
                    held.push((header, data.into_owned()));
                } else {
                    w.write_to_known_channel(&header, &data).unwrap();
                }
            }
            // The logger's counts come last, as the logger writes them.
            Record::Metadata(m) if m.name == "testbed.log_stats" => metadata.push(m),
            Record::Metadata(m) => w.write_metadata(&m).unwrap(),
            Record::Attachment { header, data, .. } => w
                .attach(&mcap::Attachment {
                    log_time: header.log_time,
                    create_time: header.create_time,
                    name: header.name,
                    media_type: header.media_type,
                    data,
                })
                .unwrap(),
            _ => {}
        }
    }
    assert!(!held.is_empty(), "no {topic} messages");
    for (header, data) in held {
        w.write_to_known_channel(&header, &data).unwrap();
    }
    for m in metadata {
        w.write_metadata(&m).unwrap();
    }
    w.finish().unwrap();
}

/// Item 15 (N11): a whole log whose diagnostics all come after the other
/// channels (more steps than the reader holds at once) never replays
/// "rows lost": the rows are in the file, so replay says the log is out
/// of order beyond its bound, and the row count lost is 0.
#[test]
fn a_log_out_of_order_beyond_the_bound_loses_no_rows() {
    let dir = tempfile::tempdir().unwrap();
    // More steps than the reader's bound of 16 384 rows.
    let out = crate::util::ok(
        testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--duration",
                "17",
                "--json",
                "--runs-dir",
            ])
            .arg(dir.path()),
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let log = Path::new(v["log"].as_str().unwrap());
    let late = dir.path().join("diagnostics-last.mcap");
    rewrite_with_topic_last(log, &late, "/controller/diagnostics");
    let (code, s, err) = replay(&["--json"], &late);
    let s = s.unwrap_or_else(|| panic!("no summary: {err}"));
    let reasons = s["timing"]["reasons"].to_string();
    assert!(!reasons.contains("rows lost"), "{reasons}");
    assert_eq!(s["missing_rows"], 0, "{reasons}");
    assert!(
        reasons.contains("out of order beyond the reader's bound"),
        "{reasons}"
    );
    // Not every row was read, so the figures are not the whole run's.
    assert_eq!(code, Some(4), "{err}");
}
