//! Any URDF arm: the shipped arms end to end, and URDFs that cannot be used.

use crate::util::{fails, json, ok, testbed};

const ARMS: [&str; 8] = [
    "robots/two_link.urdf",
    "robots/three_link_planar.urdf",
    "robots/ur5.urdf",
    "robots/iiwa14.urdf",
    "robots/panda.urdf",
    "robots/xarm7.urdf",
    "robots/so101.urdf",
    "robots/z1.urdf",
];

/// Each shipped arm runs its default scenario to the end at 1 kHz, in
/// process and in lockstep, with the same bits, finite signals, the
/// envelope kept after T_c and no barrier breach.
#[test]
fn every_shipped_arm_runs_its_default_scenario() {
    let dir = tempfile::tempdir().unwrap();
    for arm in ARMS {
        let (a, b) = (dir.path().join("sim.csv"), dir.path().join("lockstep.csv"));
        let sim = json(&ok(testbed()
            .args(["sim", "--json", "--robot", arm, "--csv"])
            .arg(&a)));
        let run = json(&ok(testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--json",
                "--robot",
                arm,
                "--runs-dir",
            ])
            .arg(dir.path())
            .arg("--csv")
            .arg(&b)));
        for s in [&sim, &run] {
            assert_eq!(s["finite"], true, "{arm}: {s}");
            assert_eq!(s["constraint_satisfied_after_tc"], true, "{arm}: {s}");
            assert_eq!(s["barrier_breached_steps"], 0, "{arm}: {s}");
            assert_eq!(s["dt_s"], 1e-3, "{arm}: {s}");
            assert!(
                (s["duration_s"].as_f64().unwrap() - 10.0).abs() < 1e-3,
                "{arm}: {s}"
            );
        }
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "{arm}: lockstep differs from sim"
        );
    }
}

#[test]
fn robot_command_reports_joint_order_and_masses() {
    let out = ok(testbed().args(["robot", "robots/ur5.urdf"]));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("6 actuated joints"), "{text}");
    let order: Vec<usize> = [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    .iter()
    .map(|j| text.find(j).unwrap())
    .collect();
    assert!(
        order.windows(2).all(|w| w[0] < w[1]),
        "joints not in tree order: {text}"
    );
    assert!(text.contains("merged fixed joint ee_fixed_joint"), "{text}");
    assert!(text.contains("moving mass 16.9939 kg"), "{text}");
}

/// The 7-joint KUKA iiwa 14: read and merged; per-joint gains at 1 kHz.
#[test]
fn the_seven_joint_iiwa_loads_with_per_joint_gains() {
    let text =
        String::from_utf8(ok(testbed().args(["robot", "robots/iiwa14.urdf"])).stdout).unwrap();
    assert!(text.contains("7 actuated joints"), "{text}");
    assert!(text.contains("merged fixed joint iiwa_joint_ee"), "{text}");
    assert!(text.contains("moving mass 25.6100 kg"), "{text}");
    assert!(text.contains("10 s at 1000 Hz"), "{text}");
    assert!(text.contains("why K1"), "{text}");
}

/// The Panda: its mimic finger is coupled, the default scenario locks the
/// fingers, and the log records both.
#[test]
fn panda_fingers_are_mimic_and_locked_by_default() {
    let text =
        String::from_utf8(ok(testbed().args(["robot", "robots/panda.urdf"])).stdout).unwrap();
    assert!(
        text.contains("mimic joint panda_finger_joint2 (prismatic) = 1 × panda_finger_joint1"),
        "{text}"
    );
    assert!(
        text.contains("locked panda_finger_joint1 at 0.0200"),
        "{text}"
    );
    assert!(
        text.contains("(URDF <dynamics>, MJCF damping and frictionloss) act in the plant"),
        "{text}"
    );
    let dir = tempfile::tempdir().unwrap();
    let s = json(&ok(testbed()
        .args(["run", "--mode", "lockstep", "--json", "--duration", "0.2"])
        .args(["--robot", "robots/panda.urdf", "--runs-dir"])
        .arg(dir.path())));
    assert_eq!(s["dof"], 7, "{s}");
    let log = s["log"].as_str().unwrap();
    let bytes = std::fs::read(log).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let idx = summary
        .metadata_indexes
        .iter()
        .find(|m| m.name == "testbed.run")
        .unwrap();
    let meta = mcap::read::metadata(&bytes, idx).unwrap();
    assert_eq!(
        meta.metadata["locked_joints"],
        "panda_finger_joint1=0.02,panda_finger_joint2=0.02 (mimics panda_finger_joint1)"
    );
    assert!(meta.metadata["k2"].starts_with('['), "{:?}", meta.metadata);
}

