//! One episode after another of a scenario, stepped by an action: the
//! loop of `testbed sim` with the controller's torque replaced by the
//! agent's (or added to a built-in law's), and the observation, reward,
//! cost and end of each step.
//!
//! A step is the sim loop's step k: the state s_k and the reference sample
//! due at its time give the torque, the plant steps one period, and the
//! observation, reward and cost are those of s_{k+1}. With a zero residual
//! on the scenario's own law the rows are `testbed sim`'s, bit for bit.

use controller::{ControllerMachine, LawName};
use plant_rapier::{PlantError, PlantMachine};
use scenario::Plan;
use trajectory::TrajectoryMachine;
use wire::{Command, Header, JointState, ReferenceSample};

/// What the action is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ActionMode {
    /// Joint torques: τ_i = clip(a_i, −1, 1) · scale_i.
    Torque,
    /// A residual on a built-in law: τ = τ_law + clip(a_i, −1, 1) ·
    /// residual_scale · scale_i.
    Residual(LawName),
}

/// How an environment is made, beyond its scenario.
#[derive(Debug, Clone)]
pub struct EnvOptions {
    /// What the action is.
    pub action: ActionMode,
    /// The residual's span as a fraction of the torque scale.
    pub residual_scale: f64,
    /// Weight of the effort term of the reward.
    pub effort_weight: f64,
    /// End the episode (`terminated`) once, after T_c, a joint's error
    /// passes this many times its envelope; None: never.
    pub breach_factor: Option<f64>,
    /// Torque per unit of action, per joint (None: the effort limits).
    pub torque_scale: Option<Vec<f64>>,
}

