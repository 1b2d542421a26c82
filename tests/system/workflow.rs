//! The newcomer's tasks of #29, one command each: change a setting without
//! writing a file (`--set`), export an arm's default scenario to edit
//! (`robot --write-scenario`), name a run's folder (`run --name`).

use crate::util::{fails, json, ok, repo_root, testbed};

#[test]
fn set_changes_one_key_checked_like_the_file() {
    let s = json(&ok(testbed().args([
        "sim",
        "--json",
        "--duration",
        "2.5",
        "--set",
        "controller.k1=20",
        "--set",
        "plant.engine=rapier",
    ])));
    assert_eq!(s["k1"], serde_json::json!([20.0, 20.0]), "{s}");
    assert!(
        s["scenario_source"]
            .as_str()
            .unwrap()
            .contains("--set controller.k1=20"),
        "{s}"
    );
    // The same key through a file gives the same run.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("k1.toml");
    std::fs::write(
        &file,
        "duration_s = 2.5\n[controller]\nk1 = 20.0\n[plant]\nengine = \"rapier\"\n",
    )
    .unwrap();
    let f = json(&ok(testbed()
        .args(["sim", "--json", "--scenario"])
        .arg(&file)));
    assert_eq!(f["metrics"], s["metrics"]);
    // Bad keys and values are refused, named.
    let err = fails(testbed().args(["sim", "--set", "controller.nope=1"]));
    assert!(
        err.contains("unknown field `nope`") && err.contains("--set controller.nope=1"),
        "{err}"
    );
    let err = fails(testbed().args(["sim", "--set", "duration_s=-1"]));
    assert!(err.contains("duration_s"), "{err}");
    let err = fails(testbed().args(["sim", "--set", "k1"]));
    assert!(err.contains("is not KEY=VALUE"), "{err}");
}

#[test]
fn robot_writes_its_default_scenario_as_an_editable_file() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("ur5.toml");
    let urdf = repo_root().join("robots/ur5.urdf");
    ok(testbed()
        .arg("robot")
        .arg(&urdf)
        .arg("--write-scenario")
        .arg(&file));
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.starts_with("# The default scenario"), "{text}");
    // It runs from anywhere, and is the run `--robot` makes.
    let from_file = json(&ok(testbed()
        .args(["sim", "--json", "--duration", "3", "--scenario"])
        .arg(&file)));
    let default = json(&ok(testbed()
        .args(["sim", "--json", "--duration", "3", "--robot"])
        .arg(&urdf)));
    assert_eq!(from_file["metrics"], default["metrics"]);
    assert_eq!(from_file["dof"], 6);
}

#[test]
fn a_named_run_folder_is_made_once() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str| {
        let mut c = testbed();
        c.args([
            "run",
            "--mode",
            "lockstep",
            "--json",
            "--duration",
            "1",
            "--name",
            name,
        ])
        .arg("--runs-dir")
        .arg(dir.path());
        c
    };
    let s = json(&ok(&mut run("baseline")));
    assert!(
        s["log"].as_str().unwrap().ends_with("baseline/run.mcap"),
        "{s}"
    );
    let before = std::fs::read(dir.path().join("baseline/run.mcap")).unwrap();
    let err = fails(&mut run("baseline"));
    assert!(err.contains("a run folder of that name exists"), "{err}");
    assert_eq!(
        std::fs::read(dir.path().join("baseline/run.mcap")).unwrap(),
        before
    );
    let err = fails(&mut run("../escape"));
    assert!(err.contains("not a run folder name"), "{err}");
}
