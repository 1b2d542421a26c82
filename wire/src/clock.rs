//! Sleeping to absolute deadlines on CLOCK_MONOTONIC.
//!
//! A fixed-rate loop must not drift by its own work time, and iceoryx2's
//! WaitSet rounds timeouts up to whole milliseconds, so the real-time loops
//! sleep with `clock_nanosleep(TIMER_ABSTIME)` and a 1 ns timer slack.

use nix::sys::time::TimeSpec;
use nix::time::{ClockId, ClockNanosleepFlags, clock_nanosleep};

pub use crate::monotonic_ns;

/// Asks the kernel not to coalesce this thread's timers (default slack is
/// 50 µs). Failure only costs precision, so it is ignored.
pub fn tighten_timer_slack() {
    let _ = nix::sys::prctl::set_timerslack(1);
}

/// Sleeps until CLOCK_MONOTONIC reaches `deadline_ns`. Returns early (Ok)
/// if a signal interrupts the sleep, so the caller can check for termination.
pub fn sleep_until(deadline_ns: u64) {
    let ts = TimeSpec::new(
        (deadline_ns / 1_000_000_000) as i64,
        (deadline_ns % 1_000_000_000) as i64,
    );
    let _ = clock_nanosleep(
        ClockId::CLOCK_MONOTONIC,
        ClockNanosleepFlags::TIMER_ABSTIME,
        &ts,
    );
}
