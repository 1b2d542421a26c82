//! #47: an MJCF arm's default scenario starts at the file's keyframe
//! `home`, outside the envelope as every default start is; a URDF arm's
//! start is chosen as before (it has no home).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use plant_rapier::ArmModel;
use scenario::ArmDefault;

fn ur5e() -> String {
    let path = format!(
        "{}/../robots/menagerie/universal_robots_ur5e/ur5e.xml",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(path).unwrap()
}

#[test]
fn the_ur5e_starts_at_its_home_keyframe_outside_the_envelope() {
    let text = ur5e();
    let s = ArmDefault::new(&text).unwrap().scenario;
    let model = ArmModel::from_urdf_str_locked(&text, &s.plant.lock).unwrap();
    assert_eq!(Some(&s.initial.q), model.home.as_ref());
    for (i, r) in s.reference.joints.iter().enumerate() {
        let error = (s.initial.q[i] - r.eval(0.0)[0]).abs();
        let bound = s.envelope.joints[i].eval(0.0)[0];
        assert!(
            error > bound,
            "joint {i}: starts {error} from the reference, inside the envelope {bound}"
        );
    }
}

#[test]
fn without_a_home_keyframe_the_start_is_chosen_as_for_a_urdf() {
    let text = ur5e();
    let start = text.find("<keyframe>").unwrap();
    let end = text.find("</keyframe>").unwrap() + "</keyframe>".len();
    let no_home = format!("{}{}", &text[..start], &text[end..]);
    let s = ArmDefault::new(&no_home).unwrap().scenario;
    let home = ArmModel::from_urdf_str(&text).unwrap().home.unwrap();
    assert_ne!(s.initial.q, home);
}
