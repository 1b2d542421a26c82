//! Rebuilds [`StepRecord`]s from the messages of a multi-process run.
//!
//! Row k needs joint state k (q, q̇), joint state k+1 (the torque the plant
//! applied over the step and q̇ for the mean acceleration) and the
//! controller diagnostics of step k (the reference it used, Z1, Z2, ‖Ŵa‖);
//! of an external controller that declared diagnostics of its own, also
//! those of step k.
//! The arithmetic is the in-process loop's, so a lockstep run gives the
//! same bits as `testbed sim`.

use std::collections::BTreeMap;

use scenario::ns_to_s;
use wire::{ControllerDiagnostics, JointState, OwnDiagnostics};

use crate::record::StepRecord;

/// Each topic arrives in sequence order (one publisher, delivered in order),
/// but topics are interleaved in batches: a log may hold a thousand states
/// before their diagnostics. So a row is given up only when the topic it
/// lacks has moved past it (a sample dropped in real time), with a little
/// slack for reordering.
const GIVE_UP_AFTER: u64 = 8;

/// Rows that may wait for a topic at once: a sample this far past the next
/// row gives up the rows before it, so that a log missing a topic (or
/// naming steps far ahead) cannot make replay's memory grow with its
/// length. 16 384 rows of every topic hold at most about 105 MB (a state
/// is 1.6 kB, a diagnostics sample 4.4 kB, own diagnostics 0.3 kB, at
/// `MAX_DOF` joints), where the logger interleaves topics within a few
/// thousand steps.
pub const PENDING_ROWS: u64 = 16_384;

/// Collects states and diagnostics and emits complete rows in step order.
#[derive(Debug)]
pub struct RecordAssembler {
    n: usize,
    dt: f64,
    steps: u64,
    next: u64,
    newest_state: Option<u64>,
    newest_diag: Option<u64>,
    // Boxed: a B-tree moves its values around its nodes, and these are
    // large (a third of `replay`'s copying was B-tree removals).
    states: BTreeMap<u64, Box<JointState>>,
    diags: BTreeMap<u64, Box<ControllerDiagnostics>>,
    /// Values of the own diagnostics a row needs (None: no row needs any).
    own_len: Option<usize>,
    newest_own: Option<u64>,
    owns: BTreeMap<u64, Box<OwnDiagnostics>>,
    missing: u64,
    /// Rows given up, as ranges `start -> end` (end exclusive): a sample
    /// that comes for one of them later shows the log out of order, not
    /// the row lost.
    given_up: BTreeMap<u64, u64>,
    /// Rows given up whose samples came later in the file.
    late: u64,
    qdd: Vec<f64>,
}

impl RecordAssembler {
    /// For `n` joints, period `dt` s and `steps` rows.
    pub fn new(n: usize, dt: f64, steps: u64) -> Self {
        Self {
            n,
            dt,
            steps,
            next: 0,
            newest_state: None,
            newest_diag: None,
            states: BTreeMap::new(),
            diags: BTreeMap::new(),
            own_len: None,
            newest_own: None,
            owns: BTreeMap::new(),
            missing: 0,
            given_up: BTreeMap::new(),
            late: 0,
            qdd: vec![0.0; n],
        }
    }

    /// Rows also need an external controller's own diagnostics, `len`
    /// values each.
    pub fn with_own(mut self, len: usize) -> Self {
        self.own_len = Some(len.min(wire::MAX_OWN_DIAGNOSTICS));
        self
    }

    /// Adds an own-diagnostics sample (ignored unless rows need them).
    pub fn push_own(&mut self, o: OwnDiagnostics) {
        let seq = o.header.seq;
        if self.own_len.is_some() {
            self.make_room(seq);
        }
        if self.own_len.is_some() && seq < self.next {
            self.came_late(seq);
        }
        if self.own_len.is_some() && (self.next..self.steps).contains(&seq) {
            self.newest_own = Some(self.newest_own.map_or(seq, |n| n.max(seq)));
            self.owns.insert(seq, Box::new(o));
        }
    }

    /// Adds a joint state.
    pub fn push_state(&mut self, s: JointState) {
        let seq = s.header.seq;
        self.make_room(seq);
        // State k serves rows k and k - 1.
        if seq < self.next {
            self.came_late(seq);
        }
        if let Some(row) = seq.checked_sub(1)
            && row < self.next
        {
            self.came_late(row);
        }
        // Rows need states up to `steps` (row k uses k + 1).
        if (self.next..=self.steps).contains(&seq) {
            self.newest_state = Some(self.newest_state.map_or(seq, |n| n.max(seq)));
            self.states.insert(seq, Box::new(s));
        }
    }

