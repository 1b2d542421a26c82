//! Many arms of one scenario stepped in one call, each resetting itself on
//! the step after its episode ended (Gymnasium's "next step" autoreset),
//! with a stream of seeds so that a seeded vector repeats exactly.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use scenario::Plan;

use crate::arm::{ArmEnv, Outcome, ResetOptions};
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

/// Many arms of one scenario, stepped in one call, on a pool of threads
/// (one arm is never split: each steps on one thread, so the results do
/// not depend on the thread count).
pub struct ArmEnvs {
    envs: Vec<ArmEnv>,
    seeds: Vec<SeedStream>,
    ended: Vec<bool>,
    obs_dim: usize,
    n: usize,
    /// None: the arms step one after another on the caller's thread.
    pool: Option<rayon::ThreadPool>,
    /// Counts the calls that use the pool: a lingering worker (below)
    /// stops when it changes.
    calls: Arc<AtomicU64>,
    /// Rows for the outcomes and final observations a call does not ask
    /// for (a reset; a NEXT_STEP step), kept to allocate once.
    spare_out: Vec<Outcome>,
    spare_obs: Vec<f64>,
}

/// One arm's part of a call: its environment, seed stream, ended flag,
/// observation row, outcome and final-observation row.
struct Arm<'a> {
    index: usize,
    env: &'a mut ArmEnv,
    seeds: &'a mut SeedStream,
    ended: &'a mut bool,
    obs: &'a mut [f64],
    out: &'a mut Outcome,
    final_obs: &'a mut [f64],
}

/// What happens to an arm whose episode ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Autoreset {
    /// Gymnasium's NEXT_STEP: the arm resets on the next step (which
    /// ignores its action and returns the new episode's first observation).
    NextStep,
    /// Stable-Baselines3's: the arm resets in the step that ended it; its
    /// observation is the new episode's first, and the last one of the
    /// ended episode goes to the caller's `final_obs`.
    SameStep,
}

/// The threads a vector steps on by default: one per CPU this process
/// may use.
pub fn default_threads() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}

impl ArmEnvs {
    /// `count` copies of the environment of `plan`, stepped on
    /// [`default_threads`] threads.
    pub fn new(plan: Plan, opts: EnvOptions, count: usize) -> Result<Self, EnvError> {
        Self::with_threads(plan, opts, count, default_threads())
    }

