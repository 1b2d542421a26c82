//! `testbed run`: real processes over iceoryx2.

use std::process::{Command, Stdio};
use std::time::Duration;

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

use crate::util::{
    assert_same_csv, fails, json, nodes_of, ok, shm_files, testbed, wait_bounded, wait_for_nodes,
};

fn sim_csv(dir: &std::path::Path, duration: &str) -> Vec<u8> {
    let path = dir.join(format!("sim-{duration}.csv"));
    ok(testbed()
        .args(["sim", "--duration", duration, "--csv"])
        .arg(&path));
    std::fs::read(path).unwrap()
}

/// The lockstep stack computes exactly what the in-process loop computes.
#[test]
fn lockstep_equals_sim_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("lockstep.csv");
    let out = ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "2.5",
            "--json",
            "--runs-dir",
        ])
        .arg(dir.path())
        .arg("--csv")
        .arg(&csv));
    let run = json(&out);
    assert_same_csv(
        "lockstep vs sim",
        &std::fs::read(&csv).unwrap(),
        &sim_csv(dir.path(), "2.5"),
    );
    let sim = json(&ok(testbed().args(["sim", "--duration", "2.5", "--json"])));
    for key in [
        "joints",
        "steps",
        "dt_s",
        "finite",
        "constraint_satisfied_after_tc",
        "barrier_breached_steps",
    ] {
        assert_eq!(run[key], sim[key], "{key}");
    }
    assert_eq!(run["timing"]["mode"], "lockstep");
    assert_eq!(run["timing"]["cycles"], 2500);
    assert_eq!(run["missing_rows"], 0);
}

#[test]
fn short_realtime_run_reports_timing() {
    let dir = tempfile::tempdir().unwrap();
    let out = crate::util::ran(
        testbed()
            .args(["run", "--duration", "1", "--json", "--runs-dir"])
            .arg(dir.path()),
    );
    let s = json(&out);
    assert_eq!(s["steps"], 1000);
    assert_eq!(s["finite"], true, "{s}");
    assert_eq!(s["missing_rows"], 0);
    let t = &s["timing"];
    assert_eq!(t["mode"], "realtime");
    assert_eq!(t["rate_hz"], 1000.0);
    assert_eq!(t["cycles"], 1000);
    assert!(t["deadline_misses"].as_u64().unwrap() < 1000);
    for k in ["period_jitter_us", "round_trip_us", "controller_compute_us"] {
        for p in ["p50", "p99", "max"] {
            assert!(t[k][p].as_f64().unwrap() >= 0.0, "{k}.{p} in {t}");
        }
        assert!(t[k]["p50"].as_f64().unwrap() <= t[k]["max"].as_f64().unwrap());
    }
    // Every cycle either got its command in time (and has a round trip) or
    // is a counted miss.
    assert!(t["late_wakeups"].as_u64().unwrap() <= 1000, "{t}");
    let misses = t["deadline_misses"].as_u64().unwrap();
    assert_eq!(
        t["round_trip_us"]["count"].as_u64().unwrap() + misses,
        1000,
        "{t}"
    );
}