/// Why an environment cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    /// An option out of range.
    #[error("{0}")]
    Option(String),
    /// The scenario drawn for a seed is unusable.
    #[error("{0}")]
    Scenario(#[from] scenario::ScenarioError),
    /// The plant cannot be built.
    #[error("plant: {0}")]
    Plant(#[from] PlantError),
    /// The base law cannot be built.
    #[error("base law: {0}")]
    Controller(#[from] controller::ControllerError),
}

/// The reward of a step whose state is not finite (the episode then ends).
pub const NON_FINITE_REWARD: f64 = -100.0;

/// What a step returns besides the observation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Outcome {
    /// −mean((e/k_c)²) − w · mean((τ/scale)²).
    pub reward: f64,
    /// 1 when, after T_c, a joint's error is at or past its envelope.
    pub cost: f64,
    /// The state is not finite, or breached (see `breach_factor`).
    pub terminated: bool,
    /// The scenario's end.
    pub truncated: bool,
}

/// The machines of one episode.
struct Episode {
    plant: PlantMachine,
    reference: TrajectoryMachine,
    base: Option<ControllerMachine>,
    state: JointState,
    r: ReferenceSample,
    k: u64,
}

/// One arm's episodes.
pub struct ArmEnv {
    plan: Plan,
    opts: EnvOptions,
    scale: Vec<f64>,
    n: usize,
    ep: Episode,
    tau: Vec<f64>,
    /// The current episode's seed.
    seed: u64,
}

impl ArmEnv {
    /// The environment of `plan`, its first episode drawn with the plan's
    /// own seed.
    pub fn new(plan: Plan, opts: EnvOptions) -> Result<Self, EnvError> {
        let n = plan.robot.model.dof();
        let scale = torque_scale(&plan, opts.torque_scale.as_deref())?;
        check_options(&opts)?;
        let seed = plan.scenario.seed;
        let ep = episode(&plan, &opts)?;
        Ok(Self {
            plan,
            opts,
            scale,
            n,
            ep,
            tau: vec![0.0; n],
            seed,
        })
    }

    /// Starts an episode with the scenario's `[randomise]` table drawn
    /// for `seed` (and the plant's noise seeded by it), and writes its
    /// first observation.
    pub fn reset(&mut self, seed: u64, obs: &mut [f64]) -> Result<(), EnvError> {
        let mut s = self.plan.undrawn.clone();
        s.seed = seed;
        s.validate(&self.plan.source)?;
        let plan = scenario::plan(
            s,
            self.plan.source.clone(),
            self.plan.toml.clone(),
            self.plan.robot.clone(),
        )?;
        self.ep = episode(&plan, &self.opts)?;
        self.plan = plan;
        self.seed = seed;
        self.observe(obs);
        Ok(())
    }

    /// Number of controlled joints.
    pub fn dof(&self) -> usize {
        self.n
    }

    /// Length of the observation: e, ė, q, q̇, q_d, q̇_d, k_c, t / T.
    pub fn obs_dim(&self) -> usize {
        obs_dim(self.n)
    }

    /// Torque per unit of action, per joint.
    pub fn scale(&self) -> &[f64] {
        &self.scale
    }

    /// The plan of the current episode.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The current episode's seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The step the next action acts at.
    pub fn step_index(&self) -> u64 {
        self.ep.k
    }

    /// The state as the plant published it last.
    pub fn state(&self) -> &JointState {
        &self.ep.state
    }

    /// The torque commanded by the last step.
    pub fn last_torque(&self) -> &[f64] {
        &self.tau
    }

    /// One step with `action` (checked finite by the caller), writing the
    /// next observation into `obs`.
    pub fn step(&mut self, action: &[f64], obs: &mut [f64]) -> Outcome {
        let n = self.n;
        let ep = &mut self.ep;
        let mut command = match ep.base.as_mut() {
            Some(base) => base.step(&ep.state, Some(&ep.r)).0,
            None => Command {
                header: Header {
                    seq: ep.state.header.seq,
                    t_ns: ep.state.header.t_ns,
                    wall_ns: 0,
                },
                dof: n as u32,
                fault: 0,
                tau: [0.0; wire::MAX_DOF],
                state_wall_ns: 0,
                compute_ns: 0,
                started_wall_ns: 0,
                reference_t_ns: ep.r.header.t_ns,
                stale_references: 0,
            },
        };
        let span = match self.opts.action {
            ActionMode::Torque => 1.0,
            ActionMode::Residual(_) => self.opts.residual_scale,
        };
        for (i, a) in action.iter().enumerate().take(n) {
            let a = a.clamp(-1.0, 1.0);
            // x + 0.0 is x: a zero residual leaves the law's torque's bits.
            command.tau[i] += a * span * self.scale[i];
            self.tau[i] = command.tau[i];
        }
        let stepped = ep.plant.step(Some(&command));
        ep.k += 1;
        ep.state = ep.plant.state(ep.k, 0);
        ep.r = reference_at(&mut ep.reference, &ep.state);
        self.observe(obs);
        let finite = stepped.is_ok() && obs.iter().all(|v| v.is_finite());
        let out = self.outcome(finite);
        // An envelope at zero makes e/k_c infinite: that state is no better.
        if out.reward.is_finite() {
            out
        } else {
            self.outcome(false)
        }
    }

    fn outcome(&self, finite: bool) -> Outcome {
        let (n, ep) = (self.n, &self.ep);
        let truncated = ep.k >= ep.plant.steps();
        if !finite {
            return Outcome {
                reward: NON_FINITE_REWARD,
                cost: 1.0,
                terminated: true,
                truncated: false,
            };
        }
        let t = wire::ns_to_s(ep.state.header.t_ns);
        let judged = t >= self.plan.scenario.controller.tc;
        let (mut err2, mut effort2, mut outside, mut breached) = (0.0, 0.0, false, false);
        for i in 0..n {
            let e = (ep.state.q[i] - ep.r.q_d[i]).abs();
            let kc = ep.r.kc[i];
            err2 += (e / kc) * (e / kc);
            effort2 += (self.tau[i] / self.scale[i]).powi(2);
            outside |= e >= kc;
            breached |= self.opts.breach_factor.is_some_and(|f| e > f * kc);
        }
        let nf = n as f64;
        Outcome {
            reward: -err2 / nf - self.opts.effort_weight * effort2 / nf,
            cost: if judged && outside { 1.0 } else { 0.0 },
            terminated: judged && breached,
            truncated,
        }
    }

    /// The observation of the current state: what a controller sees
    /// (measured q, q̇) and the reference sample due.
    fn observe(&self, obs: &mut [f64]) {
        let (n, s, r) = (self.n, &self.ep.state, &self.ep.r);
        for i in 0..n {
            obs[i] = s.q_measured[i] - r.q_d[i];
            obs[n + i] = s.qd_measured[i] - r.qd_d[i];
            obs[2 * n + i] = s.q_measured[i];
            obs[3 * n + i] = s.qd_measured[i];
            obs[4 * n + i] = r.q_d[i];
            obs[5 * n + i] = r.qd_d[i];
            obs[6 * n + i] = r.kc[i];
        }
        obs[7 * n] = self.ep.k as f64 / self.ep.plant.steps() as f64;
    }
}

/// Length of the observation of an arm with `n` joints.
pub fn obs_dim(n: usize) -> usize {
    7 * n + 1
}

fn check_options(o: &EnvOptions) -> Result<(), EnvError> {
    let bad = |what: &str, v: f64, need: &str| {
        Err(EnvError::Option(format!(
            "{what} = {v} is invalid: it must be {need}"
        )))
    };
    if !(o.residual_scale.is_finite() && o.residual_scale > 0.0) {
        return bad("residual_scale", o.residual_scale, "a positive number");
    }
    if !(o.effort_weight.is_finite() && o.effort_weight >= 0.0) {
        return bad("effort_weight", o.effort_weight, "a number ≥ 0");
    }
    if let Some(f) = o.breach_factor
        && !(f.is_finite() && f >= 1.0)
    {
        return bad("breach_factor", f, "a number ≥ 1, or None");
    }
    Ok(())
}

/// The torque per unit of action: `given`, else the plant's effort limits
/// (the scenario's `plant.effort_limit`, else the URDF's).
fn torque_scale(plan: &Plan, given: Option<&[f64]>) -> Result<Vec<f64>, EnvError> {
    let m = &plan.robot.model;
    let n = m.dof();
    let names = m.joint_names();
    let scale = match (given, &plan.scenario.plant.effort_limit) {
        (Some(g), _) => {
            if g.len() != n {
                return Err(EnvError::Option(format!(
                    "torque_scale: {} values; {} has {n} controlled joints ({})",
                    g.len(),
                    plan.robot.label(),
                    names.join(", ")
                )));
            }
            g.to_vec()
        }
        (None, Some(limit)) => limit.resolve("plant.effort_limit", n)?,
        (None, None) => m
            .actuated
            .iter()
            .map(|&j| m.joints[j].effort.unwrap_or(f64::NAN))
            .collect(),
    };
    match scale.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        Some(i) => Err(EnvError::Option(format!(
            "joint {} of {} has no usable torque scale ({}): give torque_scale=[...] (N m or N per \
             unit of action) or set plant.effort_limit",
            names[i],
            plan.robot.label(),
            scale[i]
        ))),
        None => Ok(scale),
    }
}

