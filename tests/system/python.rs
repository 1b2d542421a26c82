//! Controllers written in Python (`python/`): the package's own tests, its
//! PD equal to the Rust `pd` law bit for bit, the numpy paper law against
//! the Rust law, a real-time run, and supervision of a Python node that
//! crashes, is killed or cannot start.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

use crate::util::{fails, json, ok, repo_root, shm_files, testbed};

/// The virtual environment's python, set up once (python/setup-venv.sh
/// installs the iceoryx2 wheel, numpy and the package; it locks against
/// the other test processes doing the same).
fn python() -> &'static str {
    static PYTHON: OnceLock<String> = OnceLock::new();
    PYTHON.get_or_init(|| crate::util::venv_python("python/setup-venv.sh"))
}

fn example(name: &str) -> String {
    format!("{} python/examples/{name}", python())
}

/// Every `tau{i}` column of two CSV files: the largest difference.
fn max_torque_difference(a: &Path, b: &Path) -> f64 {
    let read = |p: &Path| {
        let text = std::fs::read_to_string(p).unwrap();
        let mut lines = text.lines();
        let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let cols: Vec<usize> = (0..head.len())
            .filter(|&i| head[i].starts_with("tau"))
            .collect();
        assert!(!cols.is_empty(), "{} has no torque column", p.display());
        lines
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                cols.iter().map(|&i| f[i].parse::<f64>().unwrap()).collect()
            })
            .collect::<Vec<Vec<f64>>>()
    };
    let (a, b) = (read(a), read(b));
    assert_eq!(a.len(), b.len(), "both runs have every step");
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn lockstep(dir: &Path, extra: &[&str], csv: &str) -> serde_json::Value {
    let mut cmd = testbed();
    cmd.args(["run", "--mode", "lockstep", "--json", "--runs-dir"])
        .arg(dir)
        .arg("--csv")
        .arg(dir.join(csv))
        .args(extra);
    json(&ok(&mut cmd))
}

fn verify(log: &str) -> serde_json::Value {
    json(&ok(testbed().args(["replay", "--json", "--verify", log])))
}

#[test]
fn the_python_packages_own_tests_pass() {
    let out = Command::new(python())
        .args(["-m", "unittest", "discover", "-s", "tests"])
        .current_dir(repo_root().join("python"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "python unit tests failed:\n{err}");
    assert!(err.trim_end().ends_with("OK"), "{err}");
}

/// The Python PD computes what the Rust `pd` law computes, in the same
/// order: a lockstep run gives the same torques to the last bit.
#[test]
fn a_python_pd_equals_the_rust_pd_law_in_lockstep() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["--law", "pd", "--duration", "3"];
    let py_cmd = example("pd.py");
    let mut py_args = args.to_vec();
    py_args.extend(["--controller-cmd", py_cmd.as_str()]);
    let py = lockstep(dir.path(), &py_args, "py.csv");
    let rs = lockstep(dir.path(), &args, "rs.csv");
    let diff = max_torque_difference(&dir.path().join("py.csv"), &dir.path().join("rs.csv"));
    assert!(diff <= 1e-12, "Python PD differs from Rust pd by {diff}");
    assert_eq!(py["controller_cmd"].as_str(), Some(py_cmd.as_str()));
    assert!(rs.get("controller_cmd").is_none());
    assert_eq!(py["fault_steps"], 0);
    let v = verify(py["log"].as_str().unwrap());
    assert_eq!(v["verified_steps"], 3000);
    assert!(v["max_abs_torque_diff"].as_f64().unwrap() <= 1e-12, "{v}");
}

