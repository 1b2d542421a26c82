//! Many arms of one scenario stepped in one call, each resetting itself on
//! the step after its episode ended (Gymnasium's "next step" autoreset),
//! with a stream of seeds so that a seeded vector repeats exactly.

use scenario::Plan;

use crate::arm::{ArmEnv, Outcome};
use crate::options::{EnvError, EnvOptions};

/// A stream of episode seeds (SplitMix64): what a reset without a seed
/// draws, so that a seeded vector of environments repeats exactly.
#[derive(Debug, Clone)]
pub struct SeedStream(u64);

impl SeedStream {
    /// The stream after `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next seed (below 2⁶³, so any language's signed integer holds it).
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

/// Many arms of one scenario, stepped in one call.
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
            return Err(EnvError::option(
                "num_envs",
                count,
                format!("must be from 1 to {MAX_ENVS}"),
            ));
        }
        let first = ArmEnv::new(plan, opts)?;
        let obs_dim = first.obs_dim();
        let mut envs = Vec::with_capacity(count);
        for _ in 1..count {
            envs.push(ArmEnv::new(first.plan().clone(), first.options().clone())?);
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

    /// The environments, to render one.
    pub fn envs_mut(&mut self) -> &mut [ArmEnv] {
        &mut self.envs
    }

    /// Length of one observation.
    pub fn obs_dim(&self) -> usize {
        self.obs_dim
    }

    /// Resets every environment: environment i with `seed + i` (refused
    /// past 2⁶⁴ − 1 rather than wrapped), and its later episodes with
    /// seeds drawn from a stream that starts there.
    pub fn reset(&mut self, seed: u64, obs: &mut [f64]) -> Result<(), EnvError> {
        let d = self.obs_dim;
        let count = self.envs.len() as u64;
        if seed.checked_add(count - 1).is_none() {
            return Err(EnvError::option(
                "seed",
                seed,
                format!(
                    "arm i gets seed + i: it must be at most {}",
                    u64::MAX - (count - 1)
                ),
            ));
        }
        for (i, env) in self.envs.iter_mut().enumerate() {
            let s = seed + i as u64;
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
