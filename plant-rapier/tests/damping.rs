//! URDF damping on a near-massless link (issue 27): the articulated engine
//! integrates it exactly (ETDRK4), so one step per period is stable and
//! accurate where explicit RK4 needed a thousand.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use plant_rapier::{ArmModel, EngineName, PerJoint, Plant, PlantConfig};

/// A 1 kg upper arm on a shoulder damped `shoulder` N m s, and a 5 g wheel
/// on a joint damped `damping`: at 10 N m s its decay rate d/I is 5e5 /s,
/// 500 per millisecond.
fn arm(shoulder: f64, damping: f64) -> String {
    format!(
        r#"<robot name="damped">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.15 0 0"/><mass value="1.0"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.008" iyz="0" izz="0.008"/></inertial></link>
  <link name="wheel"><inertial><origin xyz="0.01 0 0"/><mass value="0.005"/>
    <inertia ixx="2e-5" ixy="0" ixz="0" iyy="2e-5" iyz="0" izz="2e-5"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="50" velocity="5"/>
    <dynamics damping="{shoulder}"/></joint>
  <joint name="wheel_joint" type="continuous"><parent link="upper"/><child link="wheel"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/><limit effort="5" velocity="50"/>
    <dynamics damping="{damping}"/></joint>
</robot>"#
    )
}

/// A smooth torque with a step in it, so the wheel's velocity has a fast
/// transient to follow as well as a slow drift.
fn torque(t: f64) -> [f64; 2] {
    let step = if t > 0.05 { 0.3 } else { -0.2 };
    [2.0 * (3.0 * t).sin(), step + 0.05 * (20.0 * t).cos()]
}

fn run(plant: &mut Plant, seconds: f64) -> States {
    let dt = 1e-3;
    plant.set_state(&[0.3, 0.0], &[0.0, 2.0]).unwrap();
    let mut out = Vec::new();
    for k in 0..(seconds / dt).round() as usize {
        plant.step(&torque(k as f64 * dt), dt).unwrap();
        out.push(plant.state());
    }
    out
}

type States = Vec<(Vec<f64>, Vec<f64>)>;

/// The largest |Δq| and |Δq̇| between two runs, step by step.
fn largest_gaps(a: &States, b: &States) -> (f64, f64) {
    let (mut gap_q, mut gap_qd) = (0.0f64, 0.0f64);
    for ((qa, va), (qb, vb)) in a.iter().zip(b) {
        for i in 0..qa.len() {
            gap_q = gap_q.max((qa[i] - qb[i]).abs());
            gap_qd = gap_qd.max((va[i] - vb[i]).abs());
        }
    }
    (gap_q, gap_qd)
}

/// One step per period with URDF damping 10 N m s on a 5 g wheel, against
/// the same damping as the scenario's viscous friction, which acts through
/// explicit RK4 and so takes the engine's substep bound (an independent
/// fine-step reference: 489 RK4 steps per period). Explicit RK4 at one
/// step per period diverges at once (λh = 500).
///
/// The wheel's damping is stiff and solved in its mode; the shoulder's
/// 0.5 N m s is mild (h·d·(M⁻¹)₀₀ = 0.016) and stays explicit. Measured
/// over 0.3 s: 3.2e-7 rad and 6.0e-6 rad/s apart, the explicit shoulder
/// damping seeing the wheel's fast transient through the coupling; with
/// the shoulder undamped (all the damping in the mode), 6.2e-10 rad and
/// 3.8e-9 rad/s. Both are inside what the mild path (plain RK4) gives:
/// 3.3e-6 rad and 6.4e-4 rad/s below.
#[test]
fn a_heavily_damped_light_joint_takes_one_step_and_matches_a_fine_reference() {
    let d = 10.0;
    for (shoulder, within) in [(0.5, [1e-6, 2e-5]), (0.0, [1e-8, 1e-7])] {
        let exact = ArmModel::from_urdf_str(&arm(shoulder, d)).unwrap();
        let mut plant = Plant::new(&exact, &PlantConfig::default()).unwrap();
        assert_eq!(plant.engine_name(), EngineName::Articulated);
        assert_eq!(plant.substeps_per_period(1e-3), 1);

        // The reference: no URDF damping (plain RK4), the same as the
        // scenario's viscous friction.
        let explicit = ArmModel::from_urdf_str(&arm(0.0, 0.0)).unwrap();
        let mut config = PlantConfig::default();
        config.friction.viscous = PerJoint::Each(vec![shoulder, d]);
        let mut reference = Plant::new(&explicit, &config).unwrap();
        let fine = reference.substeps_per_period(1e-3);
        assert!(fine > 300, "the reference takes only {fine} substeps");

        let a = run(&mut plant, 0.3);
        let b = run(&mut reference, 0.3);
        let (gap_q, gap_qd) = largest_gaps(&a, &b);
        let moved = (a[a.len() - 1].0[1] - 0.0).abs();
        assert!(moved > 1e-3, "the wheel did not move ({moved})");
        assert!(
            gap_q < within[0] && gap_qd < within[1],
            "shoulder {shoulder}: one step per period vs {fine} RK4 substeps: |Δq| {gap_q:e} rad, |Δq̇| {gap_qd:e} rad/s"
        );
    }
}

/// Ten seconds at one step per period, damping up to 1000 N m s (a decay
/// rate of 5e7 /s): finite and bounded, settling to the torque's speed.
#[test]
fn a_heavily_damped_light_joint_stays_stable_at_one_step_per_period() {
    for d in [1.0, 10.0, 1000.0] {
        let model = ArmModel::from_urdf_str(&arm(0.5, d)).unwrap();
        let mut plant = Plant::new(&model, &PlantConfig::default()).unwrap();
        assert_eq!(plant.substeps_per_period(1e-3), 1, "damping {d}");
        let states = run(&mut plant, 10.0);
        for (q, qd) in &states {
            assert!(
                q.iter().chain(qd).all(|x| x.is_finite() && x.abs() < 1e3),
                "damping {d}: {q:?} {qd:?}"
            );
        }
    }
}

/// Mild URDF damping (the wheel's rate about 200 /s, λh ≈ 0.2): the step
/// is plain RK4 with the damping explicit (no modes), and one step per
/// period matches the same arm at 64 substeps a period. Measured over
/// 0.3 s: 3.3e-6 rad and 6.4e-4 rad/s apart, on a wheel turning at up to
/// 75 rad/s through a torque step (RK4's 1e-5 relative on the fast mode;
/// the modes would give 5.5e-9 and 8.6e-8). That is the accuracy class the
/// engine already accepts for the scenario's explicit viscous friction (a
/// substep while h·rate ≤ 1); steps with stiffer damping keep the modes.
#[test]
fn a_mildly_damped_joint_takes_plain_rk4_and_matches_a_fine_reference() {
    let model = ArmModel::from_urdf_str(&arm(0.5, 0.004)).unwrap();
    let mut plant = Plant::new(&model, &PlantConfig::default()).unwrap();
    assert_eq!(plant.substeps_per_period(1e-3), 1);
    let config = PlantConfig {
        substeps: Some(64),
        ..PlantConfig::default()
    };
    let mut reference = Plant::new(&model, &config).unwrap();
    assert_eq!(reference.substeps_per_period(1e-3), 64);
    let a = run(&mut plant, 0.3);
    let b = run(&mut reference, 0.3);
    let (gap_q, gap_qd) = largest_gaps(&a, &b);
    assert!(
        gap_q < 1e-5 && gap_qd < 2e-3,
        "one step vs 64: |Δq| {gap_q:e} rad, |Δq̇| {gap_qd:e} rad/s"
    );
}