/// The paper's law written in numpy from SPEC keeps the paper scenario's
/// envelope, and the Rust law re-driven on its logged states gives its
/// torques to 1e-9; a Rust run of the whole scenario agrees with it too.
#[test]
fn the_numpy_paper_law_keeps_the_envelope_and_matches_the_rust_law() {
    let dir = tempfile::tempdir().unwrap();
    let py_cmd = example("nac.py");
    let py = lockstep(dir.path(), &["--controller-cmd", &py_cmd], "py.csv");
    assert_eq!(py["constraint_satisfied_after_tc"], true, "{py}");
    assert_eq!(py["fault_steps"], 0);
    assert_eq!(py["barrier_breached_steps"], 0);
    let v = verify(py["log"].as_str().unwrap());
    assert_eq!(v["verified_steps"], 20000);
    let step_diff = v["max_abs_torque_diff"].as_f64().unwrap();
    assert!(
        step_diff <= 1e-9,
        "Rust law on the numpy run's states: {step_diff}"
    );
    lockstep(dir.path(), &[], "rs.csv");
    let run_diff = max_torque_difference(&dir.path().join("py.csv"), &dir.path().join("rs.csv"));
    assert!(run_diff <= 1e-9, "whole runs differ by {run_diff}");
}

/// Every message of a real lockstep run's log decodes with the official
/// Python readers (`mcap`, `mcap-ros2-support`), through the package's
/// one-call reader: one table per topic, as many rows as the log has
/// messages, per-joint fields as rows × joints.
#[test]
fn every_message_of_a_run_decodes_with_the_official_python_reader() {
    let dir = tempfile::tempdir().unwrap();
    let r = lockstep(dir.path(), &["--duration", "1"], "r.csv");
    let log = r["log"].as_str().unwrap();
    let out = Command::new(python())
        .args(["python/examples/read_log.py", log, "--json"])
        .current_dir(repo_root())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "read_log.py failed:\n{err}");
    let py: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // What the Rust reader counts, per topic.
    let mut per_topic = std::collections::BTreeMap::<String, u64>::new();
    let contents = logger::read_log(
        Path::new(log),
        Some(&mut |m: &logger::RawMessage<'_>| {
            *per_topic.entry(m.topic.to_string()).or_default() += 1;
            Ok(())
        }),
    )
    .unwrap();
    let rows = py["rows"].as_object().unwrap();
    let decoded: u64 = rows.values().map(|v| v.as_u64().unwrap()).sum();
    assert_eq!(decoded, contents.messages, "{py}");
    for (topic, n) in &per_topic {
        assert_eq!(rows[topic].as_u64(), Some(*n), "{topic}: {py}");
    }
    // Every channel but an external controller's own diagnostics (the
    // testbed's controller declares none) and contact's (no obstacles).
    let silent = ["/controller/own_diagnostics", "/contact", "/arm/contact"];
    assert_eq!(
        per_topic.len(),
        logger::channels().len() - silent.len(),
        "{per_topic:?}"
    );
    assert!(silent.iter().all(|t| !per_topic.contains_key(*t)));
    assert_eq!(py["log_format"], logger::LOG_FORMAT);
    assert_eq!(py["types"]["/joint_state"], "testbed_msgs/msg/JointState");
    assert_eq!(py["types"]["/joint_states"], "sensor_msgs/msg/JointState");
    assert_eq!(py["types"]["/tf"], "tf2_msgs/msg/TFMessage");
    assert_eq!(py["q_shape"], serde_json::json!([1001, 2]), "{py}");
    assert_eq!(py["last_t"], 1.0);
    // A contact run's /contact and /arm/contact decode too.
    let r = lockstep(
        dir.path(),
        &["--scenario", "paper_obstacle", "--duration", "2.5"],
        "c.csv",
    );
    let out = Command::new(python())
        .args([
            "python/examples/read_log.py",
            r["log"].as_str().unwrap(),
            "--json",
        ])
        .current_dir(repo_root())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let py: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(py["rows"]["/contact"], 2501, "{py}");
    assert!(py["rows"]["/arm/contact"].as_u64().unwrap() > 0, "{py}");
    assert_eq!(py["types"]["/contact"], "testbed_msgs/msg/ContactState");
}

/// A 10 s real-time run at 1 kHz with the Python PD completes and reports
/// its timing (how many deadlines it missed is the machine's to say).
#[test]
fn a_python_pd_runs_in_real_time_at_1khz() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = example("pd.py");
    let r = json(&crate::util::ran(
        testbed()
            .args([
                "run",
                "--json",
                "--law",
                "pd",
                "--duration",
                "10",
                "--rate",
                "1000",
            ])
            .args(["--controller-cmd", &cmd, "--runs-dir"])
            .arg(dir.path()),
    ));
    let t = &r["timing"];
    assert_eq!(t["cycles"], 10000, "{t}");
    assert!(t["round_trip_us"]["p50"].as_f64().unwrap() > 0.0, "{t}");
    assert!(t["deadline_misses"].as_u64().is_some(), "{t}");
    assert_eq!(r["run_end"], "finished");
}