/// kill -9 of any node: the launcher names it, stops the rest, exits
/// non-zero, and leaves no process and no shared memory; the next run works.
#[test]
fn killing_any_node_fails_the_run_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    for victim in ["plant", "trajectory", "controller", "logger"] {
        let mut launcher = testbed()
            .args(["run", "--duration", "60", "--runs-dir"])
            .arg(dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let nodes = wait_for_nodes(launcher.id());
        // The logger closes a chunk every 0.5 s: give it time to write one.
        let ms = if victim == "logger" { 1500 } else { 500 };
        std::thread::sleep(Duration::from_millis(ms));
        let (_, pid, prefix) = nodes.iter().find(|n| n.0 == victim).unwrap().clone();
        kill(Pid::from_raw(pid as i32), Signal::SIGKILL).unwrap();
        let status = wait_bounded(&mut launcher, 20);
        let mut err = String::new();
        std::io::Read::read_to_string(&mut launcher.stderr.take().unwrap(), &mut err).unwrap();
        assert!(!status.success(), "{victim}: launcher exited 0");
        assert!(
            err.contains(&format!("the {victim} node was killed by signal 9")),
            "{victim}: {err}"
        );
        assert!(
            nodes_of(launcher.id()).is_empty(),
            "{victim}: nodes left running"
        );
        assert_eq!(
            shm_files(&prefix),
            Vec::<String>::new(),
            "{victim}: shared memory left"
        );
        if victim != "logger" {
            // The log says the run did not finish, and which node it lost.
            let log = newest_log(dir.path());
            let s = crate::util::json(&crate::util::replayed(
                testbed().arg("replay").arg(&log).arg("--json"),
            ));
            let w = s["warning"].as_str().unwrap_or_default();
            assert!(
                w.contains(&format!("the run did not finish (lost the {victim})")),
                "{victim}: {s}"
            );
        }
        if victim == "logger" {
            // The unfinished log keeps what was flushed before the kill.
            let log = newest_log(dir.path());
            let out = crate::util::replayed(testbed().arg("replay").arg(&log).arg("--json"));
            let s = crate::util::json(&out);
            assert!(s["steps"].as_u64().unwrap() > 0, "{s}");
            assert!(s["warning"].as_str().unwrap().contains("recovered"), "{s}");
        }
        // A run right after the killed one starts normally.
        ok(testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--duration",
                "0.3",
                "--runs-dir",
            ])
            .arg(dir.path()));
    }
}

#[test]
fn ctrl_c_stops_everything() {
    let dir = tempfile::tempdir().unwrap();
    let mut launcher = testbed()
        .args(["run", "--duration", "60", "--runs-dir"])
        .arg(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let nodes = wait_for_nodes(launcher.id());
    std::thread::sleep(Duration::from_millis(300));
    kill(Pid::from_raw(launcher.id() as i32), Signal::SIGINT).unwrap();
    let status = wait_bounded(&mut launcher, 20);
    assert_eq!(status.code(), Some(130));
    assert!(nodes_of(launcher.id()).is_empty());
    assert_eq!(shm_files(&nodes[0].2), Vec::<String>::new());
    let log = newest_log(dir.path());
    let s = crate::util::json(&crate::util::replayed(
        testbed().arg("replay").arg(&log).arg("--json"),
    ));
    let w = s["warning"].as_str().unwrap_or_default();
    assert!(w.contains("the run did not finish (interrupted)"), "{s}");
}

/// A node whose launcher disappears exits by itself.
#[test]
fn nodes_exit_when_the_launcher_is_killed() {
    let dir = tempfile::tempdir().unwrap();
    let mut launcher = testbed()
        .args(["run", "--duration", "60", "--runs-dir"])
        .arg(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let pid = launcher.id();
    let prefix = wait_for_nodes(pid)[0].2.clone();
    kill(Pid::from_raw(pid as i32), Signal::SIGKILL).unwrap();
    wait_bounded(&mut launcher, 5);
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    while !nodes_of(pid).is_empty() {
        assert!(
            std::time::Instant::now() < deadline,
            "nodes of killed launcher still running: {:?}",
            nodes_of(pid)
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // The logger finished the file and says the launcher vanished.
    let log = newest_log(dir.path());
    let s = crate::util::json(&crate::util::replayed(
        testbed().arg("replay").arg(&log).arg("--json"),
    ));
    let w = s["warning"].as_str().unwrap_or_default();
    assert!(
        w.contains(&format!(
            "the run did not finish (the launcher (pid {pid}) vanished)"
        )),
        "{s}"
    );
    // The very next run removes what the killed launcher left (#18 row 6),
    // not only domains older than a minute.
    ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "0.1",
            "--runs-dir",
        ])
        .arg(dir.path()));
    assert_eq!(
        shm_files(&prefix),
        Vec::<String>::new(),
        "the killed run's shared memory is left"
    );
}

/// Two runs at the same time use separate shared memory and both get
/// exactly the in-process result.
#[test]
fn two_runs_at_once_do_not_interfere() {
    let dir = tempfile::tempdir().unwrap();
    let spawn = |duration: &str| {
        testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--duration",
                duration,
                "--runs-dir",
            ])
            .arg(dir.path())
            .arg("--csv")
            .arg(dir.path().join(format!("run-{duration}.csv")))
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let mut a = spawn("1.5");
    let mut b = spawn("2");
    assert!(wait_bounded(&mut a, 120).success());
    assert!(wait_bounded(&mut b, 120).success());
    for d in ["1.5", "2"] {
        let run = std::fs::read(dir.path().join(format!("run-{d}.csv"))).unwrap();
        assert!(
            run == sim_csv(dir.path(), d),
            "run of {d} s differs from sim"
        );
    }
}

