//! `[plant.actuator]`: each effect on a one-joint rotor (no gravity torque)
//! against its closed form — the torque lag, the slew limit, a
//! series-elastic joint, backlash and cogging — and the errors a setting
//! missing its partner gives.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use plant_rapier::{
    ActuatorConfig, ArmModel, Effects, EngineName, Harmonic, PerJoint, PlantConfig, PlantError, Rig,
};

const PERIOD_NS: u64 = 1_000_000;
const DT: f64 = 1e-3;
/// The rotor's inertia about its axis, kg m².
const I: f64 = 0.5;

/// One continuous joint about the vertical: gravity gives it no torque.
const ROTOR: &str = r#"<robot name="rotor">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><origin xyz="0 0 0"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.5"/></inertial>
  </link>
  <joint name="j" type="continuous">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit effort="1000" velocity="100"/>
  </joint>
</robot>"#;

fn rig(actuator: ActuatorConfig) -> Rig {
    rig_on(EngineName::Articulated, actuator).unwrap()
}

fn rig_on(engine: EngineName, actuator: ActuatorConfig) -> Result<Rig, PlantError> {
    let model = ArmModel::from_urdf_str(ROTOR).unwrap();
    let config = PlantConfig {
        engine,
        actuator,
        ..PlantConfig::default()
    };
    Rig::new(&model, &config, 0, PERIOD_NS)
}

fn state(r: &Rig) -> (f64, f64) {
    let (mut q, mut qd) = ([0.0], [0.0]);
    r.true_state_into(&mut q, &mut qd);
    (q[0], qd[0])
}

/// Steps `r` under the constant command `tau` for `periods`, calling
/// `check(t, q, q̇, rig)` after each.
fn run(r: &mut Rig, tau: f64, periods: u32, mut check: impl FnMut(f64, f64, f64, &Rig)) {
    for k in 1..=periods {
        r.step(Some(&[tau])).unwrap();
        let (q, qd) = state(r);
        check(f64::from(k) * DT, q, qd, r);
    }
}

fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol * want.abs().max(1e-3),
        "{what}: {got} vs {want}"
    );
}

/// A first-order lag of time constant T from rest under a step τ:
/// τ_m = τ (1 − e^(−t/T)), so q̇ = τ/I (t − T(1 − e^(−t/T))) and
/// q = τ/I (t²/2 − T t + T² (1 − e^(−t/T))). The logged torque is the
/// period's mean.
#[test]
fn a_torque_lag_is_its_exponential() {
    let (tau, f) = (2.0, 10.0);
    let tc = 1.0 / (2.0 * std::f64::consts::PI * f);
    let mut r = rig(ActuatorConfig {
        bandwidth_hz: PerJoint::All(f),
        ..Default::default()
    });
    assert!(r.effects().has(Effects::MOTOR_LAG));
    let decay = |t: f64| -(-t / tc).exp_m1();
    // RK4 on q̈ = τ_m(t)/I is Simpson's rule: h⁵/2880 · τ/(I T⁴) ≈ 2e-11
    // per step, 2e-8 of q̇ at the first step and far less after.
    run(&mut r, tau, 200, |t, q, qd, r| {
        close(qd, tau / I * (t - tc * decay(t)), 1e-7, "q̇");
        close(
            q,
            tau / I * (t * t / 2.0 - tc * t + tc * tc * decay(t)),
            1e-7,
            "q",
        );
        let mean = tau * (DT - tc * (decay(t) - decay(t - DT)));
        close(r.applied_torque()[0] * DT, mean, 1e-12, "mean torque");
    });
}

/// A slew limit r from rest under a step τ: τ_m = r t until τ, so q̇ =
/// r t²/(2I), then the rigid response. The ramp ends mid-period.
#[test]
fn a_slew_limit_is_a_ramp() {
    let (tau, rate) = (5.0, 48.0);
    let t1 = tau / rate;
    let mut r = rig(ActuatorConfig {
        slew_rate: PerJoint::All(rate),
        ..Default::default()
    });
    run(&mut r, tau, 200, |t, q, qd, _| {
        let (w, x) = if t <= t1 {
            (rate * t * t / (2.0 * I), rate * t.powi(3) / (6.0 * I))
        } else {
            let (w1, x1) = (rate * t1 * t1 / (2.0 * I), rate * t1.powi(3) / (6.0 * I));
            let u = t - t1;
            (w1 + tau / I * u, x1 + w1 * u + tau / I * u * u / 2.0)
        };
        // Exact along the ramp (a polynomial); after it, the one RK4 step
        // that meets its corner is Simpson's rule across a kink, off by
        // about r h²/I / 40 in q̇.
        let tol = if t < t1 { 1e-12 } else { 5e-6 };
        close(qd, w, tol, "q̇");
        close(q, x, tol, "q");
    });
}

