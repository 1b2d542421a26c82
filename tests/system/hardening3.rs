//! Hardening, round 3 (#31): one reproducer per row that the round found.

use std::process::Stdio;

use crate::util::testbed;

/// Row 14: a closed pipe ends the command quietly (141, as SIGPIPE would);
/// a full device is a named error; neither panics.
#[test]
fn a_closed_pipe_and_a_full_device_are_not_panics() {
    let mut child = testbed()
        .args(["sim", "--json", "--duration", "0.5"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The reader goes away before the summary is written.
    drop(child.stdout.take());
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
