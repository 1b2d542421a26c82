//! `[plant.actuator]`: what lies between the torque a drive is told to give
//! and the torque the link feels — the motor's bandwidth and slew limit,
//! cogging, and a series-elastic transmission with backlash. Every entry is
//! off at its default.

use serde::{Deserialize, Serialize};

use super::{PerJoint, invalid};
use crate::PlantError;

/// The actuator of each joint. Units are for revolute joints; a prismatic
/// joint takes N for N m and m for rad.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ActuatorConfig {
    /// Motor torque bandwidth, Hz: the torque follows the command through a
    /// first-order lag of time constant 1/(2π f) (default: 0, no lag).
    pub bandwidth_hz: PerJoint,
    /// Torque slew limit, N m/s: the torque moves towards the command no
    /// faster than this (default: 0, no limit).
    pub slew_rate: PerJoint,
    /// Series elasticity: stiffness of the transmission between motor and
    /// link, N m/rad (default: 0, a rigid joint). Needs `motor_inertia`.
    pub stiffness: PerJoint,
    /// Damping across the transmission, N m s/rad (default: 0). Needs
    /// `stiffness`.
    pub damping: PerJoint,
    /// The motor's inertia seen at the joint (rotor inertia × gear ratio²),
    /// kg m² (default: 0). Needs `stiffness`: with a rigid joint, rotor
    /// inertia is `[plant] armature`.
    pub motor_inertia: PerJoint,
    /// Gear backlash: the width of the dead band in the transmission, rad
    /// (default: 0). Needs `stiffness`: the teeth meet through it.
    pub backlash: PerJoint,
    /// Cogging and torque ripple: harmonics of the motor angle added to its
    /// torque (default: none).
    pub cogging: Vec<Harmonic>,
}

/// One harmonic of the cogging torque: amplitude · sin(order · θ + phase),
/// θ the motor angle (the joint angle when the joint is rigid).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Harmonic {
    /// Periods per radian of motor angle (a 6-pole-pair motor behind a 100:1
    /// gear cogs at order 600 when θ is the joint angle).
    pub order: f64,
    /// Amplitude per joint, N m.
    pub amplitude: PerJoint,
    /// Phase, rad (default: 0).
    #[serde(default)]
    pub phase: f64,
}

/// The lightest motor inertia taken, kg m²: a hundred times below a
/// millimetre-scale micromotor's rotor.
pub const MIN_MOTOR_INERTIA: f64 = 1e-9;

/// The largest cogging order taken: a period of 1 µrad.
const MAX_ORDER: f64 = 1e6;

impl ActuatorConfig {
    /// Whether every entry is at its default (the key is then not written,
    /// so scenarios' identities keep).
    pub fn is_off(&self) -> bool {
        *self == Self::default()
    }

    /// Whether any joint's torque lags or is slew limited.
    pub fn lags(&self) -> bool {
        !(self.bandwidth_hz.is_zero() && self.slew_rate.is_zero())
    }

    /// Whether any joint is series elastic.
    pub fn elastic(&self) -> bool {
        !self.stiffness.is_zero()
    }

    /// Whether any joint has backlash.
    pub fn has_backlash(&self) -> bool {
        !self.backlash.is_zero()
    }

    /// Whether any joint cogs.
    pub fn cogs(&self) -> bool {
        self.cogging.iter().any(|h| !h.amplitude.is_zero())
    }

    /// Checks every entry that does not depend on the arm.
    pub(super) fn validate(&self) -> Result<(), PlantError> {
        for (key, v) in self.per_joint() {
            v.check(&format!("plant.actuator.{key}"))?;
        }
        // A rotor lighter than any motor has makes the spring's mode too
        // fast for any step: 1e-300 kg m² faulted on every step.
        self.motor_inertia.check_with(
            "plant.actuator.motor_inertia",
            |x| x == 0.0 || (MIN_MOTOR_INERTIA..=super::per_joint::MAX_MAGNITUDE).contains(&x),
            "0 (off) or a number from 1e-9 to 1e9, kg m²",
        )?;
        for (i, h) in self.cogging.iter().enumerate() {
            let key = format!("plant.actuator.cogging[{i}]");
            if !(h.order > 0.0 && h.order <= MAX_ORDER) {
                return Err(invalid(
                    &format!("{key}.order"),
                    h.order,
                    "a number of periods per radian in (0, 1e6]",
                ));
            }
            if !h.phase.is_finite() {
                return Err(invalid(&format!("{key}.phase"), h.phase, "a finite angle"));
            }
            h.amplitude.check_signed(&format!("{key}.amplitude"))?;
        }
        Ok(())
    }

