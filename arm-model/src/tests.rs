//! The loader on small URDFs written inline.

#![allow(clippy::unwrap_used)]

use super::*;

fn arm(joints: &str, links: &str) -> String {
    format!(
        r#"<robot name="t">
  <link name="base"/>
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  {links}
  {joints}
</robot>"#
    )
}

const J1: &str = r#"<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>"#;

fn err(text: &str) -> String {
    ArmModel::from_urdf_str(text).unwrap_err().to_string()
}

#[test]
fn the_two_link_arm_reads_as_specified() {
    let m = ArmModel::from_urdf_str(crate::TWO_LINK_URDF).unwrap();
    assert_eq!(m.joint_names(), ["joint1", "joint2"]);
    assert_eq!(m.links[m.root].name, "base_link");
    assert!((m.moving_mass() - 2.85).abs() < 1e-12);
    assert_eq!(m.joints[0].axis, [0.0, -1.0, 0.0]);
    assert_eq!(m.joints[1].origin.xyz, [0.35, 0.0, 0.0]);
}

/// The 0.2 kg tool on a fixed joint 0.2 m along link3 (0.5 kg, COM at
/// 0.1 m, I = 0.5·0.2²/12 about it) folds into link3 by the parallel-axis theorem.
#[test]
fn fixed_joint_mass_merges_into_the_parent() {
    let m = ArmModel::from_urdf_str(include_str!("../../robots/three_link_planar.urdf")).unwrap();
    assert_eq!(m.dof(), 3);
    assert!(m.links.iter().all(|l| l.name != "tool"));
    let l3 = m.links.iter().find(|l| l.name == "link3").unwrap();
    let c = (0.5 * 0.1 + 0.2 * 0.2) / 0.7;
    assert!((l3.mass - 0.7).abs() < 1e-12);
    assert!((l3.inertial_origin.xyz[0] - c).abs() < 1e-12);
    let i_rod = 0.00166667; // 0.5·0.2²/12 as the URDF writes it
    let iyy = i_rod + 0.5 * (0.1 - c) * (0.1 - c) + 0.0001 + 0.2 * (0.2 - c) * (0.2 - c);
    assert!(
        (l3.inertia[3] - iyy).abs() < 1e-9,
        "{} vs {iyy}",
        l3.inertia[3]
    );
    assert_eq!(m.merged, ["tool_mount (tool into link3)"]);
}

#[test]
fn a_joint_that_moves_no_mass_is_listed() {
    let j2 = J1
        .replace("j1", "j2")
        .replace("base", "a")
        .replace("<child link=\"a\"/>", "<child link=\"b\"/>");
    let m = ArmModel::from_urdf_str(&arm(&format!("{J1}{j2}"), "<link name=\"b\"/>")).unwrap();
    assert_eq!(m.joints_moving_no_mass(), ["j2"]);
}

#[test]
fn malformed_urdfs_are_named_errors() {
    assert!(err("not xml at all").starts_with("not a valid URDF"));
    let missing = J1.replace("<child link=\"a\"/>", "<child link=\"ghost\"/>");
    assert_eq!(
        err(&arm(&missing, "")),
        "joint 'j1': child link 'ghost' does not exist"
    );
    let floating =
        r#"<joint name="free" type="floating"><parent link="base"/><child link="a"/></joint>"#;
    assert!(err(&arm(floating, "")).contains("joint 'free' is floating"));
    let mimic = J1.replace("</joint>", "<mimic joint=\"j0\"/></joint>");
    assert!(err(&arm(&mimic, "")).contains("<mimic>: it follows joint 'j0', which does not exist"));
    let neg = r#"<link name="b"><inertial><mass value="-1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>"#;
    let jb = J1.replace("j1", "j2").replace("\"a\"", "\"b\"");
    assert_eq!(
        err(&arm(&format!("{J1}{jb}"), neg)),
        "link 'b': mass -1 is negative"
    );
    let tri = r#"<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.5"/></inertial></link>"#;
    // No rigid body has these moments, yet the arm simulates: noted, not refused.
    let noted = ArmModel::from_urdf_str(&arm(&format!("{J1}{jb}"), tri)).unwrap();
    assert!(
        noted.notes.iter().any(|n| n.starts_with("link 'b'")
            && n.contains("break the triangle inequality by 60 %")
            && n.contains("simulated as given")),
        "{:?}",
        noted.notes
    );
    let loop_ = J1.replace("j1", "back").replace(
        "<parent link=\"base\"/><child link=\"a\"/>",
        "<parent link=\"a\"/><child link=\"base\"/>",
    );
    assert!(err(&arm(&format!("{J1}{loop_}"), "")).contains("loop"));
    let bad = J1.replace("lower=\"-1\" upper=\"1\"", "lower=\"1\" upper=\"-1\"");
    assert!(err(&arm(&bad, "")).contains("limit lower 1 is above upper -1"));
    // Beyond any robot (and overflowing its dynamics): refused by name.
    let far = J1.replace("<axis", "<origin xyz=\"1e300 0 0\"/><axis");
    assert!(err(&arm(&far, "")).contains("joint 'j1' origin xyz = 1e300 is invalid"));
    let heavy = arm(J1, "").replace("<mass value=\"1\"/>", "<mass value=\"1e20\"/>");
    assert!(err(&heavy).contains("link 'a' mass = 1e20 is invalid: it must be at most 1e6 kg"));
    let nan = J1.replace("0 0 1", "0 NaN 1");
    assert!(err(&arm(&nan, "")).contains("joint 'j1' axis"));
    assert!(err(&arm("", "")).contains("several root links"));
}

