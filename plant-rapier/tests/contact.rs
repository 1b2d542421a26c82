//! `[plant.contact]` through Rapier: a pendulum whose tip strikes a wall
//! rebounds at −e times its speed (restitution), stops at e = 0, sinks into
//! the wall by under a millimetre, and the state says `contact` only
//! while it touches; pushed into the wall and at rest, its contact has
//! points and a force that balances the torque; the articulated engine
//! refuses contact by name.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use plant_rapier::{
    ArmModel, ContactConfig, ContactObject, Effects, EngineName, Obstacle, PayloadConfig,
    PlantConfig, PlantError, Rig, ShapeName,
};

const PERIOD_NS: u64 = 1_000_000;

/// A 1 m pendulum about z with its mass and a 5 cm ball at the tip; no
/// gravity, so between impacts it turns at constant speed.
const PENDULUM: &str = r#"<robot name="pendulum">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><origin xyz="1 0 0"/>
      <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
    <collision><origin xyz="1 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <joint name="j" type="continuous">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit effort="1000" velocity="100"/>
  </joint>
</robot>"#;

/// A wall filling x < 0 around the tip's path at q = π/2: the ball meets it
/// when cos q = 0.05, moving along −x, the wall's normal.
fn wall() -> Obstacle {
    Obstacle {
        name: "wall".into(),
        shape: ShapeName::Box,
        size: vec![0.2, 1.0, 1.0],
        xyz: [-0.1, 1.0, 0.0],
        rpy: [0.0; 3],
    }
}

fn rig(engine: EngineName, restitution: f64) -> Result<Rig, PlantError> {
    let model = ArmModel::from_urdf_str(PENDULUM).unwrap();
    let config = PlantConfig {
        engine,
        gravity: [0.0; 3],
        substeps: Some(8),
        contact: ContactConfig {
            restitution,
            friction: 0.0,
            obstacle: vec![wall()],
            ..ContactConfig::default()
        },
        ..PlantConfig::default()
    };
    Rig::new(&model, &config, 0, PERIOD_NS)
}

struct Strike {
    /// Speed after the impact over the speed before (signed).
    ratio: f64,
    /// Periods whose state said `contact`.
    contact_periods: u32,
    /// Largest mean contact force over a period, N.
    peak_force: f64,
    /// The tip's deepest reach into x < 0.05 (the ball's centre), m.
    overshoot: f64,
}

/// Sends the pendulum at 2 rad/s towards the wall and watches 1.5 s.
fn strike(restitution: f64) -> Strike {
    let mut r = rig(EngineName::Rapier, restitution).unwrap();
    let w0 = 2.0;
    r.set_state(&[0.0], &[w0]).unwrap();
    let mut out = Strike {
        ratio: 0.0,
        contact_periods: 0,
        peak_force: 0.0,
        overshoot: 0.0,
    };
    let (mut q, mut qd) = ([0.0], [0.0]);
    for _ in 0..1500 {
        r.step(Some(&[0.0])).unwrap();
        r.true_state_into(&mut q, &mut qd);
        let c = r.plant().contact().unwrap();
        out.peak_force = out.peak_force.max(c.force);
        if r.effects().has(Effects::CONTACT) {
            out.contact_periods += 1;
        }
        out.overshoot = out.overshoot.max(0.05 - q[0].cos());
    }
    out.ratio = qd[0] / w0;
    out
}

#[test]
fn a_pendulum_rebounds_from_a_wall_at_minus_e_times_its_speed() {
    for e in [0.0, 0.5, 0.9] {
        let s = strike(e);
        assert!(
            (s.ratio + e).abs() < 1e-3,
            "restitution {e}: speed ratio {} after the strike",
            s.ratio
        );
        assert!(s.contact_periods >= 1, "restitution {e}: no contact seen");
        assert!(
            s.overshoot < 1e-3,
            "restitution {e}: the ball sank {} m into the wall",
            s.overshoot
        );
        // The impulse that turns 2 rad/s (tip 1 kg m² at 1 m) into −2e rad/s
        // is (1 + e)·2 N s; over the periods it acted, at least that much
        // mean force in one of them.
        assert!(
            s.peak_force * 1e-3 * f64::from(s.contact_periods) >= 0.9 * (1.0 + e) * 2.0,
            "restitution {e}: peak force {} N over {} periods",
            s.peak_force,
            s.contact_periods
        );
    }
}