#[test]
fn bad_run_settings_fail_before_anything_starts() {
    let dir = tempfile::tempdir().unwrap();
    let err = fails(
        testbed()
            .args(["run", "--rate", "0", "--runs-dir"])
            .arg(dir.path()),
    );
    assert!(err.contains("--rate") && err.contains("rate_hz"), "{err}");
    let err = fails(testbed().args(["run", "--mode", "fast"]));
    assert!(err.contains("fast"), "{err}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "a run folder was made"
    );
}

pub(crate) fn newest_log(runs: &std::path::Path) -> std::path::PathBuf {
    std::fs::read_dir(runs)
        .unwrap()
        .flatten()
        .map(|e| e.path().join("run.mcap"))
        .filter(|p| p.exists())
        .max_by_key(|p| std::fs::metadata(p).and_then(|m| m.modified()).ok())
        .expect("a run log")
}

/// `testbed bench` measures every part and reports the keys users script on.
#[test]
fn bench_reports_every_figure() {
    let dir = tempfile::tempdir().unwrap();
    let out = ok(testbed()
        .args([
            "bench",
            "--json",
            "--realtime-s",
            "0.3",
            "--repeats",
            "1",
            "--duration",
            "0.5",
            "--runs-dir",
        ])
        .arg(dir.path()));
    let b = crate::util::json(&out);
    for k in [
        "inprocess_wall_s",
        "lockstep_wall_s",
        "lockstep_realtime_factor",
        "lockstep_to_inprocess_ratio",
        "controller_step_us",
        "plant_step_us",
    ] {
        assert!(b[k].as_f64().unwrap() > 0.0, "{k} in {b}");
    }
    for k in ["cycles", "deadline_misses"] {
        assert!(
            b["realtime"][k].is_u64() && b["timer_floor"][k].is_u64(),
            "{k} in {b}"
        );
    }
    assert_eq!(b["realtime"]["cycles"], 300);
    // The floor counts its wake-ups inside the run's window: one per period.
    let floor = b["timer_floor"]["cycles"].as_i64().unwrap();
    assert!((floor - 300).abs() <= 2, "{b}");
    for k in ["period_jitter_us", "round_trip_us"] {
        assert!(b["realtime"][k]["p99"].as_f64().is_some(), "{k} in {b}");
    }
    assert!(
        b["timer_floor"]["period_jitter_us"]["p50"]
            .as_f64()
            .is_some()
    );
    let arms = b["arms"].as_array().unwrap();
    assert_eq!(arms.len(), 2);
    assert_eq!(arms[1]["dof"], 6);
    assert!(arms[0]["peak_rss_kb"].as_array().unwrap().len() >= 5, "{b}");
    // Where the lockstep time went: every node used some CPU.
    let cpu = arms[0]["lockstep_node_cpu_s"].as_array().unwrap();
    assert_eq!(cpu.len(), 4, "{b}");
    assert!(
        cpu.iter().all(|n| n[1].as_f64().is_some_and(|s| s > 0.0)),
        "{b}"
    );
    assert!(b["machine"]["cores"].as_u64().unwrap() >= 1);
    let err = crate::util::fails(testbed().args(["bench", "--realtime-s", "0"]));
    assert!(err.contains("--realtime-s"), "{err}");
}