fn elastic(k: f64, d: f64, b: f64, gap: f64) -> ActuatorConfig {
    ActuatorConfig {
        stiffness: PerJoint::All(k),
        damping: PerJoint::All(d),
        motor_inertia: PerJoint::All(b),
        backlash: PerJoint::All(gap),
        ..Default::default()
    }
}

/// A series-elastic joint from rest under a step τ: the centre of inertia
/// x_c = (Bθ + Iq)/(B + I) moves as τt²/(2(B + I)); the deflection φ = θ − q
/// is the damped oscillator μφ̈ + Dφ̇ + Kφ = μτ/B, μ = BI/(B + I), from
/// φ = φ̇ = 0; q = x_c − Bφ/(B + I).
#[test]
fn a_series_elastic_joint_is_its_two_mass_oscillator() {
    let (tau, k, d, b) = (1.0, 200.0, 0.5, 0.05);
    let mut r = rig(elastic(k, d, b, 0.0));
    assert!(r.effects().has(Effects::ELASTIC));
    let mu = b * I / (b + I);
    let (w0, zeta) = ((k / mu).sqrt(), d / (2.0 * (k * mu).sqrt()));
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    let phi_ss = mu * tau / (b * k);
    let phi = |t: f64| {
        let e = (-zeta * w0 * t).exp();
        phi_ss * (1.0 - e * ((wd * t).cos() + zeta * w0 / wd * (wd * t).sin()))
    };
    run(&mut r, tau, 500, |t, q, _, r| {
        let xc = tau * t * t / (2.0 * (b + I));
        close(q, xc - b / (b + I) * phi(t), 1e-7, "q");
        let (theta, _) = r.plant().motor_state().unwrap();
        close(theta[0] - q, phi(t), 1e-6, "φ");
    });
}

/// Backlash: the motor turns alone through half the gap, θ = τt²/(2B),
/// the link exactly still, until the teeth meet at t = √(gap B/τ); from
/// then on the link moves. The spring is internal: Bθ̇ + Iq̇ = τt always.
#[test]
fn backlash_leaves_the_link_still_until_the_gap_closes() {
    let (tau, b, gap): (f64, f64, f64) = (0.1, 0.05, 0.021);
    let meet = (gap * b / tau).sqrt();
    let mut r = rig(elastic(1000.0, 1.0, b, gap));
    assert!(r.effects().has(Effects::BACKLASH));
    let mut moved_at = None;
    run(&mut r, tau, 200, |t, q, qd, r| {
        let (theta, theta_dot) = r.plant().motor_state().unwrap();
        close(b * theta_dot[0] + I * qd, tau * t, 1e-9, "momentum");
        if t < meet {
            assert_eq!((q, qd), (0.0, 0.0), "t = {t}");
            close(theta[0], tau * t * t / (2.0 * b), 1e-12, "θ");
        } else if q != 0.0 && moved_at.is_none() {
            moved_at = Some(t);
        }
    });
    let moved_at = moved_at.expect("the link never moved");
    assert!(moved_at - meet <= DT, "{moved_at} vs {meet}");
}

fn cogging(order: f64, a: f64, phase: f64) -> Vec<Harmonic> {
    vec![Harmonic {
        order,
        amplitude: PerJoint::All(a),
        phase,
    }]
}