fn link(name: &str, mass: &str, inertia: &str) -> String {
    format!(
        r#"<link name="{name}"><inertial><mass value="{mass}"/><inertia {inertia}/></inertial></link>"#
    )
}

fn joint(name: &str, kind: &str, parent: &str, child: &str, extra: &str) -> String {
    format!(
        r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/>{extra}</joint>"#
    )
}

const I: &str = r#"ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1""#;

/// What nearly every published URDF has: a massless fixed root listing an
/// inertia, a frame link of 1e-9 kg with zero inertia, a point mass.
#[test]
fn real_world_mass_properties_are_accepted() {
    let text = format!(
        r#"<robot name="r">{}{}{}{}{}{}{}</robot>"#,
        link("base", "0", I),
        link("a", "1", I),
        link(
            "frame",
            "1e-9",
            r#"ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0""#
        ),
        link(
            "tip",
            "0.5",
            r#"ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0""#
        ),
        joint("j1", "revolute", "base", "a", ""),
        joint("f", "revolute", "a", "frame", ""),
        joint("j3", "revolute", "frame", "tip", ""),
    );
    let m = ArmModel::from_urdf_str(&text).unwrap();
    assert_eq!(m.joint_names(), ["j1", "f", "j3"]);
    assert_eq!(m.ignored.len(), 1);
    assert_eq!(m.ignored[0].name, "frame");
    assert!(
        m.ignored[0].reason.contains("negligible"),
        "{:?}",
        m.ignored
    );
    // 'f' carries the tip's point mass, so it moves mass.
    assert!(m.joints_moving_no_mass().is_empty());
}

#[test]
fn a_leftover_inertia_on_a_massless_moving_link_is_ignored_and_listed() {
    let text = format!(
        r#"<robot name="r"><link name="base"/>{}{}{}{}</robot>"#,
        link("a", "1", I),
        link("b", "0", I),
        joint("j1", "revolute", "base", "a", ""),
        joint("j2", "fixed", "a", "b", ""),
    );
    let m = ArmModel::from_urdf_str(&text).unwrap();
    assert_eq!(m.ignored[0].name, "b");
    assert!(m.ignored[0].reason.contains("zero mass"));
    assert!((m.moving_mass() - 1.0).abs() < 1e-15);
}

#[test]
fn joints_are_in_tree_order_whatever_the_file_order() {
    let text = format!(
        r#"<robot name="r"><link name="base"/>{}{}{}{}</robot>"#,
        link("a", "1", I),
        link("b", "1", I),
        joint("second", "revolute", "a", "b", ""),
        joint("first", "revolute", "base", "a", ""),
    );
    assert_eq!(
        ArmModel::from_urdf_str(&text).unwrap().joint_names(),
        ["first", "second"]
    );
}

fn fingers(extra2: &str) -> String {
    format!(
        r#"<robot name="r"><link name="base"/>{}{}{}{}{}{}</robot>"#,
        link("a", "1", I),
        link("f1", "0.1", I),
        link("f2", "0.1", I),
        joint("arm", "revolute", "base", "a", ""),
        joint("finger1", "prismatic", "a", "f1", ""),
        joint("finger2", "prismatic", "a", "f2", extra2),
    )
}