/// A field of /proc/<pid>/status ("Cpus_allowed_list", "Uid", …).
fn proc_status(pid: u32, key: &str) -> Option<String> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix(&format!("{key}:")))
        .map(|v| v.trim().to_string())
}

/// The scheduling policy of `pid` (0 normal, 1 SCHED_FIFO): field 41 of
/// /proc/<pid>/stat, counted after the command name in parentheses.
fn policy(pid: u32) -> Option<u32> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = &stat[stat.rfind(')')? + 2..];
    rest.split(' ').nth(38)?.parse().ok()
}

fn is_root() -> bool {
    proc_status(std::process::id(), "Uid").is_some_and(|u| u.split_whitespace().nth(1) == Some("0"))
}

/// In real time the plant and the controller share the last CPU under
/// SCHED_FIFO; the logger and the trajectory run on the other CPUs.
#[test]
fn realtime_nodes_are_placed_as_documented() {
    let cpus = std::thread::available_parallelism().unwrap().get();
    assert!(cpus >= 2, "this test needs two CPUs");
    let dir = tempfile::tempdir().unwrap();
    let mut launcher = testbed()
        .args(["run", "--duration", "4", "--runs-dir"])
        .arg(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let nodes = wait_for_nodes(launcher.id());
    let last = (cpus - 1).to_string();
    let others = if cpus == 2 {
        "0".to_string()
    } else {
        format!("0-{}", cpus - 2)
    };
    // Each node places itself as it starts: give it a moment.
    let placed = |pid: u32, cpus: &str, fifo: bool| {
        (0..100).any(|_| {
            let ok = proc_status(pid, "Cpus_allowed_list").as_deref() == Some(cpus)
                && (policy(pid) == Some(1)) == fifo;
            if !ok {
                std::thread::sleep(Duration::from_millis(20));
            }
            ok
        })
    };
    let root = is_root();
    for (name, pid, _) in &nodes {
        // Every node runs under SCHED_FIFO in real time (#25: the
        // trajectory and the logger below the loop, on the other CPUs).
        let (want_cpus, fifo) = match name.as_str() {
            "plant" | "controller" => (&last, root),
            _ => (&others, root),
        };
        assert!(
            placed(*pid, want_cpus, fifo),
            "{name}: CPUs {:?}, policy {:?}; wanted {want_cpus}, FIFO {fifo}",
            proc_status(*pid, "Cpus_allowed_list"),
            policy(*pid)
        );
    }
    assert!(matches!(
        wait_bounded(&mut launcher, 30).code(),
        Some(0 | 3)
    ));
}

/// Where the system refuses SCHED_FIFO, each loop node says so, naming
/// what would allow it, and the run goes on.
#[test]
fn refused_realtime_scheduling_is_said_and_the_run_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    // Without CAP_SYS_NICE (and with the default rtprio limit of 0).
    let mut cmd = Command::new("setpriv");
    if is_root() {
        cmd.args(["--bounding-set", "-sys_nice"]);
    }
    cmd.args(["--inh-caps", "-sys_nice"])
        .arg(crate::util::bin("testbed"))
        .args(["run", "--duration", "0.5", "--json", "--runs-dir"])
        .arg(dir.path())
        .current_dir(crate::util::repo_root());
    let out = crate::util::ran(&mut cmd);
    let stderr = String::from_utf8_lossy(&out.stderr);
    for node in ["plant", "controller"] {
        assert!(
            stderr.contains(&format!(
                "testbed node {node}: warning: SCHED_FIFO priority"
            )) && stderr.contains("CAP_SYS_NICE"),
            "{stderr}"
        );
    }
    assert!(stderr.contains("Operation not permitted"), "{stderr}");
    assert_eq!(json(&out)["steps"], 500);
}

