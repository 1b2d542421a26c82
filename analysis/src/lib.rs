//! A run's figures, from its log alone.
//!
//! Where it sits: after the run. The logger wrote `run.mcap`; [`analyse()`](crate::analyse::analyse)
//! reads it back (through `logger`'s reader), rebuilds one row per control
//! step ([`assemble::RecordAssembler`] → [`record::StepRecord`]), and feeds
//! the summary ([`summary`]), the CSV ([`csv_out`]), the figures
//! ([`plots`]), `--verify` ([`verify`]), the timing statistics and the
//! verdict ([`timing`], [`data_path`], [`whole`]). `testbed run`, `replay`, `compare`
//! and `sweep` all take their numbers from here, and `testbed sim` feeds the
//! same assembler and summary in process; [`report`] is what they print.
//! Nothing here starts a process or knows the launcher.

pub mod analyse;
pub mod assemble;
pub mod csv_out;
pub mod data_path;
pub mod law_info;
pub mod own;
pub mod percentiles;
mod plot_error;
pub mod plot_style;
pub mod plots;
pub mod record;
pub mod report;
pub mod smoothness;
pub mod stats;
pub mod summary;
pub mod timing;
pub mod verify;
pub mod whole;

pub use analyse::{AnalyseOptions, AnalysisError, LogAnalysis, Series, analyse};