#[test]
fn a_pendulum_that_misses_the_wall_feels_nothing() {
    let mut r = rig(EngineName::Rapier, 0.5).unwrap();
    // Turning away from the wall, it never reaches q = π/2 within 0.5 s.
    r.set_state(&[0.0], &[-2.0]).unwrap();
    for _ in 0..500 {
        r.step(Some(&[0.0])).unwrap();
        assert!(!r.effects().has(Effects::CONTACT));
        assert_eq!(r.plant().contact().unwrap().force, 0.0);
    }
    let (mut q, mut qd) = ([0.0], [0.0]);
    r.true_state_into(&mut q, &mut qd);
    assert!((qd[0] + 2.0).abs() < 1e-9, "{}", qd[0]);
}

#[test]
fn the_articulated_engine_refuses_contact_by_name() {
    let e = rig(EngineName::Articulated, 0.0).err().unwrap().to_string();
    assert!(
        e.contains("plant.contact") && e.contains("engine = \"rapier\""),
        "{e}"
    );
}

#[test]
fn an_obstacle_of_the_wrong_size_is_refused_by_key() {
    let mut config = PlantConfig {
        engine: EngineName::Rapier,
        ..PlantConfig::default()
    };
    let mut o = wall();
    o.size = vec![0.2, 1.0];
    config.contact.obstacle = vec![o];
    let e = config.validate().unwrap_err().to_string();
    assert!(e.contains("plant.contact.obstacle[0].size"), "{e}");
}

/// The paper's arm (with its capsules) at q = [0.3, 0.5], at rest.
fn two_link(contact: ContactConfig, payload: Option<PayloadConfig>) -> Rig {
    let model = ArmModel::from_urdf_str(plant_rapier::TWO_LINK_URDF).unwrap();
    let config = PlantConfig {
        engine: EngineName::Rapier,
        substeps: Some(8),
        contact,
        payload,
        ..PlantConfig::default()
    };
    let mut r = Rig::new(&model, &config, 0, PERIOD_NS).unwrap();
    r.set_state(&Q0, &[0.0, 0.0]).unwrap();
    r
}

const Q0: [f64; 2] = [0.3, 0.5];

/// Where the tip of link 2 (0.31 m along it) is at `Q0`, world frame.
fn tip() -> [f64; 3] {
    let (a, b) = (Q0[0], Q0[0] + Q0[1]);
    // Positive q lifts the link towards +z in the x–z plane.
    [
        0.35 * a.cos() + 0.31 * b.cos(),
        0.0,
        0.35 * a.sin() + 0.31 * b.sin(),
    ]
}

fn object(grasp_at_s: f64, release_at_s: Option<f64>) -> ContactObject {
    ContactObject {
        name: "ball".into(),
        shape: ShapeName::Sphere,
        size: vec![0.005],
        mass: 1.0,
        xyz: tip(),
        rpy: [0.0; 3],
        link: "link2".into(),
        grasp_at_s,
        release_at_s,
    }
}

fn swing(r: &mut Rig, periods: u32) -> [f64; 2] {
    let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
    for _ in 0..periods {
        r.step(Some(&[0.0, 0.0])).unwrap();
    }
    r.true_state_into(&mut q, &mut qd);
    q
}