/// The SO-ARM101 lists its joints from the gripper inwards; the testbed
/// orders them from the root, and locks the gripper.
#[test]
fn joints_are_in_tree_order_and_the_gripper_is_locked() {
    let text =
        String::from_utf8(ok(testbed().args(["robot", "robots/so101.urdf"])).stdout).unwrap();
    let pan = text.find("  0  shoulder_pan").unwrap();
    let grip = text.find("gripper ").unwrap();
    assert!(pan < grip, "{text}");
    assert!(text.contains("locked gripper at"), "{text}");
    assert!(text.contains("ignored link"), "{text}");
}

/// Per-joint gains from a scenario, in both barrier modes; wrong lengths
/// and bad locks are errors naming the key.
#[test]
fn per_joint_gains_and_locks_from_a_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let robots = crate::util::repo_root().join("robots");
    for barrier in ["per-joint", "norm"] {
        let f = dir.path().join(format!("{barrier}.toml"));
        std::fs::write(
            &f,
            format!(
                "robot = \"{}/two_link.urdf\"\nduration_s = 4.0\n[controller]\nk1 = [15.0, 20.0]\nk2 = [15.0, 10.0]\nbarrier = \"{barrier}\"\n",
                robots.display()
            ),
        )
        .unwrap();
        let s = json(&ok(testbed().args(["sim", "--json", "--scenario"]).arg(&f)));
        assert_eq!(s["constraint_satisfied_after_tc"], true, "{barrier}: {s}");
        assert_eq!(s["k2"], serde_json::json!([15.0, 10.0]), "{s}");
    }
    let cases = [
        (
            "[controller]\nk2 = [15.0]\n",
            "controller.k2 = 1 entries is invalid",
        ),
        ("[controller]\nk1 = [15.0, nan]\n", "controller.k1[1] = NaN"),
        (
            "[plant.lock]\nghost = 0.0\n",
            "plant.lock.ghost = 0 is invalid",
        ),
        ("[plant.lock]\njoint1 = 9.0\n", "within the joint's limits"),
        ("[plant]\narmature = [-1.0, 0.0]\n", "plant.armature[0]"),
    ];
    for (i, (body, needle)) in cases.iter().enumerate() {
        let f = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&f, body).unwrap();
        let err = fails(testbed().args(["sim", "--scenario"]).arg(&f));
        assert!(
            err.contains(needle) && err.contains(&format!("bad{i}.toml")),
            "{body}: {err}"
        );
    }
}

