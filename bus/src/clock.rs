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

/// The machine's timer floor beside a real-time loop: a bare sleep loop in
/// a thread of its own (no IPC, no work) on the loop's grid, counting its
/// wake-ups late by a whole period. Started from the loop's thread it
/// shares its CPU and scheduling class, so what the host does to the loop's
/// timer it does to this one; a loop late more often than its floor was
/// held back by something else.
pub struct TimerFloor {
    late: std::sync::Arc<std::sync::atomic::AtomicU64>,
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    handle: Option<std::thread::JoinHandle<()>>,
}

impl TimerFloor {
    /// Runs from `epoch_ns` on a grid of `period_ns` for at most `cycles`.
    pub fn start(epoch_ns: u64, period_ns: u64, cycles: u64) -> Self {
        use std::sync::atomic::Ordering;
        let late = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let (count, flag) = (std::sync::Arc::clone(&late), std::sync::Arc::clone(&stop));
        let handle = std::thread::Builder::new()
            .name("timer-floor".into())
            .spawn(move || {
                tighten_timer_slack();
                for k in 1..=cycles {
                    if flag.load(Ordering::Relaxed) {
                        break;
                    }
                    let deadline = epoch_ns + k * period_ns;
                    sleep_until(deadline);
                    if monotonic_ns().saturating_sub(deadline) >= period_ns {
                        count.fetch_add(1, Ordering::Relaxed);
                    }
                }
            })
            .ok();
        Self { late, stop, handle }
    }

    /// Late wake-ups so far; None if the thread could not be started.
    pub fn late_wakeups(&self) -> Option<u64> {
        self.handle
            .as_ref()
            .map(|_| self.late.load(std::sync::atomic::Ordering::Relaxed))
    }
}

impl Drop for TimerFloor {
    fn drop(&mut self) {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}
