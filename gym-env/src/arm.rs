//! One arm's episodes: reset to a seed's draw of the scenario, then steps
//! of `decimation` plant periods each with the action held, each returning
//! the next observation, the reward, the safety cost and whether the
//! episode ended.

use controller::ControllerMachine;
use scenario::Plan;
use scenario::stepper::Stepper;

use crate::options::{self, ActionMode, ERROR_CAP, EnvError, EnvOptions};
use crate::render::{Picture, Projection};
use crate::smoothing::ActionShaper;

/// What a step returns besides the observation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Outcome {
    /// The mean over the step's plant periods of −mean_i min((e_i/k_c,i)²,
    /// [`ERROR_CAP`]) − effort_weight · mean_i a_i² − action_rate_weight ·
    /// mean_i (a_i − a_i,prev)², e the true error after the period, a the
    /// clipped actions of this step and the last; an early end (a breach outside safe mode, or a state
    /// that is not finite) adds the worst reward of every step it skips.
    pub reward: f64,
    /// 1 when, at or after T_c, a joint's error was at or past its
    /// envelope after some plant period of the step; else 0.
    pub cost: f64,
    /// The state is not finite, or (outside safe mode) breached.
    pub terminated: bool,
    /// The episode's end (`episode_s`).
    pub truncated: bool,
}

/// What [`ArmEnv::reset`] may change of the scenario, beyond its seed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ResetOptions {
    /// q(0), one per controlled joint (before the scenario's draws).
    pub initial_q: Option<Vec<f64>>,
    /// q̇(0), one per controlled joint (before the scenario's draws).
    pub initial_qd: Option<Vec<f64>>,
}

/// The largest |q(0)| or |q̇(0)| a reset takes: a thousand radians is 159
/// turns, beyond any joint's range and any arm's speed.
pub const MAX_START: f64 = 1e3;

/// One arm's episodes.
pub struct ArmEnv {
    plan: Plan,
    /// The scenario before any draw or reset option: what every reset
    /// starts from, so that one reset's options do not outlive it.
    undrawn: scenario::Scenario,
    opts: EnvOptions,
    scale: Vec<f64>,
    velocity: Vec<f64>,
    n: usize,
    stepper: Stepper,
    base: Option<ControllerMachine>,
    /// The torque commanded in the last plant period.
    tau: Vec<f64>,
    /// The action's torque, clip(a) · span · scale, before smoothing.
    add: Vec<f64>,
    /// Spreads `add` over the step's plant periods.
    shaper: ActionShaper,
    /// The last decision's clipped action (zero before the first).
    last_action: Vec<f64>,
    /// The current episode's seed.
    seed: u64,
    picture: Option<Picture>,
}

impl ArmEnv {
    /// The environment of `plan`, its first episode drawn with the plan's
    /// own seed. The torque and velocity scales are derived from this
    /// first draw and kept for every later episode.
    pub fn new(plan: Plan, opts: EnvOptions) -> Result<Self, EnvError> {
        opts.check()?;
        let n = plan.robot.model.dof();
        let scale = options::torque_scale(&plan, opts.torque_scale.as_deref())?;
        let velocity = options::velocity_scale(&plan);
        let seed = plan.scenario.seed;
        let (stepper, base) = episode(&plan, &opts)?;
        let shaper = ActionShaper::new(opts.smoothing, opts.decimation, plan.dt(), n);
        Ok(Self {
            undrawn: plan.undrawn.clone(),
            plan,
            opts,
            scale,
            velocity,
            n,
            stepper,
            base,
            tau: vec![0.0; n],
            add: vec![0.0; n],
            shaper,
            last_action: vec![0.0; n],
            seed,
            picture: None,
        })
    }

    /// Starts an episode with the scenario's `[randomise]` table drawn
    /// for `seed` (and the plant's noise seeded by it), and writes its
    /// first observation.
    pub fn reset(&mut self, seed: u64, obs: &mut [f64]) -> Result<(), EnvError> {
        self.reset_with(seed, &ResetOptions::default(), obs)
    }

