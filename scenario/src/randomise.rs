//! `[randomise]`: what a seed varies besides the plant's noise, and how.
//!
//! Each declared key is drawn from its distribution with the scenario's
//! seed, before the run: the drawn scenario is an ordinary one (its
//! `[randomise]` emptied), so `sim`, `run` in lockstep and `compare` give
//! the same run for the same seed. Each key draws from a stream of its own,
//! so declaring one key does not change another's draws.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, Uniform};
use serde::{Deserialize, Serialize};
use trajectory::Signal;

use crate::{Scenario, ScenarioError};
use plant_rapier::PerJoint;

/// A distribution to draw a value from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Dist {
    /// Uniform on [min, max]: `{ uniform = { min = -0.1, max = 0.1 } }`.
    Uniform(Range),
    /// Gaussian: `{ normal = { mean = 0.0, std = 0.05 } }`.
    Normal(Gaussian),
}

/// The bounds of a uniform distribution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Range {
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// The parameters of a normal distribution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gaussian {
    /// Mean.
    pub mean: f64,
    /// Standard deviation (≥ 0).
    pub std: f64,
}

/// What a seed varies, each key optional (default: nothing).
///
/// "per joint" keys draw one value per joint, in joint order; the others
/// one value per run.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Randomise {
    /// Added to `initial.q`, per joint, rad.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_q: Option<Dist>,
    /// Added to `initial.qd`, per joint, rad/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_qd: Option<Dist>,
    /// Phase added to each reference sinusoid, per joint, rad:
    /// sin(ωt) → sin(ωt + φ), cos(ωt) → cos(ωt + φ).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_phase: Option<Dist>,
    /// Factor on each reference sinusoid's amplitudes (not its offset),
    /// per joint; uniform with min ≥ 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_amplitude: Option<Dist>,
    /// Replaces `plant.mass_scale` (the plant's links only: model error);
    /// uniform with min > 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_scale: Option<Dist>,
    /// Replaces `plant.sensor.q_noise_std` for every joint, rad; uniform
    /// with min ≥ 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub q_noise_std: Option<Dist>,
    /// Replaces `plant.disturbance.constant`, per joint, N m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub disturbance_constant: Option<Dist>,
    /// Replaces `plant.disturbance.sin_amplitude`, per joint, N m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub disturbance_sin_amplitude: Option<Dist>,
    /// Replaces `plant.disturbance.noise_std` for every joint, N m;
    /// uniform with min ≥ 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub disturbance_noise_std: Option<Dist>,
}

/// What a key's values may be.
#[derive(Clone, Copy)]
enum Support {
    /// Any finite number.
    Signed,
    /// ≥ 0: a uniform with min ≥ 0 (a normal draw could be negative).
    NonNegative,
    /// > 0: a uniform with min > 0.
    Positive,
}