fn crash_script(dir: &Path) -> PathBuf {
    crash_script_at(dir, 100)
}

/// A Python controller that raises at step `step`.
fn crash_script_at(dir: &Path, step: u64) -> PathBuf {
    let path = dir.join(format!("crash{step}.py"));
    std::fs::write(
        &path,
        format!(
            "import numpy as np\nimport testbed_controller as tc\n\n\
             class Crash(tc.Controller):\n    def step(self, state, ref):\n        \
             if state.seq == {step}:\n            raise RuntimeError('boom at step {step}')\n        \
             return np.zeros(2)\n\ntc.run(Crash())\n"
        ),
    )
    .unwrap();
    path
}

/// #50 item 5: a user law that crashes after T_c is a failed run that
/// left the envelope, never "not judged".
#[test]
fn a_user_law_that_crashes_after_tc_is_failed_not_unjudged() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = format!(
        "{} {}",
        python(),
        crash_script_at(dir.path(), 2500).display()
    );
    let out = testbed()
        .args([
            "compare",
            "--laws",
            "pd",
            "--duration",
            "3",
            "--json",
            "--runs-dir",
        ])
        .arg(dir.path())
        .args(["--controller-cmd", &format!("crash={cmd}")])
        .output()
        .unwrap();
    // Its one run failed: compare says so last and exits 1 (#60 item 4).
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("every run of crash failed"), "{err}");
    let c: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let row = c["laws"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["name"] == "crash")
        .unwrap()
        .clone();
    assert_eq!(row["failed"], 1, "{row}");
    assert_eq!(row["not_judged"], 0, "{row}");
    assert_eq!(row["left_envelope"], 1, "{row}");
}

/// The run stops, names the controller and shows its traceback, and no
/// shared memory of the run is left.
#[test]
fn a_crashing_python_controller_stops_the_run_with_its_last_words() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = format!("{} {}", python(), crash_script(dir.path()).display());
    let mut child = testbed()
        .args(["run", "--mode", "lockstep", "--duration", "5", "--runs-dir"])
        .arg(dir.path())
        .args(["--controller-cmd", &cmd])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let (status, _, err) = crate::util::ended(&mut child, 120);
    assert!(!status.success());
    assert!(err.contains("the controller node"), "{err}");
    assert!(err.contains("RuntimeError: boom at step 100"), "{err}");
    assert!(shm_files(&format!("tbrun{pid:x}x")).is_empty());
}

