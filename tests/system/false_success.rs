//! Issue 48, "false success, wrong results, leaks": a log that is not the
//! whole run, or that cannot be checked, is never `clean`, and `replay`
//! exits as `run` does for its verdict.

use std::collections::BTreeMap;
use std::path::Path;

use mcap::records::Record;

use crate::util::{lockstep_log, testbed};

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

/// Item 16 (D19): a `--runs-dir` that is a file (`/dev/null`, a regular
/// file) is named as not a folder, not "File exists".
#[test]
fn a_runs_dir_that_is_a_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("runs");
    std::fs::write(&file, "a file").unwrap();
    for runs in [Path::new("/dev/null"), &file] {
        let e = crate::util::fails(
            testbed()
                .args([
                    "run",
                    "--mode",
                    "lockstep",
                    "--duration",
                    "0.1",
                    "--runs-dir",
                ])
                .arg(runs),
        );
        assert!(
            e.contains(&runs.display().to_string())
                && e.contains("not a folder")
                && !e.contains("File exists"),
            "{e}"
        );
    }
}

/// Item 16 (N14): `robot --write-scenario` never replaces an existing file
/// without `--force`, and never writes through a symbolic link, even with it.
#[test]
fn write_scenario_keeps_what_exists_and_follows_no_link() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = crate::util::repo_root().join("robots/two_link.urdf");
    let write = |out: &Path, force: bool| {
        let mut cmd = testbed();
        cmd.arg("robot").arg(&urdf).arg("--write-scenario").arg(out);
        if force {
            cmd.arg("--force");
        }
        cmd
    };
    let mine = dir.path().join("s.toml");
    std::fs::write(&mine, "# my edits\n").unwrap();
    let e = crate::util::fails(&mut write(&mine, false));
    assert!(e.contains("exists; --force replaces it"), "{e}");
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "# my edits\n");
    crate::util::ok(&mut write(&mine, true));
    let text = std::fs::read_to_string(&mine).unwrap();
    assert!(text.starts_with("# The default scenario"), "{text}");

    let victim = dir.path().join("victim.txt");
    std::fs::write(&victim, "victim\n").unwrap();
    let link = dir.path().join("link.toml");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    let dangling = dir.path().join("dangling.toml");
    let nowhere = dir.path().join("nowhere.toml");
    std::os::unix::fs::symlink(&nowhere, &dangling).unwrap();
    for (out, force) in [
        (&link, false),
        (&link, true),
        (&dangling, false),
        (&dangling, true),
    ] {
        let e = crate::util::fails(&mut write(out, force));
        assert!(e.contains("symbolic link"), "{e}");
    }
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "victim\n");
    assert!(!nowhere.exists());
    // A new file is written as before.
    let fresh = dir.path().join("fresh.toml");
    crate::util::ok(&mut write(&fresh, false));
    assert!(fresh.is_file());
}

/// Item 13 (D15): two rows of one name (`--laws pd,pd`, one label given
/// to two `--controller-cmd`s, a label that is a default row's law) are
/// refused by name before any run, not shown as two rows no reader can
/// tell apart.
#[test]
fn compare_refuses_two_rows_of_one_name() {
    let ext = format!("ext={}", env!("CARGO_BIN_EXE_example-pd-controller"));
    let nac = format!("nac={}", env!("CARGO_BIN_EXE_example-pd-controller"));
    let compare = || {
        let mut cmd = testbed();
        cmd.args(["compare", "--duration", "0.1", "--seeds", "1", "--json"]);
        cmd
    };
    let e = crate::util::fails(compare().args(["--laws", "pd,pd"]));
    assert!(e.contains("--laws names pd twice"), "{e}");
    let e = crate::util::fails(compare().args([
        "--laws",
        "pd",
        "--controller-cmd",
        &ext,
        "--controller-cmd",
        &ext,
    ]));
    assert!(e.contains("--controller-cmd ext=… is given twice"), "{e}");
    let e = crate::util::fails(compare().args(["--controller-cmd", &nac]));
    assert!(e.contains("nac is a built-in law's name"), "{e}");
}

/// Item 16: a user's controller (a policy) that raises fails its row
/// with one line, the exception, not the traceback with its file paths,
/// which stay in the run's nodes/controller.log.
#[test]
fn a_failing_policys_traceback_stays_out_of_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("policy.sh");
    std::fs::write(
        &script,
        "case \"$1\" in --describe) exit 1;; esac\n\
         printf 'Traceback (most recent call last):\\n' >&2\n\
         printf '  File \"/home/me/secret/policy.py\", line 3, in <module>\\n' >&2\n\
         printf 'ValueError: bad weights\\n' >&2\n\
         exit 1\n",
    )
    .unwrap();
    let cmd = format!("pol=sh {}", script.display());
    let out = testbed()
        .args([
            "compare",
            "--duration",
            "0.1",
            "--seeds",
            "1",
            "--laws",
            "pd",
        ])
        .args(["--json", "--controller-cmd", &cmd, "--runs-dir"])
        .arg(dir.path())
        .output()
        .unwrap();
    let c = crate::util::json(&out);
    let row = c["laws"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "pol")
        .unwrap_or_else(|| panic!("no row pol: {c}"));
    let why = row["runs"][0]["failed"].as_str().unwrap_or_default();
    assert!(why.contains("ValueError: bad weights"), "{why}");
    assert!(
        !why.contains("/home/me/secret") && !why.contains("Traceback") && !why.contains('\n'),
        "{why}"
    );
    // The whole text is in the node's log.
    let logs: Vec<String> = walk(dir.path())
        .into_iter()
        .filter(|p| p.ends_with("nodes/controller.log"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    assert!(
        logs.iter().any(|l| l.contains("/home/me/secret/policy.py")),
        "{logs:?}"
    );
}

/// Every file under `dir`.
fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
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
