//! Rows of the hardening issue (#18) fixed so far: each input gets a named
//! error before anything runs, or runs as documented.

use std::process::Command;

use crate::util::{fails, lockstep_log as a_log, ok, testbed};

fn scenario(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Row 3 and the neurons part of row 4: no panic, no huge allocation.
#[test]
fn a_huge_network_is_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    for n in ["18446744073709551615", "1000000000", "1001"] {
        let f = scenario(
            dir.path(),
            "n.toml",
            &format!("[controller]\nneurons = {n}\n"),
        );
        let e = fails(testbed().arg("sim").arg("--scenario").arg(&f));
        assert!(
            e.contains(&format!("controller.neurons = {n} is invalid")),
            "{e}"
        );
        let out = testbed()
            .arg("sim")
            .arg("--scenario")
            .arg(&f)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{n}");
    }
}

/// Row 7: every key is optional, in a partial table too.
#[test]
fn partial_reference_and_envelope_tables_take_the_papers_values() {
    let dir = tempfile::tempdir().unwrap();
    for text in [
        "[reference]\nrate_hz = 500.0\n",
        "[envelope]\n",
        "[envelope]\nfrom_limits = false\n",
    ] {
        let f = scenario(dir.path(), "p.toml", text);
        ok(testbed()
            .args(["sim", "--duration", "0.2", "--scenario"])
            .arg(&f));
    }
}

/// Row 12: a duration shorter than one period is refused, not run as 0 steps.
#[test]
fn a_run_of_no_steps_is_refused() {
    let e = fails(testbed().args(["sim", "--duration", "1e-9"]));
    assert!(
        e.contains("duration_s = 0.000000001 is invalid: it must be at least one control period"),
        "{e}"
    );
    let e = fails(testbed().args(["run", "--mode", "lockstep", "--duration", "1e-9"]));
    assert!(e.contains("duration_s"), "{e}");
}

/// Row 10: an unwritable CSV fails `run` before any node starts.
#[test]
fn run_refuses_an_unwritable_csv_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let e = fails(
        testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--csv",
                "/proc/x.csv",
                "--runs-dir",
            ])
            .arg(dir.path()),
    );
    assert!(e.contains("/proc/x.csv"), "{e}");
    // Nothing was started: no run folder.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Row 8: a prismatic joint without `<limit>` and a negative effort are
/// named, with the file and the joint.
#[test]
fn prismatic_without_limit_and_negative_effort_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = |limit: &str| {
        format!(
            r#"<robot name="p"><link name="base"/><link name="a"><inertial><mass value="1"/>
<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
<joint name="j1" type="prismatic"><parent link="base"/><child link="a"/><axis xyz="1 0 0"/>{limit}</joint></robot>"#
        )
    };
    let cases = [
        ("", "joint 'j1' <limit> = lower = upper = 0 is invalid"),
        (
            r#"<limit lower="-1" upper="1" effort="-5" velocity="1"/>"#,
            "joint 'j1' limit effort = -5 is invalid",
        ),
    ];
    for (limit, want) in cases {
        let f = scenario(dir.path(), "p.urdf", &urdf(limit));
        for cmd in [vec!["robot"], vec!["sim", "--robot"]] {
            let e = fails(testbed().args(&cmd).arg(&f));
            assert!(e.contains("p.urdf") && e.contains(want), "{cmd:?}: {e}");
        }
    }
    let f = scenario(
        dir.path(),
        "ok.urdf",
        &urdf(r#"<limit lower="-0.5" upper="0.5" effort="50" velocity="1"/>"#),
    );
    ok(testbed()
        .args(["sim", "--duration", "0.2", "--robot"])
        .arg(&f));
}

/// Row 4, files: a device or a FIFO is refused at once, never read or waited on.
#[test]
fn special_files_are_refused_without_reading_them() {
    let dir = tempfile::tempdir().unwrap();
    let robot = scenario(dir.path(), "zero.toml", "robot = \"/dev/zero\"\n");
    let fifo = dir.path().join("fifo");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let cases: Vec<Vec<std::ffi::OsString>> = vec![
        vec!["sim".into(), "--scenario".into(), "/dev/zero".into()],
        vec!["sim".into(), "--scenario".into(), robot.into()],
        vec!["sim".into(), "--robot".into(), "/dev/zero".into()],
        vec!["replay".into(), "/dev/zero".into()],
        vec!["replay".into(), fifo.clone().into()],
    ];
    for args in cases {
        let e = fails(testbed().args(&args));
        assert!(e.contains("not a regular file"), "{args:?}: {e}");
    }
}

