//! The ROS 2 package shipped in `logger/msg/testbed_msgs/`: each `.msg` is
//! what the log's schema text says for its message (made from the wire's
//! field list), and its CMakeLists.txt builds each; both are made from the
//! wire's list of logged messages. `TESTBED_WRITE_MSG=1 cargo test -p
//! logger --test msg_files` rewrites them after a message changes.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::Path;

use logger::{LogMessage, ros2};

/// The package's files as the wire's logged messages make them: each
/// message's `.msg`, and the CMakeLists.txt that builds them all.
fn package() -> Vec<(String, String)> {
    fn msg<M: LogMessage>() -> (String, String) {
        // The schema in the log is this definition and the standard ones it uses.
        assert!(ros2::schema_text::<M>().starts_with(&ros2::msg_text::<M>()));
        (
            format!("msg/{}.msg", ros2::msg_name::<M>()),
            ros2::msg_text::<M>(),
        )
    }
    macro_rules! each {
        ($($ty:ident => $topic:ident, $channel:literal, $schema:literal;)*) => {
            vec![$(msg::<wire::$ty>(),)*]
        };
    }
    let mut files = wire::logged_messages!(each);
    let listed: String = files.iter().map(|(f, _)| format!("  \"{f}\"\n")).collect();
    files.push((
        "CMakeLists.txt".into(),
        format!(
            "cmake_minimum_required(VERSION 3.8)\nproject(testbed_msgs)\n\
             find_package(ament_cmake REQUIRED)\nfind_package(rosidl_default_generators REQUIRED)\n\
             find_package(std_msgs REQUIRED)\nrosidl_generate_interfaces(${{PROJECT_NAME}}\n\
             {listed}  DEPENDENCIES std_msgs\n)\nament_package()\n"
        ),
    ));
    files
}

/// #39 row 13: the shipped ROS 2 package (`logger/msg/testbed_msgs/`) is
/// the generated one: a `.msg` for every logged message, what the log's
/// schema says, each built by CMakeLists.txt, and no other `.msg`.
#[test]
fn the_shipped_package_is_the_generated_one() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("msg/testbed_msgs");
    let files = package();
    if std::env::var_os("TESTBED_WRITE_MSG").is_some() {
        std::fs::create_dir_all(root.join("msg")).unwrap();
        for (name, text) in &files {
            std::fs::write(root.join(name), text).unwrap();
        }
    }
    let stale: Vec<&str> = files
        .iter()
        .filter(|(name, text)| std::fs::read_to_string(root.join(name)).ok().as_ref() != Some(text))
        .map(|(name, _)| name.as_str())
        .collect();
    assert!(
        stale.is_empty(),
        "stale: {stale:?}; rewrite them: TESTBED_WRITE_MSG=1 cargo test -p logger --test msg_files"
    );
    let shipped = std::fs::read_dir(root.join("msg")).unwrap().count();
    assert_eq!(
        shipped,
        files.len() - 1,
        "a .msg file no logged message makes"
    );
    // Every testbed_msgs type a log's channels use is in the package.
    let prefix = format!("{}/msg/", ros2::PACKAGE);
    for spec in logger::channels() {
        if let Some(name) = spec.schema_name.strip_prefix(&prefix) {
            let file = format!("msg/{name}.msg");
            assert!(files.iter().any(|(f, _)| *f == file), "{file}");
        }
    }
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
        let want = ros2::qos_profiles(c.topic == ros2::ROBOT_DESCRIPTION_TOPIC);
        assert_eq!(qos, Some(want.as_str()), "{}", c.topic);
    }
}
