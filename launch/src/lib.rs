//! The `testbed` command's internals: the in-process closed loop, the node
//! processes, the launcher, the run summary and CSV output.
//!
//! Where it sits: at the top. `testbed sim` loads a [`scenario::Plan`], runs
//! [`sim::run`] and feeds each [`record::StepRecord`] to a
//! [`summary::SummaryBuilder`]. `testbed run` spawns the [`node`] processes
//! (plant, trajectory, controller) that talk over iceoryx2 ([`wire`]), and
//! [`run`] supervises them and assembles the same records from the topics.

pub mod analysis;
pub mod assemble;
pub mod bench;
pub mod csv_out;
pub mod mode;
pub mod node;
pub mod plots;
pub mod record;
pub mod run;
pub mod sim;
pub mod summary;
pub mod verify;