impl Randomise {
    /// True when nothing is randomised.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// Every key with its name and support, in a fixed order: the order
    /// defines each key's stream.
    fn keys(&self) -> [(&'static str, Option<Dist>, Support); 9] {
        use Support::*;
        [
            ("initial_q", self.initial_q, Signed),
            ("initial_qd", self.initial_qd, Signed),
            ("reference_phase", self.reference_phase, Signed),
            ("reference_amplitude", self.reference_amplitude, NonNegative),
            ("mass_scale", self.mass_scale, Positive),
            ("q_noise_std", self.q_noise_std, NonNegative),
            ("disturbance_constant", self.disturbance_constant, Signed),
            (
                "disturbance_sin_amplitude",
                self.disturbance_sin_amplitude,
                Signed,
            ),
            (
                "disturbance_noise_std",
                self.disturbance_noise_std,
                NonNegative,
            ),
        ]
    }

    /// Checks every distribution; errors name `randomise.<key>`.
    pub fn validate(&self, file: &str) -> Result<(), ScenarioError> {
        for (key, dist, support) in self.keys() {
            if let Some(d) = dist {
                check(d, support).map_err(|need| ScenarioError::Invalid {
                    file: file.to_string(),
                    key: format!("randomise.{key}"),
                    value: format!("{d:?}"),
                    need: need.to_string(),
                })?;
            }
        }
        Ok(())
    }
}

fn check(d: Dist, support: Support) -> Result<(), &'static str> {
    let (lo, spread) = match d {
        Dist::Uniform(Range { min, max }) => (min, max - min),
        Dist::Normal(_) if !matches!(support, Support::Signed) => {
            return Err("a uniform with min >= 0 (a normal draw can be negative)");
        }
        Dist::Normal(Gaussian { mean, std }) => (mean, std),
    };
    // NaN and ±∞ fail here, before any comparison.
    if !(lo.is_finite() && spread.is_finite() && lo.abs() <= 1e9 && spread <= 1e9) {
        return Err("finite numbers of magnitude at most 1e9");
    }
    if spread < 0.0 {
        return Err(match d {
            Dist::Uniform(_) => "a uniform with min <= max",
            Dist::Normal(_) => "a normal with std >= 0",
        });
    }
    match support {
        Support::NonNegative if lo < 0.0 => Err("a uniform with min >= 0"),
        Support::Positive if lo <= 0.0 => Err("a uniform with min > 0"),
        _ => Ok(()),
    }
}

/// Stream of `[randomise]` draws, apart from the plant's noise streams.
const STREAM_BASE: u64 = 0x7261_6e64_6f6d_0000;

/// `n` draws of key number `index` for `seed`.
fn draws(d: Dist, seed: u64, index: u64, n: usize) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(STREAM_BASE + index);
    match d {
        // Checked by `validate`: min <= max, finite; std >= 0, finite.
        Dist::Uniform(Range { min, max }) => match Uniform::new_inclusive(min, max) {
            Ok(u) => (0..n).map(|_| u.sample(&mut rng)).collect(),
            Err(_) => vec![min; n],
        },
        Dist::Normal(Gaussian { mean, std }) => match Normal::new(mean, std) {
            Ok(g) => (0..n).map(|_| g.sample(&mut rng)).collect(),
            Err(_) => vec![mean; n],
        },
    }
}

/// The scenario with its seed's draws applied and `[randomise]` emptied
/// (itself when nothing is randomised). `dof` is the arm's joint count.
pub fn drawn(s: &Scenario, dof: usize) -> Scenario {
    let mut out = s.clone();
    out.randomise = Randomise::default();
    for (index, (key, dist, _)) in s.randomise.keys().into_iter().enumerate() {
        let Some(d) = dist else { continue };
        let per_joint = draws(d, s.seed, index as u64, dof);
        apply(&mut out, key, &per_joint);
    }
    out
}

fn apply(s: &mut Scenario, key: &str, v: &[f64]) {
    let p = &mut s.plant;
    match key {
        "initial_q" => add(&mut s.initial.q, v),
        "initial_qd" => add(&mut s.initial.qd, v),
        "reference_phase" => each_joint(&mut s.reference.joints, v, shift_phase),
        "reference_amplitude" => each_joint(&mut s.reference.joints, v, |j, a| {
            j.sin *= a;
            j.cos *= a;
            for w in &mut j.sines {
                w.sin *= a;
                w.cos *= a;
            }
        }),
        "mass_scale" => p.mass_scale = v[0],
        "q_noise_std" => p.sensor.q_noise_std = PerJoint::All(v[0]),
        "disturbance_constant" => p.disturbance.constant = PerJoint::Each(v.to_vec()),
        "disturbance_sin_amplitude" => p.disturbance.sin_amplitude = PerJoint::Each(v.to_vec()),
        "disturbance_noise_std" => p.disturbance.noise_std = PerJoint::All(v[0]),
        _ => unreachable!("every key of Randomise::keys is applied"),
    }
}

fn add(x: &mut [f64], v: &[f64]) {
    x.iter_mut().zip(v).for_each(|(x, d)| *x += d);
}

