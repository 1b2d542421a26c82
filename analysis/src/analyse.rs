//! Everything a run's figures are computed from, read back from its log.
//!
//! `testbed run` and `testbed replay` both call [`analyse`], so a summary
//! never depends on how it is produced: the log alone decides it.

use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::path::Path;

use scenario::{Plan, RobotSource, Scenario};
use wire::{Logged, OwnLayout, Timing};

use crate::own::{OwnDiagnosticSummary, OwnStats};

use crate::assemble::RecordAssembler;
use crate::csv_out;
use crate::data_path::DataPath;
use crate::summary::{Summary, SummaryBuilder};
use crate::timing::{RunFacts, TimingStats, TimingSummary, judge};
use crate::verify::Verifier;
use logger::{
    DecodeError, LogContents, LogError, MessageError, RawMessage, read_log, read_log_head,
};
use wire::Mode;

/// Why a log could not be analysed.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// Reading the file failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The run's metadata is unusable.
    #[error("{path}: {reason}")]
    Metadata {
        /// The log.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// The CSV could not be written.
    #[error("{path}: {cause}")]
    Output {
        /// The file.
        path: String,
        /// The cause.
        cause: std::io::Error,
    },
}

/// Per-row values the figures need.
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// Sim time of each row, s.
    pub t: Vec<f64>,
    /// Per joint: q, q_d, k_c, q̇, q̇_d, Z1, ‖Ŵa‖, τ (each indexed `[joint][row]`).
    pub q: Vec<Vec<f64>>,
    /// q_d.
    pub q_d: Vec<Vec<f64>>,
    /// k_c.
    pub kc: Vec<Vec<f64>>,
    /// q̇.
    pub qd: Vec<Vec<f64>>,
    /// q̇_d.
    pub qd_d: Vec<Vec<f64>>,
    /// Z1.
    pub z1: Vec<Vec<f64>>,
    /// ‖Ŵa‖.
    pub wa: Vec<Vec<f64>>,
    /// τ.
    pub tau: Vec<Vec<f64>>,
    /// Period jitter samples, µs.
    pub jitter_us: Vec<f64>,
    /// Round-trip samples, µs.
    pub round_trip_us: Vec<f64>,
}

impl Series {
    /// Empty series for `n` joints.
    pub fn new(n: usize) -> Self {
        let v = || vec![Vec::new(); n];
        Self {
            q: v(),
            q_d: v(),
            kc: v(),
            qd: v(),
            qd_d: v(),
            z1: v(),
            wa: v(),
            tau: v(),
            ..Self::default()
        }
    }

    /// Adds one row.
    pub fn add(&mut self, r: &crate::record::StepRecord<'_>) {
        self.t.push(r.t);
        for i in 0..self.q.len() {
            self.q[i].push(r.q[i]);
            self.q_d[i].push(r.q_d[i]);
            self.kc[i].push(r.kc[i]);
            self.qd[i].push(r.qd[i]);
            self.qd_d[i].push(r.qd_d[i]);
            self.z1[i].push(r.z1[i]);
            self.wa[i].push(r.wa_norm[i]);
            self.tau[i].push(r.tau[i]);
        }
    }
}

/// What to compute besides the summary.
#[derive(Default)]
pub struct AnalyseOptions<'a> {
    /// Write one CSV row per step here (path for messages, writer).
    pub csv: Option<(&'a str, &'a mut dyn Write)>,
    /// Re-drive the controller and compare torques.
    pub verify: bool,
    /// Keep the per-row series for figures.
    pub series: bool,
}

