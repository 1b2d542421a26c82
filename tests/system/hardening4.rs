//! Hardening, round 4 (#39): one reproducer per row fixed.

use crate::util::{fails, lockstep_log as a_log, ok, testbed};

/// Row 2: an output that is one of the command's inputs (by device and
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

/// Row 2, sweeps: `sweep report D --csv D/manifest.json` is refused.
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

/// Row 15: `--law X --set controller.<X's key>=…` sets X's key.
#[test]
fn a_law_on_the_command_line_takes_its_own_keys_from_set() {
    let out = ok(testbed().args([
        "sim",
        "--duration",
        "0.2",
        "--law",
        "mpc",
        "--set",
        "controller.mpc_horizon=5",
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["law"]["law"], "mpc", "{}", v["law"]);
    let e = fails(testbed().args([
        "sim",
        "--duration",
        "0.2",
        "--law",
        "pd",
        "--set",
        "controller.beta=3",
    ]));
    assert!(
        e.contains("controller.beta is not a parameter of law 'pd'"),
        "{e}"
    );
}

/// Row 10: a controller's helper that leaves its node's process group and
/// session (`setsid`) still ends with the run.
#[test]
fn a_helper_in_its_own_session_ends_with_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let marker = format!(
        "{}.{}",
        300 + std::process::id() % 600,
        std::process::id() % 89
    );
    let (status, err) =
        crate::util::run_with_controller_script(dir.path(), &format!("setsid sleep {marker} &"));
    assert!(status.success(), "{err}");
    let helpers = std::process::Command::new("pgrep")
        .args(["-f", &format!("sleep {marker}")])
        .output()
        .unwrap();
    let left = String::from_utf8_lossy(&helpers.stdout).to_string();
    for pid in left.split_whitespace() {
        let _ = std::process::Command::new("kill")
            .args(["-9", pid])
            .status();
    }
    assert!(
        left.trim().is_empty(),
        "the helper outlived the run: {left}"
    );
}

/// #48 item 6 (D17): a helper that also clears its environment
/// (`setsid env -i`) carried no run name and outlived the run; and one
/// orphaned at once (a subshell that exits) had no parent below the nodes.
/// The launcher is its descendants' subreaper and ends the run's tree:
/// neither outlives the run.
#[test]
fn a_helper_with_a_cleared_environment_ends_with_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let id = std::process::id();
    let kept = format!("{}.{}", 300 + id % 600, 10 + id % 89);
    let orphan = format!("{}.{}", 301 + id % 600, 10 + id % 89);
    let (status, err) = crate::util::run_with_controller_script(
        dir.path(),
        &format!("setsid env -i sleep {kept} &\n(setsid env -i sleep {orphan} &)"),
    );
    let mut left = String::new();
    for marker in [&kept, &orphan] {
        let helpers = std::process::Command::new("pgrep")
            .args(["-f", &format!("^sleep {marker}$")])
            .output()
            .unwrap();
        let found = String::from_utf8_lossy(&helpers.stdout).to_string();
        for pid in found.split_whitespace() {
            let _ = std::process::Command::new("kill")
                .args(["-9", pid])
                .status();
        }
        left += &found;
    }
    assert!(status.success(), "{err}");
    assert!(left.trim().is_empty(), "a helper outlived the run: {left}");
}

/// Row 1: a byte changed in a record outside the chunks (the run's
/// metadata, a channel) makes the log invalid: the data section's
/// checksum covers them.
#[test]
fn a_changed_record_outside_the_chunks_makes_the_log_invalid() {
    let dir = tempfile::tempdir().unwrap();
    let log = a_log(dir.path());
    let bytes = std::fs::read(&log).unwrap();
    let find = |needle: &[u8]| {
        bytes
            .windows(needle.len())
            .position(|w| w == needle)
            .unwrap()
    };
    let clean = json_of(testbed().args(["replay", "--json"]).arg(&log));
    assert_ne!(clean["timing"]["verdict"], "invalid", "{clean}");
    // The first copies are in the data section: the run's metadata (its
    // scenario text) and the /joint_states channel.
    for needle in [&b"duration_s"[..], &b"/joint_states"[..]] {
        let mut b = bytes.clone();
        b[find(needle) + 1] ^= 0x01;
        let damaged = dir.path().join("damaged.mcap");
        std::fs::write(&damaged, &b).unwrap();
        let out = testbed()
            .args(["replay", "--json"])
            .arg(&damaged)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        // Either the analysis says the log is invalid, or (the run's
        // metadata no longer reads) the error says why.
        match serde_json::from_slice::<serde_json::Value>(&out.stdout) {
            Ok(s) => {
                assert_eq!(s["timing"]["verdict"], "invalid", "{s}");
                assert!(s.to_string().contains("checksum does not match"), "{s}");
            }
            Err(_) => {
                assert!(
                    !out.status.success() && err.contains("checksum does not match"),
                    "{err}"
                );
            }
        }
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// The JSON a command printed, whatever its exit code.
fn json_of(cmd: &mut std::process::Command) -> serde_json::Value {
    let out = cmd.output().unwrap();
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}", String::from_utf8_lossy(&out.stderr));
    })
}