fn each_joint(joints: &mut [Signal], v: &[f64], f: impl Fn(&mut Signal, f64)) {
    joints.iter_mut().zip(v).for_each(|(j, x)| f(j, *x));
}

/// s sin(ωt) + c cos(ωt) → s sin(ωt + φ) + c cos(ωt + φ), for the
/// signal's sinusoid and each of its `sines` (steps and ramps keep their
/// times).
fn shift_phase(j: &mut Signal, phi: f64) {
    let (sp, cp) = phi.sin_cos();
    let rotate = |s: &mut f64, c: &mut f64| {
        let (a, b) = (*s, *c);
        *s = a * cp - b * sp;
        *c = a * sp + b * cp;
    };
    rotate(&mut j.sin, &mut j.cos);
    for w in &mut j.sines {
        rotate(&mut w.sin, &mut w.cos);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scenario(randomise: &str) -> Result<Scenario, ScenarioError> {
        Scenario::from_toml_str(&format!("[randomise]\n{randomise}"), "r.toml")
    }

    #[test]
    fn a_seed_gives_the_same_draws_and_another_seed_others() {
        let s = scenario(
            "initial_q = { uniform = { min = -0.1, max = 0.1 } }\n\
             mass_scale = { uniform = { min = 0.8, max = 1.2 } }\n",
        )
        .unwrap();
        let a = drawn(&s, 2);
        assert_eq!(a, drawn(&s, 2));
        assert!(a.randomise.is_empty());
        let mut t = s.clone();
        t.seed = 1;
        let b = drawn(&t, 2);
        assert_ne!(a.initial.q, b.initial.q);
        assert_ne!(a.plant.mass_scale, b.plant.mass_scale);
        for (q, q0) in a.initial.q.iter().zip([0.6, 1.8]) {
            assert!((q - q0).abs() <= 0.1);
        }
        assert!((0.8..=1.2).contains(&a.plant.mass_scale));
    }

    #[test]
    fn a_keys_draws_do_not_depend_on_the_other_keys() {
        let one = scenario("initial_q = { normal = { mean = 0.0, std = 0.1 } }\n").unwrap();
        let two = scenario(
            "initial_q = { normal = { mean = 0.0, std = 0.1 } }\n\
             initial_qd = { normal = { mean = 0.0, std = 0.1 } }\n",
        )
        .unwrap();
        assert_eq!(drawn(&one, 2).initial.q, drawn(&two, 2).initial.q);
    }

    #[test]
    fn a_phase_shift_keeps_the_amplitude() {
        let mut j = Signal {
            sin: 1.0,
            omega: 2.0,
            ..Signal::default()
        };
        shift_phase(&mut j, std::f64::consts::FRAC_PI_2);
        assert!((j.sin).abs() < 1e-15 && (j.cos - 1.0).abs() < 1e-15);
    }

    #[test]
    fn bad_distributions_are_errors_naming_the_key() {
        let e = |t: &str| scenario(t).unwrap_err().to_string();
        assert!(
            e("mass_scale = { normal = { mean = 1.0, std = 0.1 } }")
                .contains("randomise.mass_scale")
        );
        assert!(e("mass_scale = { uniform = { min = 0.0, max = 1.0 } }").contains("min > 0"));
        assert!(e("initial_q = { uniform = { min = 1.0, max = 0.0 } }").contains("min <= max"));
        assert!(e("initial_q = { normal = { mean = 0.0, std = -1.0 } }").contains("std >= 0"));
        assert!(e("initial_q = { normal = { mean = nan, std = 1.0 } }").contains("finite"));
        assert!(e("initial_q = { beta = { a = 1.0 } }").contains("unknown variant `beta`"));
        assert!(
            e("initial_q = { uniform = { min = 0.0, max = 1.0, step = 2 } }")
                .contains("unknown field `step`")
        );
        assert!(
            e("inertia = { uniform = { min = 0.0, max = 1.0 } }")
                .contains("unknown field `inertia`")
        );
    }
}