/// A 1 kg ball grasped at the tip weighs on the arm as the payload effect's
/// 1 kg point mass there: released from rest under zero torque, the two
/// arms fall alike (the ball's own inertia, 1e-5 kg m², is all that
/// differs), and both differ from the bare arm.
#[test]
fn a_grasped_mass_weighs_as_the_payload_effect() {
    let grasped = ContactConfig {
        object: vec![object(0.0, None)],
        ..ContactConfig::default()
    };
    let payload = PayloadConfig {
        link: "link2".into(),
        mass: 1.0,
        offset: [0.31, 0.0, 0.0],
        attach_at_s: 0.0,
    };
    let mut a = two_link(grasped, None);
    let mut b = two_link(ContactConfig::default(), Some(payload));
    let mut bare = two_link(ContactConfig::default(), None);
    let (qa, qb, q0) = (
        swing(&mut a, 100),
        swing(&mut b, 100),
        swing(&mut bare, 100),
    );
    assert!(a.effects().has(Effects::PAYLOAD));
    for j in 0..2 {
        let fell = (qb[j] - Q0[j]).abs();
        assert!(
            (qa[j] - qb[j]).abs() < 2e-3 * fell,
            "joint {j}: grasped {} vs payload {} (fell {fell})",
            qa[j],
            qb[j]
        );
        assert!(
            (q0[j] - qb[j]).abs() > 0.02 * fell,
            "joint {j}: the mass changed nothing: bare {}, payload {}",
            q0[j],
            qb[j]
        );
    }
}

/// An object rests on a pedestal until the arm takes it (from afar, at
/// the offset it then has), rides with the arm, and once let go falls
/// freely at g.
#[test]
fn an_object_rests_until_grasped_and_falls_when_released() {
    // Out of the arm's plane (y = 0), where no link passes.
    let at = [0.3, 0.5, 0.2];
    let pedestal = Obstacle {
        name: "pedestal".into(),
        shape: ShapeName::Box,
        size: vec![0.05, 0.05, 0.02],
        xyz: [at[0], at[1], at[2] - 0.005 - 0.01],
        rpy: [0.0; 3],
    };
    let mut ball = object(0.1, Some(0.2));
    ball.xyz = at;
    let contact = ContactConfig {
        obstacle: vec![pedestal],
        object: vec![ball],
        ..ContactConfig::default()
    };
    let mut r = two_link(contact, None);
    let mut payload_periods = 0;
    let mut z = Vec::new();
    for k in 1..=300 {
        // Limp, then lifting hard while it holds the ball, then limp.
        let lift = if (101..=200).contains(&k) { 40.0 } else { 0.0 };
        r.step(Some(&[lift, lift / 4.0])).unwrap();
        payload_periods += u32::from(r.effects().has(Effects::PAYLOAD));
        let p = r.plant().object_position(0).unwrap();
        if k < 100 {
            let rest = (p[0] - at[0])
                .abs()
                .max((p[1] - at[1]).abs())
                .max((p[2] - at[2]).abs());
            assert!(rest < 1e-3, "period {k}: the ball left its pedestal: {p:?}");
        }
        z.push(p[2]);
    }
    assert_eq!(payload_periods, 100);
    // Carried: the arm lifted it off its pedestal from 0.1 s to 0.2 s.
    assert!(z[199] > z[98] + 0.01, "{} -> {}", z[98], z[199]);
    // Free: constant acceleration -9.81 m/s² (second differences).
    for k in [230, 260, 290] {
        let a = (z[k + 1] - 2.0 * z[k] + z[k - 1]) / 1e-6;
        assert!((a + 9.81).abs() < 0.05, "period {k}: z'' = {a}");
    }
}

