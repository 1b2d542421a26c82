//! The Gymnasium environment's core, in pure Rust: one arm's episodes
//! ([`ArmEnv`]) or many arms stepped in one call ([`ArmEnvs`]), each a
//! scenario of the testbed with the controller's torque replaced by an
//! agent's action (or added to a built-in law's), and the observation,
//! reward, safety cost, end of an episode and a picture of the arm.
//!
//! Where it sits in the data flow: a [`scenario::Plan`] comes in (loaded by
//! the caller); each step drives [`scenario::stepper::Stepper`], the loop
//! body `testbed sim` uses, for `decimation` plant periods with the action
//! held (or ramped, or low-pass filtered: [`Smoothing`]); the PyO3
//! module (`python/inprocess`, `testbed._native`) only converts Python
//! values to and from these types, and `testbed/env.py`
//! wraps that as `gymnasium.Env` and `gymnasium.vector.VectorEnv`. With a
//! zero residual on the scenario's own law and `decimation = 1` the states
//! are `testbed sim`'s, bit for bit.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let plan = scenario::load_named(None, &scenario::Overrides {
//!     duration_s: Some(0.1),
//!     ..Default::default()
//! })?;
//! let mut env = gym_env::ArmEnv::new(plan, gym_env::EnvOptions::default())?;
//! let mut obs = vec![0.0; env.obs_dim()];
//! env.reset(7, &mut obs)?;
//! let out = env.step(&vec![0.0; env.dof()], &mut obs);
//! assert!(out.reward <= 0.0);
//! # Ok(()) }
//! ```
//!
//! # Limitations
//! - The vector form steps each arm on one thread (arms in parallel on a
//!   pool, [`ArmEnvs::with_threads`]); one arm's step is never split, so
//!   few arms gain little from many threads. `cargo run --release -p
//!   gym-env --example threads [DECIMATION]` times 64 arms on 1 thread
//!   and on every CPU.
//! - The picture is a projection of the link frames' origins onto one
//!   plane: links are drawn as segments between joints, not as meshes.

mod arm;
mod options;
mod policy_io;
mod render;
mod smoothing;
mod vector;

pub use arm::{ArmEnv, Outcome, ResetOptions, obs_dim, obs_dim_with};
pub use options::{
    ActionMode, DEFAULT_DECIMATION, DEFAULT_EPISODE_S, ERROR_CAP, EnvError, EnvOptions, Smoothing,
    check_episode_s,
};
pub use policy_io::{action_torque, observe, observe_action};
pub use render::{Picture, Projection};
pub use smoothing::ActionShaper;
pub use vector::{ArmEnvs, Autoreset, MAX_ENVS, MAX_THREADS, SeedStream, default_threads};