/// Runs `testbed run ARGS --json`, stops and continues every process of the
/// run `pauses` times (`stop` then `go` each), and returns the exit status
/// and the summary. The sleeps are the stimulus, not waits; a pause after
/// the run ended finds no process (ESRCH), which is ignored.
fn run_with_pauses(
    args: &[&str],
    pauses: usize,
    (stop, go): (Duration, Duration),
) -> (std::process::ExitStatus, serde_json::Value, String) {
    let dir = tempfile::tempdir().unwrap();
    let mut launcher = testbed()
        .arg("run")
        .args(args)
        .args(["--json", "--runs-dir"])
        .arg(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let nodes = wait_for_nodes(launcher.id());
    wait_until_running(dir.path());
    let mut pids: Vec<i32> = nodes.iter().map(|n| n.1 as i32).collect();
    pids.push(launcher.id() as i32);
    for _ in 0..pauses {
        for p in &pids {
            let _ = kill(Pid::from_raw(*p), Signal::SIGSTOP);
        }
        std::thread::sleep(stop);
        for p in &pids {
            let _ = kill(Pid::from_raw(*p), Signal::SIGCONT);
        }
        std::thread::sleep(go);
    }
    let status = wait_bounded(&mut launcher, 120);
    let mut out = String::new();
    std::io::Read::read_to_string(&mut launcher.stdout.take().unwrap(), &mut out).unwrap();
    let mut err = String::new();
    std::io::Read::read_to_string(&mut launcher.stderr.take().unwrap(), &mut err).unwrap();
    let summary = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {err}"));
    (status, summary, err)
}

/// Ctrl-Z then `fg` (every process stopped, then continued) is survived in
/// real time: the run goes on and the gap shows as late wake-ups (#18 row 2).
/// Five pauses: one lands inside a listener's wait, which a stop and
/// continue interrupts (EINTR).
#[test]
fn a_stopped_and_continued_realtime_run_goes_on() {
    let pause = (Duration::from_millis(300), Duration::from_millis(200));
    let (status, s, err) = run_with_pauses(&["--duration", "6"], 5, pause);
    // The pauses may degrade the verdict (late wake-ups, misses); the run
    // itself is whole.
    assert!(matches!(status.code(), Some(0 | 3)), "{err}");
    assert_eq!(s["run_end"], "finished");
    assert_ne!(s["timing"]["verdict"], "invalid", "{s}");
    assert!(s["timing"]["late_wakeups"].as_u64().unwrap() > 0, "{s}");
    // #39 row 11: the 300 ms stops are named, whatever they changed.
    assert_eq!(s["timing"]["verdict"], "degraded", "{s}");
    assert!(
        s["timing"]["reasons"]
            .to_string()
            .contains("the plant stalled"),
        "{s}"
    );
}

/// Ctrl-Z then `fg` of a lockstep run (#25 item 5): a publisher waiting
/// for room in a reader's buffer when the stop lands once failed its send
/// ("send (testbed/timing): InternalError") about one time in two.
#[test]
fn a_stopped_and_continued_lockstep_run_goes_on() {
    let pause = (Duration::from_millis(100), Duration::from_millis(150));
    let args = ["--mode", "lockstep", "--duration", "200"];
    let (status, s, err) = run_with_pauses(&args, 10, pause);
    assert!(status.success(), "{err}");
    assert_eq!(s["run_end"], "finished");
    assert_eq!(s["timing"]["verdict"], "clean", "{s}");
}

/// Waits (watchdog: 60 s) until a run under `runs` is under way: its log
/// has grown past what it holds before START (its first chunk of messages).
pub(crate) fn wait_until_running(runs: &std::path::Path) {
    let deadline = std::time::Instant::now() + Duration::from_secs(60);
    let size = || {
        std::fs::read_dir(runs)
            .unwrap()
            .flatten()
            .filter_map(|e| std::fs::metadata(e.path().join("run.mcap")).ok())
            .map(|m| m.len())
            .max()
    };
    while size().is_none_or(|n| n < 64 * 1024) {
        assert!(
            std::time::Instant::now() < deadline,
            "the run did not start"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}
