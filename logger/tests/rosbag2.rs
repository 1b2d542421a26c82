//! What ROS 2 (Jazzy's rosbag2 MCAP plugin) and Foxglove read from a log
//! besides the messages, read back with the `mcap` crate: the `rosbag2`
//! metadata record, each channel's offered QoS, and the robot model on its
//! latched `/robot_description` (#48 item 17).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;

use logger::{LogWriter, RunMetadata, ros2};

const URDF: &str = "<robot name=\"two\"><link name=\"base\"/></robot>";

/// A finished log of `states` joint states, its bytes.
fn log_of(states: u64) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let meta = RunMetadata {
        start_time_unix_ns: 1_700_000_000_000_000_000,
        ..RunMetadata::default()
    };
    let mut log = LogWriter::create(&path, &meta, URDF).unwrap();
    for spec in logger::channels() {
        log.add_channel_spec(&spec).unwrap();
    }
    for k in 0..states {
        let mut s = wire::JointState::default();
        s.header.seq = k;
        s.header.t_ns = (k + 1) * 1_000_000;
        s.dof = 2;
        log.write(&s).unwrap();
    }
    log.finish(BTreeMap::new()).unwrap();
    std::fs::read(&path).unwrap()
}

fn metadata(bytes: &[u8], name: &str) -> BTreeMap<String, String> {
    let summary = mcap::Summary::read(bytes).unwrap().unwrap();
    let index = summary
        .metadata_indexes
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no {name} metadata record"));
    mcap::read::metadata(bytes, index).unwrap().metadata
}

/// A top-level key's scalar in the block YAML the record holds.
fn scalar<'a>(yaml: &'a str, key: &str) -> &'a str {
    yaml.lines()
        .find_map(|l| l.strip_prefix(&format!("{key}: ")))
        .unwrap_or_else(|| panic!("no {key}: in\n{yaml}"))
}

/// The record Jazzy reads `BagMetadata` from: version 8 (numeric QoS, as
/// the channels hold it), every key its decoder asks for, the topics with
/// their counts and QoS, and the messages' span.
#[test]
fn the_log_has_the_rosbag2_record_jazzy_reads() {
    let bytes = log_of(5);
    let record = metadata(&bytes, ros2::ROSBAG2_METADATA);
    assert_eq!(record["ROS_DISTRO"], "jazzy");
    let yaml = &record["serialized_metadata"];
    // Every key Jazzy's YAML::convert<BagMetadata>::decode reads at version 8.
    for key in [
        "version",
        "storage_identifier",
        "duration",
        "starting_time",
        "message_count",
        "topics_with_message_count",
        "compression_format",
        "compression_mode",
        "relative_file_paths",
        "files",
        "custom_data",
        "ros_distro",
    ] {
        assert!(
            yaml.lines().any(|l| l.starts_with(&format!("{key}:"))),
            "{key} missing:\n{yaml}"
        );
    }
    assert_eq!(scalar(yaml, "version"), "8");
    assert_eq!(scalar(yaml, "storage_identifier"), "\"mcap\"");
    assert_eq!(scalar(yaml, "ros_distro"), "\"jazzy\"");
    // One robot description and five states.
    assert_eq!(scalar(yaml, "message_count"), "6");
    assert!(yaml.contains("  nanoseconds: 5000000\n"), "{yaml}");
    assert!(yaml.contains("  - \"run.mcap\"\n"), "{yaml}");
    // Each topic with its type and the QoS its channel offers, the text
    // quoted as one YAML (and JSON) string.
    let qos_lines: Vec<&str> = yaml
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("offered_qos_profiles: "))
        .collect();
    assert_eq!(qos_lines.len(), logger::channels().len(), "{yaml}");
    for q in qos_lines {
        let text: String = serde_json::from_str(q).unwrap();
        assert!(
            text == ros2::qos_profiles(false) || text == ros2::qos_profiles(true),
            "{text}"
        );
    }
    assert!(
        yaml.contains(
            "      name: \"/joint_state\"\n      type: \"testbed_msgs/msg/JointState\"\n"
        )
    );
    assert!(yaml.contains("\n    message_count: 5\n"), "{yaml}");
}

/// The channels' QoS is the numeric form the record's version 8 says
/// (Jazzy read it as version 9's words without the record: "unknown"),
/// and `/robot_description` is latched: transient local, keep last 1.
#[test]
fn each_channel_offers_its_qos_in_the_declared_form() {
    let bytes = log_of(1);
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    for c in summary.channels.values() {
        let qos = &c.metadata["offered_qos_profiles"];
        for key in ["history", "reliability", "durability", "liveliness"] {
            let value = qos
                .lines()
                .find_map(|l| {
                    l.trim_start_matches("- ")
                        .trim()
                        .strip_prefix(&format!("{key}: "))
                })
                .unwrap_or_else(|| panic!("{}: no {key}", c.topic));
            assert!(value.parse::<u8>().is_ok(), "{}: {key}: {value}", c.topic);
        }
        let latched = c.topic == ros2::ROBOT_DESCRIPTION_TOPIC;
        assert_eq!(qos.contains("durability: 1\n"), latched, "{}", c.topic);
    }
    assert!(
        summary
            .channels
            .values()
            .any(|c| c.topic == ros2::ROBOT_DESCRIPTION_TOPIC)
    );
}

/// The model is on `/robot_description` as a `std_msgs/msg/String`, once,
/// at the run's start, whatever the run then logs.
#[test]
fn the_robot_model_is_on_a_latched_topic() {
    let bytes = log_of(3);
    let stream = mcap::MessageStream::new(&bytes).unwrap();
    let mut found = Vec::new();
    for m in stream {
        let m = m.unwrap();
        if m.channel.topic == ros2::ROBOT_DESCRIPTION_TOPIC {
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(schema.name, ros2::STRING);
            assert_eq!(&schema.data[..], b"string data\n");
            let mut r = logger::cdr::CdrReader::new(&m.data).unwrap();
            found.push((m.log_time, r.string("data").unwrap().to_string()));
        }
    }
    assert_eq!(found, [(0, URDF.to_string())]);
    // The testbed's own reader takes the log as before.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("copy.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let contents = logger::read_log(&path, None).unwrap();
    assert_eq!(contents.urdf.as_deref(), Some(URDF));
}