/// The pendulum's tip strikes a free ball in its path (no gravity, so it
/// floats until struck): the ball flies off along the tip's motion, the
/// pendulum slows, and the reading reports the ball's pose as it moves.
#[test]
fn the_arm_pushes_a_free_object() {
    let model = ArmModel::from_urdf_str(PENDULUM).unwrap();
    let q_ball: f64 = 0.5;
    let ball = ContactObject {
        name: "ball".into(),
        shape: ShapeName::Sphere,
        size: vec![0.05],
        mass: 0.2,
        xyz: [q_ball.cos(), q_ball.sin(), 0.0],
        rpy: [0.0; 3],
        link: "arm".into(),
        grasp_at_s: 100.0,
        release_at_s: None,
    };
    let config = PlantConfig {
        engine: EngineName::Rapier,
        gravity: [0.0; 3],
        substeps: Some(8),
        contact: ContactConfig {
            friction: 0.0,
            object: vec![ball],
            ..ContactConfig::default()
        },
        ..PlantConfig::default()
    };
    let mut r = Rig::new(&model, &config, 0, PERIOD_NS).unwrap();
    r.set_state(&[0.0], &[2.0]).unwrap();
    let (mut q, mut qd) = ([0.0], [0.0]);
    let mut touched = 0;
    for _ in 0..400 {
        r.step(Some(&[0.0])).unwrap();
        touched += u32::from(r.effects().has(Effects::CONTACT));
        let reading = r.plant().contact().unwrap();
        let p = r.plant().object_position(0).unwrap();
        assert_eq!(reading.n_objects, 1);
        for (a, b) in reading.objects[0][..3].iter().zip(p) {
            assert!((a - b).abs() < 1e-12, "{:?} vs {p:?}", reading.objects[0]);
        }
    }
    r.true_state_into(&mut q, &mut qd);
    let p = r.plant().object_position(0).unwrap();
    // Pushed: it left its place along the tip's motion (+y near q = 0.45).
    let moved = [p[0] - q_ball.cos(), p[1] - q_ball.sin()];
    assert!(touched > 0, "no contact");
    assert!(moved[1] > 0.2, "the ball stayed: {p:?}");
    assert!(qd[0] < 1.9, "the pendulum did not slow: {}", qd[0]);
}

/// Three links in a row, a 10 cm ball at the middle of the first and at
/// the end of the third.
const FOLDING: &str = r#"<robot name="folding">
  <link name="base"/>
  <link name="a">
    <inertial><mass value="1"/><origin xyz="0.2 0 0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><origin xyz="0.2 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <link name="b">
    <inertial><mass value="1"/><origin xyz="0.2 0 0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <link name="c">
    <inertial><mass value="1"/><origin xyz="0.2 0 0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><origin xyz="0.2 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="continuous"><parent link="a"/><child link="b"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="j3" type="continuous"><parent link="b"/><child link="c"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/></joint>
</robot>"#;

/// Folded back (q2 = q3 = 2.2 rad), the third link's ball lies on the
/// first's: with `self_contact` the two meet, without they pass.
#[test]
fn self_contact_makes_links_that_are_not_neighbours_meet() {
    let model = ArmModel::from_urdf_str(FOLDING).unwrap();
    let run = |self_contact: bool| {
        let config = PlantConfig {
            engine: EngineName::Rapier,
            gravity: [0.0; 3],
            contact: ContactConfig {
                self_contact,
                ..ContactConfig::default()
            },
            ..PlantConfig::default()
        };
        let mut r = Rig::new(&model, &config, 0, PERIOD_NS).unwrap();
        r.set_state(&[0.0, 2.2, 2.2], &[0.0, 0.0, 0.0]).unwrap();
        let mut touched = 0;
        for _ in 0..50 {
            r.step(Some(&[0.0, 0.0, 0.0])).unwrap();
            touched += u32::from(r.effects().has(Effects::CONTACT));
        }
        touched
    };
    assert!(run(true) > 0, "self contact on: the folded links never met");
    assert_eq!(run(false), 0);
}

