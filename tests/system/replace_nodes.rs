//! Replacing a node: a controller written outside the testbed
//! (`examples/pd_controller.rs`) and a trajectory that publishes another
//! reference, started by hand where `--external` says.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use crate::util::{testbed, wait_bounded};

/// Starts `testbed run … --external NODE`, waits for the command it prints,
/// and returns the child and that command's arguments (the caller waits
/// for the child; a panic here fails the test, and the run's node exits
/// when its launcher does).
#[allow(
    clippy::zombie_processes,
    reason = "the caller waits for the child it is handed"
)]
fn start_with_external(args: &[&str], node: &str) -> (std::process::Child, Vec<String>) {
    let mut child = testbed()
        .args(args)
        .args(["--external", node])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    // A watchdog, not a timing assertion: the line comes within seconds.
    let deadline = std::time::Instant::now() + Duration::from_secs(120);
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        let line = rx
            .recv_timeout(left)
            .expect("the launcher printed no command");
        let prefix = format!("testbed node {node} ");
        if let Some(rest) = line.trim().strip_prefix(&prefix) {
            let argv = rest.split_whitespace().map(String::from).collect();
            std::thread::spawn(move || for _ in rx {});
            return (child, argv);
        }
    }
}

fn value<'a>(argv: &'a [String], flag: &str) -> &'a str {
    let i = argv.iter().position(|a| a == flag).unwrap();
    &argv[i + 1]
}

fn finish(mut child: std::process::Child) -> serde_json::Value {
    let status = wait_bounded(&mut child, 240);
    let mut out = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take().unwrap(), &mut out).unwrap();
    // 3: degraded timing on a loaded machine, a whole run all the same.
    assert!(
        matches!(status.code(), Some(0 | 3)),
        "testbed run failed: {out}"
    );
    serde_json::from_str(&out).unwrap()
}

/// The example PD controller drives a lockstep run in place of the paper's.
#[test]
fn an_example_controller_replaces_the_controller_node() {
    let dir = tempfile::tempdir().unwrap();
    let (run, argv) = start_with_external(
        &[
            "run",
            "--mode",
            "lockstep",
            "--json",
            "--duration",
            "2",
            "--runs-dir",
        ]
        .map(String::from)
        .iter()
        .map(String::as_str)
        .chain([dir.path().to_str().unwrap()])
        .collect::<Vec<_>>(),
        "controller",
    );
    let mut pd = Command::new(crate::util::bin("example-pd-controller"))
        .args(&argv)
        .spawn()
        .unwrap();
    let s = finish(run);
    assert!(wait_bounded(&mut pd, 60).success());
    assert_eq!(s["steps"], 2000, "{s}");
    assert_eq!(s["finite"], true, "{s}");
    assert_eq!(s["fault_steps"], 0, "{s}");
    // The paper's law kicks joint 1 with −107 N m at t = 0; PD gives
    // −400·0.6 − 40·(0 − 2) = −160 N m.
    let tau = s["joints"][0]["max_abs_torque"].as_f64().unwrap();
    assert!(tau > 150.0, "{s}");
    // #39 row 15: the run does not pass the hand-started node off as the
    // scenario's law.
    assert_eq!(
        s["controller_cmd"], "a controller node started by hand (--external controller)",
        "{s}"
    );
}

