//! The run log (MCAP) and `testbed replay`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::util::{assert_same_csv, fails, json, ok, testbed};

/// Runs a lockstep run of `duration` seconds; returns its JSON and log path.
fn lockstep_run(dir: &Path, duration: &str) -> (serde_json::Value, PathBuf) {
    let out = ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            duration,
            "--json",
            "--runs-dir",
        ])
        .arg(dir));
    let s = json(&out);
    let log = PathBuf::from(s["log"].as_str().expect("run JSON has log"));
    (s, log)
}

/// The log, read with the official MCAP library: header (the `ros2`
/// profile), footer, summary with statistics; every channel CDR with a
/// `ros2msg` schema; every testbed message decodes, its log time its sim
/// time (the header's stamp) and its publish time its wall stamp; one
/// message per step on each step topic.
#[test]
fn log_is_complete_ros2_mcap_whose_messages_decode() {
    let dir = tempfile::tempdir().unwrap();
    let (run, log) = lockstep_run(dir.path(), "0.5");
    let buf = std::fs::read(&log).unwrap();
    assert!(buf.starts_with(mcap::MAGIC) && buf.ends_with(mcap::MAGIC));
    mcap::read::footer(&buf).unwrap();
    let summary = mcap::Summary::read(&buf).unwrap().expect("summary section");
    let stats = summary.stats.as_ref().expect("statistics");
    let mut counts: BTreeMap<String, u64> = BTreeMap::new();
    for (id, ch) in &summary.channels {
        let n = stats.channel_message_counts.get(id).copied().unwrap_or(0);
        counts.insert(ch.topic.clone(), n);
        let schema = ch.schema.as_ref().expect("every channel has a schema");
        assert_eq!(schema.encoding, "ros2msg");
        assert_eq!(ch.message_encoding, "cdr");
        assert!(schema.name.contains("/msg/"), "{}", schema.name);
    }
    let steps = run["steps"].as_u64().unwrap();
    assert_eq!(steps, 500);
    assert_eq!(counts["/joint_state"], steps + 1, "{counts:?}"); // states 0..=steps
    assert_eq!(counts["/command"], steps, "{counts:?}");
    assert_eq!(counts["/controller/diagnostics"], steps, "{counts:?}");
    assert_eq!(counts["/timing"], steps, "{counts:?}");
    assert_eq!(counts["/reference"], steps + 1, "{counts:?}");
    // The standard views and the arm's frames at 50 Hz of sim time
    // (states at 0, 20, …, 500 ms), its figure once a second.
    assert_eq!(counts["/joint_states"], 26, "{counts:?}");
    assert_eq!(counts["/joint_commands"], 25, "{counts:?}");
    assert_eq!(counts["/tf"], 26, "{counts:?}");
    assert_eq!(counts["/arm/scene"], 1, "{counts:?}");

    let mut seen = 0;
    for msg in mcap::MessageStream::new(&buf).unwrap() {
        let msg = msg.unwrap();
        let enc = logger::Encoding::Cdr;
        // Each message read by the schema its channel stores.
        let stored = msg.channel.schema.as_ref().expect("a schema");
        let schema = logger::msg_schema::MsgSchema::parse(&stored.name, &stored.data).ok();
        let raw = logger::RawMessage {
            topic: &msg.channel.topic,
            encoding: enc,
            schema: schema
                .as_ref()
                .filter(|_| stored.name.starts_with("testbed_msgs/")),
            data: &msg.data,
        };
        let header = match logger::decode_logged(&raw) {
            Ok(Some(m)) => Ok(*m.header()),
            Ok(None) => {
                logger::check_message(enc, &msg.data).unwrap();
                seen += 1;
                continue;
            }
            Err(e) => Err(e),
        };
        let header =
            header.unwrap_or_else(|e| panic!("{} {}: {e}", msg.channel.topic, msg.sequence));
        assert_eq!(msg.log_time, header.t_ns);
        assert_eq!(msg.publish_time, header.wall_ns);
        seen += 1;
    }
    assert_eq!(seen, counts.values().sum::<u64>());
    // Metadata and attachment.
    let meta: Vec<_> = summary
        .metadata_indexes
        .iter()
        .map(|m| m.name.clone())
        .collect();
    assert!(
        meta.contains(&"testbed.run".to_string())
            && meta.contains(&"testbed.log_stats".to_string())
    );
    let run_meta = summary
        .metadata_indexes
        .iter()
        .find(|m| m.name == "testbed.run")
        .map(|idx| mcap::read::metadata(&buf, idx).unwrap())
        .unwrap();
    for k in [
        "scenario_toml",
        "run_id",
        "mode",
        "rate_hz",
        "software",
        "start_time_unix_ns",
    ] {
        assert!(run_meta.metadata.contains_key(k), "testbed.run lacks {k}");
    }
    assert_eq!(run_meta.metadata["mode"], "lockstep");
    assert!(run_meta.metadata["scenario_toml"].contains("[controller]"));
    let urdf = summary
        .attachment_indexes
        .iter()
        .find(|a| a.name == "robot.urdf")
        .expect("URDF attached");
    let att = mcap::read::attachment(&buf, urdf).unwrap();
    assert!(String::from_utf8_lossy(&att.data).contains("<robot name=\"two_link\">"));
}

