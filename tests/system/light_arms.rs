//! Arms as public packages ship them (issue 27): feather-light links that no
//! gain holds at 1 kHz, motors too weak to hold the arm up, and URDFs in
//! Drake's dialect. Each runs clean or is explained by `testbed robot`.

use std::path::{Path, PathBuf};

use crate::util::{json, ok, testbed};

/// base → shoulder (about y, carries gravity) → a 2 kg upper arm →
/// `last` (about the upper arm's z) → `tip`, the tip's centre of mass on
/// `last`'s axis.
fn two_joint_arm(tip_mass: f64, tip_izz: f64, shoulder_limits: (f64, f64), effort: f64) -> String {
    let (lo, hi) = shoulder_limits;
    format!(
        r#"<robot name="light">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.2 0 0"/><mass value="2.0"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/></inertial></link>
  <link name="tip"><inertial><origin xyz="0 0 0"/><mass value="{tip_mass}"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="{tip_izz}"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 1 0"/><limit lower="{lo}" upper="{hi}" effort="{effort}" velocity="3"/></joint>
  <joint name="last" type="revolute"><parent link="upper"/><child link="tip"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" effort="5" velocity="3"/></joint>
</robot>
"#
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn robot_text(urdf: &Path) -> String {
    String::from_utf8(ok(testbed().arg("robot").arg(urdf)).stdout).unwrap()
}

/// The summary of `sim` on the arm's default scenario, which must end
/// finite, inside the envelope after T_c and without a breach at 1 kHz.
fn runs_clean(urdf: &Path) -> serde_json::Value {
    let s = json(&ok(testbed().args(["sim", "--json", "--robot"]).arg(urdf)));
    assert_eq!(s["finite"], true, "{s}");
    assert_eq!(s["constraint_satisfied_after_tc"], true, "{s}");
    assert_eq!(s["barrier_breached_steps"], 0, "{s}");
    assert_eq!(s["dt_s"], 1e-3, "{s}");
    s
}

/// A 1 g placeholder on the last joint (M⁻¹ 1e6): the barrier term alone
/// breaks the sampled loop at any gain (before issue 27 the run breached
/// the barrier on most steps). It moves under 1 % of the arm, so the default
/// scenario locks it, says why, and the rest runs clean.
#[test]
fn a_feather_light_placeholder_joint_is_locked_and_the_arm_runs_clean() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = write(
        dir.path(),
        "placeholder.urdf",
        &two_joint_arm(0.001, 1e-6, (-2.5, 2.5), 100.0),
    );
    let text = robot_text(&urdf);
    assert!(
        text.contains("warning: locked last: a placeholder") && text.contains("barrier term"),
        "{text}"
    );
    let s = runs_clean(&urdf);
    assert_eq!(s["dof"], 1, "{s}");
}

/// A 0.3 kg tool whose inertia about its own axis is 1e-7 kg m²: a real
/// part of the arm (13 % of its mass), so it gets armature instead, named
/// with its amount in `testbed robot`, and stays controlled.
#[test]
fn a_light_joint_that_moves_real_mass_gets_armature_and_runs_clean() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = write(
        dir.path(),
        "light_tool.urdf",
        &two_joint_arm(0.3, 1e-7, (-2.5, 2.5), 100.0),
    );
    let text = robot_text(&urdf);
    assert!(
        text.contains("armature") && text.contains("added to last ([plant] armature)"),
        "{text}"
    );
    assert!(text.contains("warning: armature"), "{text}");
    let s = runs_clean(&urdf);
    assert_eq!(s["dof"], 2, "{s}");
}

/// A shoulder whose gravity load at every posture its limits allow is six
/// times its effort limit: no controller holds it, so the default scenario
/// locks it (`robot` says so, naming the joint and both numbers) and the
/// elbow runs clean.
#[test]
fn gravity_beyond_an_effort_limit_locks_the_joint_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = write(
        dir.path(),
        "weak.urdf",
        &two_joint_arm(0.3, 1e-4, (-0.3, 0.3), 1.0),
    );
    let text = robot_text(&urdf);
    assert!(
        text.contains("warning: locked shoulder: gravity alone loads it with")
            && text.contains("beyond its effort limit 1 N m"),
        "{text}"
    );
    let s = runs_clean(&urdf);
    assert_eq!(s["dof"], 1, "{s}");
}

/// Drake's dialect: the base welded to a `world` the file never defines,
/// and `drake:` tags without `xmlns:drake`. Pinocchio and MuJoCo read it;
/// so does the testbed, saying what it assumed, and the arm runs.
#[test]
fn a_drake_style_urdf_loads_with_notes_and_runs() {
    let dir = tempfile::tempdir().unwrap();
    let text = two_joint_arm(0.3, 1e-4, (-2.5, 2.5), 100.0)
        .replace(
            "<link name=\"base\"/>",
            "<link name=\"base\"/><joint name=\"weld\" type=\"fixed\"><parent link=\"world\"/><child link=\"base\"/></joint>",
        )
        .replace(
            "velocity=\"3\"/></joint>",
            "velocity=\"3\" drake:acceleration=\"10\"/><drake:rotor_inertia value=\"0\"/></joint>",
        );
    let urdf = write(dir.path(), "drake_style.urdf", &text);
    let out = robot_text(&urdf);
    assert!(
        out.contains("note: XML namespace prefix 'drake' used without an xmlns declaration"),
        "{out}"
    );
    assert!(
        out.contains("note: joint 'weld' hangs from link 'world'") && out.contains("fixed world"),
        "{out}"
    );
    runs_clean(&urdf);
}
