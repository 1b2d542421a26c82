//! MJCF files read into the model: what is taken, what is refused by name,
//! what is said (issue #47). The dynamics against MuJoCo are in mujoco.rs.

// The helpers outside #[test] fail the test on bad input too.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::{Path, PathBuf};

use arm_model::{ArmModel, JointKind, Locks, ModelError};

fn data(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file)
}

fn load(file: &str) -> Result<ArmModel, ModelError> {
    ArmModel::from_mjcf_file(&data(file), &Locks::new())
}

fn joint<'a>(m: &'a ArmModel, name: &str) -> &'a arm_model::JointInfo {
    m.joints.iter().find(|j| j.name == name).unwrap()
}

#[test]
fn a_hinge_arm_takes_its_limits_in_degrees_its_dynamics_and_its_actuators() {
    let m = load("two_link_hinge.xml").unwrap();
    assert_eq!(m.joint_names(), ["shoulder", "elbow"]);
    let shoulder = joint(&m, "shoulder");
    assert_eq!(shoulder.kind, JointKind::Revolute);
    let (lo, hi) = shoulder.limits.unwrap();
    assert!((hi - 170f64.to_radians()).abs() < 1e-12 && (lo + hi).abs() < 1e-12);
    assert_eq!((shoulder.damping, shoulder.friction), (0.5, 0.1));
    assert_eq!(shoulder.armature, 0.01);
    // A motor's limit is gear × ctrlrange; a servo's its forcerange.
    assert_eq!(shoulder.effort, Some(100.0));
    assert_eq!(joint(&m, "elbow").effort, Some(30.0));
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("elbow_servo") && n.contains("gains are ignored")),
        "{:?}",
        m.notes
    );
    assert_eq!(
        m.home,
        Some(vec![0.3, -0.7]),
        "the key named home, not the first"
    );
}

#[test]
fn mjcf_text_is_told_from_urdf_by_its_root_element() {
    let text = std::fs::read_to_string(data("two_link_hinge.xml")).unwrap();
    let from_text = ArmModel::from_urdf_str(&text).unwrap();
    assert_eq!(from_text, load("two_link_hinge.xml").unwrap());
}

#[test]
fn bodies_without_inertial_weigh_their_geoms() {
    let m = load("geom_inertia.xml").unwrap();
    let link2 = m.links.iter().find(|l| l.name == "link2").unwrap();
    // Cylinder 0.03 × 0.2 m of water, a 0.7 kg sphere, an ellipsoid; the
    // density-0 sphere weighs nothing.
    let pi = std::f64::consts::PI;
    let expected = 1000.0 * (pi * 0.03 * 0.03 * 0.2 + 4.0 / 3.0 * pi * 0.02 * 0.03 * 0.04) + 0.7;
    assert!((link2.mass - expected).abs() < 1e-12, "{}", link2.mass);
    assert_eq!(
        joint(&m, "j1").kind,
        JointKind::Continuous,
        "no range: turns freely"
    );
}

#[test]
fn a_slide_joint_and_two_hinges_in_one_body_keep_their_armature() {
    let m = load("slide_armature.xml").unwrap();
    assert_eq!(m.joint_names(), ["rail", "yaw", "pitch"]);
    let rail = joint(&m, "rail");
    assert_eq!(rail.kind, JointKind::Prismatic);
    assert_eq!((rail.armature, rail.damping), (0.3, 2.0));
    // min(forcerange 60, gear 1 × ctrlrange 100).
    assert_eq!(rail.effort, Some(60.0));
    assert_eq!(joint(&m, "pitch").armature, 0.05);
    assert_eq!(m.home, None);
}

#[test]
fn includes_and_default_classes_are_resolved() {
    let m = load("includes_defaults.xml").unwrap();
    assert_eq!(m.joint_names(), ["a1", "a2", "a3"]);
    assert_eq!(
        (joint(&m, "a1").damping, joint(&m, "a1").armature),
        (0.3, 0.04)
    );
    assert_eq!(
        (joint(&m, "a3").damping, joint(&m, "a3").armature),
        (0.1, 0.01)
    );
    assert_eq!(joint(&m, "a2").limits, Some((-2.5, 2.5)));
}

