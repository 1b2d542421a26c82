//! The node's own command line, run as the launcher runs it. (Having a test
//! of its own is also what makes `cargo nextest run --workspace` build the
//! binary that the system tests in tests/system run.)

#![allow(clippy::unwrap_used, reason = "test code")]

use std::process::Command;

fn node() -> Command {
    Command::new(env!("CARGO_BIN_EXE_testbed-policy"))
}

#[test]
fn no_policy_file_is_named_and_fails() {
    let out = node().output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no policy file: testbed-policy FILE.onnx"),
        "{err}"
    );
}

#[test]
fn a_missing_policy_is_named_by_path() {
    let out = node()
        .args(["no/such/policy.onnx", "--describe"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no/such/policy.onnx"), "{err}");
}

#[test]
fn help_exits_0_with_the_usage() {
    let out = node().arg("--help").output().unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("usage: testbed-policy FILE.onnx"));
}
