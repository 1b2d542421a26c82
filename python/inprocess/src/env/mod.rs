//! The Gymnasium environment's core: one arm ([`core::ArmEnv`]) or many
//! ([`core::ArmEnvs`]) stepped in Rust, and their Python classes
//! ([`py`]); `testbed/gym.py` wraps them as `gymnasium.Env` and
//! `gymnasium.vector.VectorEnv`.

pub mod core;
pub mod py;