    /// [`ArmEnv::reset`] with the scenario's start changed by `opts`.
    pub fn reset_with(
        &mut self,
        seed: u64,
        opts: &ResetOptions,
        obs: &mut [f64],
    ) -> Result<(), EnvError> {
        let mut s = self.undrawn.clone();
        s.seed = seed;
        for (name, given, into) in [
            ("initial_q", &opts.initial_q, &mut s.initial.q),
            ("initial_qd", &opts.initial_qd, &mut s.initial.qd),
        ] {
            if let Some(v) = given {
                if v.len() != self.n {
                    return Err(EnvError::option(
                        name,
                        format!("{v:?}"),
                        format!(
                            "has {} values; this arm has {} controlled joints",
                            v.len(),
                            self.n
                        ),
                    ));
                }
                if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                    return Err(EnvError::option(
                        &format!("{name}[{i}]"),
                        v[i],
                        "must be a finite number",
                    ));
                }
                // 1e300 rad is finite but no posture: sin and cos of it are
                // noise, and the plant's first step overflows (#60 item 11).
                if let Some(i) = v.iter().position(|x| x.abs() > MAX_START) {
                    return Err(EnvError::option(
                        &format!("{name}[{i}]"),
                        v[i],
                        format!(
                            "must be within ±{MAX_START} (rad or m; per second for initial_qd)"
                        ),
                    ));
                }
                *into = v.clone();
            }
        }
        s.validate(&self.plan.source)?;
        let plan = scenario::plan(
            s,
            self.plan.source.clone(),
            self.plan.toml.clone(),
            self.plan.robot.clone(),
        )?;
        let (stepper, base) = episode(&plan, &self.opts)?;
        self.stepper = stepper;
        self.base = base;
        self.plan = plan;
        self.seed = seed;
        self.tau.fill(0.0);
        self.shaper.reset();
        self.last_action.fill(0.0);
        self.observe(obs);
        Ok(())
    }

    /// Number of controlled joints.
    pub fn dof(&self) -> usize {
        self.n
    }

    /// Length of the observation: e, ė, q, q̇, q_d, q̇_d, k_c, t / T
    /// (errors and velocities scaled unless `scale_obs` is off), then the
    /// last clipped action with `observe_action`.
    pub fn obs_dim(&self) -> usize {
        obs_dim_with(self.n, self.opts.observe_action)
    }

    /// Torque per unit of action, per joint.
    pub fn scale(&self) -> &[f64] {
        &self.scale
    }

    /// Velocity per unit of observation, per joint (rad/s or m/s).
    pub fn velocity_scale(&self) -> &[f64] {
        &self.velocity
    }

    /// The options it was made with.
    pub fn options(&self) -> &EnvOptions {
        &self.opts
    }

    /// The plan of the current episode.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The current episode's seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The plant period the next action acts at.
    pub fn step_index(&self) -> u64 {
        self.stepper.k()
    }

    /// Decisions in an episode: ⌈plant periods / decimation⌉.
    pub fn decisions(&self) -> u64 {
        self.plan.steps.div_ceil(u64::from(self.opts.decimation))
    }

    /// The state as the plant published it last.
    pub fn state(&self) -> &wire::JointState {
        self.stepper.state()
    }

    /// The reference sample due at the current state's time.
    pub fn reference(&self) -> &wire::ReferenceSample {
        self.stepper.reference()
    }

    /// The torque commanded in the last plant period.
    pub fn last_torque(&self) -> &[f64] {
        &self.tau
    }

    /// One step with `action` (checked finite by the caller; clipped to
    /// [−1, 1] here), writing the next observation into `obs`.
    pub fn step(&mut self, action: &[f64], obs: &mut [f64]) -> Outcome {
        let span = match self.opts.action {
            ActionMode::Torque => 1.0,
            ActionMode::Residual(_) => self.opts.residual_scale,
        };
        let effort = crate::action_torque(action, span, &self.scale, &mut self.add);
        self.shaper.decide(&self.add);
        let mut rate = 0.0;
        for (last, a) in self.last_action.iter_mut().zip(action) {
            let a = a.clamp(-1.0, 1.0);
            rate += (a - *last) * (a - *last);
            *last = a;
        }
        // + 0.0 when the rate's weight is 0: the effort term keeps its bits.
        let effort = self.opts.effort_weight * effort / self.n as f64
            + self.opts.action_rate_weight * rate / self.n as f64;
        let (mut reward, mut periods, mut cost, mut breached) = (0.0, 0u32, 0.0, false);
        let mut finite = true;
        while periods < self.opts.decimation && self.stepper.k() < self.stepper.steps() {
            let mut command = match self.base.as_mut() {
                Some(base) => self.stepper.command(base).0,
                None => self.stepper.zero_command(),
            };
            let add = self.shaper.period_torque();
            for (i, add) in add.iter().enumerate() {
                // x + 0.0 is x: a zero residual leaves the law's torque's bits.
                command.tau[i] += add;
                self.tau[i] = command.tau[i];
            }
            let stepped = self.stepper.advance(&command);
            periods += 1;
            let p = self.judge();
            if stepped.is_err() || !p.error.is_finite() {
                finite = false;
                break;
            }
            reward += -p.error - effort;
            if p.outside {
                cost = 1.0;
            }
            breached |= p.breached;
            if breached && !self.opts.safe {
                break;
            }
        }
        self.observe(obs);
        let finite = finite && obs.iter().all(|v| v.is_finite());
        let truncated = self.stepper.k() >= self.stepper.steps();
        let reward = reward / f64::from(periods.max(1));
        // Every decision this early end skips is charged the worst reward
        // a step can have, so ending never pays more than staying.
        let skipped = self.decisions_left() as f64;
        let worst = -(ERROR_CAP + self.opts.effort_weight + 4.0 * self.opts.action_rate_weight);
        if !finite {
            return Outcome {
                reward: worst * (1.0 + skipped),
                cost: 1.0,
                terminated: true,
                truncated: false,
            };
        }
        let terminated = breached && !self.opts.safe;
        Outcome {
            reward: if terminated && !truncated {
                reward + worst * skipped
            } else {
                reward
            },
            cost,
            terminated,
            truncated: truncated && !terminated,
        }
    }

    /// Decisions left in the episode after the current plant period.
    fn decisions_left(&self) -> u64 {
        let left = self.stepper.steps().saturating_sub(self.stepper.k());
        left.div_ceil(u64::from(self.opts.decimation))
    }

    /// The reward's error term, the cost and the breach of the state now.
    fn judge(&self) -> Judged {
        let (s, r) = (self.stepper.state(), self.stepper.reference());
        let t = wire::ns_to_s(s.header.t_ns);
        let judged = t >= self.plan.scenario.controller.tc;
        let (mut err2, mut outside, mut breached) = (0.0, false, false);
        for i in 0..self.n {
            let e = (s.q[i] - r.q_d[i]).abs();
            let kc = r.kc[i];
            // An envelope at zero makes e/k_c infinite: not finite, ends.
            err2 += ((e / kc) * (e / kc)).min(ERROR_CAP);
            if !(e / kc).is_finite() {
                err2 = f64::NAN;
            }
            outside |= e >= kc;
            breached |= self.opts.breach_factor.is_some_and(|f| e > f * kc);
        }
        Judged {
            error: err2 / self.n as f64,
            outside: judged && outside,
            breached: judged && breached,
        }
    }

    /// The observation of the current state: what a controller sees
    /// (measured q, q̇) and the reference sample due.
    fn observe(&self, obs: &mut [f64]) {
        crate::observe(
            self.stepper.state(),
            self.stepper.reference(),
            self.stepper.k(),
            self.stepper.steps(),
            self.opts.scale_obs,
            &self.velocity,
            obs,
        );
        if self.opts.observe_action {
            crate::observe_action(&self.last_action, obs);
        }
    }

    /// A picture of the arm now (dark) over its reference pose (light), as
    /// `height` rows of `width` RGB pixels.
    pub fn render(&mut self, width: usize, height: usize) -> Result<Vec<u8>, EnvError> {
        let (q, q_d) = {
            let (s, r) = (self.stepper.state(), self.stepper.reference());
            (s.q[..self.n].to_vec(), r.q_d[..self.n].to_vec())
        };
        let picture = match &mut self.picture {
            Some(p) => p,
            None => self.picture.insert(Picture::new(
                &self.plan.robot.model,
                &self.plan.scenario.initial.q,
            )),
        };
        picture.draw(width, height, &q, &q_d)
    }

    /// The plane the picture is drawn on (None before the first picture).
    pub fn projection(&self) -> Option<Projection> {
        self.picture.as_ref().map(Picture::projection)
    }
}