/// `--log-compression lz4` and `none` write logs the official reader
/// reads, with chunks compressed as asked, holding the same messages as
/// the default zstd log of the same (deterministic) run.
#[test]
fn logs_of_every_compression_hold_the_same_messages() {
    use logger::Decode;
    let enc = logger::Encoding::Cdr;
    let dir = tempfile::tempdir().unwrap();
    let messages = |compression: &str| {
        let out = ok(testbed()
            .args(["run", "--mode", "lockstep", "--duration", "0.3", "--json"])
            .args(["--log-compression", compression, "--runs-dir"])
            .arg(dir.path()));
        let log = PathBuf::from(json(&out)["log"].as_str().unwrap());
        let buf = std::fs::read(&log).unwrap();
        let summary = mcap::Summary::read(&buf).unwrap().unwrap();
        let kinds: std::collections::BTreeSet<String> = summary
            .chunk_indexes
            .iter()
            .map(|c| c.compression.clone())
            .collect();
        let mut all = Vec::new();
        for m in mcap::MessageStream::new(&buf).unwrap() {
            let m = m.unwrap();
            // Wall stamps and measured times differ from run to run; the
            // rest may not.
            let v = match m.channel.topic.as_str() {
                "/timing" => Vec::new(),
                "/joint_state" => {
                    let mut s = wire::JointState::decode_as(enc, &m.data).unwrap();
                    (s.header.wall_ns, s.applied_wall_ns) = (0, 0);
                    format!("{s:?}").into_bytes()
                }
                "/command" => {
                    let mut c = wire::Command::decode_as(enc, &m.data).unwrap();
                    c.header.wall_ns = 0;
                    (c.state_wall_ns, c.compute_ns, c.started_wall_ns) = (0, 0, 0);
                    format!("{c:?}").into_bytes()
                }
                "/controller/diagnostics" => {
                    let mut d = wire::ControllerDiagnostics::decode_as(enc, &m.data).unwrap();
                    (d.header.wall_ns, d.compute_ns) = (0, 0);
                    format!("{d:?}").into_bytes()
                }
                "/reference" => {
                    let mut r = wire::ReferenceSample::decode_as(enc, &m.data).unwrap();
                    r.header.wall_ns = 0;
                    format!("{r:?}").into_bytes()
                }
                _ => m.data.to_vec(),
            };
            all.push((m.channel.topic.clone(), m.log_time, v));
        }
        // The order across topics depends on when the logger drained.
        all.sort_by(|a, b| (&a.0, a.1).cmp(&(&b.0, b.1)));
        (kinds, all)
    };
    let (zstd_kinds, zstd) = messages("zstd");
    assert_eq!(zstd_kinds, ["zstd".to_string()].into());
    for (name, kind) in [("lz4", "lz4"), ("none", "")] {
        let (kinds, msgs) = messages(name);
        assert_eq!(kinds, [kind.to_string()].into(), "{name}");
        assert_eq!(msgs.len(), zstd.len(), "{name}");
        if let Some((a, b)) = msgs.iter().zip(&zstd).find(|(a, b)| a != b) {
            panic!("{name}: {a:?}\nzstd: {b:?}");
        }
    }
}

/// One analysis path: replaying the log prints what the run printed.
#[test]
fn replay_summary_equals_the_run_summary() {
    let dir = tempfile::tempdir().unwrap();
    let (mut run, log) = lockstep_run(dir.path(), "2.5");
    let mut replay = json(&ok(testbed().arg("replay").arg(&log).arg("--json")));
    run.as_object_mut().unwrap().remove("run_dir");
    assert_eq!(replay.as_object_mut().unwrap().remove("warning"), None);
    assert_eq!(run, replay);
    assert_eq!(run["timing"]["cycles"], 2500);
}

