//! The ROS 2 package shipped in `logger/msg/testbed_msgs/`: each `.msg` is
//! what the log's schema text says for its message (made from the wire's
//! field list). `TESTBED_WRITE_MSG=1 cargo test -p logger --test msg_files`
//! rewrites them after a message changes.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use logger::{LogMessage, ros2};
use wire::{
    Command, ContactState, ControllerDiagnostics, JointState, OwnDiagnostics, ReferenceSample,
    Timing,
};

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
    check::<OwnDiagnostics>(&mut stale);
    check::<ContactState>(&mut stale);
    assert!(
        stale.is_empty(),
        "stale: {stale:?}; rewrite them: TESTBED_WRITE_MSG=1 cargo test -p logger --test msg_files"
    );
}

/// #39 row 13: every testbed_msgs type a log's channels use has its `.msg`
/// file and is built by the package's CMakeLists.txt.
#[test]
fn the_package_has_every_logged_type() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("msg/testbed_msgs");
    let cmake = std::fs::read_to_string(root.join("CMakeLists.txt")).unwrap();
    let prefix = format!("{}/msg/", ros2::PACKAGE);
    let mut seen = 0;
    for spec in logger::channels() {
        let Some(name) = spec.schema_name.strip_prefix(&prefix) else {
            continue;
        };
        seen += 1;
        let file = format!("msg/{name}.msg");
        assert!(root.join(&file).is_file(), "{file} is missing");
        assert!(
            cmake.contains(&format!("\"{file}\"")),
            "CMakeLists.txt lacks {file}"
        );
    }
    assert_eq!(seen, 7);
}

/// #39 row 13: every channel carries the QoS profile rosbag2 writes.
#[test]
fn every_channel_offers_a_qos_profile() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let mut log =
        logger::LogWriter::create(&path, &logger::RunMetadata::default(), "<robot/>").unwrap();
    for spec in logger::channels() {
        log.add_channel_spec(&spec).unwrap();
    }
    log.finish(Default::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(summary.channels.len(), logger::channels().len());
    for c in summary.channels.values() {
        let qos = c.metadata.get("offered_qos_profiles").map(String::as_str);
        assert_eq!(qos, Some(ros2::OFFERED_QOS_PROFILES), "{}", c.topic);
    }
}
