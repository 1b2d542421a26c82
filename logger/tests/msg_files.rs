//! The ROS 2 package shipped in `logger/msg/testbed_msgs/`: each `.msg` is
//! what the log's schema text says for its message (made from the wire's
//! field list). `TESTBED_WRITE_MSG=1 cargo test -p logger --test msg_files`
//! rewrites them after a message changes.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use logger::{LogMessage, ros2};
use wire::{Command, ControllerDiagnostics, JointState, ReferenceSample, Timing};

fn check<M: LogMessage>(stale: &mut Vec<String>) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("msg/testbed_msgs/msg");
    let path = dir.join(format!("{}.msg", ros2::msg_name::<M>()));
    let want = ros2::msg_text::<M>();
    if std::env::var_os("TESTBED_WRITE_MSG").is_some() {
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(&path, &want).unwrap();
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    if have != want {
        stale.push(path.display().to_string());
    }
    // The schema in the log is this definition and the standard ones it uses.
    assert!(ros2::schema_text::<M>().starts_with(&want));
}

#[test]
fn the_shipped_msg_files_are_the_generated_ones() {
    let mut stale = Vec::new();
    check::<JointState>(&mut stale);
    check::<ReferenceSample>(&mut stale);
    check::<Command>(&mut stale);
    check::<ControllerDiagnostics>(&mut stale);
    check::<Timing>(&mut stale);
    assert!(
        stale.is_empty(),
        "stale: {stale:?}; rewrite them: TESTBED_WRITE_MSG=1 cargo test -p logger --test msg_files"
    );
}