/// Re-driving the controller from a lockstep log gives the logged torques exactly.
#[test]
fn verify_is_exact_on_a_lockstep_log() {
    let dir = tempfile::tempdir().unwrap();
    let (_, log) = lockstep_run(dir.path(), "2.5");
    let s = json(&ok(testbed()
        .arg("replay")
        .arg(&log)
        .args(["--verify", "--json"])));
    assert_eq!(s["max_abs_torque_diff"], 0.0);
    assert_eq!(s["verified_steps"], 2500);
}

/// The replay CSV is the sim CSV, and the figures are written.
#[test]
fn replay_writes_csv_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let (_, log) = lockstep_run(dir.path(), "1");
    let (csv, sim_csv, plots) = (
        dir.path().join("r.csv"),
        dir.path().join("s.csv"),
        dir.path().join("plots"),
    );
    ok(testbed()
        .arg("replay")
        .arg(&log)
        .arg("--csv")
        .arg(&csv)
        .arg("--plots")
        .arg(&plots));
    ok(testbed()
        .args(["sim", "--duration", "1", "--csv"])
        .arg(&sim_csv));
    assert_same_csv(
        "replay vs sim",
        &std::fs::read(&csv).unwrap(),
        &std::fs::read(&sim_csv).unwrap(),
    );
    for fig in [
        "fig1_positions",
        "fig2_velocities",
        "fig3_errors",
        "fig4_actor_weights",
        "fig5_torques",
        "fig6_timing",
    ] {
        for ext in ["png", "svg"] {
            let f = plots.join(format!("{fig}.{ext}"));
            let len = std::fs::metadata(&f).map(|m| m.len()).unwrap_or(0);
            assert!(len > 5_000, "{} missing or empty", f.display());
        }
        assert!(
            std::fs::read(plots.join(format!("{fig}.png")))
                .unwrap()
                .starts_with(b"\x89PNG")
        );
    }
}

/// A log cut anywhere is read as far as it goes, with a warning saying how much.
#[test]
fn truncated_logs_are_analysed_as_far_as_they_go() {
    let dir = tempfile::tempdir().unwrap();
    let (_, log) = lockstep_run(dir.path(), "3");
    let full = std::fs::read(&log).unwrap();
    let mut last_steps = 0;
    for frac in [0.2, 0.45, 0.7, 0.9] {
        let cut = dir.path().join(format!("cut-{frac}.mcap"));
        std::fs::write(&cut, &full[..(full.len() as f64 * frac) as usize]).unwrap();
        let out = crate::util::replayed(testbed().arg("replay").arg(&cut).arg("--json"));
        let s = json(&out);
        let steps = s["steps"].as_u64().unwrap();
        // A cut loses its whole (compressed) chunk, and two cuts can fall in
        // the same chunk: more of the file never recovers fewer steps.
        assert!(steps >= last_steps && steps < 3000, "{frac}: {steps} steps");
        last_steps = steps;
        let warning = s["warning"].as_str().unwrap();
        assert!(
            warning.contains(&format!("recovered {steps} of 3000 steps")),
            "{warning}"
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("warning"), "{err}");
    }
    assert!(last_steps > 0, "no cut recovered any step");
    // Cut in the summary section: every step is there, but the file is
    // still reported as unfinished.
    let cut = dir.path().join("cut-summary.mcap");
    std::fs::write(&cut, &full[..full.len() - 40]).unwrap();
    let s = json(&crate::util::replayed(
        testbed().arg("replay").arg(&cut).arg("--json"),
    ));
    assert_eq!(s["steps"], 3000);
    assert!(
        s["warning"]
            .as_str()
            .unwrap()
            .contains("recovered 3000 of 3000 steps"),
        "{s}"
    );
}

#[test]
fn replay_of_a_non_log_fails_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.mcap");
    std::fs::write(&junk, "hello").unwrap();
    let err = fails(testbed().arg("replay").arg(&junk));
    assert!(
        err.contains("junk.mcap") && err.contains("not an MCAP file"),
        "{err}"
    );
    let err = fails(testbed().args(["replay", "nope.mcap"]));
    assert!(err.contains("nope.mcap"), "{err}");
    // Cut inside the first bytes: not even the metadata is there.
    let (_, log) = lockstep_run(dir.path(), "0.2");
    let head = dir.path().join("head.mcap");
    std::fs::write(&head, &std::fs::read(&log).unwrap()[..20]).unwrap();
    let err = fails(testbed().arg("replay").arg(&head));
    assert!(
        err.contains("head.mcap") && err.contains("testbed.run"),
        "{err}"
    );
}

