//! What a control period costs the articulated engine: how many substeps
//! it takes and why (a stiff spring or damper on a light joint), refused
//! past [`MAX_SUBSTEPS_PER_SECOND`], and a measured wall time a substep.

use super::{Engine, Plant, Torques, articulated};
use crate::PlantError;

/// The most integrator substeps a simulated second may take (the
/// articulated engine's, counted before a run). At about a microsecond a
/// substep on the two-link arm, that is some 10 s of wall time per
/// simulated second (0.1× real time) there, and more on a larger arm;
/// beyond it a run is refused, naming the keys that make it stiff.
pub const MAX_SUBSTEPS_PER_SECOND: f64 = 1e7;

/// What one control period costs the engine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodCost {
    /// The period, s.
    pub period_s: f64,
    /// Substeps a period takes.
    pub substeps: u32,
    /// Substeps the scenario asks for (`[plant] substeps`).
    pub asked: u32,
    /// Why a period takes more than the scenario asks (None: it does not).
    pub cause: Option<StiffCause>,
}

/// What makes the articulated engine take more substeps than asked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StiffCause {
    /// A series-elastic joint oscillates fast: `rate` bounds its angular
    /// frequency, rad/s (from K/B and M(q)⁻¹K at the start).
    Elastic {
        /// rad/s.
        rate: f64,
    },
    /// Explicit damping decays fast: `rate` bounds it, 1/s (the friction
    /// slope, and a series-elastic joint's damping over its motor inertia).
    Damped {
        /// 1/s.
        rate: f64,
    },
}

impl StiffCause {
    /// The scenario keys that set it.
    fn keys(&self) -> &'static str {
        match self {
            Self::Elastic { .. } => "plant.actuator.stiffness / plant.actuator.motor_inertia",
            Self::Damped { .. } => {
                "plant.friction (viscous, coulomb / smoothing_velocity) / plant.actuator.damping"
            }
        }
    }

    /// What it is, with its rate.
    fn describe(&self) -> String {
        match self {
            Self::Elastic { rate } => format!(
                "the series-elastic joints oscillate at up to {rate:.3e} rad/s, and a substep may advance that by at most 0.2 rad"
            ),
            Self::Damped { rate } => format!(
                "the explicit damping decays at up to {rate:.3e} /s, and a substep times it may be at most 1"
            ),
        }
    }
}

impl PeriodCost {
    /// The plant alone's speed against real time when a substep takes
    /// `seconds_per_substep` of wall time.
    pub fn real_time_factor(&self, seconds_per_substep: f64) -> f64 {
        self.period_s / (f64::from(self.substeps) * seconds_per_substep)
    }

    /// A warning for a run the engine's own substeps make slower than real
    /// time (None when it takes only the scenario's, or keeps up).
    pub fn warning(&self, seconds_per_substep: f64) -> Option<String> {
        let cause = self.cause?;
        let factor = self.real_time_factor(seconds_per_substep);
        (factor < 1.0).then(|| {
            format!(
                "{}: {}, so the plant takes {} substeps per {} s period (the scenario asks {}); at {:.2} µs a substep here, the plant alone runs at about {:.3}× real time (a real-time run will miss its deadlines; sim takes about {:.0} s per simulated second)",
                cause.keys(),
                cause.describe(),
                self.substeps,
                self.period_s,
                self.asked,
                seconds_per_substep * 1e6,
                factor,
                1.0 / factor,
            )
        })
    }
}

impl Plant {
    /// What a period of `dt` s costs the engine: its substeps and why it
    /// takes more than the scenario's. Err when it needs more than
    /// [`MAX_SUBSTEPS_PER_SECOND`] a simulated second (or more than a
    /// period's cap): a stiff spring on a light motor needs 2e8, which ran
    /// at 0.0026× real time with no word of why.
    pub fn period_cost(&self, dt: f64) -> Result<PeriodCost, PlantError> {
        let asked = self.substeps;
        let Engine::Articulated(a) = &self.engine else {
            return Ok(PeriodCost {
                period_s: dt,
                substeps: asked,
                asked,
                cause: None,
            });
        };
        let need = a.substeps_needed(dt);
        let (count, cause) = if need.oscillating >= need.damped {
            (
                need.oscillating,
                StiffCause::Elastic {
                    rate: need.oscillation_rate,
                },
            )
        } else {
            (
                need.damped,
                StiffCause::Damped {
                    rate: need.damping_rate,
                },
            )
        };
        if count <= f64::from(asked) {
            return Ok(PeriodCost {
                period_s: dt,
                substeps: asked,
                asked,
                cause: None,
            });
        }
        let per_second = count / dt;
        if per_second > MAX_SUBSTEPS_PER_SECOND || count > articulated::MAX_SUBSTEPS {
            return Err(PlantError::TooStiff {
                keys: cause.keys(),
                why: cause.describe(),
                substeps: count,
                period_s: dt,
                per_second,
            });
        }
        Ok(PeriodCost {
            period_s: dt,
            substeps: a.substeps_for(dt, asked),
            asked,
            cause: Some(cause),
        })
    }

    /// The wall time one substep takes on this machine, s, measured on a
    /// copy of the arm stepping `count` substeps of a period of `dt` with
    /// no torque (this plant is untouched). None for the Rapier engine,
    /// whose substeps are the scenario's own.
    pub fn time_substeps(&self, dt: f64, count: u32) -> Option<f64> {
        let Engine::Articulated(a) = &self.engine else {
            return None;
        };
        let mut arm = a.clone();
        let mut motors = self.motors.clone();
        motors.begin(&vec![0.0; self.dof()]);
        let drive = Torques {
            motors: &motors,
            external: &self.external,
            friction: &self.friction,
        };
        // Substeps of the length a period of `dt` takes, `count` of them.
        let h = dt / f64::from(a.substeps_for(dt, self.substeps));
        let start = std::time::Instant::now();
        arm.step(&drive, h * f64::from(count.max(1)), count.max(1))
            .ok()?;
        let taken = arm.substeps_taken();
        (taken > 0).then(|| start.elapsed().as_secs_f64() / f64::from(taken))
    }
}