/// Rows 3 and 4, logs: a Header claiming u64::MAX bytes and a chunk asking
/// for 4.28 GB are named, never a panic or a huge allocation.
#[test]
fn damaged_record_lengths_in_a_log_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let log = a_log(dir.path());
    let good = std::fs::read(&log).unwrap();
    // The Header record: opcode at byte 8, its length at 9..17.
    let mut bad = good.clone();
    bad[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
    let f = dir.path().join("header.mcap");
    std::fs::write(&f, &bad).unwrap();
    let out = testbed().arg("replay").arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("header.mcap") && e.contains("testbed.run metadata"),
        "{e}"
    );
    // The first chunk's uncompressed size: walk the records to it.
    let mut at = 8;
    while good[at] != 0x06 {
        at += 9 + u64::from_le_bytes(good[at + 1..at + 9].try_into().unwrap()) as usize;
    }
    let mut bad = good.clone();
    bad[at + 9 + 16..at + 9 + 24].copy_from_slice(&4_280_000_000u64.to_le_bytes());
    let f = dir.path().join("chunk.mcap");
    std::fs::write(&f, &bad).unwrap();
    let out = testbed().arg("replay").arg(&f).output().unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    // Read as far as it goes (invalid, exit 4) or not at all (1).
    assert!(matches!(out.status.code(), Some(1 | 4)), "{e}");
    assert!(e.contains("4280000000 bytes uncompressed"), "{e}");
}

/// Row 5: a finished run's log says so and replays without a warning.
#[test]
fn a_finished_run_is_recorded_as_finished() {
    let dir = tempfile::tempdir().unwrap();
    let log = a_log(dir.path());
    let s: serde_json::Value =
        serde_json::from_slice(&ok(testbed().arg("replay").arg("--json").arg(&log)).stdout)
            .unwrap();
    assert!(s.get("warning").is_none(), "{s}");
    assert_eq!(s["run_end"], "finished");
    let text = std::fs::read(&log).unwrap();
    let needle = b"run_end";
    assert!(text.windows(needle.len()).any(|w| w == needle));
}

/// Row 9: a value that would overflow the run is refused up front, shortly.
#[test]
fn an_overflowing_setting_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    for (table, key) in [
        ("plant.sensor", "q_noise_std"),
        ("plant.disturbance", "noise_std"),
    ] {
        let f = scenario(
            dir.path(),
            "big.toml",
            &format!("[{table}]\n{key} = 1e308\n"),
        );
        let e = fails(testbed().arg("sim").arg("--scenario").arg(&f));
        assert!(
            e.contains(&format!(
                "{table}.{key} = 1e308 is invalid: it must be a number from 0 to 1e9"
            )),
            "{e}"
        );
    }
}

/// Row 12: control characters in the name never reach the terminal.
#[test]
fn a_name_with_escape_codes_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let f = scenario(dir.path(), "ansi.toml", "name = \"a\\u001b[31mred\"\n");
    let e = fails(testbed().arg("sim").arg("--scenario").arg(&f));
    assert!(
        e.contains("name = \"a\\u{1b}[31mred\" is invalid") && !e.contains('\u{1b}'),
        "{e}"
    );
}

/// Row 13: a URDF the size of a scene is refused at once, in a short message.
#[test]
fn a_urdf_of_thousands_of_links_is_refused_quickly() {
    let dir = tempfile::tempdir().unwrap();
    let links: String = (0..5000)
        .map(|i| format!("<link name=\"l{i}\"/>"))
        .collect();
    let f = scenario(
        dir.path(),
        "scene.urdf",
        &format!("<robot name=\"s\">{links}</robot>"),
    );
    let e = fails(testbed().arg("robot").arg(&f));
    assert!(
        e.contains("5000 links, 0 joints is invalid: it must be at most 1000"),
        "{e}"
    );
    assert!(e.len() < 500, "{} bytes of error", e.len());
}
