//! Arms with more joints than the old wire's 12 (issue 27): dual arms and
//! humanoid upper bodies run; an arm past the wire's capacity is refused by
//! name, before anything starts, by every command that would run it.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use crate::util::{fails, json, ok, testbed};

/// A serial chain of `n` revolute joints, alternating about z and y so that
/// some joints carry gravity and some do not. Links get lighter towards the
/// tip, as real arms do; the effort limits cover the chain's gravity load.
fn chain_urdf(n: usize) -> String {
    let mut s = String::from(r#"<robot name="chain"><link name="base"/>"#);
    for i in 0..n {
        let mass = 2.0 * 0.93f64.powi(i as i32);
        let inertia = 0.01 * mass;
        let _ = write!(
            s,
            r#"<link name="l{i}"><inertial><origin xyz="0 0 0.04"/><mass value="{mass}"/><inertia ixx="{inertia}" ixy="0" ixz="0" iyy="{inertia}" iyz="0" izz="{inertia}"/></inertial></link>"#
        );
        let parent = if i == 0 {
            "base".to_string()
        } else {
            format!("l{}", i - 1)
        };
        let axis = if i % 2 == 0 { "0 0 1" } else { "0 1 0" };
        let z = if i == 0 { 0.0 } else { 0.08 };
        let _ = write!(
            s,
            r#"<joint name="j{i}" type="revolute"><parent link="{parent}"/><child link="l{i}"/><origin xyz="0 0 {z}"/><axis xyz="{axis}"/><limit lower="-2.5" upper="2.5" effort="1000" velocity="3"/></joint>"#
        );
    }
    s.push_str("</robot>\n");
    s
}

fn write_chain(dir: &Path, n: usize) -> PathBuf {
    let path = dir.join(format!("chain{n}.urdf"));
    std::fs::write(&path, chain_urdf(n)).unwrap();
    path
}

/// A 14-joint (dual arm) and a 30-joint chain run their default scenario in
/// process and in lockstep, finite and bit-identical; `sim` once panicked
/// on 14 joints (a slice of the wire's 12-joint arrays).
#[test]
fn chains_of_14_and_30_joints_run_in_sim_and_lockstep() {
    let dir = tempfile::tempdir().unwrap();
    for n in [14, 30] {
        let urdf = write_chain(dir.path(), n);
        let robot = ok(testbed().arg("robot").arg(&urdf));
        let text = String::from_utf8_lossy(&robot.stdout);
        assert!(text.contains(&format!("{n} actuated joints")), "{text}");
        assert!(!text.contains("wire carries at most"), "{text}");
        let (a, b) = (
            dir.path().join(format!("sim{n}.csv")),
            dir.path().join(format!("lockstep{n}.csv")),
        );
        let sim = json(&ok(testbed()
            .args(["sim", "--json", "--duration", "0.5", "--robot"])
            .arg(&urdf)
            .arg("--csv")
            .arg(&a)));
        let run = json(&ok(testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--json",
                "--duration",
                "0.5",
                "--robot",
            ])
            .arg(&urdf)
            .arg("--runs-dir")
            .arg(dir.path())
            .arg("--csv")
            .arg(&b)));
        for s in [&sim, &run] {
            assert_eq!(s["finite"], true, "{n} joints: {s}");
            assert_eq!(s["dt_s"], 1e-3, "{n} joints: {s}");
        }
        let header = std::fs::read_to_string(&a).unwrap();
        let first = header.lines().next().unwrap();
        assert!(
            first.contains(&format!(",q{},", n - 1)) && !first.contains(&format!(",q{n},")),
            "{n} joints: CSV header {first}"
        );
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "{n} joints: lockstep differs from sim"
        );
    }
}

/// 33 joints, one past the wire: `sim` and `run` refuse before starting,
/// naming the robot, the count, the joint past the limit and the remedy;
/// `robot` still describes the arm and says the same.
#[test]
fn a_33_joint_chain_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = write_chain(dir.path(), 33);
    let runs = dir.path().join("runs");
    let runs = runs.to_str().unwrap();
    for args in [
        vec!["sim"],
        vec!["run", "--mode", "lockstep", "--runs-dir", runs],
        vec!["compare", "--laws", "pd"],
    ] {
        let err = fails(testbed().args(&args).arg("--robot").arg(&urdf));
        for want in [
            "chain33.urdf",
            "33 controlled joints",
            "at most 32",
            "[plant.lock]",
            "j32",
        ] {
            assert!(err.contains(want), "{args:?}: no {want:?} in {err}");
        }
    }
    // Refused before anything started: no run folder.
    assert!(!Path::new(runs).exists(), "a run folder was made");
    let robot = ok(testbed().arg("robot").arg(&urdf));
    let text = String::from_utf8_lossy(&robot.stdout);
    assert!(text.contains("33 actuated joints"), "{text}");
    assert!(
        text.contains("warning: 33 controlled joints; the wire carries at most 32"),
        "{text}"
    );
}