    /// Every per-joint entry with its key.
    fn per_joint(&self) -> [(&'static str, &PerJoint); 6] {
        [
            ("bandwidth_hz", &self.bandwidth_hz),
            ("slew_rate", &self.slew_rate),
            ("stiffness", &self.stiffness),
            ("damping", &self.damping),
            ("motor_inertia", &self.motor_inertia),
            ("backlash", &self.backlash),
        ]
    }

    /// The actuator of each of `n` joints; the error names the key and the
    /// joint where a setting needs another one.
    pub fn resolve(&self, n: usize) -> Result<Vec<JointActuator>, PlantError> {
        let get = |key: &str, v: &PerJoint| v.resolve(&format!("plant.actuator.{key}"), n);
        let bandwidth = get("bandwidth_hz", &self.bandwidth_hz)?;
        let slew = get("slew_rate", &self.slew_rate)?;
        let stiffness = get("stiffness", &self.stiffness)?;
        let damping = get("damping", &self.damping)?;
        let inertia = get("motor_inertia", &self.motor_inertia)?;
        let backlash = get("backlash", &self.backlash)?;
        let mut cogging = Vec::with_capacity(self.cogging.len());
        for (k, h) in self.cogging.iter().enumerate() {
            let key = format!("plant.actuator.cogging[{k}].amplitude");
            cogging.push(h.amplitude.resolve_signed(&key, n)?);
        }
        (0..n)
            .map(|i| {
                let spring = match (stiffness[i], inertia[i]) {
                    (k, b) if k > 0.0 && b > 0.0 => Some(Spring {
                        stiffness: k,
                        damping: damping[i],
                        motor_inertia: b,
                        half_gap: backlash[i] / 2.0,
                    }),
                    (k, _) if k > 0.0 => {
                        return Err(needs(i, "stiffness", "motor_inertia > 0"));
                    }
                    _ => {
                        for (key, v) in [
                            ("damping", damping[i]),
                            ("motor_inertia", inertia[i]),
                            ("backlash", backlash[i]),
                        ] {
                            if v > 0.0 {
                                return Err(needs(i, key, "stiffness > 0"));
                            }
                        }
                        None
                    }
                };
                Ok(JointActuator {
                    time_constant: match bandwidth[i] {
                        0.0 => 0.0,
                        f => 1.0 / (2.0 * std::f64::consts::PI * f),
                    },
                    slew_rate: match slew[i] {
                        0.0 => f64::INFINITY,
                        r => r,
                    },
                    spring,
                    cogging: self
                        .cogging
                        .iter()
                        .zip(&cogging)
                        .filter(|(_, a)| a[i] != 0.0)
                        .map(|(h, a)| (h.order, a[i], h.phase))
                        .collect(),
                })
            })
            .collect()
    }
}

fn needs(joint: usize, key: &str, need: &str) -> PlantError {
    invalid(
        &format!("plant.actuator.{key}[{joint}]"),
        "set",
        format!("paired with plant.actuator.{need} for that joint (a series-elastic joint)"),
    )
}

/// One joint's actuator, resolved.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointActuator {
    /// Time constant of the torque lag, s (0: none).
    pub time_constant: f64,
    /// Slew limit, N m/s (infinite: none).
    pub slew_rate: f64,
    /// The series-elastic transmission, if the joint has one.
    pub spring: Option<Spring>,
    /// Cogging harmonics: (order, amplitude, phase).
    pub cogging: Vec<(f64, f64, f64)>,
}

/// A series-elastic transmission with backlash.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// N m/rad.
    pub stiffness: f64,
    /// N m s/rad.
    pub damping: f64,
    /// kg m².
    pub motor_inertia: f64,
    /// Half the backlash, rad.
    pub half_gap: f64,
}

impl Spring {
    /// The torque the transmission passes to the link at a deflection φ =
    /// θ − q and its rate: nothing inside the gap, K (φ ∓ gap/2) + D φ̇ once
    /// the teeth meet.
    pub fn torque(&self, phi: f64, phi_dot: f64) -> f64 {
        let g = self.half_gap;
        let engaged = if phi > g {
            phi - g
        } else if phi < -g {
            phi + g
        } else if g == 0.0 {
            0.0
        } else {
            return 0.0;
        };
        self.stiffness * engaged + self.damping * phi_dot
    }
}

impl JointActuator {
    /// The cogging torque at motor angle `theta`.
    pub fn cogging_at(&self, theta: f64) -> f64 {
        self.cogging
            .iter()
            .map(|(order, a, phase)| a * (order * theta + phase).sin())
            .sum()
    }

    /// Whether the motor torque lags or is slew limited.
    pub fn lags(&self) -> bool {
        self.time_constant > 0.0 || self.slew_rate.is_finite()
    }
}
