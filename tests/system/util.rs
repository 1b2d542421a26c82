//! Running the `testbed` binary from tests.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The built `testbed` binary.
pub fn testbed() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_testbed"));
    c.current_dir(repo_root());
    c
}

/// The repository root (scenario and robot paths in tests are relative to it).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs and returns the output, failing the test with stderr if it did not exit 0.
pub fn ok(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("spawn testbed");
    assert!(
        out.status.success(),
        "{cmd:?} exited {:?}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs, expects a non-zero exit, and returns stderr.
pub fn fails(cmd: &mut Command) -> String {
    let out = cmd.output().expect("spawn testbed");
    assert!(!out.status.success(), "{cmd:?} should have failed");
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!err.contains("panicked"), "{cmd:?} panicked:\n{err}");
    err
}

/// Parses stdout as JSON.
pub fn json(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}
