//! What a command writes: never over one of its inputs or results, never
//! through a link, refused up front when it cannot be written, and a closed
//! pipe or a full device is an error, not a panic.

use std::path::Path;
use std::process::Stdio;

use crate::util::{fails, lockstep_log as a_log, ok, testbed};

/// #18 row 10: an unwritable CSV fails `run` before any node starts.
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

/// #31 row 14: a closed pipe ends the command quietly (141, as SIGPIPE would);
/// a full device is a named error; neither panics.
#[test]
fn a_closed_pipe_and_a_full_device_are_not_panics() {
    // The reader is gone before the command starts: its write always
    // meets a closed pipe (closing it after the spawn raced the write).
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let child = testbed()
        .args(["sim", "--json", "--duration", "0.5"])
        .stdout(writer)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for args in [&["sim", "--duration", "0.2"][..], &["scenarios"][..]] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = testbed().args(args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("writing to standard output") && err.contains("No space"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// #31 row 16: `--live 127.0.0.1:0` says which port the system chose, on
/// stderr and in the run folder.
#[test]
fn a_live_view_on_port_0_says_its_port() {
    let dir = tempfile::tempdir().unwrap();
    let out = testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "0.2",
            "--live",
            "127.0.0.1:0",
        ])
        .arg("--runs-dir")
        .arg(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("live view at ws://127.0.0.1:"))
        .unwrap_or_else(|| panic!("{err}"));
    let port: u16 = line.rsplit(':').next().unwrap().trim().parse().unwrap();
    assert_ne!(port, 0, "{line}");
    let run = std::fs::read_dir(dir.path())
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let kept = std::fs::read_to_string(run.join("live-address.txt")).unwrap();
    assert_eq!(kept.trim(), format!("ws://127.0.0.1:{port}"));
}

/// #39 row 2: an output that is one of the command's inputs (by device and
/// inode, so a second name counts) is refused before anything is written,
/// and the input is left as it was.
#[test]
fn an_output_never_overwrites_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("s.toml");
    std::fs::copy(
        crate::util::repo_root().join("scenarios/paper.toml"),
        &scenario,
    )
    .unwrap();
    let same = dir.path().join("same.toml");
    std::fs::hard_link(&scenario, &same).unwrap();
    let before = std::fs::read(&scenario).unwrap();
    let s = scenario.to_str().unwrap();
    for args in [
        vec!["sim", "--duration", "0.1", "--scenario", s, "--csv", s],
        vec![
            "sim",
            "--duration",
            "0.1",
            "--scenario",
            s,
            "--csv",
            same.to_str().unwrap(),
        ],
        vec![
            "compare",
            "--duration",
            "0.1",
            "--laws",
            "pd",
            "--scenario",
            s,
            "--csv",
            s,
        ],
        vec![
            "run",
            "--mode",
            "lockstep",
            "--duration",
            "0.1",
            "--scenario",
            s,
            "--csv",
            s,
        ],
    ] {
        let e = fails(testbed().args(&args));
        assert!(
            e.contains("--csv") && e.contains("an input of this command"),
            "{args:?}: {e}"
        );
        assert_eq!(std::fs::read(&scenario).unwrap(), before, "{args:?}");
    }
    let urdf = dir.path().join("arm.urdf");
    std::fs::copy(crate::util::repo_root().join("robots/two_link.urdf"), &urdf).unwrap();
    let urdf_text = std::fs::read(&urdf).unwrap();
    let e = fails(
        testbed()
            .arg("robot")
            .arg(&urdf)
            .arg("--write-scenario")
            .arg(&urdf),
    );
    assert!(e.contains("--write-scenario"), "{e}");
    let e = fails(
        testbed()
            .args(["sim", "--duration", "0.1", "--robot"])
            .arg(&urdf)
            .arg("--csv")
            .arg(&urdf),
    );
    assert!(e.contains("an input of this command"), "{e}");
    assert_eq!(std::fs::read(&urdf).unwrap(), urdf_text);
    let log = a_log(dir.path());
    let log_bytes = std::fs::read(&log).unwrap();
    let e = fails(testbed().arg("replay").arg(&log).arg("--csv").arg(&log));
    assert!(e.contains("an input of this command"), "{e}");
    assert_eq!(std::fs::read(&log).unwrap(), log_bytes);
}