/// The machines of an episode of `plan`, at its first state.
fn episode(plan: &Plan, opts: &EnvOptions) -> Result<Episode, EnvError> {
    let s = &plan.scenario;
    let mut plant = PlantMachine::new(
        &plan.robot.model,
        &s.plant,
        s.seed,
        plan.period_ns,
        plan.steps,
        (&s.initial.q, &s.initial.qd),
    )?;
    let base = match opts.action {
        ActionMode::Torque => None,
        ActionMode::Residual(law) => {
            let params = if s.controller.law == law {
                s.controller.clone()
            } else {
                s.controller.for_law(law)
            };
            let model = law.model_based().then_some(&plan.robot.model);
            Some(ControllerMachine::new(
                &params,
                plan.robot.model.dof(),
                plan.period_ns,
                model,
            )?)
        }
    };
    let mut reference = TrajectoryMachine::new(plan.reference.clone(), plan.reference_period_ns);
    let state = plant.state(0, 0);
    let r = reference_at(&mut reference, &state);
    Ok(Episode {
        plant,
        reference,
        base,
        state,
        r,
        k: 0,
    })
}

/// The reference sample a controller uses at `state`'s time.
fn reference_at(reference: &mut TrajectoryMachine, state: &JointState) -> ReferenceSample {
    reference.sample(reference.index_at(state.header.t_ns), 0)
}

