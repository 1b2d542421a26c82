//! MJCF arms through the binary (#47): every shipped Menagerie arm runs its
//! default scenario clean, and a run's log carries the model with the
//! files it includes, so `replay` needs nothing else.

use std::path::Path;

use crate::util::{json, ok, testbed};

/// The shipped Menagerie arms (robots/menagerie/README.md): each folder's
/// `.xml` files, by path from the repository's root.
fn menagerie() -> Vec<String> {
    let root = crate::util::repo_root();
    let mut arms: Vec<String> = std::fs::read_dir(root.join("robots/menagerie"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .flat_map(|d| std::fs::read_dir(d).unwrap().map(|e| e.unwrap().path()))
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .map(|p| p.strip_prefix(&root).unwrap().display().to_string())
        .collect();
    arms.sort();
    arms
}

#[test]
fn every_shipped_menagerie_arm_runs_its_default_scenario_clean() {
    let arms = menagerie();
    assert!(arms.len() >= 10, "{arms:?}");
    for arm in &arms {
        let arm = arm.as_str();
        let text = String::from_utf8(ok(testbed().args(["robot", arm])).stdout).unwrap();
        assert!(text.contains("default scenario"), "{arm}: {text}");
        // An arm with a keyframe starts there (the M1013 has none).
        let keyed = std::fs::read_to_string(crate::util::repo_root().join(arm))
            .unwrap()
            .contains("<key ");
        assert_eq!(
            text.contains("(the model's home pose: its MJCF keyframe, inside the limits)"),
            keyed,
            "{arm}: {text}"
        );
        let s = json(&ok(testbed().args(["sim", "--json", "--robot", arm])));
        assert_eq!(s["finite"], true, "{arm}: {s}");
        assert_eq!(s["constraint_satisfied_after_tc"], true, "{arm}: {s}");
        assert_eq!(s["barrier_breached_steps"], 0, "{arm}: {s}");
    }
}

/// The attachment of a log whose arm came from `main` (with includes).
fn attached_model(log: &Path) -> String {
    let bytes = std::fs::read(log).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let index = summary
        .attachment_indexes
        .iter()
        .find(|a| a.name == "robot.urdf")
        .expect("the model is attached");
    let att = mcap::read::attachment(&bytes, index).unwrap();
    String::from_utf8(att.data.into_owned()).unwrap()
}

#[test]
fn an_mjcf_logs_attachment_holds_its_includes_and_replays_alone() {
    let models = tempfile::tempdir().unwrap();
    let data = crate::util::repo_root().join("arm-model/tests/data");
    for f in ["includes_defaults.xml", "included_arm.xml"] {
        std::fs::copy(data.join(f), models.path().join(f)).unwrap();
    }
    let runs = tempfile::tempdir().unwrap();
    let s = json(&ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--json",
            "--duration",
            "0.5",
            "--robot",
        ])
        .arg(models.path().join("includes_defaults.xml"))
        .arg("--runs-dir")
        .arg(runs.path())));
    let log = Path::new(s["log"].as_str().unwrap()).to_path_buf();
    let model = attached_model(&log);
    // The included file's joints are in the attachment, its tag is not.
    assert!(model.contains("name=\"a3\""), "{model}");
    assert!(!model.contains("<include"), "{model}");
    // Neither file exists any more: the log alone replays, exactly.
    drop(models);
    let r = json(&ok(testbed()
        .arg("replay")
        .arg(&log)
        .args(["--verify", "--json"])));
    assert_eq!(r["max_abs_torque_diff"], 0.0, "{r}");
    assert_eq!(r["dof"], 3, "{r}");
}
