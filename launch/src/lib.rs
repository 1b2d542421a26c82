//! The `testbed` command's internals: the in-process run, the node
//! dispatcher, the launcher and its supervision, and the experiments built
//! on them (compare, sweep, bench).
//!
//! Where it sits: at the top. `testbed sim` loads a [`scenario::Plan`] and
//! [`sim::run`] calls the role crates' step machines in order; `testbed run`
//! writes each node its config ([`node::configs`]), spawns the nodes (whose
//! code lives in the role crates; [`node`] only dispatches to them) and
//! [`run`] supervises them. Either way the rows come from one
//! [`analysis::assemble::RecordAssembler`] and feed a
//! [`analysis::summary::SummaryBuilder`]; the `analysis` crate reads a
//! run's log back for `run` and `replay`.

pub mod bench;
pub mod bench_controller;
pub mod bench_peer;
pub mod bench_pingpong;
pub mod compare;
pub mod compare_external;
pub mod compare_findings;
pub mod compare_plots;
pub mod compare_ratio_plot;
pub mod compare_scores;
pub mod compare_tradeoff;
pub mod mode;
pub mod node;
pub mod run;
pub mod sim;
pub mod sweep;
