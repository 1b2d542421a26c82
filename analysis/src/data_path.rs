//! The ages of the samples on a run's data path, recounted from the log's
//! stamps alone: `/joint_state` (which command the plant took, and when),
//! `/command` (when the controller started, which reference sample it
//! used). The live counts travel in the same messages (the plant's
//! `deadline_misses`, the controller's `stale_references`); a recount that
//! differs from them means the log is not the run.

use serde::Serialize;
use wire::{Command, JointState, NONE_U64, is_stale};

use crate::percentiles::{Percentiles, Quantiles};

/// What the log says about one state.
#[derive(Debug, Clone, Copy, Default)]
struct StateStamp {
    wall_ns: u64,
    command_seq: u64,
    applied_wall_ns: u64,
}

/// What the log says about one command.
#[derive(Debug, Clone, Copy, Default)]
struct CommandStamp {
    wall_ns: u64,
    started_wall_ns: u64,
    /// Its age was counted (when the plant first took it).
    taken: bool,
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
    /// Steps with a timing fault (a miss or a stale reference), in order:
    /// the first [`MAX_FAULT_STEPS`] of them.
    #[serde(skip)]
    pub fault_steps: Vec<u64>,
    /// More faults than [`MAX_FAULT_STEPS`] came up (the list is their start).
    #[serde(skip)]
    pub fault_steps_cut: bool,
}

/// Fault steps kept by number (8 MB); the counts go on past it.
pub const MAX_FAULT_STEPS: usize = 1 << 20;

/// Steps of stamps kept: a state is judged once one 2048 steps newer came,
/// so a log's topics may interleave that far out of order. Memory stays
/// the same whatever the run's length.
const WINDOW: u64 = 4096;

/// The last [`WINDOW`] stamps of one topic, by seq.
#[derive(Debug, Clone)]
struct Ring<T> {
    slots: Vec<Option<(u64, T)>>,
}

impl<T: Copy> Ring<T> {
    fn new() -> Self {
        Self {
            slots: vec![None; WINDOW as usize],
        }
    }

    fn slot(&mut self, seq: u64) -> &mut Option<(u64, T)> {
        &mut self.slots[(seq % WINDOW) as usize]
    }

    fn get(&mut self, seq: u64) -> Option<&mut T> {
        match self.slot(seq) {
            Some((s, t)) if *s == seq => Some(t),
            _ => None,
        }
    }

    #[cfg(test)]
    fn is_empty(&self) -> bool {
        self.slots.iter().all(Option::is_none)
    }
}

/// Collects the stamps while a log is read, judging each step as soon as
/// its partners are in.
#[derive(Debug, Clone)]
pub struct DataPath {
    reference_period_ns: u64,
    /// Seqs past this are not the run's (a damaged or hostile log).
    last_seq: u64,
    states: Ring<StateStamp>,
    commands: Ring<CommandStamp>,
    /// States before this seq are judged.
    next_state: u64,
    /// The command the plant took last, among the states judged.
    last_taken: u64,
    live_stale: u64,
    misses: u64,
    stale: u64,
    state_age: Quantiles,
    command_age: Quantiles,
    lag: Quantiles,
    faults: Vec<u64>,
    faults_cut: bool,
}

impl DataPath {
    /// For a run of `steps` steps whose reference comes every `reference_period_ns`.
    pub fn new(steps: u64, reference_period_ns: u64) -> Self {
        Self {
            reference_period_ns,
            last_seq: steps,
            states: Ring::new(),
            commands: Ring::new(),
            next_state: 0,
            last_taken: NONE_U64,
            live_stale: 0,
            misses: 0,
            stale: 0,
            state_age: Quantiles::default(),
            command_age: Quantiles::default(),
            lag: Quantiles::default(),
            faults: Vec::new(),
            faults_cut: false,
        }
    }

    /// Adds a state. One older than the states already judged (a copy, or
    /// a log shuffled by more than half the window) is left out.
    pub fn add_state(&mut self, s: &JointState) {
        let seq = s.header.seq;
        if seq > self.last_seq || seq < self.next_state {
            return;
        }
        // Judged first, so that the new stamp takes no unjudged one's slot.
        let judge_to = (seq + 1).saturating_sub(WINDOW / 2);
        if judge_to > self.next_state + WINDOW {
            // A jump past the window (a gap in the log): all kept are judged.
            self.judge_until(self.next_state + WINDOW);
            self.next_state = judge_to;
        }
        self.judge_until(judge_to);
        *self.states.slot(seq) = Some((
            seq,
            StateStamp {
                wall_ns: s.header.wall_ns,
                command_seq: s.command_seq,
                applied_wall_ns: s.applied_wall_ns,
            },
        ));
    }