/// A trajectory node publishing another reference (the paper's shifted by
/// 0.2 rad on joint 1) in lockstep and in real time: the run follows it.
#[test]
fn a_replacement_trajectory_is_followed_in_lockstep_and_real_time() {
    for mode in ["lockstep", "realtime"] {
        let dir = tempfile::tempdir().unwrap();
        let runs = dir.path().to_str().unwrap().to_string();
        let (run, argv) = start_with_external(
            &[
                "run",
                "--mode",
                mode,
                "--json",
                "--duration",
                "3",
                "--runs-dir",
                &runs,
            ],
            "trajectory",
        );
        let config = value(&argv, "--config").to_string();
        let mut c: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&config).unwrap()).unwrap();
        let offset = c["reference"]["joints"][0]["offset"].as_f64().unwrap();
        c["reference"]["joints"][0]["offset"] = (offset + 0.2).into();
        let other = dir.path().join("other-trajectory.json");
        std::fs::write(&other, c.to_string()).unwrap();
        let mut args = argv.clone();
        let i = args.iter().position(|a| a == "--config").unwrap();
        args[i + 1] = other.display().to_string();
        let mut traj = testbed()
            .arg("node")
            .arg("trajectory")
            .args(&args)
            .spawn()
            .unwrap();
        let s = finish(run);
        assert!(wait_bounded(&mut traj, 60).success());
        assert_eq!(s["constraint_satisfied_after_tc"], true, "{mode}: {s}");
        // The log's diagnostics hold the reference the controller used.
        let log = s["log"].as_str().unwrap();
        let csv = dir.path().join("r.csv");
        crate::util::replayed(testbed().args(["replay", log, "--csv"]).arg(&csv));
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut rows = text.lines();
        let header: Vec<&str> = rows.next().unwrap().split(',').collect();
        let col = header.iter().position(|h| *h == "qref0").unwrap();
        let first: Vec<&str> = rows.next().unwrap().split(',').collect();
        let qref0: f64 = first[col].parse().unwrap();
        assert!((qref0 - 0.2).abs() < 1e-12, "{mode}: q_d1(0) = {qref0}");
        let q_col = header.iter().position(|h| *h == "q0").unwrap();
        let last: Vec<&str> = text.lines().last().unwrap().split(',').collect();
        let (q, qr): (f64, f64) = (last[q_col].parse().unwrap(), last[col].parse().unwrap());
        assert!(
            (q - qr).abs() < 0.1,
            "{mode}: q {q} does not follow q_d {qr}"
        );
    }
}

/// An external node started with the other `--mode` fails the run at
/// START, saying why (#18 row 12), instead of running with faults.
#[test]
fn an_external_node_with_the_wrong_mode_fails_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let (mut run, mut argv) = start_with_external(
        &["run", "--mode", "lockstep", "--duration", "2", "--runs-dir"]
            .map(String::from)
            .iter()
            .map(String::as_str)
            .chain([dir.path().to_str().unwrap()])
            .collect::<Vec<_>>(),
        "controller",
    );
    let i = argv.iter().position(|a| a == "--mode").unwrap();
    argv[i + 1] = "realtime".into();
    let node = testbed()
        .args(["node", "controller"])
        .args(&argv)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&node.stderr);
    assert!(!node.status.success());
    assert!(
        said.contains("started with --mode realtime but the run is lockstep"),
        "{said}"
    );
    let status = wait_bounded(&mut run, 60);
    assert!(!status.success(), "the run went on");
}

/// #29: the Rust template is a law of its own under `--controller-cmd`:
/// it declares `pd-example` with `kp` and `kd`, the scenario sets `kp`,
/// and the summary names both; its own diagnostic `error_norm` = ‖q − q_d‖
/// is summed up there too.
#[test]
fn the_rust_template_declares_its_law_and_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("s.toml");
    std::fs::write(&s, "duration_s = 3.0\n[external]\nkp = 900\n").unwrap();
    let out = crate::util::ok(
        crate::util::testbed()
            .args(["run", "--mode", "lockstep", "--json", "--controller-cmd"])
            .arg(crate::util::bin("example-pd-controller"))
            .arg("--scenario")
            .arg(&s)
            .arg("--runs-dir")
            .arg(dir.path()),
    );
    let r = crate::util::json(&out);
    assert_eq!(r["controller_law"]["name"], "pd-example", "{r}");
    assert_eq!(r["controller_law"]["parameters"], "kd=40.0,kp=900", "{r}");
    let d = &r["controller_law"]["diagnostics"][0];
    assert_eq!(d["name"], "error_norm", "{r}");
    // The norm over the whole run is at least any joint's error after T_c.
    let max_abs = d["max_abs"][0].as_f64().unwrap();
    let largest = (r["joints"].as_array().unwrap().iter())
        .map(|j| j["max_abs_error_after_tc"].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(
        largest > 0.0 && largest <= max_abs && max_abs.is_finite(),
        "{r}"
    );
}