/// The result of reading a log.
#[derive(Debug)]
pub struct LogAnalysis {
    /// The scenario and robot as the run used them.
    pub plan: Plan,
    /// Metadata, stats, completeness.
    pub contents: LogContents,
    /// Mode of the run.
    pub mode: Mode,
    /// The step figures.
    pub summary: Summary,
    /// The timing figures.
    pub timing: TimingSummary,
    /// Rows the run should have.
    pub expected_rows: u64,
    /// Rows whose samples were dropped or never came (of a finished run).
    pub missing_rows: u64,
    /// Rows whose samples are in the log but came too late in the file
    /// for the reader ([`crate::assemble::PENDING_ROWS`] steps behind the
    /// other topics): not lost, but not in the figures either.
    pub out_of_order_rows: u64,
    /// Largest |τ_replayed − τ_logged| and steps compared, with `verify`.
    pub verify: Option<(f64, u64)>,
    /// Per-row values, with `series`.
    pub series: Option<Series>,
    /// Wall time between the first and the last logged joint state, s.
    pub wall_span_s: f64,
    /// CLOCK_MONOTONIC of the first and the last logged joint state, ns.
    pub wall_window_ns: (u64, u64),
    /// An external controller's own diagnostics, summed up (empty when it
    /// declared none).
    pub own_diagnostics: Vec<OwnDiagnosticSummary>,
}

impl LogAnalysis {
    /// A warning for a log that was read only in part, or of a run that
    /// did not finish, or None.
    pub fn warning(&self) -> Option<String> {
        let rows = self.summary.steps;
        let ended = self.contents.run_end().filter(|e| *e != "finished");
        let why = match (&self.contents.cut_short, ended) {
            (Some(cut), _) => cut.clone(),
            (None, Some(end)) => format!("the run did not finish ({end})"),
            (None, None) => return None,
        };
        Some(format!(
            "{}: {why}; recovered {rows} of {} steps ({:.3} s of {:.3} s)",
            self.contents.path.display(),
            self.expected_rows,
            rows as f64 * self.plan.dt(),
            self.expected_rows as f64 * self.plan.dt()
        ))
    }
}

fn meta_err(path: &Path, reason: impl Into<String>) -> AnalysisError {
    AnalysisError::Metadata {
        path: path.display().to_string(),
        reason: reason.into(),
    }
}

/// `e`, a log's metadata that does not make a plan, with the reason when
/// the log's checksums say it was changed (read in full only then).
fn damaged_or(path: &Path, e: AnalysisError) -> AnalysisError {
    match logger::read_log(path, None).ok().and_then(|c| c.cut_short) {
        Some(why) => meta_err(path, format!("{e}; the log is damaged: {why}")),
        None => e,
    }
}

/// Rebuilds the run's plan from the log's metadata and URDF attachment.
fn plan_from(contents: &LogContents) -> Result<(Plan, Mode), AnalysisError> {
    let path = contents.path.as_path();
    let get = |k: &str| {
        contents
            .run
            .get(k)
            .ok_or_else(|| meta_err(path, format!("testbed.run metadata has no '{k}'")))
    };
    let toml = get("scenario_toml")?;
    let label = format!("{} (testbed.run scenario_toml)", path.display());
    let mut scenario =
        Scenario::from_log_toml(toml, &label).map_err(|e| meta_err(path, e.to_string()))?;
    // The robot is the attached URDF, wherever the original file was.
    scenario.robot = None;
    let robot = match &contents.urdf {
        Some(urdf) => RobotSource::from_text(
            urdf,
            &format!("{} (robot.urdf)", path.display()),
            &scenario.plant.lock,
        )
        .map_err(|e| meta_err(path, e.to_string()))?,
        None => return Err(meta_err(path, "the log has no robot.urdf attachment")),
    };
    let mode: Mode = get("mode")?
        .parse()
        .map_err(|e: wire::UnknownMode| meta_err(path, format!("testbed.run mode: {e}")))?;
    let plan = scenario::plan(scenario, label, toml.clone(), robot)
        .map_err(|e| meta_err(path, e.to_string()))?;
    Ok((plan, mode))
}

/// What is computed from a log's messages while it is read.
struct Analyser<'a, 'o> {
    plan: &'a Plan,
    n: usize,
    assembler: RecordAssembler,
    summary: SummaryBuilder,
    timing: TimingStats,
    data_path: DataPath,
    series: Option<Series>,
    verifier: Option<Verifier>,
    csv: Option<&'o mut dyn Write>,
    wall: (u64, u64),
    /// Values an own-diagnostics sample carries (0: none declared).
    own_len: usize,
    own: OwnStats,
    /// Messages read per topic, to tell whether the log is the whole run.
    topics: HashMap<String, u64>,
    /// Messages nothing is computed from (the arm's frames and figure, the
    /// standard views) that do not decode, by topic: how many, and the
    /// first one's fault. They are skipped: one bad `/robot_description`
    /// once discarded every step of a log (#60 item 8).
    skipped: BTreeMap<String, (u64, String)>,
}

