//! Experiments built on the stack: [`compare`] runs laws on one scenario
//! and judges them, [`sweep`] runs a grid of scenarios (here or on Slurm),
//! [`bench`](mod@bench) measures the testbed itself.
//!
//! Where it sits: above [`run_stack`] (each experiment's runs go through
//! [`run_stack::sim`] or [`run_stack::run`]) and below the `testbed` CLI
//! (`launch/`), which parses arguments and prints what these return. The
//! Python module (`python/inprocess`) calls [`compare`] the same way.
//! Each folder keeps its types at the bottom (`types.rs`), so no file
//! imports one that imports it back.

pub mod bench;
pub mod compare;
pub mod progress;
pub mod sweep;