    /// Judges the states before seq `end`.
    fn judge_until(&mut self, end: u64) {
        while self.next_state < end {
            self.judge_state(self.next_state);
            self.next_state += 1;
        }
    }

    /// Adds a command; whether its reference was stale is judged at once.
    pub fn add_command(&mut self, c: &Command) {
        self.live_stale = self.live_stale.max(c.stale_references);
        let seq = c.header.seq;
        if seq > self.last_seq {
            return;
        }
        // A copy of one in the window is the same command: judged once.
        if self.commands.get(seq).is_some() {
            return;
        }
        *self.commands.slot(seq) = Some((
            seq,
            CommandStamp {
                wall_ns: c.header.wall_ns,
                started_wall_ns: c.started_wall_ns,
                taken: false,
            },
        ));
        let used = (c.reference_t_ns != NONE_U64).then(|| reference_at(c.reference_t_ns));
        if is_stale(used.as_ref(), c.header.t_ns, self.reference_period_ns) {
            self.stale += 1;
            self.fault(seq);
            if let Some(r) = used {
                let period = self.reference_period_ns.max(1);
                let due = c.header.t_ns / period * period;
                self.lag.add(due.saturating_sub(r.header.t_ns) as f64 / 1e3);
            }
        }
    }

    /// State `k` against its command (state age) and the command it took
    /// (a miss, and that command's age the first time it was taken).
    fn judge_state(&mut self, k: u64) {
        let Some(s) = self.states.get(k).copied() else {
            return;
        };
        *self.states.slot(k) = None;
        if k >= 1 && s.command_seq != k - 1 {
            self.misses += 1;
            self.fault(k - 1);
        }
        if s.command_seq != self.last_taken
            && let Some(c) = self.commands.get(s.command_seq)
            && !c.taken
        {
            c.taken = true;
            let age = micros(s.applied_wall_ns, c.wall_ns);
            self.command_age.add(age);
            self.last_taken = s.command_seq;
        }
        if let Some(c) = self.commands.get(k) {
            let age = micros(c.started_wall_ns, s.wall_ns);
            self.state_age.add(age);
        }
    }

    fn fault(&mut self, step: u64) {
        if self.faults.len() < MAX_FAULT_STEPS {
            self.faults.push(step);
        } else {
            self.faults_cut = true;
        }
    }

    /// The figures, once every stamp is in.
    pub fn finish(mut self) -> DataPathSummary {
        self.judge_until(self.next_state + WINDOW);
        self.faults.sort_unstable();
        self.faults.dedup();
        DataPathSummary {
            recount: Recount {
                deadline_misses: self.misses,
                stale_references: self.stale,
            },
            stale_references: self.live_stale,
            state_age_us: self.state_age.finish(),
            command_age_us: self.command_age.finish(),
            reference_lag_us: self.lag.finish(),
            fault_steps: self.faults,
            fault_steps_cut: self.faults_cut,
        }
    }
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

    /// A run far longer than the window, with a miss every 1000 steps, is
    /// counted exactly in the window's memory.
    #[test]
    fn a_long_run_is_recounted_in_bounded_memory() {
        let n = 50_000;
        let mut d = DataPath::new(n, 1000);
        for k in 0..n {
            let taken = if k % 1000 == 999 {
                k.saturating_sub(2)
            } else {
                k.wrapping_sub(1)
            };
            d.add_state(&state(k, if k == 0 { NONE_U64 } else { taken }));
            d.add_command(&command(k, k * 1000, 0));
        }
        let s = d.finish();
        assert_eq!(s.recount.deadline_misses, 50);
        assert_eq!(s.state_age_us.count, n);
        assert_eq!(s.fault_steps.len(), 50);
        // States 1.. take a command each; the 50 late ones take again the
        // one before, counted once.
        assert_eq!(s.command_age_us.count, n - 1 - 50);
    }

    /// A hostile seq far ahead neither stalls the reader nor loses the
    /// stamps already in.
    #[test]
    fn a_jump_far_ahead_judges_what_was_kept() {
        let mut d = DataPath::new(u64::MAX / 2, 1000);
        d.add_state(&state(0, NONE_U64));
        d.add_state(&state(1, NONE_U64));
        d.add_state(&state(1 << 40, 0));
        assert_eq!(d.next_state, (1 << 40) + 1 - WINDOW / 2);
        assert_eq!(d.finish().recount.deadline_misses, 2);
    }

    #[test]
    fn a_seq_past_the_run_is_ignored() {
        let mut d = DataPath::new(2, 1000);
        d.add_state(&state(u64::MAX - 1, 0));
        d.add_command(&command(1 << 40, 0, 0));
        assert!(d.states.is_empty() && d.commands.is_empty());
        assert_eq!(d.finish().recount.deadline_misses, 0);
    }
}