impl Analyser<'_, '_> {
    fn on_message(&mut self, m: &RawMessage<'_>) -> Result<(), MessageError> {
        match self.topics.get_mut(m.topic) {
            Some(n) => *n += 1,
            None => {
                self.topics.insert(m.topic.to_string(), 1);
            }
        }
        // Every logged message has its arm: the match is over the wire's
        // one list of them.
        match logger::decode_logged(m)? {
            Some(Logged::JointState(s)) => {
                check_dof(s.dof, self.n)?;
                self.wall = (
                    self.wall.0.min(s.header.wall_ns),
                    self.wall.1.max(s.header.wall_ns),
                );
                if let Some(ver) = self.verifier.as_mut() {
                    ver.push_state(s);
                }
                self.data_path.add_state(&s);
                self.assembler.push_state(s);
            }
            Some(Logged::ControllerDiagnostics(d)) => {
                check_dof(d.dof, self.n)?;
                if let Some(ver) = self.verifier.as_mut() {
                    ver.push_diag(d);
                }
                self.assembler.push_diag(d);
            }
            Some(Logged::Command(c)) => {
                self.data_path.add_command(&c);
                if let Some(ver) = self.verifier.as_mut() {
                    ver.push_command(c);
                }
            }
            Some(Logged::Timing(t)) => self.on_timing(&t),
            Some(Logged::OwnDiagnostics(o)) => {
                if o.count as usize != self.own_len {
                    return Err(DecodeError::DiagnosticsCount {
                        got: o.count as usize,
                        declared: self.own_len,
                    }
                    .into());
                }
                self.assembler.push_own(o);
            }
            // Decoded (a damaged one fails the log) but not analysed: the
            // reference is in the diagnostics, contact in the effect bits.
            Some(Logged::ReferenceSample(_) | Logged::ContactState(_)) => {}
            // The arm's frames and figure, the standard views: not
            // analysed, but a log whose message is not JSON (formats 1 and
            // 2) or CDR (format 3) is damaged there.
            None => {
                if let Err(e) = logger::check_message(m.encoding, m.data) {
                    let entry = self
                        .skipped
                        .entry(m.topic.to_string())
                        .or_insert_with(|| (0, e.to_string()));
                    entry.0 += 1;
                }
            }
        }
        let (summary, series, csv) = (&mut self.summary, &mut self.series, &mut self.csv);
        let own = &mut self.own;
        self.assembler.emit(|r| {
            summary.add(r);
            own.add(r.own);
            if let Some(s) = series.as_mut() {
                s.add(r);
            }
            match csv.as_mut() {
                Some(w) => csv_out::write_row(w, r),
                None => Ok(()),
            }
        })?;
        Ok(())
    }

    fn on_timing(&mut self, t: &Timing) {
        self.timing.add(t);
        if let Some(s) = self.series.as_mut() {
            if t.period_ns > 0 {
                s.jitter_us
                    .push((t.period_ns - self.plan.period_ns as i64).unsigned_abs() as f64 / 1e3);
            }
            if t.round_trip_ns >= 0 {
                s.round_trip_us.push(t.round_trip_ns as f64 / 1e3);
            }
        }
    }
}

