//! The `testbed` command line's own answers. (Having a test of its own is
//! also what makes `cargo nextest run --workspace` build the binary that
//! the system tests in tests/system run.)

#![allow(clippy::unwrap_used, reason = "test code")]

use std::process::Command;

fn testbed() -> Command {
    Command::new(env!("CARGO_BIN_EXE_testbed"))
}

#[test]
fn version_is_the_packages() {
    let out = testbed().arg("--version").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains(env!("CARGO_PKG_VERSION")), "{text}");
}

#[test]
fn an_unknown_command_is_a_usage_error() {
    let out = testbed().arg("simm").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("simm"));
}
