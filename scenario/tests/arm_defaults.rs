//! #38 item 3: the default scenario of an arm holds on arms the shipped
//! ones do not cover: gains stable along the whole reference, a mobile
//! base swung within its effort, URDF friction no motor overcomes.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use plant_rapier::ArmModel;
use scenario::{ArmDefault, Prober};

const ARMS: [&str; 8] = [
    "two_link",
    "three_link_planar",
    "ur5",
    "iiwa14",
    "panda",
    "xarm7",
    "so101",
    "z1",
];

#[test]
fn default_gains_are_stable_everywhere_along_the_reference() {
    for arm in ARMS {
        let path = format!("{}/../robots/{arm}.urdf", env!("CARGO_MANIFEST_DIR"));
        let urdf = std::fs::read_to_string(&path).unwrap();
        let d = ArmDefault::new(&urdf).unwrap();
        let s = &d.scenario;
        let model = ArmModel::from_urdf_str_locked(&urdf, &s.plant.lock).unwrap();
        let armature = s.plant.armature.resolve("a", model.dof()).unwrap();
        let k2: Vec<f64> = d.gains.joints.iter().map(|j| j.k2).collect();
        let dt = 1.0 / s.rate_hz;
        let mut prober = Prober::new(&model, &armature).unwrap();
        let steps = 2000;
        let worst = (0..=steps)
            .map(|k| {
                let t = s.duration_s * f64::from(k) / f64::from(steps);
                let q: Vec<f64> = s.reference.joints.iter().map(|r| r.eval(t)[0]).collect();
                prober.at(&q).unwrap().stability_number(&k2, dt)
            })
            .fold(0.0, f64::max);
        assert!(
            d.gains.stability_number <= 1.0 + 1e-9,
            "{arm}: chosen at {}",
            d.gains.stability_number
        );
        // Between the postures it was checked at, M(q) moves a little.
        assert!(
            worst <= 1.02,
            "{arm}: {worst} somewhere along the reference"
        );
    }
}

