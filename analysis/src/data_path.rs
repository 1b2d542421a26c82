//! The ages of the samples on a run's data path, recounted from the log's
//! stamps alone: `/joint_state` (which command the plant took, and when),
//! `/command` (when the controller started, which reference sample it
//! used). The live counts travel in the same messages (the plant's
//! `deadline_misses`, the controller's `stale_references`); a recount that
//! differs from them means the log is not the run.

use serde::Serialize;
use wire::{Command, JointState, NONE_U64, is_stale};

use crate::timing::Percentiles;

/// What the log says about one state.
#[derive(Debug, Clone, Copy, Default)]
struct StateStamp {
    seen: bool,
    wall_ns: u64,
    command_seq: u64,
    applied_wall_ns: u64,
}

/// What the log says about one command.
#[derive(Debug, Clone, Copy, Default)]
struct CommandStamp {
    seen: bool,
    t_ns: u64,
    wall_ns: u64,
    started_wall_ns: u64,
    reference_t_ns: u64,
}

/// Counts recomputed from the log's stamps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Recount {
    /// States k ≥ 1 for which the plant had not taken command k − 1.
    pub deadline_misses: u64,
    /// Commands computed with a reference sample older than the one due.
    pub stale_references: u64,
}

/// The data path's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DataPathSummary {
    /// The counts recomputed from the stamps.
    pub recount: Recount,
    /// Stale references as the controller counted them live (the timing
    /// summary's `stale_references` shows it).
    #[serde(skip)]
    pub stale_references: u64,
    /// State published → the controller starts on it, µs.
    pub state_age_us: Percentiles,
    /// Command sent → the plant takes it, µs.
    pub command_age_us: Percentiles,
    /// Of the stale references that had a sample: how much older it was
    /// than the one due, µs of sim time.
    pub reference_lag_us: Percentiles,
    /// Steps with a timing fault (a miss or a stale reference), in order.
    #[serde(skip)]
    pub fault_steps: Vec<u64>,
}

/// Collects the stamps while a log is read.
#[derive(Debug, Clone)]
pub struct DataPath {
    reference_period_ns: u64,
    /// Seqs past this are not the run's (a damaged or hostile log).
    last_seq: u64,
    states: Vec<StateStamp>,
    commands: Vec<CommandStamp>,
    live_stale: u64,
}

impl DataPath {
    /// For a run of `steps` steps whose reference comes every `reference_period_ns`.
    pub fn new(steps: u64, reference_period_ns: u64) -> Self {
        Self {
            reference_period_ns,
            last_seq: steps,
            states: Vec::new(),
            commands: Vec::new(),
            live_stale: 0,
        }
    }

    /// Adds a state.
    pub fn add_state(&mut self, s: &JointState) {
        if let Some(slot) = slot(&mut self.states, s.header.seq, self.last_seq) {
            *slot = StateStamp {
                seen: true,
                wall_ns: s.header.wall_ns,
                command_seq: s.command_seq,
                applied_wall_ns: s.applied_wall_ns,
            };
        }
    }

    /// Adds a command.
    pub fn add_command(&mut self, c: &Command) {
        self.live_stale = self.live_stale.max(c.stale_references);
        if let Some(slot) = slot(&mut self.commands, c.header.seq, self.last_seq) {
            *slot = CommandStamp {
                seen: true,
                t_ns: c.header.t_ns,
                wall_ns: c.header.wall_ns,
                started_wall_ns: c.started_wall_ns,
                reference_t_ns: c.reference_t_ns,
            };
        }
    }

    /// The figures, from every stamp collected.
    pub fn finish(&self) -> DataPathSummary {
        let mut faults = std::collections::BTreeSet::new();
        let (mut misses, mut stale) = (0, 0);
        let (mut state_age, mut command_age, mut lag) = (Vec::new(), Vec::new(), Vec::new());
        let mut last_taken = NONE_U64;
        for (k, s) in self.states.iter().enumerate().filter(|(_, s)| s.seen) {
            let k = k as u64;
            if k >= 1 && s.command_seq != k - 1 {
                misses += 1;
                faults.insert(k - 1);
            }
            // Each command's age once: when the plant took it.
            if s.command_seq != last_taken
                && let Some(c) = self.command(s.command_seq)
            {
                command_age.push(micros(s.applied_wall_ns, c.wall_ns));
                last_taken = s.command_seq;
            }
        }
        for (k, c) in self.commands.iter().enumerate().filter(|(_, c)| c.seen) {
            let used = (c.reference_t_ns != NONE_U64).then(|| reference_at(c.reference_t_ns));
            if is_stale(used.as_ref(), c.t_ns, self.reference_period_ns) {
                stale += 1;
                faults.insert(k as u64);
                if let Some(r) = used {
                    let due =
                        c.t_ns / self.reference_period_ns.max(1) * self.reference_period_ns.max(1);
                    lag.push(due.saturating_sub(r.header.t_ns) as f64 / 1e3);
                }
            }
            if let Some(s) = self.states.get(k).filter(|s| s.seen) {
                state_age.push(micros(c.started_wall_ns, s.wall_ns));
            }
        }
        DataPathSummary {
            recount: Recount {
                deadline_misses: misses,
                stale_references: stale,
            },
            stale_references: self.live_stale,
            state_age_us: Percentiles::of(state_age),
            command_age_us: Percentiles::of(command_age),
            reference_lag_us: Percentiles::of(lag),
            fault_steps: faults.into_iter().collect(),
        }
    }