/// Cogging A sin(nθ + φ) is a potential torque: the command −A sin(nq₀ + φ)
/// holds the rotor still at q₀, and without a command ½Iq̇² + (A/n)
/// cos(nq + φ) is conserved.
#[test]
fn cogging_is_a_potential_torque() {
    let (n, a, phase) = (6.0, 0.2, 0.3);
    let config = ActuatorConfig {
        cogging: cogging(n, a, phase),
        ..Default::default()
    };
    let q0 = 0.4;
    let mut r = rig(config.clone());
    assert!(r.effects().has(Effects::COGGING));
    r.set_state(&[q0], &[0.0]).unwrap();
    run(&mut r, -a * (n * q0 + phase).sin(), 500, |_, q, _, _| {
        close(q, q0, 1e-12, "held q");
    });
    let energy = |q: f64, qd: f64| 0.5 * I * qd * qd + a / n * (n * q + phase).cos();
    let mut r = rig(config);
    r.set_state(&[0.0], &[1.0]).unwrap();
    let e0 = energy(0.0, 1.0);
    let mut speeds = (f64::INFINITY, 0.0f64);
    run(&mut r, 0.0, 1000, |_, q, qd, _| {
        close(energy(q, qd), e0, 1e-9, "energy");
        speeds = (speeds.0.min(qd), speeds.1.max(qd));
    });
    // The cogging really acts: the speed swings by more than 10 %.
    assert!(speeds.1 - speeds.0 > 0.1, "{speeds:?}");
}

/// On an elastic joint cogging acts on the motor: holding the motor still
/// at θ₀ with the spring unloaded takes −A sin(nθ₀ + φ).
#[test]
fn an_elastic_joint_cogs_at_its_motor_angle() {
    let (n, a, phase, q0) = (6.0, 0.2, 0.3, 0.4);
    let mut r = rig(ActuatorConfig {
        cogging: cogging(n, a, phase),
        ..elastic(500.0, 0.5, 0.05, 0.0)
    });
    r.set_state(&[q0], &[0.0]).unwrap();
    run(&mut r, -a * (n * q0 + phase).sin(), 300, |_, q, _, r| {
        let (theta, _) = r.plant().motor_state().unwrap();
        close(theta[0], q0, 1e-12, "held θ");
        close(q, q0, 1e-12, "held q");
    });
}

/// Rapier takes the lag, slew and cogging (evaluated at each of its
/// substeps); the motors' mean torque does not depend on the engine.
#[test]
fn rapier_takes_the_motor_lag_with_the_same_torque() {
    let config = ActuatorConfig {
        bandwidth_hz: PerJoint::All(20.0),
        slew_rate: PerJoint::All(30.0),
        ..Default::default()
    };
    let mut a = rig(config.clone());
    let mut b = rig_on(EngineName::Rapier, config).unwrap();
    for k in 0..100 {
        let tau = [if k < 50 { 2.0 } else { -1.0 }];
        a.step(Some(&tau)).unwrap();
        b.step(Some(&tau)).unwrap();
        assert_eq!(a.applied_torque(), b.applied_torque());
    }
    let ((qa, _), (qb, _)) = (state(&a), state(&b));
    close(qb, qa, 1e-2, "Rapier's q");
}

fn error_of(engine: EngineName, config: ActuatorConfig) -> String {
    rig_on(engine, config).unwrap_err().to_string()
}

#[test]
fn a_setting_without_its_partner_is_named() {
    let art = EngineName::Articulated;
    let e = error_of(
        art,
        ActuatorConfig {
            stiffness: PerJoint::All(100.0),
            ..Default::default()
        },
    );
    assert!(
        e.contains("plant.actuator.stiffness[0]") && e.contains("motor_inertia"),
        "{e}"
    );
    let e = error_of(
        art,
        ActuatorConfig {
            backlash: PerJoint::All(0.01),
            ..Default::default()
        },
    );
    assert!(
        e.contains("plant.actuator.backlash[0]") && e.contains("stiffness"),
        "{e}"
    );
    let e = error_of(EngineName::Rapier, elastic(100.0, 0.0, 0.1, 0.0));
    assert!(
        e.contains("plant.actuator.stiffness") && e.contains("articulated"),
        "{e}"
    );
    let e = error_of(
        art,
        ActuatorConfig {
            cogging: cogging(0.0, 0.1, 0.0),
            ..Default::default()
        },
    );
    assert!(e.contains("plant.actuator.cogging[0].order"), "{e}");
    let e = error_of(
        art,
        ActuatorConfig {
            slew_rate: PerJoint::Each(vec![1.0, 2.0]),
            ..Default::default()
        },
    );
    assert!(e.contains("plant.actuator.slew_rate"), "{e}");
}