/// URDFs a user may bring that the plant cannot simulate: each is a clear
/// error naming the file and what is wrong, with a non-zero exit, never a panic.
#[test]
fn malformed_and_unsupported_urdfs_are_clear_errors() {
    let link = |name: &str, mass: &str, inertia: &str| {
        format!(
            r#"<link name="{name}"><inertial><mass value="{mass}"/><inertia {inertia}/></inertial></link>"#
        )
    };
    let good_i = r#"ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1""#;
    let joint = |name: &str, kind: &str, parent: &str, child: &str, extra: &str| {
        format!(
            r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/>{extra}</joint>"#
        )
    };
    let robot = |body: String| format!(r#"<robot name="r"><link name="base"/>{body}</robot>"#);
    let a = link("a", "1", good_i);
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "not_xml",
            "this is not xml".into(),
            "not XML: it starts with",
        ),
        ("empty", String::new(), "not XML: the file is empty"),
        (
            "merge_conflict",
            "<<<<<<< HEAD\n<robot name=\"r\"/>\n".into(),
            "line 1 is a merge-conflict marker",
        ),
        (
            "launch_file",
            "<launch><node name=\"n\"/></launch>".into(),
            "root element is <launch>, not <robot>",
        ),
        (
            "missing_parent",
            robot(format!("{a}{}", joint("j", "revolute", "ghost", "a", ""))),
            "parent link 'ghost' does not exist",
        ),
        (
            "cycle",
            robot(format!(
                "{a}{}{}",
                joint("j1", "revolute", "base", "a", ""),
                joint("j2", "revolute", "a", "base", "")
            )),
            "loop",
        ),
        (
            "not_positive_definite",
            robot(format!(
                "{}{}",
                link(
                    "a",
                    "1",
                    r#"ixx="0.1" ixy="0.2" ixz="0" iyy="0.1" iyz="0" izz="0.1""#
                ),
                joint("j", "revolute", "base", "a", "")
            )),
            "link 'a': the inertia tensor is not positive semi-definite",
        ),
        (
            "negative_mass",
            robot(format!(
                "{}{}",
                link("a", "-2", good_i),
                joint("j", "revolute", "base", "a", "")
            )),
            "link 'a': mass -2 is negative",
        ),
        (
            "floating",
            robot(format!("{a}{}", joint("j", "floating", "base", "a", ""))),
            "joint 'j' is floating",
        ),
        (
            "planar",
            robot(format!("{a}{}", joint("j", "planar", "base", "a", ""))),
            "joint 'j' is planar",
        ),
        (
            "mimic",
            robot(format!(
                "{a}{}",
                joint("j", "revolute", "base", "a", r#"<mimic joint="k"/>"#)
            )),
            "joint 'j' has <mimic>: it follows joint 'k', which does not exist",
        ),
        (
            "bad_number",
            robot(format!(
                "{}{}",
                link("a", "abc", good_i),
                joint("j", "revolute", "base", "a", "")
            )),
            "not a valid URDF",
        ),
        (
            "nan_axis",
            robot(format!(
                "{a}{}",
                joint("j", "revolute", "base", "a", "").replace("0 0 1", "0 nan 1")
            )),
            "joint 'j' axis",
        ),
        (
            "limits_reversed",
            robot(format!(
                "{a}{}",
                joint("j", "revolute", "base", "a", "")
                    .replace(r#"lower="-1" upper="1""#, r#"lower="1" upper="-1""#)
            )),
            "limit lower 1 is above upper -1",
        ),
        (
            "duplicate_link",
            robot(format!("{a}{a}{}", joint("j", "revolute", "base", "a", ""))),
            "two links are named 'a'",
        ),
        (
            "no_actuated_joint",
            robot(format!("{a}{}", joint("j", "fixed", "base", "a", ""))),
            "no actuated",
        ),
        (
            "massless_moving_link",
            robot(format!(
                "<link name=\"a\"/>{}",
                joint("j", "revolute", "base", "a", "")
            )),
            "no mass",
        ),
        ("two_roots", robot(a.clone()), "several root links"),
        (
            "mimic_of_fixed",
            robot(format!(
                "{a}{}{}{}",
                link("b", "1", good_i),
                joint("f", "fixed", "base", "a", ""),
                joint("j", "revolute", "a", "b", r#"<mimic joint="f"/>"#)
            )),
            "it follows joint 'f', which is fixed",
        ),
        (
            "floating_inside",
            robot(format!(
                "{a}{}{}{}",
                link("b", "1", good_i),
                joint("j", "revolute", "base", "a", ""),
                joint("free", "floating", "a", "b", "")
            )),
            "joint 'free' is floating",
        ),
    ];
    assert!(cases.len() >= 10);
    let dir = tempfile::tempdir().unwrap();
    for (name, text, needle) in &cases {
        let path = dir.path().join(format!("{name}.urdf"));
        std::fs::write(&path, text).unwrap();
        for cmd in [vec!["robot"], vec!["sim", "--duration", "0.1", "--robot"]] {
            let err = fails(testbed().args(&cmd).arg(&path));
            assert!(
                err.contains(needle),
                "{name} ({cmd:?}): expected '{needle}' in: {err}"
            );
            assert!(
                err.contains(&format!("{name}.urdf")),
                "{name}: error does not name the file: {err}"
            );
        }
    }
    let err = fails(testbed().args(["robot", "no/such.urdf"]));
    assert!(err.contains("no/such.urdf"), "{err}");
}

/// The envelope taken from the URDF's joint limits (paper Section III),
/// in both barrier modes.
#[test]
fn envelope_from_joint_limits_is_respected() {
    let dir = tempfile::tempdir().unwrap();
    let shipped =
        std::fs::read_to_string(crate::util::repo_root().join("scenarios/three_link_limits.toml"))
            .unwrap();
    let abs_robots = crate::util::repo_root().join("robots");
    for barrier in ["per-joint", "norm"] {
        let text = shipped
            .replace("k2 = 5.0", &format!("k2 = 5.0\nbarrier = \"{barrier}\""))
            .replace("../robots", abs_robots.to_str().unwrap());
        let path = dir.path().join(format!("{barrier}.toml"));
        std::fs::write(&path, text).unwrap();
        let s = json(&ok(testbed()
            .args(["sim", "--json", "--scenario"])
            .arg(&path)));
        assert_eq!(s["constraint_satisfied_after_tc"], true, "{barrier}: {s}");
        assert_eq!(s["finite"], true, "{barrier}: {s}");
    }
    // A continuous joint has no limits to take an envelope from.
    let cont = dir.path().join("cont.urdf");
    std::fs::write(
        &cont,
        std::fs::read_to_string(crate::util::repo_root().join("robots/three_link_planar.urdf"))
            .unwrap()
            .replacen("type=\"revolute\"", "type=\"continuous\"", 1),
    )
    .unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        shipped.replace("../robots/three_link_planar.urdf", cont.to_str().unwrap()),
    )
    .unwrap();
    let err = fails(testbed().args(["sim", "--scenario"]).arg(&bad));
    assert!(
        err.contains("bad.toml") && err.contains("joint 'joint1' has no position limits"),
        "{err}"
    );
}

/// #38 item 3: `sim` says what it changed and why (the panda's fingers
/// locked, on stderr and in `--json`), and warns where the reference loads
/// a joint past 80 % of its effort, or a joint has no limit at all, in
/// `sim` and in `robot` alike.
#[test]
fn sim_and_robot_say_what_they_changed_and_where_effort_runs_short() {
    let out = ok(testbed().args(["sim", "--json", "--robot", "robots/panda.urdf"]));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("testbed: note: locked panda_finger_joint1 at 0.0200: a gripper"),
        "{stderr}"
    );
    let changes = json(&out)["changes"].clone();
    assert!(
        changes.as_array().unwrap().iter().any(|c| c
            .as_str()
            .unwrap()
            .starts_with("locked panda_finger_joint1")),
        "{changes}"
    );
    // The paper's reference needs 7.79 N m at the shoulder, 1.52 at the
    // elbow: 8 N m is 97 %, 2 N m 76 % (not warned).
    let dir = tempfile::tempdir().unwrap();
    let weak = dir.path().join("weak.toml");
    std::fs::write(&weak, "[plant]\neffort_limit = [8.0, 2.0]\n").unwrap();
    let out = ok(testbed().args(["sim", "--scenario"]).arg(&weak));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("joint 'joint1': the reference needs up to")
            && stderr.contains("97 % of its effort limit 8 N m: expect saturation"),
        "{stderr}"
    );
    assert!(!stderr.contains("'joint2'"), "{stderr}");
    // No effort limit: said by `robot` and by `sim`.
    let text = std::fs::read_to_string(crate::util::repo_root().join("robots/two_link.urdf"))
        .unwrap()
        .replace("effort=", "data-effort=");
    let free = dir.path().join("free.urdf");
    std::fs::write(&free, text).unwrap();
    let said = "no effort limit for joint1, joint2";
    let robot = ok(testbed().arg("robot").arg(&free));
    let robot = String::from_utf8_lossy(&robot.stdout);
    assert!(robot.contains(&format!("warning: {said}")), "{robot}");
    let sim = ok(testbed().args(["sim", "--robot"]).arg(&free));
    let stderr = String::from_utf8_lossy(&sim.stderr);
    assert!(
        stderr.contains(&format!("testbed: note: {said}")),
        "{stderr}"
    );
    // A tensor taken otherwise than written (a 10 mg tool with the identity
    // tensor) is said before the run too, not only by `robot`.
    let tool = r#"<link name="tool"><inertial><mass value="0.00001"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="tool_joint" type="fixed"><parent link="link2"/><child link="tool"/></joint></robot>"#;
    let text = std::fs::read_to_string(crate::util::repo_root().join("robots/two_link.urdf"))
        .unwrap()
        .replace("</robot>", tool);
    let tooled = dir.path().join("tooled.urdf");
    std::fs::write(&tooled, text).unwrap();
    let sim = ok(testbed().args(["sim", "--robot"]).arg(&tooled));
    let stderr = String::from_utf8_lossy(&sim.stderr);
    assert!(
        stderr.contains("testbed: note: link 'tool'")
            && stderr.contains("its tensor replaced by a uniform sphere's"),
        "{stderr}"
    );
}
