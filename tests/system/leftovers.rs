//! No leaks after any kill (#18 row 6): a node killed while it is being
//! created, an earlier run's half-made node, and a node started by hand and
//! stopped with Ctrl-C leave nothing in shared memory or iceoryx2's folders
//! once the very next run (or the node itself) is done.

use std::path::{Path, PathBuf};
use std::process::Stdio;

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

use crate::util::{ok, shm_files, testbed, wait_bounded};

/// Every file of `prefix` in /dev/shm and below /tmp/iceoryx2.
fn files_of(prefix: &str) -> Vec<String> {
    let mut out = shm_files(prefix);
    let mut stack = vec![PathBuf::from("/tmp/iceoryx2")];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if e.path().is_dir() {
                stack.push(e.path());
            } else if name.starts_with(prefix) {
                out.push(e.path().display().to_string());
            }
        }
    }
    out
}

/// The pid of a process that has ended (for a prefix whose launcher is gone).
fn dead_pid() -> u32 {
    let mut c = std::process::Command::new("true").spawn().unwrap();
    let pid = c.id();
    c.wait().unwrap();
    pid
}

/// What a node killed while iceoryx2 was creating it leaves: its details
/// file in a node folder of its own, which iceoryx2 does not list.
fn half_made_node(prefix: &str) -> PathBuf {
    let dir = Path::new("/tmp/iceoryx2/nodes").join(format!("9{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{prefix}node.details"));
    std::fs::write(&file, b"").unwrap();
    file
}

#[test]
fn the_next_run_removes_an_earlier_runs_half_made_node() {
    let prefix = format!("tbrun{:x}x1234_", dead_pid());
    let file = half_made_node(&prefix);
    let dir = tempfile::tempdir().unwrap();
    ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "0.2",
            "--runs-dir",
        ])
        .arg(dir.path()));
    assert!(!file.exists(), "{} is still there", file.display());
    assert!(!file.parent().unwrap().exists());
}

/// kill -9 of each node as soon as it exists: whatever it had made, the run
/// fails naming it and leaves no file of its prefix.
#[test]
fn kill_9_of_a_node_during_start_up_leaves_nothing() {
    for node in ["plant", "trajectory", "controller", "logger"] {
        let dir = tempfile::tempdir().unwrap();
        let mut launcher = testbed()
            .args(["run", "--mode", "lockstep", "--duration", "1", "--runs-dir"])
            .arg(dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let prefix = format!("tbrun{:x}x", launcher.id());
        let pid = loop {
            let found = crate::util::nodes_of(launcher.id())
                .into_iter()
                .find(|n| n.0 == node);
            if let Some((_, pid, _)) = found {
                break pid;
            }
            assert!(
                launcher.try_wait().unwrap().is_none(),
                "the run ended first"
            );
        };
        kill(Pid::from_raw(pid as i32), Signal::SIGKILL).unwrap();
        let status = wait_bounded(&mut launcher, 60);
        let mut err = String::new();
        std::io::Read::read_to_string(&mut launcher.stderr.take().unwrap(), &mut err).unwrap();
        assert!(!status.success(), "{node}: {err}");
        assert!(err.contains(&format!("the {node} node")), "{err}");
        assert_eq!(files_of(&prefix), Vec::<String>::new(), "{node}");
    }
}

/// Whether process `pid` has a handler for SIGINT (bit 2 of SigCgt in
/// /proc/<pid>/status).
fn catches_sigint(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("SigCgt:"))?.to_string();
            u64::from_str_radix(line.trim_start_matches("SigCgt:").trim(), 16).ok()
        })
        .is_some_and(|mask| mask & (1 << (2 - 1)) != 0)
}

/// A node started by hand on a domain of its own and stopped with Ctrl-C
/// removes the domain it was the last node of.
#[test]
fn a_hand_started_node_stopped_with_ctrl_c_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("controller.json");
    std::fs::write(&config, r#"{"params": {}, "dof": 2, "period_ns": 1000000}"#).unwrap();
    let prefix = format!("handtest{}_", std::process::id());
    let mut node = testbed()
        .args([
            "node",
            "controller",
            "--mode",
            "lockstep",
            "--prefix",
            &prefix,
            "--config",
        ])
        .arg(&config)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Watchdog-bounded poll until the node has made its domain and catches
    // SIGINT: its files appear before its handlers are installed, and a
    // Ctrl-C in between kills it the default way (a loaded machine showed it).
    for _ in 0..3000 {
        if !shm_files(&prefix).is_empty() && catches_sigint(node.id()) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(!shm_files(&prefix).is_empty(), "the node made no domain");
    assert!(catches_sigint(node.id()), "the node never caught SIGINT");
    kill(Pid::from_raw(node.id() as i32), Signal::SIGINT).unwrap();
    wait_bounded(&mut node, 60);
    assert_eq!(files_of(&prefix), Vec::<String>::new());
}
