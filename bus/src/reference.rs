//! Which reference sample a controller uses for a state: the newest one at
//! or before the state's sim time. In lockstep the controller waits until
//! that choice is final (a sample at or after the state's time has come),
//! so a run is deterministic whoever publishes the reference; in real time
//! it takes what has arrived. Every controller node, the testbed's and a
//! replacement, uses this one rule.
//!
//! A sample older than the one due at the state's time (the newest on the
//! reference grid at or before it) is a *stale reference*; none at all is
//! one too. The window counts them; the count travels in each
//! [`wire::Command`] and the log recounts it from the samples' times.

use std::collections::VecDeque;
use std::time::Duration;

use crate::{NodeError, NodeLink, TopicSubscriber};
use wire::{Mode, ReferenceSample, is_stale};

/// The reference topic and the samples received but not yet passed.
pub struct ReferenceWindow {
    sub: TopicSubscriber<ReferenceSample>,
    recent: VecDeque<ReferenceSample>,
    wait_for_final: bool,
    period_ns: u64,
    stale: u64,
}

impl ReferenceWindow {
    /// Subscribes `link` to the reference topic for a run in `mode` whose
    /// reference samples come every `period_ns`.
    pub fn new(link: &NodeLink, mode: Mode, period_ns: u64) -> Result<Self, NodeError> {
        Ok(Self {
            sub: link.bus.subscriber()?,
            recent: VecDeque::with_capacity(2048),
            wait_for_final: mode == Mode::Lockstep,
            period_ns: period_ns.max(1),
            stale: 0,
        })
    }

    /// Stale references so far (see the module's documentation).
    pub fn stale_count(&self) -> u64 {
        self.stale
    }

    /// The sample for sim time `t_ns`, if there is one (in lockstep, once
    /// it is final).
    pub fn take(
        &mut self,
        link: &mut NodeLink,
        t_ns: u64,
    ) -> Result<Option<ReferenceSample>, NodeError> {
        loop {
            while let Some(r) = self.sub.receive()? {
                arrive(&mut self.recent, r);
            }
            let settled = self.recent.back().is_some_and(|r| r.header.t_ns >= t_ns);
            if settled || !self.wait_for_final {
                let picked = pick(&mut self.recent, t_ns);
                self.stale += u64::from(is_stale(picked.as_ref(), t_ns, self.period_ns));
                return Ok(picked);
            }
            // Only at the start, or when a replacement trajectory is slow.
            link.bus.wait(Duration::from_millis(1))?;
            link.check()?;
        }
    }
}

/// Keeps `recent` in time order: samples from one publisher come in order,
/// so this is a push at the back; a late one is put in its place.
fn arrive(recent: &mut VecDeque<ReferenceSample>, r: ReferenceSample) {
    if recent.back().is_none_or(|b| b.header.t_ns <= r.header.t_ns) {
        recent.push_back(r);
    } else {
        let i = recent.partition_point(|x| x.header.t_ns <= r.header.t_ns);
        recent.insert(i, r);
    }
}

/// The newest sample at or before `t_ns`, dropping the older ones. Samples
/// after `t_ns` are kept: when the plant runs late, the trajectory's timer is
/// ahead of it and those samples are needed for the next states. O(1) per
/// state (the lockstep trajectory runs a thousand samples ahead).
fn pick(recent: &mut VecDeque<ReferenceSample>, t_ns: u64) -> Option<ReferenceSample> {
    while recent.get(1).is_some_and(|r| r.header.t_ns <= t_ns) {
        recent.pop_front();
    }
    recent.front().filter(|r| r.header.t_ns <= t_ns).copied()
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    fn sample(t_ns: u64) -> ReferenceSample {
        ReferenceSample {
            header: wire::Header {
                seq: t_ns,
                t_ns,
                wall_ns: 0,
            },
            dof: 1,
            kc: [1.0; wire::MAX_DOF],
            ..ReferenceSample::default()
        }
    }

    fn arrived(ts: &[u64]) -> VecDeque<ReferenceSample> {
        let mut recent = VecDeque::new();
        for &t in ts {
            arrive(&mut recent, sample(t));
        }
        recent
    }

    #[test]
    fn newest_sample_not_after_the_state_wins() {
        let mut recent = arrived(&[3, 1, 2, 5]);
        assert_eq!(pick(&mut recent, 4).unwrap().header.t_ns, 3);
        assert_eq!(
            recent.iter().map(|r| r.header.t_ns).collect::<Vec<_>>(),
            [3, 5]
        );
        assert!(pick(&mut arrived(&[7]), 6).is_none());
    }

    #[test]
    fn a_sample_older_than_the_one_due_is_stale() {
        assert!(!is_stale(Some(&sample(4)), 4, 1));
        assert!(is_stale(Some(&sample(3)), 4, 1));
        assert!(is_stale(None, 4, 1));
        // On a coarser grid the sample at 4 serves every state until 8.
        assert!(!is_stale(Some(&sample(4)), 7, 4));
        assert!(is_stale(Some(&sample(4)), 8, 4));
    }

    /// Regression: with the plant 20 periods behind the trajectory, the
    /// controller once kept only the newest 8 samples, all later than the
    /// state, and faulted with no reference.
    #[test]
    fn reference_is_found_when_the_plant_runs_late() {
        let mut recent = arrived(&(0..40).collect::<Vec<_>>());
        for k in 0..40 {
            assert_eq!(pick(&mut recent, k).unwrap().header.t_ns, k);
        }
    }
}
