//! #38 item 3: the default gains of every shipped arm hold the sampled
//! loop's stability number at its target (1, half the limit of 2) along
//! the whole reference, checked ten times as densely as they were chosen.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

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
