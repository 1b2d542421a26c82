//! Running the `testbed` binary from tests.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A binary of the workspace (`testbed`, `testbed-policy`,
/// `example-pd-controller`), each its own package's: cargo builds them into
/// the folder above this test's own (target/<profile>/deps/system-…) when
/// the suite runs as `cargo nextest run --workspace` (each package has a
/// test of its own, which is what makes cargo build its binary).
pub fn bin(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's own path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("a test binary lives in target/<profile>/deps");
    let path = dir.join(name);
    assert!(
        path.is_file(),
        "{} is not built: run the suite as `cargo nextest run --workspace` (or `cargo build --bin {name}` first)",
        path.display()
    );
    path
}

/// The built `testbed` binary.
pub fn testbed() -> Command {
    let mut c = Command::new(bin("testbed"));
    c.current_dir(repo_root());
    c
}

/// The repository root (scenario and robot paths in tests are relative to it).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs and returns the output, failing the test with stderr if it did not exit 0.
pub fn ok(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("spawn testbed");
    assert!(
        out.status.success(),
        "{cmd:?} exited {:?}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs a real-time `testbed run` where timing is not what is tested:
/// exit 0 (verdict clean) or 3 (degraded: a loaded machine) both pass;
/// anything else fails the test with stderr.
pub fn ran(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("spawn testbed");
    assert!(
        matches!(out.status.code(), Some(0 | 3)),
        "{cmd:?} exited {:?}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs `testbed replay` of a log whatever its verdict: the exit status
/// must be the verdict's (0 clean, 3 degraded, 4 invalid), as its JSON
/// summary (when printed) says; anything else fails the test with stderr.
pub fn replayed(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("spawn testbed");
    let verdict = serde_json::from_slice::<serde_json::Value>(&out.stdout)
        .ok()
        .and_then(|s| s["timing"]["verdict"].as_str().map(str::to_string));
    let expected = match verdict.as_deref() {
        Some("clean") => vec![0],
        Some("degraded") => vec![3],
        Some("invalid") => vec![4],
        _ => vec![0, 3, 4],
    };
    assert!(
        out.status.code().is_some_and(|c| expected.contains(&c)),
        "{cmd:?} exited {:?} (verdict {verdict:?})\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs, expects a non-zero exit, and returns stderr.
pub fn fails(cmd: &mut Command) -> String {
    let out = cmd.output().expect("spawn testbed");
    assert!(!out.status.success(), "{cmd:?} should have failed");
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!err.contains("panicked"), "{cmd:?} panicked:\n{err}");
    err
}

/// Fails the test unless two CSV texts are equal, naming the first row
/// that differs and the column values on it (a bare "differs" tells a
/// flaky failure's reader nothing).
pub fn assert_same_csv(what: &str, a: &[u8], b: &[u8]) {
    if a == b {
        return;
    }
    let (a, b) = (String::from_utf8_lossy(a), String::from_utf8_lossy(b));
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let header: Vec<&str> = la.first().map_or(vec![], |h| h.split(',').collect());
    let row = la.iter().zip(&lb).position(|(x, y)| x != y);
    let detail = match row {
        Some(i) => {
            let cols: Vec<String> = la[i]
                .split(',')
                .zip(lb[i].split(','))
                .enumerate()
                .filter(|(_, (x, y))| x != y)
                .map(|(c, (x, y))| format!("{}: {x} vs {y}", header.get(c).unwrap_or(&"?")))
                .collect();
            format!("line {} differs first: {}", i + 1, cols.join("; "))
        }
        None => "one is a prefix of the other".into(),
    };
    panic!(
        "{what}: CSVs differ ({} vs {} lines); {detail}",
        la.len(),
        lb.len()
    );
}

/// Parses stdout as JSON.
pub fn json(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

/// Waits for `child` at most `secs` seconds (a watchdog, not a timing
/// assertion): kills it and fails the test if it does not end.
pub fn wait_bounded(child: &mut std::process::Child, secs: u64) -> std::process::ExitStatus {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("try_wait") {
            return status;
        }
        if start.elapsed().as_secs() >= secs {
            let _ = child.kill();
            let _ = child.wait();
            panic!("process {} did not end within {secs} s", child.id());
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Waits for `child` (watchdog: `secs`) and returns how it ended with
/// what it wrote to its piped stdout and stderr (empty if not piped).
pub fn ended(
    child: &mut std::process::Child,
    secs: u64,
) -> (std::process::ExitStatus, String, String) {
    let status = wait_bounded(child, secs);
    let read = |r: Option<&mut dyn std::io::Read>| {
        let mut out = String::new();
        if let Some(r) = r {
            r.read_to_string(&mut out).expect("read output");
        }
        out
    };
    let out = read(child.stdout.as_mut().map(|o| o as &mut dyn std::io::Read));
    let err = read(child.stderr.as_mut().map(|e| e as &mut dyn std::io::Read));
    (status, out, err)
}

/// Node processes started by launcher `pid`: (node name, pid, run prefix).
pub fn nodes_of(launcher: u32) -> Vec<(String, u32, String)> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return out;
    };
    let marker = launcher.to_string();
    for e in entries.flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(raw) = std::fs::read(e.path().join("cmdline")) else {
            continue;
        };
        let args: Vec<String> = raw
            .split(|b| *b == 0)
            .map(|a| String::from_utf8_lossy(a).to_string())
            .collect();
        let is_child = args
            .windows(2)
            .any(|w| w[0] == "--parent-pid" && w[1] == marker);
        let pos = args.iter().position(|a| a == "node");
        if let (true, Some(i)) = (is_child, pos) {
            let prefix = args
                .windows(2)
                .find(|w| w[0] == "--prefix")
                .map(|w| w[1].clone())
                .unwrap_or_default();
            out.push((args[i + 1].clone(), pid, prefix));
        }
    }
    out
}

/// Polls until launcher `pid` has started all four nodes; returns them.
pub fn wait_for_nodes(launcher: u32) -> Vec<(String, u32, String)> {
    for _ in 0..1500 {
        let nodes = nodes_of(launcher);
        if nodes.len() == 4 {
            return nodes;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    panic!("launcher {launcher} did not start its nodes");
}

/// Files in /dev/shm that belong to run prefix `prefix`.
pub fn shm_files(prefix: &str) -> Vec<String> {
    std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name().to_string_lossy().to_string())
                .filter(|n| !prefix.is_empty() && n.starts_with(prefix))
                .collect()
        })
        .unwrap_or_default()
}

/// Runs `testbed ARGS --csv DIR/NAME` and returns the CSV's bytes.
pub fn csv_of(args: &[&str], dir: &Path, name: &str) -> Vec<u8> {
    let path = dir.join(name);
    ok(testbed().args(args).arg("--csv").arg(&path));
    std::fs::read(&path).unwrap()
}

/// Runs `script` (python/setup-venv.sh or python/build-module.sh: each
/// locks against other test processes running it) and returns the Python
/// it prints.
pub fn venv_python(script: &str) -> String {
    let out = Command::new("bash")
        .arg(repo_root().join(script))
        .output()
        .unwrap_or_else(|e| panic!("run {script}: {e}"));
    assert!(
        out.status.success(),
        "{script} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// A fresh lockstep log of 0.3 s in `dir`.
pub fn lockstep_log(dir: &Path) -> PathBuf {
    let out = ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "0.3",
            "--json",
            "--runs-dir",
        ])
        .arg(dir));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    PathBuf::from(v["log"].as_str().unwrap())
}

/// A 0.5 s lockstep `pd` run whose controller is a shell script that runs
/// `before` and then the Rust example controller; returns its exit status
/// and stderr (watchdog: 60 s, long before any helper would end).
pub fn run_with_controller_script(dir: &Path, before: &str) -> (std::process::ExitStatus, String) {
    let script = dir.join("ctl.sh");
    std::fs::write(
        &script,
        format!(
            "#!/bin/sh\n{before}\nexec {} \"$@\"\n",
            crate::util::bin("example-pd-controller").display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&script, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let mut run = testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "0.5",
            "--law",
            "pd",
        ])
        .arg("--controller-cmd")
        .arg(&script)
        .arg("--runs-dir")
        .arg(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let status = wait_bounded(&mut run, 60);
    let mut err = String::new();
    std::io::Read::read_to_string(&mut run.stderr.take().unwrap(), &mut err).unwrap();
    (status, err)
}