    /// [`ArmEnvs::new`] on `threads` threads (1: on the caller's thread,
    /// no pool; more than the arms gives no more speed, so the pool is
    /// capped at the arm count).
    pub fn with_threads(
        plan: Plan,
        opts: EnvOptions,
        count: usize,
        threads: usize,
    ) -> Result<Self, EnvError> {
        if !(1..=MAX_ENVS).contains(&count) {
            return Err(EnvError::option(
                "num_envs",
                count,
                format!("must be from 1 to {MAX_ENVS}"),
            ));
        }
        if !(1..=MAX_THREADS).contains(&threads) {
            return Err(EnvError::option(
                "num_threads",
                threads,
                format!("must be from 1 to {MAX_THREADS}"),
            ));
        }
        let first = ArmEnv::new(plan, opts)?;
        let obs_dim = first.obs_dim();
        let n = first.dof();
        let mut envs = Vec::with_capacity(count);
        for _ in 1..count {
            envs.push(ArmEnv::new(first.plan().clone(), first.options().clone())?);
        }
        envs.insert(0, first);
        let threads = threads.min(count);
        // The calling thread is one of the threads: the pool has the others.
        let pool = if threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads - 1)
                    .thread_name(|i| format!("gym-env-{i}"))
                    .build()?,
            )
        } else {
            None
        };
        Ok(Self {
            seeds: (0..count).map(|i| SeedStream::new(i as u64)).collect(),
            ended: vec![false; count],
            spare_out: vec![Outcome::default(); count],
            spare_obs: vec![0.0; count * obs_dim],
            envs,
            obs_dim,
            n,
            pool,
            calls: Arc::new(AtomicU64::new(0)),
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

    /// The threads the arms step on.
    pub fn threads(&self) -> usize {
        self.pool
            .as_ref()
            .map_or(1, |p| p.current_num_threads() + 1)
    }

    /// Runs `f` on every arm, on the pool if there is one; the first
    /// error (by arm order) is returned. `out` and `final_obs`: None for
    /// the spare rows.
    fn each<F>(
        &mut self,
        obs: &mut [f64],
        out: Option<&mut [Outcome]>,
        final_obs: Option<&mut [f64]>,
        f: F,
    ) -> Result<(), EnvError>
    where
        F: Fn(&mut Arm<'_>) -> Result<(), EnvError> + Sync,
    {
        let d = self.obs_dim;
        let out = out.unwrap_or(&mut self.spare_out);
        let fin = final_obs.unwrap_or(&mut self.spare_obs);
        let (envs, seeds, ended) = (&mut self.envs, &mut self.seeds, &mut self.ended);
        let arm = |(index, (((((env, seeds), ended), obs), out), final_obs))| Arm {
            index,
            env,
            seeds,
            ended,
            obs,
            out,
            final_obs,
        };
        let arms = envs
            .iter_mut()
            .zip(seeds.iter_mut())
            .zip(ended.iter_mut())
            .zip(obs.chunks_mut(d))
            .zip(out.iter_mut())
            .zip(fin.chunks_mut(d))
            .enumerate()
            .map(arm);
        let Some(pool) = &self.pool else {
            return arms.into_iter().try_for_each(|mut a| f(&mut a));
        };
        // Each arm behind a lock only one thread ever takes (an arm index
        // is handed out once): safe sharing of the rows, uncontended.
        let arms: Vec<Mutex<Arm<'_>>> = arms.map(Mutex::new).collect();
        let done = AtomicUsize::new(0);
        let first_error: Mutex<Option<(usize, EnvError)>> = Mutex::new(None);
        let threads = pool.current_num_threads() + 1;
        let blocks = Blocks::new(arms.len(), threads);
        let step = |i: usize| {
            let Some(a) = arms.get(i) else { return };
            let mut a = a.lock().unwrap_or_else(PoisonError::into_inner);
            if let Err(e) = f(&mut a) {
                let mut slot = first_error.lock().unwrap_or_else(PoisonError::into_inner);
                if slot.as_ref().is_none_or(|(j, _)| i < *j) {
                    *slot = Some((i, e));
                }
            }
            done.fetch_add(1, Ordering::Release);
        };
        // Thread k steps block k of neighbouring arms from its front, then
        // takes arms from the back of the others' blocks (a thread the OS
        // holds back gets fewer). Whole blocks, not alternate arms:
        // neighbouring arms' memory shares cache lines, and two threads
        // stepping alternate arms fought over them (64 two-link arms were
        // no faster on two threads than on one).
        let work = |k: usize| {
            while let Some(i) = blocks.front(k) {
                step(i);
            }
            for j in (1..threads).map(|o| (k + o) % threads) {
                while let Some(i) = blocks.back(j) {
                    step(i);
                }
            }
        };
        // Ends the workers' lingering after the last call: they take this
        // call's arms at once, awake.
        let call = self.calls.fetch_add(1, Ordering::AcqRel) + 1;
        // The calling thread steps arms too, while the pool's threads
        // wake up (which, in a virtual machine, can take as long as
        // stepping a few arms).
        pool.in_place_scope(|scope| {
            for k in 1..threads {
                let work = &work;
                scope.spawn(move |_| work(k));
            }
            work(0);
            // The last arms may still be stepping on the pool: wait for
            // them spinning, up to a bound, rather than sleeping on the
            // scope's latch, whose wake-up costs more than a short step.
            let start = std::time::Instant::now();
            while done.load(Ordering::Acquire) < arms.len() && start.elapsed() < SPIN_WAIT {
                std::hint::spin_loop();
            }
        });
        // A worker that sleeps between calls is woken by the next one, which
        // costs (in a virtual machine) tens of microseconds, a good part
        // of a call of 64 two-link arms at one plant period. So each
        // worker stays awake for a while after a call, spinning until the
        // next one starts or LINGER passes: a caller that steps in a
        // loop finds it awake.
        for _ in 0..pool.current_num_threads() {
            let calls = Arc::clone(&self.calls);
            pool.spawn(move || {
                let start = std::time::Instant::now();
                while calls.load(Ordering::Acquire) == call && start.elapsed() < LINGER {
                    std::hint::spin_loop();
                }
            });
        }
        match first_error
            .into_inner()
            .unwrap_or_else(PoisonError::into_inner)
        {
            Some((_, e)) => Err(e),
            None => Ok(()),
        }
    }

    /// Resets every environment: environment i with `seed + i` (refused
    /// past 2⁶⁴ − 1 rather than wrapped), and its later episodes with
    /// seeds drawn from a stream that starts there.
    pub fn reset(&mut self, seed: u64, obs: &mut [f64]) -> Result<(), EnvError> {
        self.reset_with(seed, &[ResetOptions::default()], obs)
    }

    /// [`ArmEnvs::reset`] with each arm's start changed by `opts`: one
    /// entry for every arm, or one per arm. Only this episode: the arms'
    /// later episodes (their autoresets) start as the scenario says.
    pub fn reset_with(
        &mut self,
        seed: u64,
        opts: &[ResetOptions],
        obs: &mut [f64],
    ) -> Result<(), EnvError> {
        let count = self.envs.len();
        if seed.checked_add(count as u64 - 1).is_none() {
            return Err(EnvError::option(
                "seed",
                seed,
                format!(
                    "arm i gets seed + i: it must be at most {}",
                    u64::MAX - (count as u64 - 1)
                ),
            ));
        }
        if opts.len() != 1 && opts.len() != count {
            return Err(EnvError::option(
                "options",
                format!("{} entries", opts.len()),
                format!("one for every arm, or one per arm ({count})"),
            ));
        }
        self.check_len(obs.len(), self.obs_dim, "observations")?;
        self.each(obs, None, None, |a| {
            let s = seed + a.index as u64;
            *a.seeds = SeedStream::new(s);
            a.env
                .reset_with(s, &opts[a.index.min(opts.len() - 1)], a.obs)?;
            *a.ended = false;
            Ok(())
        })
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
        self.step_with(Autoreset::NextStep, actions, obs, None, out)
    }

    /// One step of every environment, ended episodes restarting as
    /// `mode` says. With [`Autoreset::SameStep`], `final_obs` (one row per
    /// arm, as `obs`; None: not kept) receives the last observation of each arm whose
    /// episode ended in this step (other rows are left as they were), and
    /// `out` keeps that step's outcome; the arm's next episode's seed is
    /// the same one [`Autoreset::NextStep`] would draw.
    pub fn step_with(
        &mut self,
        mode: Autoreset,
        actions: &[f64],
        obs: &mut [f64],
        final_obs: Option<&mut [f64]>,
        out: &mut [Outcome],
    ) -> Result<(), EnvError> {
        let (d, n) = (self.obs_dim, self.n);
        self.check_len(actions.len(), n, "actions")?;
        self.check_len(obs.len(), d, "observations")?;
        self.check_len(out.len(), 1, "outcomes")?;
        if let Some(f) = &final_obs {
            self.check_len(f.len(), d, "final observations")?;
        }
        self.each(obs, Some(out), final_obs, |a| {
            if *a.ended {
                a.env.reset(a.seeds.next_seed(), a.obs)?;
                *a.out = Outcome::default();
                *a.ended = false;
                return Ok(());
            }
            *a.out = a.env.step(&actions[a.index * n..(a.index + 1) * n], a.obs);
            if a.out.terminated || a.out.truncated {
                match mode {
                    Autoreset::SameStep => {
                        a.final_obs.copy_from_slice(a.obs);
                        a.env.reset(a.seeds.next_seed(), a.obs)?;
                    }
                    Autoreset::NextStep => *a.ended = true,
                }
            }
            Ok(())
        })
    }

    /// A buffer of `len` values must hold `per` for every arm.
    fn check_len(&self, len: usize, per: usize, what: &str) -> Result<(), EnvError> {
        let count = self.envs.len();
        if len == count * per {
            Ok(())
        } else {
            Err(EnvError::option(
                what,
                format!("{len} values"),
                format!("must be {per} per arm for {count} arms"),
            ))
        }
    }
}

/// The most threads a vector steps on.
pub const MAX_THREADS: usize = 1024;

/// How long the calling thread spins for the pool's last arms before it
/// sleeps until they are done.
const SPIN_WAIT: std::time::Duration = std::time::Duration::from_micros(200);

/// How long the pool's threads stay awake after a call for the next one.
const LINGER: std::time::Duration = std::time::Duration::from_micros(500);

/// The arms cut into one block of neighbours per thread, each taken from
/// its front by its own thread and from its back by the others: per block
/// the next front and the end, packed in one atomic word.
struct Blocks(Vec<AtomicU64>);

impl Blocks {
    fn new(count: usize, threads: usize) -> Self {
        let per = count.div_ceil(threads);
        Self(
            (0..threads)
                .map(|k| {
                    let (front, end) = ((k * per).min(count), ((k + 1) * per).min(count));
                    AtomicU64::new(pack(front, end))
                })
                .collect(),
        )
    }

    /// The next arm from block `k`'s front, if any is left.
    fn front(&self, k: usize) -> Option<usize> {
        self.take(k, |front, end| {
            (front < end).then(|| (front, pack(front + 1, end)))
        })
    }

    /// The last arm left in block `k`, if any.
    fn back(&self, k: usize) -> Option<usize> {
        self.take(k, |front, end| {
            (front < end).then(|| (end - 1, pack(front, end - 1)))
        })
    }

    fn take(&self, k: usize, pick: impl Fn(usize, usize) -> Option<(usize, u64)>) -> Option<usize> {
        let block = self.0.get(k)?;
        let mut now = block.load(Ordering::Acquire);
        loop {
            let (front, end) = unpack(now);
            let (arm, next) = pick(front, end)?;
            match block.compare_exchange_weak(now, next, Ordering::AcqRel, Ordering::Acquire) {
                Ok(_) => return Some(arm),
                Err(seen) => now = seen,
            }
        }
    }
}

/// A block's next front and end in one word (each below 2³², as the
/// arms are at most [`MAX_ENVS`]).
fn pack(front: usize, end: usize) -> u64 {
    ((front as u64) << 32) | end as u64
}

fn unpack(v: u64) -> (usize, usize) {
    ((v >> 32) as usize, (v & 0xFFFF_FFFF) as usize)
}
