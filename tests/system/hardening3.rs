//! Hardening, round 3 (#31): one reproducer per row that the round found.

use std::process::Stdio;

use crate::util::testbed;

/// Row 14: a closed pipe ends the command quietly (141, as SIGPIPE would);
/// a full device is a named error; neither panics.
#[test]
fn a_closed_pipe_and_a_full_device_are_not_panics() {
    // The reader is gone before the command starts: its write always
    // meets a closed pipe (closing it after the spawn raced the write).
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let child = testbed()
        .args(["sim", "--json", "--duration", "0.5"])
        .stdout(writer)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for args in [&["sim", "--duration", "0.2"][..], &["scenarios"][..]] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = testbed().args(args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("writing to standard output") && err.contains("No space"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// Row 16: `--live 127.0.0.1:0` says which port the system chose, on
/// stderr and in the run folder.
#[test]
fn a_live_view_on_port_0_says_its_port() {
    let dir = tempfile::tempdir().unwrap();
    let out = testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "0.2",
            "--live",
            "127.0.0.1:0",
        ])
        .arg("--runs-dir")
        .arg(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("live view at ws://127.0.0.1:"))
        .unwrap_or_else(|| panic!("{err}"));
    let port: u16 = line.rsplit(':').next().unwrap().trim().parse().unwrap();
    assert_ne!(port, 0, "{line}");
    let run = std::fs::read_dir(dir.path())
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let kept = std::fs::read_to_string(run.join("live-address.txt")).unwrap();
    assert_eq!(kept.trim(), format!("ws://127.0.0.1:{port}"));
}

/// Row 18: values pasted into `#SBATCH` lines are checked, not pasted: a
/// line break in `--partition` once injected shell lines.
#[test]
fn slurm_options_cannot_inject_lines() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("s.toml");
    std::fs::write(&sweep, "[set]\nduration_s = 0.01\n").unwrap();
    for (flag, value) in [
        ("--partition", "x\necho X"),
        ("--time", "1:00\n#SBATCH --x"),
    ] {
        let out = dir.path().join(flag.trim_start_matches('-'));
        let err = crate::util::fails(
            testbed()
                .args(["sweep", "slurm"])
                .arg(&sweep)
                .arg("--out")
                .arg(&out)
                .args([flag, value]),
        );
        assert!(err.contains(flag), "{err}");
        assert!(!out.join("sweep.sbatch").exists());
    }
}

/// Row 19: a node's config is checked like a scenario, and read only if it
/// is a regular file of a sane size.
#[test]
fn node_configs_are_checked_and_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("controller.json");
    std::fs::write(
        &config,
        r#"{"params": {}, "dof": 100, "period_ns": 1000000}"#,
    )
    .unwrap();
    let prefix = format!("cfgtest{}_", std::process::id());
    let node = |config: &std::path::Path| {
        crate::util::fails(
            testbed()
                .args([
                    "node",
                    "controller",
                    "--mode",
                    "lockstep",
                    "--prefix",
                    &prefix,
                    "--config",
                ])
                .arg(config),
        )
    };
    let err = node(&config);
    assert!(err.contains("dof") && err.contains("100 joints"), "{err}");
    let err = node(std::path::Path::new("/dev/zero"));
    assert!(
        err.contains("/dev/zero") && err.contains("not a regular file"),
        "{err}"
    );
    assert!(crate::util::shm_files(&prefix).is_empty());
}

/// Rows 8 and 9: a controller command that leaves a helper behind (which
/// holds its stderr open) and writes a line that is not UTF-8: the run
/// ends, the helper ends with it, and the launcher does not wait on the
/// stray pipe.
#[test]
fn a_controllers_helper_ends_with_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let marker = format!(
        "{}.{}",
        300 + std::process::id() % 600,
        std::process::id() % 97
    );
    let (status, err) = crate::util::run_with_controller_script(
        dir.path(),
        &format!("sleep {marker} &\nprintf 'bytes \\377\\376 not utf-8\\n' >&2"),
    );
    assert!(status.success(), "{err}");
    assert!(
        err.contains("[controller] bytes \u{fffd}\u{fffd} not utf-8"),
        "{err}"
    );
    let helpers = std::process::Command::new("pgrep")
        .args(["-f", &format!("sleep {marker}")])
        .output()
        .unwrap();
    assert!(helpers.stdout.is_empty(), "the helper outlived the run");
}

/// Row 13: a byte changed anywhere in a log either changes nothing or is
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

/// Row 20: `--verify` of a log with no complete step is refused, not
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

/// Row 20: no file of a run in /dev/shm is writable by other users
/// (iceoryx2 makes its global_mgmt file 0666).
#[test]
fn realtime_shared_memory_is_not_writable_by_others() {
    let dir = tempfile::tempdir().unwrap();
    let mut run = testbed()
        .args(["run", "--duration", "3", "--runs-dir"])
        .arg(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let prefix = format!("tbrun{:x}x", run.id());
    crate::run_cli::wait_until_running(dir.path());
    let files = crate::util::shm_files(&prefix);
    assert!(!files.is_empty());
    for f in &files {
        use std::os::unix::fs::PermissionsExt;
        // A file gone meanwhile (the run ended) has nothing to check.
        let mode = std::fs::metadata(format!("/dev/shm/{f}")).map_or(0, |m| m.permissions().mode());
        assert_eq!(mode & 0o022, 0, "{f}: {mode:o}");
    }
    let _ = crate::util::wait_bounded(&mut run, 60);
}

/// Row 20: runs that end before T_c say nothing about the constraint: the
/// sweep report calls them "not judged", not a 0 % success.
#[test]
fn runs_shorter_than_tc_are_not_judged() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("short.toml");
    std::fs::write(&file, "[set]\nduration_s = 0.5\n").unwrap();
    let out = dir.path().join("res");
    crate::util::ok(
        testbed()
            .args(["sweep", "run", "--no-progress", "--out"])
            .arg(&out)
            .arg(&file),
    );
    let text = crate::util::ok(testbed().args(["sweep", "report"]).arg(&out)).stdout;
    assert!(
        String::from_utf8_lossy(&text).contains("not judged"),
        "{}",
        String::from_utf8_lossy(&text)
    );
    let json = crate::util::ok(testbed().args(["sweep", "report", "--json"]).arg(&out)).stdout;
    let r: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert!(r["cells"][0]["success_rate"].is_null(), "{r}");
}

/// Row 15: a URDF of 50 000 nested elements (350 KB) is refused by name, not
/// a stack overflow.
#[test]
fn a_deeply_nested_urdf_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = dir.path().join("deep.urdf");
    let text = format!(
        "<robot name=\"deep\">{}{}</robot>",
        "<link name=\"a\">".repeat(50_000),
        "</link>".repeat(50_000)
    );
    std::fs::write(&urdf, text).unwrap();
    for args in [&["robot"][..], &["sim", "--robot"][..]] {
        let err = crate::util::fails(testbed().args(args).arg(&urdf));
        assert!(
            err.contains("deep.urdf") && err.contains("nested more than 100 deep"),
            "{err}"
        );
    }
}