/// A stream of episode seeds (SplitMix64): what a reset without a seed
/// draws, so that a seeded vector of environments repeats exactly.
#[derive(Debug, Clone)]
pub struct SeedStream(u64);

impl SeedStream {
    /// The stream after `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next seed.
    pub fn next_seed(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) >> 1
    }
}

/// The most arms one vector of environments steps (each holds its
/// plant, reference and buffers: tens of kB).
pub const MAX_ENVS: usize = 1 << 16;

/// Many arms of one scenario, stepped in one call, each resetting itself
/// on the step after its episode ended (Gymnasium's "next step" autoreset).
pub struct ArmEnvs {
    envs: Vec<ArmEnv>,
    seeds: Vec<SeedStream>,
    ended: Vec<bool>,
    obs_dim: usize,
}

impl ArmEnvs {
    /// `count` copies of the environment of `plan`.
    pub fn new(plan: Plan, opts: EnvOptions, count: usize) -> Result<Self, EnvError> {
        if !(1..=MAX_ENVS).contains(&count) {
            return Err(EnvError::Option(format!(
                "num_envs = {count} is invalid: it must be from 1 to {MAX_ENVS}"
            )));
        }
        let first = ArmEnv::new(plan, opts)?;
        let obs_dim = first.obs_dim();
        let mut envs = Vec::with_capacity(count);
        for _ in 1..count {
            envs.push(ArmEnv::new(first.plan.clone(), first.opts.clone())?);
        }
        envs.insert(0, first);
        Ok(Self {
            seeds: (0..count).map(|i| SeedStream::new(i as u64)).collect(),
            ended: vec![false; count],
            envs,
            obs_dim,
        })
    }

    /// The environments.
    pub fn envs(&self) -> &[ArmEnv] {
        &self.envs
    }

    /// Length of one observation.
    pub fn obs_dim(&self) -> usize {
        self.obs_dim
    }

    /// Resets every environment: environment i with `seed + i`, and its
    /// later episodes with seeds drawn from a stream that starts there.
    pub fn reset(&mut self, seed: u64, obs: &mut [f64]) -> Result<(), EnvError> {
        let d = self.obs_dim;
        for (i, env) in self.envs.iter_mut().enumerate() {
            let s = seed.wrapping_add(i as u64);
            self.seeds[i] = SeedStream::new(s);
            env.reset(s, &mut obs[i * d..(i + 1) * d])?;
            self.ended[i] = false;
        }
        Ok(())
    }

    /// One step of every environment with its row of `actions` (n per
    /// environment), writing observations and outcomes. An environment
    /// whose episode ended on the previous step is reset instead (its
    /// action ignored, reward 0, neither terminated nor truncated).
    pub fn step(
        &mut self,
        actions: &[f64],
        obs: &mut [f64],
        out: &mut [Outcome],
    ) -> Result<(), EnvError> {
        let d = self.obs_dim;
        for (i, env) in self.envs.iter_mut().enumerate() {
            let n = env.dof();
            let o = &mut obs[i * d..(i + 1) * d];
            if self.ended[i] {
                env.reset(self.seeds[i].next_seed(), o)?;
                out[i] = Outcome::default();
                self.ended[i] = false;
            } else {
                out[i] = env.step(&actions[i * n..(i + 1) * n], o);
                self.ended[i] = out[i].terminated || out[i].truncated;
            }
        }
        Ok(())
    }
}