/// Logs kept in the repository, one per log format (`log_format` in the
/// run's metadata): each still replays, exactly under `--verify`, and
/// all three, written from the same scenario, give the same figures. A format-1 log has no data-path stamps: its stale
/// references are unknown, never a made-up zero.
#[test]
fn golden_logs_of_every_format_still_replay() {
    let golden = crate::util::repo_root().join("tests/golden");
    let replay = |name: &str| {
        let log = golden.join(name);
        json(&ok(testbed()
            .args(["replay", "--json", "--verify"])
            .arg(&log)))
    };
    let v1 = replay("paper_lockstep_format1.mcap");
    let v2 = replay("paper_lockstep_format2.mcap");
    // Today's format (tests/golden/regenerate.sh writes it): a new format
    // needs its own golden log beside the old ones.
    assert_eq!(
        logger::LOG_FORMAT,
        3,
        "a new log format: write its golden log (bash tests/golden/regenerate.sh)"
    );
    let v3 = replay("paper_lockstep_format3.mcap");
    for s in [&v1, &v2, &v3] {
        assert_eq!(s["steps"], 200, "{s}");
        assert_eq!(s["run_end"], "finished");
        assert_eq!(s["missing_rows"], 0);
        assert_eq!(s["max_abs_torque_diff"], 0.0, "{s}");
        assert_eq!(s["timing"]["verdict"], "clean", "{s}");
    }
    for key in ["joints", "metrics", "finite", "fault_steps"] {
        assert_eq!(v1[key], v2[key], "{key}");
    }
    assert!(
        v1["timing"]["stale_references"].is_null(),
        "{}",
        v1["timing"]
    );
    assert!(v1["timing"].get("recount").is_none());
    assert_eq!(v2["timing"]["stale_references"], 0);
    assert_eq!(v2["timing"]["recount"]["deadline_misses"], 0);
    // Format 3 (CDR) from the same scenario: the same figures but for the
    // last bits of sums the law's arithmetic order has moved since.
    let close = |a: &serde_json::Value, b: &serde_json::Value| match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(1e-12),
        _ => a == b,
    };
    for (k, want) in v2["metrics"].as_object().unwrap() {
        assert!(
            close(want, &v3["metrics"][k]),
            "{k}: {want} vs {}",
            v3["metrics"][k]
        );
    }
    assert_eq!(v3["steps"], v2["steps"]);
    assert_eq!(v3["timing"]["recount"]["deadline_misses"], 0);
}

/// #31 row 6: a log file is read record by record (memory does not grow
/// with its length), and what that gives equals reading it whole, for the
/// whole file and for the file cut at points inside records.
#[test]
fn a_log_read_from_its_file_equals_the_log_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let (_, log) = lockstep_run(dir.path(), "3");
    let bytes = std::fs::read(&log).unwrap();
    for cut in [bytes.len(), bytes.len() - 7, bytes.len() * 2 / 3, 4096, 300] {
        let path = dir.path().join(format!("cut{cut}.mcap"));
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let (mut a, mut b) = (Vec::<String>::new(), Vec::<String>::new());
        let mut on_a = |m: &logger::RawMessage<'_>| {
            a.push(format!("{}:{}", m.topic, m.data.len()));
            Ok(())
        };
        let streamed = logger::read_log(&path, Some(&mut on_a));
        let mut on_b = |m: &logger::RawMessage<'_>| {
            b.push(format!("{}:{}", m.topic, m.data.len()));
            Ok(())
        };
        let whole = logger::read_log_bytes(&bytes[..cut], &path, Some(&mut on_b));
        match (streamed, whole) {
            (Ok(s), Ok(w)) => {
                assert_eq!(a, b, "cut at {cut}");
                assert_eq!(
                    (s.messages, s.complete, s.run, s.stats, s.urdf),
                    (w.messages, w.complete, w.run, w.stats, w.urdf),
                    "cut at {cut}"
                );
                assert_eq!(s.cut_short.is_some(), w.cut_short.is_some(), "cut at {cut}");
            }
            (Err(s), Err(w)) => assert_eq!(s.to_string(), w.to_string()),
            (s, w) => panic!("cut at {cut}: streamed {s:?}, whole {w:?}"),
        }
    }
}
