//! Which reference sample is due at a state's time, and when the one a
//! controller used is stale: the rule every controller node follows (the
//! `bus` crate's `ReferenceWindow`) and the log's recount checks.

use crate::ReferenceSample;

/// Whether `used` is older than the sample due at `t_ns` on a grid of
/// `period_ns` (or missing).
pub fn is_stale(used: Option<&ReferenceSample>, t_ns: u64, period_ns: u64) -> bool {
    let due = t_ns / period_ns.max(1) * period_ns.max(1);
    used.is_none_or(|r| r.header.t_ns < due)
}
