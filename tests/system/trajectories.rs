//! References as a researcher writes them (#29): minimum-jerk moves through
//! waypoints and a trajectory from a CSV file run the same in process and
//! as four processes, in real time too; a bad file is named with its row
//! and column; a log replays without the file.

use std::path::Path;

use crate::util::{assert_same_csv, csv_of, fails, json, ok, ran, repo_root, testbed};

#[test]
fn waypoints_and_a_trajectory_file_run_bit_identical_in_sim_and_lockstep() {
    let dir = tempfile::tempdir().unwrap();
    let runs = dir.path().join("runs");
    for name in ["iiwa_waypoints", "iiwa_csv"] {
        let sim = csv_of(&["sim", "--scenario", name], dir.path(), "sim.csv");
        let runs = runs.to_str().unwrap();
        let args = [
            "run",
            "--mode",
            "lockstep",
            "--scenario",
            name,
            "--runs-dir",
            runs,
        ];
        let lockstep = csv_of(&args, dir.path(), "lockstep.csv");
        assert_same_csv(name, &sim, &lockstep);
        let s = json(&ok(testbed().args(["sim", "--json", "--scenario", name])));
        assert_eq!(s["constraint_satisfied_after_tc"], true, "{name}: {s}");
        assert_eq!(s["dof"], 7, "{name}: {s}");
    }
}

#[test]
fn waypoints_and_a_trajectory_file_run_in_realtime() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["iiwa_waypoints", "iiwa_csv"] {
        let out = ran(testbed()
            .args([
                "run",
                "--json",
                "--duration",
                "3",
                "--scenario",
                name,
                "--runs-dir",
            ])
            .arg(dir.path()));
        let s = json(&out);
        assert_eq!(s["finite"], true, "{name}: {s}");
        assert_eq!(s["steps"], 3000, "{name}: {s}");
    }
}

/// A scenario in `dir` whose reference is `csv` (written as `traj.csv`).
fn scenario_with(dir: &Path, csv: &str) -> std::path::PathBuf {
    let shipped = repo_root().join("scenarios/iiwa_csv.toml");
    let text = std::fs::read_to_string(shipped).unwrap();
    let robot = repo_root().join("robots/iiwa14.urdf");
    let text = text
        .replace("../robots/iiwa14.urdf", robot.to_str().unwrap())
        .replace("iiwa_recorded.csv", "traj.csv");
    std::fs::write(dir.join("traj.csv"), csv).unwrap();
    let path = dir.join("s.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_bad_trajectory_file_is_named_with_its_row_and_column() {
    let dir = tempfile::tempdir().unwrap();
    // The columns are the iiwa's joints, by name.
    let header = "t,iiwa_joint_1,iiwa_joint_2,iiwa_joint_3,iiwa_joint_4,iiwa_joint_5,iiwa_joint_6,iiwa_joint_7\n";
    for (rows, want) in [
        (
            "0,0,0,0,0,0,0,0\n1,0,0,x,0,0,0,0\n",
            "traj.csv: row 3, column 4 ('iiwa_joint_3'): \"x\" is not a number",
        ),
        (
            "0,0,0,0,0,0,0,0\n0,0,0,0,0,0,0,0\n",
            "traj.csv: row 3, column 1 ('t'): time 0 does not come after",
        ),
        (
            "0,0,0,0,0,0,0,0\n1,0,0,0,0,0,0,inf\n",
            "row 3, column 8 ('iiwa_joint_7'): inf is not finite",
        ),
        (
            "0,0,0,0,0,0,0\n1,0,0,0,0,0,0\n",
            "traj.csv: row 1, column 8 ('iiwa_joint_7'): no column for joint iiwa_joint_7",
        ),
    ] {
        let header = if want.contains("no column") {
            "t,iiwa_joint_1,iiwa_joint_2,iiwa_joint_3,iiwa_joint_4,iiwa_joint_5,iiwa_joint_6\n"
        } else {
            header
        };
        let s = scenario_with(dir.path(), &format!("{header}{rows}"));
        let err = fails(testbed().args(["sim", "--scenario"]).arg(&s));
        assert!(err.contains(want), "{want}\n{err}");
        assert!(err.contains("s.toml"), "{err}");
    }
    std::fs::remove_file(dir.path().join("traj.csv")).unwrap();
    let err = fails(
        testbed()
            .args(["sim", "--scenario"])
            .arg(dir.path().join("s.toml")),
    );
    assert!(err.contains("traj.csv"), "{err}");
}

/// The log keeps the samples, so the file may go: replay verifies the run.
#[test]
fn a_log_of_a_file_driven_run_verifies_without_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from(
        "t,iiwa_joint_1,iiwa_joint_2,iiwa_joint_3,iiwa_joint_4,iiwa_joint_5,iiwa_joint_6,iiwa_joint_7\n",
    );
    for k in 0..=20 {
        let t = k as f64 * 0.1;
        let v = 0.2 * (t * 1.5).sin();
        csv += &format!("{t},{v},0.5,{v},-1.3,{v},0.5,{v}\n");
    }
    let s = scenario_with(dir.path(), &csv);
    let runs = dir.path().join("runs");
    let out = ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--json",
            "--duration",
            "2",
            "--scenario",
        ])
        .arg(&s)
        .arg("--runs-dir")
        .arg(&runs));
    let log = json(&out)["log"].as_str().unwrap().to_string();
    std::fs::remove_file(dir.path().join("traj.csv")).unwrap();
    ok(testbed().args(["replay", "--verify", &log]));
}
