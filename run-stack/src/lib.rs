//! The stack of one run, in one process or many: the in-process run
//! ([`sim`]), the node dispatcher and each node's config ([`node`]), and the
//! launcher that spawns the node processes and supervises them ([`run`]).
//!
//! Where it sits: below the `testbed` CLI (`launch/`) and the experiments
//! (`experiments/`), above the role crates. [`sim::run`] loads nothing: it
//! takes a [`scenario::Plan`] and calls the role crates' step machines in
//! order; [`run::run`] writes each node its config ([`node::configs`]),
//! spawns the nodes (whose code lives in the role crates; [`node`] only
//! dispatches to them) and supervises them. Either way the rows come from
//! one [`analysis::assemble::RecordAssembler`] and feed a
//! [`analysis::summary::SummaryBuilder`]; the `analysis` crate reads a run's
//! log back.

pub mod mode;
pub mod node;
pub mod run;
pub mod sim;
