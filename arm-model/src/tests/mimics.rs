//! Mimic joints and locks.

use super::*;

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