/// Reads the log at `path` and computes everything from it.
pub fn analyse(path: &Path, opts: AnalyseOptions<'_>) -> Result<LogAnalysis, AnalysisError> {
    let head = read_log_head(path)?;
    let (plan, mode) = plan_from(&head).map_err(|e| damaged_or(path, e))?;
    let n = plan.robot.model.dof();
    let own = own_layout(&head, n)?;
    let own_len = own.len(n);
    let verifier = if opts.verify {
        Some(Verifier::new(
            plan.controller_config()
                .machine()
                .map_err(|e| meta_err(path, e.to_string()))?,
        ))
    } else {
        None
    };
    let (csv_path, mut csv) = match opts.csv {
        Some((p, w)) => (p.to_string(), Some(w)),
        None => (String::new(), None),
    };
    let out_err = |cause| AnalysisError::Output {
        path: csv_path.clone(),
        cause,
    };
    if let Some(w) = csv.as_mut() {
        writeln!(w, "{}", csv_out::header_with_own(n, &own.columns(n))).map_err(out_err)?;
    }
    let mut a = Analyser {
        plan: &plan,
        n,
        assembler: match own_len {
            0 => RecordAssembler::new(n, plan.dt(), plan.steps),
            len => RecordAssembler::new(n, plan.dt(), plan.steps).with_own(len),
        },
        summary: SummaryBuilder::new(
            plan.robot.model.joint_names(),
            plan.dt(),
            plan.scenario.controller.tc,
        )
        .with_gravity(&plan.robot.model),
        timing: TimingStats::new(plan.period_ns),
        data_path: DataPath::new(plan.steps, plan.reference_period_ns),
        series: opts.series.then(|| Series::new(n)),
        verifier,
        csv,
        wall: (u64::MAX, 0),
        own_len,
        own: OwnStats::new(own, n),
        topics: HashMap::new(),
        skipped: BTreeMap::new(),
    };
    let contents = match read_log(path, Some(&mut |m| a.on_message(m))) {
        Err(LogError::Sink { cause, .. }) => return Err(out_err(cause)),
        other => other?,
    };
    if let Some(w) = a.csv.as_mut() {
        w.flush().map_err(out_err)?;
    }
    let wall = a.wall;
    // A log the logger finished holds every row it was sent: the rows
    // still incomplete are lost too.
    let finished = contents.cut_short.is_none() && contents.run_end() == Some("finished");
    let unfinished = if finished {
        a.assembler.unfinished()
    } else {
        0
    };
    let missing_rows = a.assembler.missing() + unfinished;
    let summary = a.summary.finish();
    // A log of format 1 has no data-path stamps to recount from.
    let data_path = (contents.log_format().unwrap_or(0) >= 2).then(|| a.data_path.finish());
    let mut timing = a.timing.finish(mode, plan.scenario.rate_hz, data_path);
    let mut damaged_aside: Vec<String> = a
        .skipped
        .iter()
        .map(|(topic, (n, why))| format!("{n} {topic} message(s) skipped: malformed ({why})"))
        .collect();
    damaged_aside.extend(contents.end_damaged.clone());
    // A log read only in part says so already.
    let not_whole = match contents.cut_short {
        Some(_) => Vec::new(),
        None => crate::whole::gaps(&contents, &a.topics, own_len > 0),
    };
    judge(
        &mut timing,
        &RunFacts {
            missing_rows,
            out_of_order_rows: a.assembler.out_of_order(),
            run_end: contents.run_end(),
            cut_short: contents.cut_short.as_deref(),
            not_whole: &not_whole,
            unchecked: contents.unchecked.as_deref(),
            damaged_aside: &damaged_aside,
            first_non_finite_s: summary.first_non_finite_s,
            period_ns: plan.period_ns,
        },
    );
    Ok(LogAnalysis {
        wall_span_s: wall.1.saturating_sub(wall.0) as f64 / 1e9,
        wall_window_ns: wall,
        expected_rows: plan.steps,
        missing_rows,
        out_of_order_rows: a.assembler.out_of_order(),
        summary,
        timing,
        verify: a.verifier.map(|v| (v.max_abs_torque_diff, v.steps)),
        own_diagnostics: if own_len == 0 {
            Vec::new()
        } else {
            a.own.finish()
        },
        series: a.series,
        contents,
        plan,
        mode,
    })
}

/// The external controller's declared diagnostics (metadata
/// `controller_diagnostics`; none in a log without it).
fn own_layout(contents: &LogContents, n: usize) -> Result<OwnLayout, AnalysisError> {
    let text = contents
        .run
        .get("controller_diagnostics")
        .map_or("", String::as_str);
    OwnLayout::parse(text, n).map_err(|e| {
        meta_err(
            &contents.path,
            format!("testbed.run controller_diagnostics: {e}"),
        )
    })
}

fn check_dof(dof: u32, n: usize) -> Result<(), DecodeError> {
    if dof as usize == n {
        Ok(())
    } else {
        Err(DecodeError::Dof { dof, joints: n })
    }
}