/// Issue 48 item 10 (N12): a motor inertia of 1e-300 kg m² passed "> 0"
/// and then faulted on every step; below 1e-9 kg m² it is refused by key,
/// value and range, and the edge is taken.
#[test]
fn a_motor_inertia_below_any_rotor_is_refused() {
    let art = EngineName::Articulated;
    for b in [1e-300, 1e-10] {
        let e = error_of(art, elastic(100.0, 0.0, b, 0.0));
        assert!(
            e.contains("plant.actuator.motor_inertia") && e.contains("1e-9 to 1e9"),
            "{e}"
        );
    }
    let e = error_of(art, elastic(100.0, 0.0, 1e-300, 0.0));
    assert!(e.contains("1e-300"), "the value is named: {e}");
    rig_on(art, elastic(100.0, 0.0, 1e-9, 0.0)).unwrap();
}

fn machine(actuator: ActuatorConfig) -> Result<plant_rapier::PlantMachine, PlantError> {
    machine_of(ROTOR, actuator)
}

fn machine_of(
    urdf: &str,
    actuator: ActuatorConfig,
) -> Result<plant_rapier::PlantMachine, PlantError> {
    let model = ArmModel::from_urdf_str(urdf).unwrap();
    let n = model.dof();
    plant_rapier::PlantMachineConfig {
        model,
        plant: PlantConfig {
            actuator,
            ..PlantConfig::default()
        },
        seed: 0,
        period_ns: PERIOD_NS,
        steps: 10,
        initial_q: vec![0.0; n],
        initial_qd: vec![0.0; n],
    }
    .machine()
}

/// Issue 48 item 7 (N3): K = 1e9 N m/rad on B = 1e-6 kg m², both within
/// their documented ranges, needs 2.2e5 substeps per millisecond (the
/// two-link arm ran at 0.0026× real time, silently). Refused before the
/// first step, naming the keys, the substeps and the bound; a rigid joint
/// costs the scenario's own substeps, a stiff spring under the bound more,
/// with its cause.
#[test]
fn a_spring_too_stiff_to_integrate_is_refused_before_the_run() {
    let e = machine(elastic(1e9, 0.0, 1e-6, 0.0)).unwrap_err();
    assert!(matches!(e, PlantError::TooStiff { .. }), "{e:?}");
    let text = e.to_string();
    for want in [
        "plant.actuator.stiffness",
        "motor_inertia",
        "223608 integrator substeps per 0.001 s period",
        "at most 1e7 a simulated second",
    ] {
        assert!(text.contains(want), "{want:?} missing from: {text}");
    }
    let rigid = machine(ActuatorConfig::default()).unwrap();
    let cost = rigid.period_cost().unwrap();
    assert_eq!((cost.substeps, cost.asked, cost.cause), (1, 1, None));
    assert_eq!(rigid.speed_warning().unwrap(), None);
    let stiff = machine(elastic(1e4, 0.5, 1e-3, 0.0)).unwrap();
    let cost = stiff.period_cost().unwrap();
    assert!(cost.substeps > 1 && cost.cause.is_some(), "{cost:?}");
}

/// Under the bound but slower than real time: 8e6 substeps a simulated
/// second on the two-link arm, whose substep takes about 1.3 µs in a
/// release build (so about 0.1× real time, ten times under the line): the
/// warning estimates the factor from substeps timed here and names the
/// keys.
#[test]
fn a_plant_slower_than_real_time_is_warned() {
    let m = machine_of(plant_rapier::TWO_LINK_URDF, elastic(1.28e6, 0.0, 1e-6, 0.0)).unwrap();
    let cost = m.period_cost().unwrap();
    assert!((8000..8100).contains(&cost.substeps), "{cost:?}");
    let w = m.speed_warning().unwrap().expect("a warning");
    for want in [
        "plant.actuator.stiffness",
        &format!("{} substeps per 0.001 s period", cost.substeps),
        "× real time",
    ] {
        assert!(w.contains(want), "{want:?} missing from: {w}");
    }
}