#[test]
fn an_include_inside_a_body_reads_as_mujoco_reads_it() {
    let m = load("body_include.xml").unwrap();
    // The commented include names a file that does not exist: not read.
    assert_eq!(m.joint_names(), ["shoulder", "elbow", "tag_slide"]);
    assert_eq!(joint(&m, "elbow").armature, 0.01);
    // `ref` turns the frame, not the numbers: q is MuJoCo's qpos.
    assert_eq!(joint(&m, "elbow").limits, Some((-2.5, 2.5)));
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("1 <equality><joint> not simulated")),
        "{:?}",
        m.notes
    );
}

#[test]
fn a_tiny_mass_is_kept_as_mujoco_keeps_it() {
    let m = load("body_include.xml").unwrap();
    let tag = m.links.iter().find(|l| l.name == "tag").unwrap();
    assert_eq!(tag.mass, 1e-8);
    assert!(m.ignored.is_empty(), "{:?}", m.ignored);
}

#[test]
fn gravcomp_and_the_models_gravity_are_named_not_applied() {
    let m = load("body_include.xml").unwrap();
    let said = m.notes.join("\n");
    assert!(
        said.contains("gravcomp on 1 body (upper) is not applied"),
        "{said}"
    );
    assert!(
        said.contains("<option gravity=\"0 0 -9.8\"> is not applied")
            && said.contains("plant.gravity = [0, 0, -9.8]"),
        "{said}"
    );
}

#[test]
fn a_floating_base_is_refused_by_name() {
    let e = load("free_joint.xml").unwrap_err().to_string();
    assert!(
        e.contains("'root'") && e.contains("floating base") && e.contains("free_joint.xml"),
        "{e}"
    );
}

#[test]
fn a_ball_joint_is_refused_by_name() {
    let text = r#"<mujoco><worldbody><body name="b"><joint name="shoulder" type="ball"/>
        <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/></body></worldbody></mujoco>"#;
    let e = ArmModel::from_urdf_str(text).unwrap_err().to_string();
    assert!(e.contains("'shoulder'") && e.contains("ball"), "{e}");
}

#[test]
fn a_mesh_body_without_inertial_is_refused_by_name() {
    let text = r#"<mujoco><asset><mesh name="shell" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/></asset>
        <worldbody><body name="link1"><joint name="j"/>
        <geom name="hull" type="mesh" mesh="shell"/></body></worldbody></mujoco>"#;
    let e = ArmModel::from_urdf_str(text).unwrap_err().to_string();
    assert!(
        e.contains("hull") && e.contains("link1") && e.contains("<inertial>"),
        "{e}"
    );
}

