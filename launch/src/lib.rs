//! The `testbed` command's internals: the in-process closed loop, the run
//! summary, and CSV output.
//!
//! Where it sits: at the top. `testbed sim` loads a [`scenario::Plan`], runs
//! [`closed_loop::run`] and feeds each [`record::StepRecord`] to a
//! [`summary::SummaryBuilder`] and, if asked, a CSV file.

pub mod closed_loop;
pub mod csv_out;
pub mod record;
pub mod summary;