/// A mobile base on a ±1000 m rail (a prismatic joint of 100 N carrying
/// 20 kg) under a 1 kg arm joint: its reference is a swing of at most
/// 0.25 m that its motor drives with room to spare (metres and newtons,
/// not a third of the rail), and a reference too hard for a joint's effort
/// is slowed to fit.
#[test]
fn a_mobile_base_gets_a_reference_within_its_effort() {
    let urdf = r#"<robot name="cart">
      <link name="world"/>
      <link name="base"><inertial><mass value="20"/><origin xyz="0 0 0"/>
        <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
      <link name="arm"><inertial><mass value="1"/><origin xyz="0.3 0 0"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <joint name="rail" type="prismatic"><parent link="world"/><child link="base"/>
        <axis xyz="1 0 0"/><limit lower="-1000" upper="1000" effort="100" velocity="1"/></joint>
      <joint name="turn" type="revolute"><parent link="base"/><child link="arm"/>
        <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="50" velocity="3"/></joint>
    </robot>"#;
    let d = ArmDefault::new(urdf).unwrap();
    let rail = &d.scenario.reference.joints[0];
    let swing = (0..1000)
        .map(|k| (rail.eval(f64::from(k) * 0.01)[0] - rail.offset).abs())
        .fold(0.0, f64::max);
    assert!(swing > 0.01 && swing <= 0.25 + 1e-9, "{swing} m");
    let g = &d.gains.joints[0];
    assert!(g.load <= 0.7 * 100.0 + 1e-9, "{} N", g.load);
    assert!(d.gains.envelope[0] <= 0.15, "{} m", d.gains.envelope[0]);
    // A weak rail motor: 21 kg swung 0.25 m at 0.8 rad/s needs 3.4 N; the
    // swing is cut to fit 70 % of its 3 N.
    let weak = urdf.replace(r#"effort="100""#, r#"effort="3""#);
    let d = ArmDefault::new(&weak).unwrap();
    let g = &d.gains.joints[0];
    assert!(g.load <= 0.7 * 3.0 * 1.01, "{} N of 3", g.load);
    let rail = &d.scenario.reference.joints[0];
    let amp = rail.eval(std::f64::consts::PI / 1.6)[0] - rail.offset;
    assert!(amp.abs() < 0.2, "{amp} m");
}

/// Drake's Allegro hand lists 10 N m of dry friction on 0.7 N m motors:
/// no motor could move a finger, so the default turns URDF dynamics off
/// and says which joints and why.
#[test]
fn urdf_friction_beyond_effort_turns_urdf_dynamics_off_and_says_so() {
    let urdf = std::fs::read_to_string(format!(
        "{}/../robots/two_link.urdf",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let d = ArmDefault::new(&urdf).unwrap();
    assert!(d.scenario.plant.urdf_dynamics);
    let stuck = urdf.replacen(
        "<limit lower=\"-3.14159\" upper=\"3.14159\" effort=\"500\" velocity=\"20\"/>",
        "<limit lower=\"-3.14159\" upper=\"3.14159\" effort=\"20\" velocity=\"20\"/>\n    <dynamics damping=\"0\" friction=\"25\"/>",
        1,
    );
    assert_ne!(stuck, urdf);
    let d = ArmDefault::new(&stuck).unwrap();
    assert!(!d.scenario.plant.urdf_dynamics);
    assert!(
        d.changes()
            .iter()
            .any(|c| c.contains("joint1 (25 N m ≥ 20 N m)") && c.contains("urdf_dynamics = false")),
        "{:?}",
        d.changes()
    );
}

/// The paper's arm with a 5 N m shoulder: gravity along the default swing
/// takes the room, so the swing is halved until it fits (and said); at
/// 3 N m gravity alone is beyond the motor and the joint is locked.
#[test]
fn a_swing_gravity_makes_too_heavy_is_cut_and_said() {
    let urdf = std::fs::read_to_string(format!(
        "{}/../robots/two_link.urdf",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let with_effort = |e: &str| urdf.replacen("effort=\"500\"", &format!("effort=\"{e}\""), 1);
    let d = ArmDefault::new(&with_effort("5")).unwrap();
    let cut = d
        .changes()
        .into_iter()
        .find(|c| c.starts_with("joint 'joint1': reference swing cut to"));
    assert!(cut.is_some(), "{:?}", d.changes());
    let g = &d.gains.joints[0];
    assert!(g.load <= 0.8 * 5.0, "{} N m of 5", g.load);
    let d = ArmDefault::new(&with_effort("3")).unwrap();
    assert!(
        d.scenario.plant.lock.contains_key("joint1"),
        "{:?}",
        d.changes()
    );
}

/// The AL5D's wrist carries a point mass on its axis: M(q) is singular
/// there. The default locks that joint, says why, and controls the rest.
#[test]
fn a_joint_with_no_inertia_about_its_axis_is_locked_and_said() {
    let urdf = r#"<robot name="r"><link name="base"/>
      <link name="a"><inertial><mass value="1"/><origin xyz="0.3 0 0"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <link name="tip"><inertial><mass value="0.2"/><origin xyz="0 0 0"/>
        <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="a"/>
        <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="50" velocity="2"/></joint>
      <joint name="wrist" type="revolute"><parent link="a"/><child link="tip"/>
        <origin xyz="0.6 0 0"/><axis xyz="1 0 0"/><limit lower="-2" upper="2" effort="5" velocity="2"/></joint>
    </robot>"#;
    let d = ArmDefault::new(urdf).unwrap();
    assert!(
        d.scenario.plant.lock.contains_key("wrist"),
        "{:?}",
        d.changes()
    );
    assert!(
        d.changes()
            .iter()
            .any(|c| c.starts_with("locked wrist") && c.contains("M(q) is singular there")),
        "{:?}",
        d.changes()
    );
}

/// A weak motor: on the three-link arm turned about z (no gravity), a
/// 0.3 N m elbow gets K1 = √(a/E) below the paper's 15, with the reason; a
/// 0.041 N m one could not bring its joint in by T_c and is locked, and
/// said; an arm whose only motor is that weak is refused by name.
#[test]
fn a_weak_motor_gets_a_gain_it_can_follow_or_is_locked() {
    let urdf = std::fs::read_to_string(format!(
        "{}/../robots/three_link_planar.urdf",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace("<axis xyz=\"0 -1 0\"/>", "<axis xyz=\"0 0 1\"/>");
    let with_effort = |e: &str| {
        let at = urdf.rfind("effort=\"").unwrap();
        let end = at + urdf[at + 8..].find('"').unwrap() + 9;
        format!("{}effort=\"{e}\"{}", &urdf[..at], &urdf[end..])
    };
    let d = ArmDefault::new(&with_effort("0.3")).unwrap();
    let g = &d.gains.joints[2];
    assert!(
        g.k1 < 15.0 && g.motor_entry_s.is_some_and(|t| t < 2.0),
        "{g:?}"
    );
    assert!(g.k1_reason.starts_with("√(a/E) = "), "{}", g.k1_reason);
    let d = ArmDefault::new(&with_effort("0.041")).unwrap();
    assert!(
        d.changes()
            .iter()
            .any(|c| c.starts_with("locked joint3") && c.contains("after T_c = 2 s")),
        "{:?}",
        d.changes()
    );
    let one = r#"<robot name="r"><link name="base"/>
      <link name="a"><inertial><mass value="1"/><origin xyz="0.3 0 0"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <joint name="j" type="revolute"><parent link="base"/><child link="a"/>
        <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1e-9" velocity="2"/></joint></robot>"#;
    let e = ArmDefault::new(one).unwrap_err().to_string();
    assert!(
        e.contains("every controlled joint") && e.contains("'j': its motor"),
        "{e}"
    );
}
