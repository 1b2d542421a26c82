//! The example node's command line, as an outside author would first try
//! it. (Having a test of its own is also what makes `cargo nextest run
//! --workspace` build the binary that the system tests in tests/system run.)

#![allow(clippy::unwrap_used, reason = "test code")]

use std::process::Command;

fn node() -> Command {
    Command::new(env!("CARGO_BIN_EXE_example-pd-controller"))
}

#[test]
fn describe_declares_the_law_and_its_parameters() {
    let out = node().arg("--describe").output().unwrap();
    assert!(out.status.success());
    let d: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(d["name"], "pd-example", "{d}");
    assert!(
        d["params"]["kp"].is_number() && d["params"]["kd"].is_number(),
        "{d}"
    );
}

#[test]
fn started_without_the_launchers_arguments_it_names_the_first_missing() {
    let out = node().output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("missing --prefix"), "{err}");
}