/// #39 row 2, sweeps: `sweep report D --csv D/manifest.json` is refused.
#[test]
fn a_sweep_report_never_overwrites_its_results() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("tiny.toml");
    std::fs::write(
        &file,
        "name = \"tiny\"\nseeds = 1\nlaws = [\"pd\"]\n[set]\nduration_s = 0.1\n\
         [[axis]]\nkey = \"controller.k1\"\nvalues = [10.0, 15.0]\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    ok(testbed()
        .args(["sweep", "run", "--no-progress", "--out"])
        .arg(&out)
        .arg(&file));
    let manifest = out.join("manifest.json");
    let before = std::fs::read(&manifest).unwrap();
    let e = fails(
        testbed()
            .args(["sweep", "report"])
            .arg(&out)
            .arg("--csv")
            .arg(&manifest),
    );
    assert!(e.contains("an input of this command"), "{e}");
    assert_eq!(std::fs::read(&manifest).unwrap(), before);
    ok(testbed()
        .args(["sweep", "report"])
        .arg(&out)
        .arg("--csv")
        .arg(dir.path().join("report.csv")));
}

/// Item 16 (D19): a `--runs-dir` that is a file (`/dev/null`, a regular
/// file) is named as not a folder, not "File exists".
#[test]
fn a_runs_dir_that_is_a_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("runs");
    std::fs::write(&file, "a file").unwrap();
    for runs in [Path::new("/dev/null"), &file] {
        let e = crate::util::fails(
            testbed()
                .args([
                    "run",
                    "--mode",
                    "lockstep",
                    "--duration",
                    "0.1",
                    "--runs-dir",
                ])
                .arg(runs),
        );
        assert!(
            e.contains(&runs.display().to_string())
                && e.contains("not a folder")
                && !e.contains("File exists"),
            "{e}"
        );
    }
}

/// Item 16 (N14): `robot --write-scenario` never replaces an existing file
/// without `--force`, and never writes through a symbolic link, even with it.
#[test]
fn write_scenario_keeps_what_exists_and_follows_no_link() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = crate::util::repo_root().join("robots/two_link.urdf");
    let write = |out: &Path, force: bool| {
        let mut cmd = testbed();
        cmd.arg("robot").arg(&urdf).arg("--write-scenario").arg(out);
        if force {
            cmd.arg("--force");
        }
        cmd
    };
    let mine = dir.path().join("s.toml");
    std::fs::write(&mine, "# my edits\n").unwrap();
    let e = crate::util::fails(&mut write(&mine, false));
    assert!(e.contains("exists; --force replaces it"), "{e}");
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "# my edits\n");
    crate::util::ok(&mut write(&mine, true));
    let text = std::fs::read_to_string(&mine).unwrap();
    assert!(text.starts_with("# The default scenario"), "{text}");

    let victim = dir.path().join("victim.txt");
    std::fs::write(&victim, "victim\n").unwrap();
    let link = dir.path().join("link.toml");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    let dangling = dir.path().join("dangling.toml");
    let nowhere = dir.path().join("nowhere.toml");
    std::os::unix::fs::symlink(&nowhere, &dangling).unwrap();
    for (out, force) in [
        (&link, false),
        (&link, true),
        (&dangling, false),
        (&dangling, true),
    ] {
        let e = crate::util::fails(&mut write(out, force));
        assert!(e.contains("symbolic link"), "{e}");
    }
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "victim\n");
    assert!(!nowhere.exists());
    // A new file is written as before.
    let fresh = dir.path().join("fresh.toml");
    crate::util::ok(&mut write(&fresh, false));
    assert!(fresh.is_file());
}
