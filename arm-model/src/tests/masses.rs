//! Which mass matters: merged, ignored, malformed and implausible tensors.

use super::*;

/// The 0.2 kg tool on a fixed joint 0.2 m along link3 (0.5 kg, COM at
/// 0.1 m, I = 0.5·0.2²/12 about it) folds into link3 by the parallel-axis theorem.
#[test]
fn fixed_joint_mass_merges_into_the_parent() {
    let m =
        ArmModel::from_urdf_str(include_str!("../../../robots/three_link_planar.urdf")).unwrap();
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
