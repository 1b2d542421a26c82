//! The loader on small URDFs written inline: reading and the tree here;
//! mass properties and mimics/locks in their own files.

#![allow(
    clippy::unwrap_used,
    reason = "test code: a broken expectation should fail loudly"
)]

use super::*;

mod masses;
mod mimics;

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

#[test]
fn malformed_urdfs_are_named_errors() {
    assert!(err("not xml at all").starts_with("not XML: it starts with"));
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

/// A document over the size cap is refused before it is parsed, with its
/// size and the cap (#48 item 8: 16 MB took 119 s to refuse).
#[test]
fn a_urdf_over_the_size_cap_is_refused_with_the_cap() {
    let mut text = arm(J1, "");
    let pad = MAX_URDF_BYTES + 1 - text.len();
    text.insert_str(text.len() - "</robot>".len(), &" ".repeat(pad));
    assert_eq!(
        ArmModel::from_urdf_str(&text).unwrap_err(),
        ModelError::TooLarge {
            bytes: MAX_URDF_BYTES + 1,
            cap: MAX_URDF_BYTES
        }
    );
}

/// A tag with more attributes than the cap is refused by name and line,
/// before the XML readers compare its attributes pairwise.
#[test]
fn a_tag_with_too_many_attributes_is_refused_by_name() {
    let extra: String = (0..MAX_ATTRIBUTES)
        .map(|i| format!(r#" x{i}="{i}""#))
        .collect();
    let links = format!(
        r#"<link name="b"><inertial><origin xyz="0 0 0"{extra}/><mass value="BAD"/></inertial></link>"#
    );
    let got = err(&arm(J1, &links));
    assert!(
        got.starts_with("line 4: <origin> has 257 attributes or more, over the cap of 256"),
        "{got}"
    );
}

/// #47 item 4: what urdfdom and Pinocchio read, found on public files: a
/// link whose visuals and collisions interleave, and a visual's material
/// given by colour with no name. Both read, with a note, and give the same
/// model as the tidy file.
#[test]
fn interleaved_visuals_and_a_nameless_material_read_as_urdfdom_reads_them() {
    let shapes = |order: &str| {
        let v = r#"<visual><geometry><box size="0.1 0.1 0.1"/></geometry><material><color rgba="1 0 0 1"/></material></visual>"#;
        let c = r#"<collision><geometry><sphere radius="0.05"/></geometry></collision>"#;
        let body: String = order
            .chars()
            .map(|k| if k == 'v' { v } else { c })
            .collect();
        format!(
            r#"<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>{body}</link>"#
        )
    };
    let joints = format!("{J1}{}", J1.replace("j1", "j2").replace("\"a\"", "\"b\""));
    let messy = ArmModel::from_urdf_str(&arm(&joints, &shapes("vcvc"))).unwrap();
    let tidy = ArmModel::from_urdf_str(&arm(&joints, &shapes("vvcc"))).unwrap();
    assert_eq!(messy.links, tidy.links);
    assert_eq!(messy.joints, tidy.joints);
    let said = |m: &ArmModel, what: &str| m.notes.iter().any(|n| n.contains(what));
    assert!(said(&messy, "interleaved"), "{:?}", messy.notes);
    assert!(!said(&tidy, "interleaved"), "{:?}", tidy.notes);
    assert!(
        said(&tidy, "<material> element(s) without a name"),
        "{:?}",
        tidy.notes
    );
}
