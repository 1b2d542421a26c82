//! The launcher's view of a running stack: it drains every topic in
//! batches (never on the critical path), rebuilds the step records, and
//! keeps the summary, the CSV and the timing statistics up to date.

use std::fs::File;
use std::io::{BufWriter, Write};

use wire::{
    Bus, ControllerDiagnostics, JointState, ReferenceSample, Timing, Topic, TopicSubscriber,
};

use crate::assemble::RecordAssembler;
use crate::csv_out;
use crate::mode::Mode;
use crate::run::RunError;
use crate::run::timing::{TimingStats, TimingSummary};
use crate::summary::{Summary, SummaryBuilder};

/// Subscriptions and what has been built from them.
pub struct Collector {
    states: TopicSubscriber<JointState>,
    diags: TopicSubscriber<ControllerDiagnostics>,
    timing: TopicSubscriber<Timing>,
    refs: TopicSubscriber<ReferenceSample>,
    assembler: RecordAssembler,
    summary: SummaryBuilder,
    csv: Option<(BufWriter<File>, String)>,
    timing_stats: TimingStats,
    /// Samples received per topic: states, diagnostics, timing, references.
    pub received: [u64; 4],
}

impl Collector {
    /// Subscribes to every data topic (before any node starts, so nothing is missed).
    pub fn new(
        bus: &Bus,
        plan: &scenario::Plan,
        csv: Option<(BufWriter<File>, String)>,
    ) -> Result<Self, RunError> {
        let n = plan.robot.model.dof();
        Ok(Self {
            states: bus.subscriber(Topic::JointState)?,
            diags: bus.subscriber(Topic::Diagnostics)?,
            timing: bus.subscriber(Topic::Timing)?,
            refs: bus.subscriber(Topic::Reference)?,
            assembler: RecordAssembler::new(n, plan.dt(), plan.steps),
            summary: SummaryBuilder::new(
                plan.robot.model.joint_names(),
                plan.dt(),
                plan.scenario.controller.tc,
            ),
            csv,
            timing_stats: TimingStats::new(plan.period_ns),
            received: [0; 4],
        })
    }

    /// Takes everything buffered and emits the rows that are complete.
    pub fn drain(&mut self) -> Result<(), RunError> {
        while let Some(s) = self.states.receive()? {
            self.received[0] += 1;
            self.assembler.push_state(s);
        }
        while let Some(d) = self.diags.receive()? {
            self.received[1] += 1;
            self.assembler.push_diag(d);
        }
        while let Some(t) = self.timing.receive()? {
            self.received[2] += 1;
            self.timing_stats.add(&t);
        }
        while let Some(_r) = self.refs.receive()? {
            self.received[3] += 1;
        }
        for sub in [
            self.states.listener(),
            self.diags.listener(),
            self.timing.listener(),
            self.refs.listener(),
        ] {
            let _ = sub.try_wait(|_| {});
        }
        let summary = &mut self.summary;
        let csv = &mut self.csv;
        self.assembler
            .emit(|r| {
                summary.add(r);
                match csv {
                    Some((w, _)) => csv_out::write_row(w, r),
                    None => Ok(()),
                }
            })
            .map_err(|e| RunError::Output(self.csv_name(), e))
    }

    fn csv_name(&self) -> String {
        self.csv
            .as_ref()
            .map_or_else(String::new, |(_, p)| p.clone())
    }

    /// Rows emitted so far.
    pub fn rows(&self) -> u64 {
        self.assembler.next_step()
    }

    /// True once every row is in.
    pub fn complete(&self) -> bool {
        self.assembler.complete()
    }

    /// Rows that could not be built (real time, samples dropped).
    pub fn missing_rows(&self) -> u64 {
        self.assembler.missing()
    }

    /// Flushes the CSV and returns the summaries.
    pub fn finish(
        &mut self,
        mode: Mode,
        rate_hz: f64,
    ) -> Result<(Summary, TimingSummary), RunError> {
        if let Some((w, path)) = self.csv.as_mut() {
            w.flush().map_err(|e| RunError::Output(path.clone(), e))?;
        }
        Ok((
            self.summary.finish(),
            self.timing_stats.finish(mode, rate_hz),
        ))
    }
}