    fn command(&self, seq: u64) -> Option<&CommandStamp> {
        usize::try_from(seq)
            .ok()
            .and_then(|i| self.commands.get(i))
            .filter(|c| c.seen)
    }
}

/// The slot for `seq`, grown on demand; None past the run's last step.
fn slot<T: Default + Clone>(v: &mut Vec<T>, seq: u64, last: u64) -> Option<&mut T> {
    let i = usize::try_from(seq).ok().filter(|_| seq <= last)?;
    if v.len() <= i {
        v.resize(i + 1, T::default());
    }
    v.get_mut(i)
}

/// `later − earlier` in µs (negative if the clocks disagree).
fn micros(later: u64, earlier: u64) -> f64 {
    (later as i128 - earlier as i128) as f64 / 1e3
}

/// A reference sample known only by its time (all the stale rule needs).
fn reference_at(t_ns: u64) -> wire::ReferenceSample {
    wire::ReferenceSample {
        header: wire::Header {
            t_ns,
            ..wire::Header::default()
        },
        ..wire::ReferenceSample::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(k: u64, command_seq: u64) -> JointState {
        JointState {
            header: wire::Header {
                seq: k,
                t_ns: k.wrapping_mul(1000),
                wall_ns: k.wrapping_mul(1000).wrapping_add(10_000),
            },
            command_seq,
            applied_wall_ns: k.wrapping_mul(1000).wrapping_add(10_000),
            ..JointState::default()
        }
    }

    fn command(k: u64, reference_t_ns: u64, stale_so_far: u64) -> Command {
        Command {
            header: wire::Header {
                seq: k,
                t_ns: k.wrapping_mul(1000),
                wall_ns: k.wrapping_mul(1000).wrapping_add(10_300),
            },
            started_wall_ns: k.wrapping_mul(1000).wrapping_add(10_100),
            reference_t_ns,
            stale_references: stale_so_far,
            ..Command::default()
        }
    }

    #[test]
    fn misses_and_stale_references_are_recounted_from_the_stamps() {
        let mut d = DataPath::new(4, 1000);
        // Step 1's command is late: state 2 was made with command 0 held.
        for (k, taken) in [(0, NONE_U64), (1, 0), (2, 0), (3, 2), (4, 3)] {
            d.add_state(&state(k, taken));
        }
        // Step 2 used the sample of t = 1000 (one period old); step 3 had none.
        for (k, r, live) in [(0, 0, 0), (1, 1000, 0), (2, 1000, 1), (3, NONE_U64, 2)] {
            d.add_command(&command(k, r, live));
        }
        let s = d.finish();
        assert_eq!(
            s.recount,
            Recount {
                deadline_misses: 1,
                stale_references: 2
            }
        );
        assert_eq!(s.stale_references, 2);
        assert_eq!(s.fault_steps, [1, 2, 3]);
        assert_eq!((s.reference_lag_us.count, s.reference_lag_us.max), (1, 1.0));
        assert_eq!((s.state_age_us.count, s.state_age_us.p50), (4, 0.1));
        // Commands 0, 2, 3 were taken, each 0.7 µs after it was sent.
        assert_eq!(s.command_age_us.count, 3);
        assert!((s.command_age_us.max - 0.7).abs() < 1e-9);
    }

    #[test]
    fn a_seq_past_the_run_is_ignored() {
        let mut d = DataPath::new(2, 1000);
        d.add_state(&state(u64::MAX - 1, 0));
        d.add_command(&command(1 << 40, 0, 0));
        assert_eq!(d.finish().recount.deadline_misses, 0);
        assert!(d.states.is_empty() && d.commands.is_empty());
    }
}