#[test]
fn a_mimic_joint_is_coupled_not_controlled() {
    let m = ArmModel::from_urdf_str(&fingers(
        r#"<mimic joint="finger1" multiplier="-2" offset="0.1"/>"#,
    ))
    .unwrap();
    assert_eq!(m.joint_names(), ["arm", "finger1"]);
    assert_eq!(m.mimic.len(), 1);
    let c = &m.mimic[0];
    assert_eq!(m.joints[c.joint].name, "finger2");
    assert_eq!((c.leader, c.multiplier, c.offset), (1, -2.0, 0.1));
}

#[test]
fn a_chain_of_mimics_composes_to_its_first_leader() {
    let text = format!(
        r#"<robot name="r"><link name="base"/>{}{}{}{}{}{}</robot>"#,
        link("a", "1", I),
        link("b", "1", I),
        link("c", "1", I),
        joint("j1", "revolute", "base", "a", ""),
        joint(
            "j2",
            "revolute",
            "a",
            "b",
            r#"<mimic joint="j1" multiplier="2" offset="1"/>"#
        ),
        joint(
            "j3",
            "revolute",
            "b",
            "c",
            r#"<mimic joint="j2" multiplier="3" offset="0.5"/>"#
        ),
    );
    let m = ArmModel::from_urdf_str(&text).unwrap();
    let j3 = m
        .mimic
        .iter()
        .find(|c| m.joints[c.joint].name == "j3")
        .unwrap();
    // q3 = 3 (2 q1 + 1) + 0.5
    assert_eq!((j3.leader, j3.multiplier, j3.offset), (0, 6.0, 3.5));
    let looped = text.replace(
        r#"<mimic joint="j1" multiplier="2" offset="1"/>"#,
        r#"<mimic joint="j3"/>"#,
    );
    assert!(err(&looped).contains("loops back"), "{}", err(&looped));
}