/// What one plant period's state is judged to be.
struct Judged {
    /// mean_i min((e_i/k_c,i)², ERROR_CAP); NaN when not finite.
    error: f64,
    /// At or after T_c, some |e_i| ≥ k_c,i.
    outside: bool,
    /// At or after T_c, some |e_i| > breach_factor · k_c,i.
    breached: bool,
}

/// Length of the observation of an arm with `n` joints.
pub fn obs_dim(n: usize) -> usize {
    7 * n + 1
}

/// Length of the observation of an arm with `n` joints, the last action
/// included when `observe_action`.
pub fn obs_dim_with(n: usize, observe_action: bool) -> usize {
    obs_dim(n) + if observe_action { n } else { 0 }
}

/// The stepper and base law of an episode of `plan`, at its first state.
fn episode(
    plan: &Plan,
    opts: &EnvOptions,
) -> Result<(Stepper, Option<ControllerMachine>), EnvError> {
    let stepper = Stepper::new(plan)?;
    let base = match opts.action {
        ActionMode::Torque => None,
        ActionMode::Residual(law) => {
            let params = if plan.scenario.controller.law == law {
                plan.scenario.controller.clone()
            } else {
                plan.scenario.controller.for_law(law)
            };
            Some(plan.controller_config_for(params).machine()?)
        }
    };
    Ok((stepper, base))
}
