//! Timing statistics of a run: percentiles of what the plant measured.

use serde::Serialize;
use wire::Timing;

use crate::mode::Mode;

/// p50, p99 and max of one quantity, in microseconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Percentiles {
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Largest.
    pub max: f64,
    /// Samples.
    pub count: u64,
}

impl Percentiles {
    /// Nearest-rank percentiles of `values` (µs); zeros if empty.
    pub fn of(mut values: Vec<f64>) -> Self {
        if values.is_empty() {
            return Self {
                p50: 0.0,
                p99: 0.0,
                max: 0.0,
                count: 0,
            };
        }
        values.sort_by(f64::total_cmp);
        let rank =
            |p: f64| values[((p * values.len() as f64).ceil() as usize).clamp(1, values.len()) - 1];
        Self {
            p50: rank(0.50),
            p99: rank(0.99),
            max: values[values.len() - 1],
            count: values.len() as u64,
        }
    }
}

/// The `timing` object of a run summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimingSummary {
    /// Timing mode.
    pub mode: Mode,
    /// Control rate, Hz.
    pub rate_hz: f64,
    /// Plant cycles measured.
    pub cycles: u64,
    /// Cycles whose command had not arrived by the next deadline.
    pub deadline_misses: u64,
    /// Plant wake-ups late by a whole period or more (real time): what a
    /// bare sleep loop counts as a miss, so the one figure to compare with
    /// the bench's timer floor.
    pub late_wakeups: u64,
    /// |actual − nominal period| of the plant's wake-ups (real time).
    pub period_jitter_us: Percentiles,
    /// How late the plant woke after each deadline (real time).
    pub wake_late_us: Percentiles,
    /// State published → its command sent by the controller.
    pub round_trip_us: Percentiles,
    /// Controller compute time per step.
    pub controller_compute_us: Percentiles,
}

/// Accumulates [`Timing`] samples.
#[derive(Debug, Clone, Default)]
pub struct TimingStats {
    period_ns: u64,
    cycles: u64,
    misses: u64,
    late_wakeups: u64,
    jitter: Vec<f64>,
    late: Vec<f64>,
    round_trip: Vec<f64>,
    compute: Vec<f64>,
}

impl TimingStats {
    /// For a nominal period of `period_ns`.
    pub fn new(period_ns: u64) -> Self {
        Self {
            period_ns,
            ..Self::default()
        }
    }

    /// Adds one plant cycle.
    pub fn add(&mut self, t: &Timing) {
        self.cycles += 1;
        self.misses += u64::from(t.deadline_missed);
        if t.period_ns > 0 {
            self.jitter
                .push((t.period_ns - self.period_ns as i64).unsigned_abs() as f64 / 1e3);
        }
        self.late.push(t.wake_late_ns.max(0) as f64 / 1e3);
        self.late_wakeups += u64::from(t.wake_late_ns >= self.period_ns as i64);
        if t.round_trip_ns >= 0 {
            self.round_trip.push(t.round_trip_ns as f64 / 1e3);
        }
        if t.controller_compute_ns >= 0 {
            self.compute.push(t.controller_compute_ns as f64 / 1e3);
        }
    }

    /// The summary so far.
    pub fn finish(&self, mode: Mode, rate_hz: f64) -> TimingSummary {
        TimingSummary {
            mode,
            rate_hz,
            cycles: self.cycles,
            deadline_misses: self.misses,
            late_wakeups: self.late_wakeups,
            period_jitter_us: Percentiles::of(self.jitter.clone()),
            wake_late_us: Percentiles::of(self.late.clone()),
            round_trip_us: Percentiles::of(self.round_trip.clone()),
            controller_compute_us: Percentiles::of(self.compute.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let p = Percentiles::of((1..=100).map(f64::from).collect());
        assert_eq!((p.p50, p.p99, p.max, p.count), (50.0, 99.0, 100.0, 100));
        let p = Percentiles::of(vec![3.0]);
        assert_eq!((p.p50, p.p99, p.max), (3.0, 3.0, 3.0));
        assert_eq!(Percentiles::of(vec![]).count, 0);
    }

    #[test]
    fn jitter_is_distance_from_the_nominal_period() {
        let mut s = TimingStats::new(1_000_000);
        for (period, missed) in [(0, 0), (1_000_500, 0), (998_000, 1)] {
            s.add(&Timing {
                period_ns: period,
                deadline_missed: missed,
                round_trip_ns: -1,
                controller_compute_ns: 2_000,
                ..Timing::default()
            });
        }
        let t = s.finish(Mode::Realtime, 1000.0);
        assert_eq!((t.cycles, t.deadline_misses), (3, 1));
        assert_eq!(t.late_wakeups, 0);
        let mut late = TimingStats::new(1_000_000);
        for wake_late_ns in [999_999, 1_000_000, 2_500_000] {
            late.add(&Timing {
                wake_late_ns,
                ..Timing::default()
            });
        }
        assert_eq!(late.finish(Mode::Realtime, 1000.0).late_wakeups, 2);
        assert_eq!(t.period_jitter_us.max, 2.0);
        assert_eq!(t.period_jitter_us.count, 2);
        assert_eq!(t.round_trip_us.count, 0);
        assert_eq!(t.controller_compute_us.p50, 2.0);
    }
}