#[test]
fn locking_a_leader_locks_its_mimic_and_leaves_the_arm() {
    let mut locks = Locks::new();
    locks.insert("finger1".into(), 0.02);
    let m = ArmModel::from_urdf_str_locked(
        &fingers(r#"<mimic joint="finger1" multiplier="1"/>"#),
        &locks,
    )
    .unwrap();
    assert_eq!(m.joint_names(), ["arm"]);
    assert!(m.mimic.is_empty());
    let names: Vec<(&str, f64, Option<&str>)> = m
        .locked
        .iter()
        .map(|l| (l.name.as_str(), l.position, l.follows.as_deref()))
        .collect();
    assert_eq!(
        names,
        [("finger1", 0.02, None), ("finger2", 0.02, Some("finger1"))]
    );
    // Both fingers are folded into the arm link, 0.02 m out along z.
    let a = m.links.iter().find(|l| l.name == "a").unwrap();
    assert!((a.mass - 1.2).abs() < 1e-12);
    assert!((a.inertial_origin.xyz[2] - 0.2 * 0.02 / 1.2).abs() < 1e-12);
}

#[test]
fn bad_locks_name_the_key() {
    let text = fingers(r#"<mimic joint="finger1"/>"#);
    let lock_err = |name: &str, at: f64| {
        let mut locks = Locks::new();
        locks.insert(name.into(), at);
        ArmModel::from_urdf_str_locked(&text, &locks)
            .unwrap_err()
            .to_string()
    };
    assert!(
        lock_err("ghost", 0.0)
            .starts_with("plant.lock.ghost = 0 is invalid: it must be a joint of the arm")
    );
    assert!(lock_err("finger2", 0.0).contains("it follows 'finger1' (<mimic>), lock that one"));
    assert!(lock_err("arm", 2.0).contains("within the joint's limits [-1, 1]"));
    assert!(lock_err("arm", f64::NAN).contains("plant.lock.arm = NaN"));
    let all: Locks = [("arm".to_string(), 0.0), ("finger1".to_string(), 0.0)].into();
    let e = ArmModel::from_urdf_str_locked(&text, &all).unwrap_err();
    assert_eq!(e, ModelError::NoActuatedJoints);
}

#[test]
fn link_poses_place_the_two_link_arm_as_drawn() {
    use nalgebra::Point3;
    let m = ArmModel::from_urdf_str(crate::TWO_LINK_URDF).unwrap();
    let mut d = dynamics::Dynamics::new(&m, 1.0);
    let half_pi = std::f64::consts::FRAC_PI_2;
    // Shoulder up, elbow back down: link 1 points along +z, link 2 along +x.
    let poses = d.link_poses(&[half_pi, -half_pi]).to_vec();
    let link = |name: &str| m.links.iter().position(|l| l.name == name).unwrap();
    let elbow = poses[link("link2")] * Point3::origin();
    assert!(
        (elbow - Point3::new(0.0, 0.0, 0.35)).norm() < 1e-12,
        "{elbow}"
    );
    let tip = poses[link("link2")] * Point3::new(0.31, 0.0, 0.0);
    assert!((tip - Point3::new(0.31, 0.0, 0.35)).norm() < 1e-12, "{tip}");
    assert_eq!(poses[m.root], nalgebra::Isometry3::identity());
}

/// Issue 27: what Pinocchio and MuJoCo read, this reads too, and says so.
#[test]
fn an_undeclared_namespace_prefix_is_read_as_declared() {
    let limit =
        r#"<limit lower="-1" upper="1" effort="10" velocity="1" drake:acceleration="8.0"/>"#;
    let j = J1
        .replace(
            r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#,
            limit,
        )
        .replace("</joint>", "<drake:rotor_inertia value=\"0.1\"/></joint>");
    let m = ArmModel::from_urdf_str(&arm(&j, "")).unwrap();
    assert_eq!(m.joint_names(), ["j1"]);
    assert_eq!(m.joints[m.actuated[0]].effort, Some(10.0));
    assert!(
        m.notes[0].contains("prefix 'drake' used without an xmlns declaration"),
        "{:?}",
        m.notes
    );
    // Declared: no note.
    let declared = arm(&j, "").replace(
        "<robot name=\"t\">",
        "<robot name=\"t\" xmlns:drake=\"http://drake.mit.edu\">",
    );
    assert!(ArmModel::from_urdf_str(&declared).unwrap().notes.is_empty());
}

/// A Drake-style root joint from an undefined `world` link: the world is
/// the fixed root, said in a note; a fixed weld folds the base into it.
#[test]
fn a_world_parent_without_a_world_link_is_the_fixed_root() {
    let weld =
        r#"<joint name="weld" type="fixed"><parent link="world"/><child link="base"/></joint>"#;
    let m = ArmModel::from_urdf_str(&arm(&format!("{weld}{J1}"), "")).unwrap();
    assert_eq!(m.links[m.root].name, "world");
    assert_eq!(m.joint_names(), ["j1"]);
    assert!(
        m.notes.iter().any(
            |n| n.contains("joint 'weld' hangs from link 'world'") && n.contains("fixed world")
        ),
        "{:?}",
        m.notes
    );
    // A revolute first joint from the world moves too.
    let from_world = J1.replace("<parent link=\"base\"/>", "<parent link=\"world\"/>");
    let text = arm(&from_world, "").replace("<link name=\"base\"/>", "");
    let m = ArmModel::from_urdf_str(&text).unwrap();
    assert_eq!((m.links[m.root].name.as_str(), m.dof()), ("world", 1));
    // Another missing parent is still an error, naming it.
    let ghost = J1.replace("<parent link=\"base\"/>", "<parent link=\"ghost\"/>");
    assert_eq!(
        err(&arm(&ghost, "")),
        "joint 'j1': parent link 'ghost' does not exist"
    );
}

/// A 3.8 g fingertip with moments (0, 0, 1e-6), which no body has, on a
/// 1 kg arm: kept with its mass (the arm still carries it) and a sphere's
/// tensor, and said; the same tensor on a link of real mass is simulated as
/// given, and said.
#[test]
fn a_light_link_with_malformed_inertia_keeps_its_mass() {
    let bad = r#"ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="1e-6""#;
    let jb = J1.replace("j1", "tip_joint").replace("\"a\"", "\"tip\"");
    let jb = jb.replace("<parent link=\"base\"/>", "<parent link=\"a\"/>");
    let text = arm(&format!("{J1}{jb}"), &link("tip", "0.0038", bad));
    let m = ArmModel::from_urdf_str(&text).unwrap();
    assert!(m.ignored.is_empty(), "{:?}", m.ignored);
    let tip = m.links.iter().find(|l| l.name == "tip").unwrap();
    assert_eq!(tip.mass, 0.0038);
    // 3.8 g of water: r = 9.68 mm, 2/5 m r² = 1.42e-7 kg m².
    let moment =
        0.4 * 0.0038 * (3.0 * 0.0038 / (4.0 * std::f64::consts::PI * 1000.0)).powf(2.0 / 3.0);
    assert!((tip.inertia[0] - moment).abs() < 1e-18 && (moment - 1.424e-7).abs() < 1e-9);
    assert_eq!(tip.inertia[5], tip.inertia[0]);
    assert!(
        m.notes
            .iter()
            .any(|n| n.starts_with("link 'tip'") && n.contains("kept with its mass")),
        "{:?}",
        m.notes
    );
    assert!(m.joints_moving_no_mass().is_empty());
    // A real link with the same tensor is simulated as given, and said.
    let heavy = arm(&format!("{J1}{jb}"), &link("tip", "0.5", bad));
    let m = ArmModel::from_urdf_str(&heavy).unwrap();
    assert!(m.ignored.is_empty(), "{:?}", m.ignored);
    assert!(
        m.notes
            .iter()
            .any(|n| n.starts_with("link 'tip': principal moments")
                && n.contains("simulated as given")),
        "{:?}",
        m.notes
    );
}

/// That some note of `m` starts with `start` and has each of `has`.
fn assert_noted(m: &ArmModel, start: &str, has: &[&str]) {
    assert!(
        m.notes
            .iter()
            .any(|n| n.starts_with(start) && has.iter().all(|h| n.contains(h))),
        "{:?}",
        m.notes
    );
}

/// The pincher's fingers: 1e-5 kg given the identity tensor (1 kg m², a
/// radius of gyration of 316 m on an arm under 1 m) made the whole wrist a
/// flywheel of 3 kg m² that no gain at 1 kHz could move. A light link so
/// is kept with its mass and a sphere's tensor, and said; a heavy one is
/// simulated as given, and said; a plausible tensor is left alone.
#[test]
fn a_tensor_no_link_of_the_arm_has_is_named() {
    let identity = r#"ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1""#;
    let jb = J1.replace("j1", "finger").replace("\"a\"", "\"tip\"");
    let jb = jb.replace("<parent link=\"base\"/>", "<parent link=\"a\"/>");
    let text = arm(&format!("{J1}{jb}"), &link("tip", "0.00001", identity));
    let m = ArmModel::from_urdf_str(&text).unwrap();
    let tip = m.links.iter().find(|l| l.name == "tip").unwrap();
    assert_eq!(tip.mass, 0.00001);
    assert!(tip.inertia[0] < 1e-8, "{:?}", tip.inertia);
    assert_noted(
        &m,
        "link 'tip'",
        &["radius of gyration of 3.162e2 m", "kept with its mass"],
    );
    // A 5 m pedestal welded to the world does not make the arm 5 m long:
    // 1e-2 kg m² on 10 mg (31.6 m) is still flagged, against 10 m, not 50.
    let small = r#"ixx="1e-2" ixy="0" ixz="0" iyy="1e-2" iyz="0" izz="1e-2""#;
    let pedestal = r#"<link name="world"/><joint name="weld" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0 0 5"/></joint>"#;
    let m = ArmModel::from_urdf_str(&arm(
        &format!("{J1}{jb}{pedestal}"),
        &link("tip", "0.00001", small),
    ))
    .unwrap();
    assert_noted(&m, "link 'tip'", &["kept with its mass"]);
    // 0.5 kg (half the arm) with 1e4 kg m²: 141 m, simulated as given.
    let huge = r#"ixx="1e4" ixy="0" ixz="0" iyy="1e4" iyz="0" izz="1e4""#;
    let m = ArmModel::from_urdf_str(&arm(&format!("{J1}{jb}"), &link("tip", "0.5", huge))).unwrap();
    let tip = m.links.iter().find(|l| l.name == "tip").unwrap();
    assert_eq!(tip.inertia[0], 1e4);
    assert_noted(&m, "link 'tip'", &["simulated as given"]);
    // 0.5 kg with 1 kg m² is 1.4 m: a long link, not a placeholder.
    let m =
        ArmModel::from_urdf_str(&arm(&format!("{J1}{jb}"), &link("tip", "0.5", identity))).unwrap();
    assert!(m.notes.is_empty(), "{:?}", m.notes);
}

/// iCub's head: 1.34 kg with moments ±2.4e-35 (zero but for rounding) is a
/// point mass, noted; no refusal for a sign in the 35th decimal.
#[test]
fn a_tensor_zero_to_rounding_is_a_point_mass() {
    let tiny = r#"ixx="0" ixy="0" ixz="2.40741e-35" iyy="0" iyz="0" izz="0""#;
    let jb = J1.replace("j1", "neck").replace("\"a\"", "\"head\"");
    let jb = jb.replace("<parent link=\"base\"/>", "<parent link=\"a\"/>");
    let text = arm(&format!("{J1}{jb}"), &link("head", "1.33687", tiny));
    let m = ArmModel::from_urdf_str(&text).unwrap();
    assert!(m.ignored.is_empty(), "{:?}", m.ignored);
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("link 'head'") && n.contains("point mass")),
        "{:?}",
        m.notes
    );
}