/// What a contact scenario must be before it runs: no obstacle through the
/// arm where it starts, no broken primitive, objects held by moving links.
#[test]
fn a_contact_scenario_is_checked_before_it_runs() {
    let model = ArmModel::from_urdf_str(PENDULUM).unwrap();
    let mut contact = ContactConfig {
        obstacle: vec![wall()],
        ..ContactConfig::default()
    };
    plant_rapier::check_contact(&model, &contact, &[0.0]).unwrap();
    // At q = π/2 the ball is inside the wall.
    let e = plant_rapier::check_contact(&model, &contact, &[std::f64::consts::FRAC_PI_2])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("plant.contact.obstacle[0]") && e.contains("overlaps link 'arm'"),
        "{e}"
    );
    let broken = PENDULUM.replace("sphere radius=\"0.05\"", "sphere radius=\"-0.05\"");
    let e =
        plant_rapier::check_contact(&ArmModel::from_urdf_str(&broken).unwrap(), &contact, &[0.0])
            .unwrap_err()
            .to_string();
    assert!(
        e.contains("link 'arm' collision 1: <sphere radius> -0.05"),
        "{e}"
    );
    contact.object = vec![ContactObject {
        link: "base".into(),
        ..object(0.0, None)
    }];
    let e = plant_rapier::check_contact(&model, &contact, &[0.0])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("plant.contact.object[0].link") && e.contains("not the fixed base"),
        "{e}"
    );
    // A free object through the tip at the start is refused; grasped from
    // the first step, it is part of the link at once and allowed.
    let mut at_tip = ContactObject {
        link: "arm".into(),
        xyz: [1.0, 0.0, 0.0],
        ..object(0.5, None)
    };
    contact.object = vec![at_tip.clone()];
    let e = plant_rapier::check_contact(&model, &contact, &[0.0])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("plant.contact.object[0]") && e.contains("overlaps link 'arm'"),
        "{e}"
    );
    at_tip.grasp_at_s = 0.0;
    contact.object = vec![at_tip];
    plant_rapier::check_contact(&model, &contact, &[0.0]).unwrap();
    // A material with nothing to touch.
    let lone = ContactConfig {
        restitution: 0.5,
        ..ContactConfig::default()
    };
    let e = lone.validate().unwrap_err().to_string();
    assert!(
        e.contains("plant.contact.restitution") && e.contains("nothing to touch"),
        "{e}"
    );
    // More objects than the log carries poses of.
    contact.object = vec![object(100.0, None); wire::MAX_OBJECTS + 1];
    let e = contact.validate().unwrap_err().to_string();
    assert!(e.contains("at most 4"), "{e}");
}

/// Issue 48 item 10 (D18): a link grasps only what is within reach; an
/// object 900 m from it is refused by name when the grasp comes, not
/// carried across the world.
#[test]
fn a_grasp_out_of_reach_is_refused() {
    let mut far = object(0.01, None);
    far.xyz = [900.0, 0.0, 0.0];
    let mut r = two_link(
        ContactConfig {
            object: vec![far],
            ..ContactConfig::default()
        },
        None,
    );
    let e = (0..20)
        .find_map(|_| r.step(Some(&[0.0, 0.0])).err())
        .expect("the grasp went ahead")
        .to_string();
    assert!(
        e.contains("plant.contact.object[0]") && e.contains("within 2 m"),
        "{e}"
    );
    assert!(!r.effects().has(Effects::PAYLOAD));
}

/// Issue 48 item 10 (N12): an object of 1e-300 kg passed "> 0" and then
/// faulted on every step; below 1e-9 kg it is refused by key, value and
/// range, and the edge is taken.
#[test]
fn an_object_lighter_than_a_microgram_is_refused() {
    let mut o = object(100.0, None);
    for mass in [1e-300, 1e-10] {
        o.mass = mass;
        let c = ContactConfig {
            object: vec![o.clone()],
            ..ContactConfig::default()
        };
        let e = c.validate().unwrap_err().to_string();
        assert!(
            e.contains("plant.contact.object[0].mass") && e.contains("[1e-9, 10000] kg"),
            "{e}"
        );
    }
    o.mass = 1e-9;
    ContactConfig {
        object: vec![o],
        ..ContactConfig::default()
    }
    .validate()
    .unwrap();
}

/// The pendulum pushed into the wall by a steady torque τ comes to rest
/// against it: the contact then has points, and its mean force balances
/// the torque about the joint (F · r_y = τ, the wall's normal along x).
#[test]
fn a_resting_contact_has_points_and_balances_the_torque() {
    let mut r = rig(EngineName::Rapier, 0.0).unwrap();
    let tau = 2.0;
    r.set_state(&[1.4], &[0.0]).unwrap();
    let (mut q, mut qd) = ([0.0], [0.0]);
    for _ in 0..3000 {
        r.step(Some(&[tau])).unwrap();
    }
    r.true_state_into(&mut q, &mut qd);
    let c = r.plant().contact().unwrap();
    assert!(qd[0].abs() < 1e-6, "still moving: q̇ {}", qd[0]);
    assert!(
        c.points > 0,
        "resting on the wall with no contact point: {c:?}"
    );
    let want = tau / q[0].sin();
    assert!(
        (c.force - want).abs() <= 1e-6 * want,
        "mean force {} N, torque balance {want} N",
        c.force
    );
}