    /// Adds a diagnostics sample.
    pub fn push_diag(&mut self, d: ControllerDiagnostics) {
        let seq = d.header.seq;
        self.make_room(seq);
        if seq < self.next {
            self.came_late(seq);
        }
        if (self.next..self.steps).contains(&seq) {
            self.newest_diag = Some(self.newest_diag.map_or(seq, |n| n.max(seq)));
            self.diags.insert(seq, Box::new(d));
        }
    }

    /// Rows given up because their data never came.
    pub fn missing(&self) -> u64 {
        self.missing - self.late
    }

    /// Rows given up whose samples came later in the file than the
    /// reader's bound ([`PENDING_ROWS`] steps behind the other topics):
    /// they are in the log, but out of order beyond what replay holds.
    pub fn out_of_order(&self) -> u64 {
        self.late
    }

    /// Rows neither emitted nor given up: at the end of a finished run's
    /// log, rows whose samples never came (a topic that was never
    /// delivered leaves every row here, not in [`Self::missing`]).
    pub fn unfinished(&self) -> u64 {
        self.steps.saturating_sub(self.next)
    }

    /// True once every row has been emitted or given up.
    pub fn complete(&self) -> bool {
        self.next >= self.steps
    }

    /// Emits every row that is complete, in order.
    pub fn emit(
        &mut self,
        mut on_step: impl FnMut(&StepRecord<'_>) -> std::io::Result<()>,
    ) -> std::io::Result<()> {
        while self.next < self.steps {
            let k = self.next;
            let (Some(s), Some(s1)) = (self.states.get(&k), self.states.get(&(k + 1))) else {
                if past(self.newest_state, k + 1) {
                    self.skip(k);
                    continue;
                }
                break;
            };
            let Some(d) = self.diags.get(&k) else {
                if past(self.newest_diag, k) {
                    self.skip(k);
                    continue;
                }
                break;
            };
            let own: &[f64] = match self.own_len {
                None => &[],
                Some(len) => match self.owns.get(&k) {
                    Some(o) => &o.values[..len],
                    None if past(self.newest_own, k) => {
                        self.skip(k);
                        continue;
                    }
                    None => break,
                },
            };
            let n = self.n;
            for i in 0..n {
                self.qdd[i] = (s1.qd[i] - s.qd[i]) / self.dt;
            }
            let record = StepRecord {
                t: ns_to_s(s.header.t_ns),
                q: &s.q[..n],
                qd: &s.qd[..n],
                q_measured: &s.q_measured[..n],
                qd_measured: &s.qd_measured[..n],
                qdd: &self.qdd,
                tau: &s1.tau_applied[..n],
                disturbance: &s1.disturbance[..n],
                effects: s1.effects,
                q_d: &d.q_d[..n],
                qd_d: &d.qd_d[..n],
                kc: &d.kc_in[..n],
                z1: &d.z1[..n],
                z1g: &d.z1g[..n],
                z2: &d.z2[..n],
                wa_norm: &d.wa_norm[..n],
                tau_actor: &d.tau_actor[..n],
                barrier_breached: d.barrier_breached != 0,
                fault: d.fault != 0,
                own,
            };
            on_step(&record)?;
            self.states.remove(&k);
            self.diags.remove(&k);
            self.owns.remove(&k);
            self.next += 1;
        }
        Ok(())
    }

    /// Gives up the rows more than [`PENDING_ROWS`] before `seq` (counted
    /// as missing), at once however far ahead `seq` is.
    fn make_room(&mut self, seq: u64) {
        let floor = seq.saturating_sub(PENDING_ROWS - 1).min(self.steps);
        if floor <= self.next {
            return;
        }
        self.missing += floor - self.next;
        self.give_up(self.next, floor);
        self.next = floor;
        self.states = self.states.split_off(&floor);
        self.diags = self.diags.split_off(&floor);
        self.owns = self.owns.split_off(&floor);
    }

    fn skip(&mut self, k: u64) {
        self.states.remove(&k);
        self.diags.remove(&k);
        self.owns.remove(&k);
        self.missing += 1;
        self.give_up(k, k + 1);
        self.next += 1;
    }

    /// Records rows `start..end` as given up, joined to the range before
    /// when they follow it (rows are given up in order).
    fn give_up(&mut self, start: u64, end: u64) {
        if let Some(mut last) = self.given_up.last_entry()
            && *last.get() == start
        {
            *last.get_mut() = end;
            return;
        }
        self.given_up.insert(start, end);
    }

    /// A sample came for row `k`, already passed: if the row was given up,
    /// it is counted late instead of lost (once).
    fn came_late(&mut self, k: u64) {
        let Some((&start, &end)) = self.given_up.range(..=k).next_back() else {
            return;
        };
        if k >= end {
            return;
        }
        self.given_up.remove(&start);
        if start < k {
            self.given_up.insert(start, k);
        }
        if k + 1 < end {
            self.given_up.insert(k + 1, end);
        }
        self.late += 1;
    }
}

/// The stream whose newest sample is `newest` has moved well past `seq`.
fn past(newest: Option<u64>, seq: u64) -> bool {
    newest.is_some_and(|n| n > seq + GIVE_UP_AFTER)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// #39 row 5: a log without diagnostics keeps at most
    /// [`PENDING_ROWS`] states waiting, and gives up the rest as missing.
    #[test]
    fn a_missing_topic_keeps_memory_bounded() {
        let steps = 3 * PENDING_ROWS;
        let mut a = RecordAssembler::new(2, 1e-3, steps);
        for k in 0..=steps {
            let mut s = JointState::default();
            s.header.seq = k;
            a.push_state(s);
            assert!(a.states.len() as u64 <= PENDING_ROWS);
        }
        assert_eq!(a.missing(), steps + 1 - PENDING_ROWS);
        // A sample naming a step far ahead gives up everything before it,
        // at once.
        let mut d = ControllerDiagnostics::default();
        d.header.seq = u64::MAX;
        a.push_diag(d);
        assert_eq!(a.missing() + a.unfinished(), steps);
        assert!(a.complete() && a.diags.is_empty() && a.states.len() <= 1);
    }

    fn state(k: u64) -> JointState {
        JointState {
            header: wire::Header {
                seq: k,
                t_ns: k * 1_000_000,
                wall_ns: 0,
            },
            dof: 1,
            ..JointState::default()
        }
    }

    fn diag(k: u64) -> ControllerDiagnostics {
        ControllerDiagnostics {
            header: wire::Header {
                seq: k,
                t_ns: k * 1_000_000,
                wall_ns: 0,
            },
            dof: 1,
            ..ControllerDiagnostics::default()
        }
    }

    fn rows(a: &mut RecordAssembler) -> u64 {
        let mut n = 0;
        a.emit(|_| {
            n += 1;
            Ok(())
        })
        .unwrap();
        n
    }

    /// Regression: a fast lockstep log holds batches of over a thousand
    /// states before their diagnostics; rows were once given up then.
    #[test]
    fn rows_survive_a_batch_of_states_before_their_diagnostics() {
        let mut a = RecordAssembler::new(1, 1e-3, 3000);
        for k in 0..=3000 {
            a.push_state(state(k));
        }
        assert_eq!(rows(&mut a), 0);
        for k in 0..3000 {
            a.push_diag(diag(k));
        }
        assert_eq!(rows(&mut a), 3000);
        assert_eq!(a.missing(), 0);
        assert!(a.complete());
    }

    #[test]
    fn a_dropped_sample_costs_only_its_row() {
        let mut a = RecordAssembler::new(1, 1e-3, 100);
        for k in 0..=100 {
            a.push_state(state(k));
        }
        for k in (0..100).filter(|k| *k != 40) {
            a.push_diag(diag(k));
        }
        assert_eq!(rows(&mut a), 99);
        assert_eq!(a.missing(), 1);
        assert_eq!(a.unfinished(), 0);
        assert!(a.complete());
    }

    /// Regression: a lockstep log whose logger never got the controller's
    /// topics (an iceoryx2 connection left unmade) gave no row, no missing
    /// row, and a run that passed with a summary of zero steps.
    #[test]
    fn a_topic_never_delivered_leaves_every_row_unfinished() {
        let mut a = RecordAssembler::new(1, 1e-3, 400);
        for k in 0..=400 {
            a.push_state(state(k));
        }
        assert_eq!(rows(&mut a), 0);
        assert_eq!(a.missing(), 0);
        assert_eq!(a.unfinished(), 400);
        assert!(!a.complete());
    }

    /// Issue 48 item 15 (N11): diagnostics written after every state of a
    /// run longer than the bound give rows up, but their samples then come:
    /// those rows are out of order, not lost.
    #[test]
    fn samples_past_the_bound_are_out_of_order_not_lost() {
        let steps = PENDING_ROWS + 600;
        let mut a = RecordAssembler::new(1, 1e-3, steps);
        for k in 0..=steps {
            a.push_state(state(k));
        }
        for k in 0..steps {
            a.push_diag(diag(k));
        }
        let read = rows(&mut a);
        assert_eq!(a.missing(), 0);
        assert_eq!(a.out_of_order() + read, steps);
        assert!(a.out_of_order() > 0 && a.complete());
        // A row truly dropped stays lost beside them.
        let mut b = RecordAssembler::new(1, 1e-3, steps);
        for k in (0..=steps).filter(|k| *k != 3) {
            b.push_state(state(k));
        }
        for k in (0..steps).filter(|k| *k != 2 && *k != 3) {
            b.push_diag(diag(k));
        }
        rows(&mut b);
        assert_eq!(b.missing(), 2);
    }
}
