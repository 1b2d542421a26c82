//! Runs whose controller cannot give a result (#60 items 4 and 5): a
//! comparison in which every run of a law failed exits non-zero naming the
//! law, and a policy path that is a FIFO or a device is refused by name at
//! once, with nothing left running.

use std::process::Stdio;

use crate::util::{ended, fails, testbed};

#[test]
fn compare_fails_when_every_run_of_a_law_failed() {
    let err = fails(testbed().args([
        "compare",
        "--seeds",
        "2",
        "--duration",
        "0.2",
        "--laws",
        "nac",
        "--controller-cmd",
        "broken=/bin/false",
    ]));
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.contains("every run of broken failed"),
        "last line: {last}\n{err}"
    );
}

#[test]
fn a_policy_path_that_is_a_fifo_or_a_device_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("p.onnx");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    for path in [fifo.display().to_string(), "/dev/zero".to_string()] {
        let cmd = format!("{} {path}", env!("CARGO_BIN_EXE_testbed-policy"));
        let mut child = testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--duration",
                "0.2",
                "--runs-dir",
            ])
            .arg(dir.path().join("runs"))
            .args(["--controller-cmd", &cmd])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Ends by itself (a watchdog, not a sleep: it used to hang here).
        let (status, _, err) = ended(&mut child, 60);
        assert!(!status.success(), "{path}: {err}");
        assert!(err.contains("not a regular file"), "{path}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        // Nothing of it is left running.
        let left = std::process::Command::new("pgrep")
            .args(["-f", &format!("testbed-policy {path}")])
            .output()
            .unwrap();
        assert!(
            left.stdout.is_empty(),
            "left running: {}",
            String::from_utf8_lossy(&left.stdout)
        );
    }
}