/// A bare `<texture />` (romeo, icub) reads as naming no file, noted.
#[test]
fn a_texture_without_a_filename_is_read() {
    let text = arm(J1, "").replace(
        "</robot>",
        "<material name=\"grey\"><texture /></material></robot>",
    );
    let m = ArmModel::from_urdf_str(&text).unwrap();
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("<texture>") && n.contains("without a filename")),
        "{:?}",
        m.notes
    );
}

/// The Robotiq 2F-85's pattern: a leader in [0, 0.8] and mimic joints at
/// multiplier −1 listing [0, 0.8757]: their stops would pin the leader at
/// 0, so their limits are dropped (as ROS drives mimic joints), with a
/// note; a mimic whose limits leave the leader a range keeps them.
#[test]
fn mimic_limits_that_leave_the_leader_no_range_are_dropped_and_said() {
    let range = |j: String, lo: &str, hi: &str| {
        j.replace(
            r#"lower="-1" upper="1""#,
            &format!(r#"lower="{lo}" upper="{hi}""#),
        )
    };
    let follow = |m: &str| format!(r#"<mimic joint="j1" multiplier="{m}" offset="0"/>"#);
    let text = format!(
        r#"<robot name="r"><link name="base"/>{}{}{}{}{}{}</robot>"#,
        link("a", "1", I),
        link("b", "1", I),
        link("c", "1", I),
        range(joint("j1", "revolute", "base", "a", ""), "0", "0.8"),
        range(
            joint("inner", "revolute", "a", "b", &follow("-1")),
            "0",
            "0.8757"
        ),
        range(
            joint("outer", "revolute", "a", "c", &follow("1")),
            "0",
            "0.81"
        ),
    );
    let m = ArmModel::from_urdf_str(&text).unwrap();
    let limits = |name: &str| m.joints.iter().find(|j| j.name == name).unwrap().limits;
    assert_eq!(limits("inner"), None);
    assert_eq!(limits("outer"), Some((0.0, 0.81)));
    assert!(
        m.notes
            .iter()
            .any(|n| n.starts_with("mimic joint 'inner'") && n.contains("leave 'j1' no range")),
        "{:?}",
        m.notes
    );
}

/// Halodi's Eve lists effort -1, SDF's "no limit": read as none, and said;
/// any other negative effort is still refused.
#[test]
fn an_effort_of_minus_one_is_no_limit() {
    let m =
        ArmModel::from_urdf_str(&arm(&J1.replace(r#"effort="10""#, r#"effort="-1""#), "")).unwrap();
    assert_eq!(m.joints[m.actuated[0]].effort, None);
    assert!(
        m.notes.iter().any(|n| n.contains("effort -1 on j1")),
        "{:?}",
        m.notes
    );
    assert!(err(&arm(&J1.replace(r#"effort="10""#, r#"effort="-5""#), "")).contains("effort = -5"));
}

/// An empty `<geometry>` (urdf-rs says only "Expected token … found
/// EndElement(geometry)") is named with its link and what to write.
#[test]
fn an_empty_geometry_is_named_with_its_link() {
    let links = r#"<link name="b"><collision><geometry/></collision></link>"#;
    let e = err(&arm(J1, links));
    assert_eq!(
        e,
        "not a valid URDF: link 'b': a <geometry> holds no shape; write one of <box>, <cylinder>, <sphere>, <capsule>, <mesh>"
    );
}