/// The Python controller of a run started by launcher `launcher`, once it runs.
fn python_controller_of(launcher: u32) -> u32 {
    for _ in 0..3000 {
        for e in std::fs::read_dir("/proc").unwrap().flatten() {
            let Ok(pid) = e.file_name().to_string_lossy().parse::<u32>() else {
                continue;
            };
            let cmdline = std::fs::read(e.path().join("cmdline")).unwrap_or_default();
            let text = String::from_utf8_lossy(&cmdline).replace('\0', " ");
            if text.contains(".py") && text.contains(&format!("--parent-pid {launcher}")) {
                return pid;
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    panic!("launcher {launcher} started no Python controller");
}

/// kill -9 of the Python node mid-run: named, nothing left behind.
#[test]
fn kill_9_of_a_python_controller_is_named_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = example("pd.py");
    let mut child = testbed()
        .args(["run", "--law", "pd", "--duration", "30", "--runs-dir"])
        .arg(dir.path())
        .args(["--controller-cmd", &cmd])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let launcher = child.id();
    let controller = python_controller_of(launcher);
    // Let it run (a watchdog-bounded poll for its first log bytes).
    crate::run_cli::wait_until_running(dir.path());
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(controller as i32),
        nix::sys::signal::Signal::SIGKILL,
    )
    .unwrap();
    let (status, _, err) = crate::util::ended(&mut child, 120);
    assert!(!status.success());
    assert!(
        err.contains("the controller node was killed by signal 9"),
        "{err}"
    );
    assert!(shm_files(&format!("tbrun{launcher:x}x")).is_empty());
}

/// #31 row 10: kill -9 of the launcher while a Python controller is stuck
/// inside `step()` (where its own check of the launcher cannot run): the
/// controller ends all the same (the kernel's parent-death signal).
#[test]
fn kill_9_of_the_launcher_ends_a_python_controller_stuck_in_step() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("pd.py");
    std::fs::write(
        &script,
        "import time, numpy as np\nimport testbed_controller as tc\n\
         class Stuck(tc.Controller):\n    def setup(self, run):\n        self.n = run.dof\n\
         \x20   def step(self, state, ref):\n        time.sleep(600)\n        return np.zeros(self.n)\n\
         \x20   def diagnostics(self):\n        return {}\n\
         tc.run(Stuck())\n",
    )
    .unwrap();
    let cmd = format!("{} {}", python(), script.display());
    let mut child = testbed()
        .args(["run", "--law", "pd", "--duration", "30", "--runs-dir"])
        .arg(dir.path())
        .args(["--controller-cmd", &cmd])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let controller = python_controller_of(child.id());
    crate::run_cli::wait_until_running(dir.path());
    child.kill().unwrap();
    let _ = child.wait();
    // Watchdog: the controller must go long before its sleep would end.
    let start = std::time::Instant::now();
    while std::path::Path::new(&format!("/proc/{controller}")).exists()
        && !std::fs::read_to_string(format!("/proc/{controller}/stat"))
            .is_ok_and(|s| s.contains(") Z "))
    {
        assert!(
            start.elapsed().as_secs() < 30,
            "the controller outlived its launcher"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

#[test]
fn a_controller_command_that_cannot_start_is_refused_before_any_node() {
    let dir = tempfile::tempdir().unwrap();
    let err = fails(
        testbed()
            .args(["run", "--mode", "lockstep", "--runs-dir"])
            .arg(dir.path())
            .args(["--controller-cmd", "/no/such/python3 my_controller.py"]),
    );
    assert!(
        err.contains("cannot start the controller node (`/no/such/python3 my_controller.py`)"),
        "{err}"
    );
    assert!(
        err.contains("no executable program '/no/such/python3'"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    let err = fails(testbed().args(["run", "--controller-cmd", "'unclosed"]));
    assert!(err.contains("cannot be split into words"), "{err}");
}

/// #29: a Python controller as a law of its own. The PID example declares
/// its name and a parameter `ki`; the scenario's `[external]` table sets
/// it (checked: unknown keys and wrong kinds are refused before the run);
/// the log and the summary name `pid` with its `ki`; its integral is a
/// diagnostic of its own, in the log (its own channel, read by name from
/// Python), the CSV and the summary; what it printed is in the run folder.
#[test]
fn a_python_pid_declares_its_law_and_takes_its_own_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = |body: &str| {
        let p = dir.path().join(format!("s{}.toml", body.len()));
        std::fs::write(&p, format!("duration_s = 3.0\n[external]\n{body}\n")).unwrap();
        p
    };
    let run = |s: &Path, name: &str| {
        let mut c = testbed();
        c.args([
            "run",
            "--mode",
            "lockstep",
            "--json",
            "--controller-cmd",
            &example("pid.py"),
        ])
        .arg("--scenario")
        .arg(s)
        .args(["--name", name, "--runs-dir"])
        .arg(dir.path().join("runs"));
        c
    };
    let s = json(&ok(&mut run(&scenario("ki = 5"), "pid")));
    assert_eq!(s["controller_law"]["name"], "pid", "{s}");
    assert_eq!(s["controller_law"]["parameters"], "ki=5", "{s}");
    let printed =
        std::fs::read_to_string(dir.path().join("runs/pid/nodes/controller.log")).unwrap();
    assert!(printed.contains("pid: ki = 5.0"), "{printed}");
    // The log says it too: replay names the law that ran.
    let log = s["log"].as_str().unwrap();
    let r = json(&ok(testbed().args(["replay", "--json", log])));
    assert_eq!(r["controller_law"], s["controller_law"]);
    own_integral_is_everywhere(&s, log, dir.path());
    // A larger integral gain changes the run.
    let s2 = json(&ok(&mut run(&scenario("ki = 50.0"), "pid2")));
    assert_ne!(s2["metrics"], s["metrics"]);
    let err = fails(&mut run(&scenario("kx = 5"), "bad1"));
    assert!(
        err.contains("[external] kx: 'pid' declares no such parameter (it has: ki)"),
        "{err}"
    );
    let err = fails(&mut run(&scenario("ki = \"a\""), "bad2"));
    assert!(err.contains("declares it like 2.0"), "{err}");
    let err = fails(
        testbed()
            .args(["sim", "--scenario"])
            .arg(scenario("ki = 1")),
    );
    assert!(err.contains("is for an external controller"), "{err}");
}

/// The PID's `integral` diagnostic: in the summary (last and largest per
/// joint), the CSV's `own.integral<i>` columns and the log's own channel,
/// all the same numbers.
fn own_integral_is_everywhere(s: &serde_json::Value, log: &str, dir: &Path) {
    let d = &s["controller_law"]["diagnostics"][0];
    assert_eq!(d["name"], "integral", "{s}");
    let last: Vec<f64> = (d["last"].as_array().unwrap().iter())
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(last.len(), 2, "{s}");
    assert!(last.iter().all(|x| x.is_finite() && *x != 0.0), "{s}");
    let csv = dir.join("pid.csv");
    ok(testbed().args(["replay", log, "--csv"]).arg(&csv));
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let row: Vec<f64> = (text.lines().last().unwrap().split(','))
        .map(|x| x.parse().unwrap())
        .collect();
    for (i, want) in last.iter().enumerate() {
        let col = header.iter().position(|h| *h == format!("own.integral{i}"));
        assert_eq!(row[col.expect("an own.integral column")], *want);
    }
    let out = Command::new(python())
        .args([
            "-c",
            "import sys, json, testbed_controller.log as t\n\
             o = t.read_log(sys.argv[1])['/controller/own_diagnostics']\n\
             print(json.dumps(o['integral'][-1].tolist()))",
            log,
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let py: Vec<f64> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(py, last);
}

/// #26 item 4: Python laws as rows of `compare`, scored like the built-in
/// ones. The PD example computes the `pd` law (same bits, so the same
/// scores); the PID example declares its law, and its logs name it.
#[test]
fn python_laws_are_rows_of_compare() {
    let dir = tempfile::tempdir().unwrap();
    let runs = dir.path().join("runs");
    let out = ok(testbed()
        .args([
            "compare",
            "--json",
            "--laws",
            "pd",
            "--duration",
            "3",
            "--seeds",
            "2",
            // Seeds that differ (sensor noise): identical ones get no paired test.
            "--set",
            "plant.sensor.q_noise_std=1e-4",
        ])
        .arg("--controller-cmd")
        .arg(format!("pypd={}", example("pd.py")))
        .arg("--controller-cmd")
        .arg(format!("pid={}", example("pid.py")))
        .arg("--runs-dir")
        .arg(&runs));
    let c = json(&out);
    let rows = c["laws"].as_array().unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["pd", "pypd", "pid"]);
    assert_eq!(rows[1]["median"]["iae"], rows[0]["median"]["iae"], "{c}");
    assert_eq!(rows[1]["runs"].as_array().unwrap().len(), 2);
    assert_eq!(rows[2]["external"]["declared"]["name"], "pid", "{c}");
    assert_ne!(rows[2]["median"]["iae"], rows[0]["median"]["iae"]);
    // The paired test is against the first row, pd, on the same seeds.
    assert!(
        c["paired"]
            .as_array()
            .unwrap()
            .iter()
            .any(|p| p["versus"] == "pid"),
        "{c}"
    );
    // Each seed of each user law left a run folder whose log names the law.
    let mut named = 0;
    for e in std::fs::read_dir(&runs).unwrap() {
        let log = e.unwrap().path().join("run.mcap");
        let r = json(&ok(testbed().arg("replay").arg("--json").arg(&log)));
        named += usize::from(r["controller_law"]["name"] == "pid");
    }
    assert_eq!(named, 2);
}