#[test]
fn a_missing_include_names_the_file() {
    let path = std::env::temp_dir().join(format!("mjcf-missing-{}.xml", std::process::id()));
    std::fs::write(&path, r#"<mujoco><include file="nowhere.xml"/></mujoco>"#).unwrap();
    let e = ArmModel::from_mjcf_file(&path, &Locks::new()).unwrap_err();
    std::fs::remove_file(&path).ok();
    assert!(matches!(e, ModelError::MjcfInclude { .. }), "{e}");
    assert!(e.to_string().contains("nowhere.xml"), "{e}");
}

#[test]
fn text_given_alone_reads_no_other_file() {
    let text = r#"<mujoco><include file="/etc/hostname"/></mujoco>"#;
    let e = ArmModel::from_urdf_str(text).unwrap_err().to_string();
    assert!(
        e.contains("/etc/hostname") && e.contains("given as text"),
        "{e}"
    );
}

#[test]
fn a_file_with_includes_becomes_text_that_reads_alone() {
    let path = data("includes_defaults.xml");
    let text = std::fs::read_to_string(&path).unwrap();
    let alone = ArmModel::self_contained(&text, path.parent().unwrap()).unwrap();
    assert!(!alone.contains("<include"), "{alone}");
    assert_eq!(
        ArmModel::from_urdf_str(&alone).unwrap(),
        load("includes_defaults.xml").unwrap()
    );
}

#[test]
fn malformed_mjcf_is_an_error_not_a_panic() {
    for text in [
        "<mujoco",
        "<mujoco><worldbody><body><joint range=\"1\"/></body></worldbody></mujoco>",
        "<mujoco><worldbody><body><joint/><inertial mass=\"nan\" pos=\"0 0 0\" diaginertia=\"1 1 1\"/></body></worldbody></mujoco>",
        "<mujoco><worldbody><body><joint axis=\"0 0 0\"/><inertial mass=\"1\" pos=\"0 0 0\" diaginertia=\"1 1 1\"/></body></worldbody></mujoco>",
        "<mujoco><worldbody/><keyframe><key qpos=\"1 2\"/></keyframe></mujoco>",
    ] {
        let outcome = std::panic::catch_unwind(|| ArmModel::from_urdf_str(text));
        assert!(matches!(outcome, Ok(Err(_))), "{text}: {outcome:?}");
    }
}

/// The shipped Menagerie UR5e reads without its meshes (they are not
/// shipped): every body has an <inertial>, so meshes are only looked at.
#[test]
fn the_menagerie_ur5e_reads_without_its_meshes() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../robots/menagerie/universal_robots_ur5e/ur5e.xml");
    assert!(
        !path.parent().unwrap().join("assets").exists(),
        "the test is of a folder without meshes"
    );
    let m = ArmModel::from_mjcf_file(&path, &Locks::new()).unwrap();
    assert_eq!(m.dof(), 6);
    // Position servos: forcerange ±150 on the three large joints, ±28 on
    // the wrist; their gains are named as ignored.
    let effort: Vec<_> = m.actuated.iter().map(|&j| m.joints[j].effort).collect();
    assert_eq!(
        effort,
        [150.0, 150.0, 150.0, 28.0, 28.0, 28.0].map(Some).to_vec()
    );
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("'wrist_3'") && n.contains("gains are ignored")),
        "{:?}",
        m.notes
    );
    assert!(m.actuated.iter().all(|&j| m.joints[j].armature == 0.1));
    // The file's own digits, not π/2.
    #[allow(clippy::approx_constant)]
    let q = 1.5708;
    assert_eq!(m.home, Some(vec![-q, -q, q, -q, -q, 0.0]));
    // Collision capsules and cylinders are contact shapes; no mesh is.
    assert!(m.links.iter().map(|l| l.collisions.len()).sum::<usize>() >= 8);
}

#[test]
fn a_base_welded_to_the_world_may_weigh_a_mesh() {
    // SO-ARM100's base: a collision mesh and no <inertial>, on no joint.
    let text = r#"<mujoco><asset><mesh name="shell" file="absent.stl"/></asset>
        <worldbody><body name="base"><geom name="hull" type="mesh" mesh="shell"/>
        <body name="link1"><joint name="j"/>
        <inertial pos="0 0 0.1" mass="1" diaginertia="0.01 0.01 0.01"/></body></body>
        </worldbody></mujoco>"#;
    let m = ArmModel::from_urdf_str(text).unwrap();
    assert_eq!(m.joint_names(), ["j"]);
    assert!(
        m.notes
            .iter()
            .any(|n| n.contains("hull") && n.contains("welded to the world")),
        "{:?}",
        m.notes
    );
    // Below a joint the same body is refused, naming the geom.
    let moving = text.replace(
        r#"<body name="base">"#,
        r#"<body name="base"><joint name="j0"/>"#,
    );
    let e = ArmModel::from_urdf_str(&moving).unwrap_err().to_string();
    assert!(e.contains("hull") && e.contains("base"), "{e}");
}

#[test]
fn a_joints_actuatorfrcrange_limits_its_effort() {
    let text = r#"<mujoco><compiler autolimits="true"/>
        <default><joint actuatorfrcrange="-40 40"/></default>
        <worldbody><body name="b1"><joint name="j1"/>
        <inertial pos="0 0 0.1" mass="1" diaginertia="0.01 0.01 0.01"/>
        <body name="b2" pos="0 0 0.2"><joint name="j2" actuatorfrcrange="-12 10"/>
        <inertial pos="0 0 0.1" mass="1" diaginertia="0.01 0.01 0.01"/></body></body></worldbody>
        <actuator><motor joint="j1" gear="2" ctrlrange="-30 30"/>
        <general joint="j2" gear="3" forcerange="-2 2"/></actuator></mujoco>"#;
    let m = ArmModel::from_urdf_str(text).unwrap();
    // j1: min(gear 2 × ctrl 30, actuatorfrcrange 40); j2: min(gear 3 × force 2, 12).
    assert_eq!(joint(&m, "j1").effort, Some(40.0));
    assert_eq!(joint(&m, "j2").effort, Some(6.0));
}
