//! `testbed run`: the launcher. It turns a validated plan into running
//! processes, starts them together, watches them, and stops them in order.

mod error;
pub mod external;
mod files;
mod nodes;
pub mod spawn;
mod strays;
mod supervise;
mod transport;

pub use error::RunError;
pub use files::{MAX_RUN_NAME_CHARS, run_name_problem};

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Duration;

use bus::{Bus, RunPrefix, monotonic_ns};
use logger::LogCompression;
use logger::live::LiveConfig;
use scenario::Plan;
use wire::{CONTROL_STOP, Control, Delivery, Header, MAX_DOF, NodeKind, NodeStatus, RunEnd};

use crate::mode::Mode;
use analysis::analyse::{AnalyseOptions, LogAnalysis, analyse};
use files::RunFiles;
use spawn::{Children, describe};
use supervise::supervise;

/// The nodes `testbed run` starts, in start order (the logger first, so it
/// is listening before anything is sent).
pub const NODES: [NodeKind; 4] = [
    NodeKind::Logger,
    NodeKind::Plant,
    NodeKind::Trajectory,
    NodeKind::Controller,
];

/// Grace period between STOP, SIGTERM and SIGKILL.
const STOP_GRACE: Duration = Duration::from_secs(2);

/// Everything `testbed run` needs, validated.
#[derive(Debug)]
pub struct RunOptions {
    /// The scenario, checked against its robot.
    pub plan: Plan,
    /// Timing mode.
    pub mode: Mode,
    /// Write one row per step here.
    pub csv: Option<PathBuf>,
    /// Nodes the user starts by hand instead of the launcher.
    pub external: Vec<NodeKind>,
    /// Folder under which the run's folder is made.
    pub runs_dir: PathBuf,
    /// The run folder's name (default: `<epoch seconds>-<pid>`); a folder
    /// of that name must not exist yet.
    pub name: Option<String>,
    /// Show a progress bar (real time, on a terminal).
    pub progress: bool,
    /// Pin the nodes to CPUs and, in real time, run the loop under
    /// SCHED_FIFO with locked memory (see [`crate::node::placement`]).
    pub realtime_setup: bool,
    /// Let the nodes print iceoryx2's own messages.
    pub verbose: bool,
    /// Run this command (program and arguments) as the controller node
    /// instead of `testbed node controller`; the node arguments are appended.
    pub controller_cmd: Option<Vec<String>>,
    /// Serve the run live to Foxglove from the logger (`--live`).
    pub live: Option<LiveConfig>,
    /// The log's chunk compression.
    pub log_compression: LogCompression,
}

/// What a finished run produced.
#[derive(Debug)]
pub struct RunOutcome {
    /// Everything computed from the run's log.
    pub analysis: LogAnalysis,
    /// The run's folder (holds the scenario it ran and the log).
    pub run_dir: PathBuf,
    /// The MCAP log.
    pub log: PathBuf,
    /// Wall time from START to the plant's last step, s.
    pub wall_time_s: f64,
    /// Peak resident memory of each node (kB), read just before STOP.
    pub peak_rss_kb: Vec<(NodeKind, u64)>,
    /// CPU time of each node (s) up to just before STOP.
    pub node_cpu_s: Vec<(NodeKind, f64)>,
}

/// A fresh folder name for a run: UTC-free, sortable, unique on this machine.
fn run_id() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    format!("{secs}-{}", std::process::id())
}

/// The arguments of `testbed node <kind>` for this run.
pub fn node_args(
    prefix: &RunPrefix,
    config: &Path,
    mode: Mode,
    parent: Option<u32>,
) -> Vec<String> {
    let mut args = vec![
        "--prefix".to_string(),
        prefix.as_str().to_string(),
        "--config".to_string(),
        config.display().to_string(),
        "--mode".to_string(),
        mode.as_str().to_string(),
    ];
    if let Some(pid) = parent {
        args.push("--parent-pid".into());
        args.push(pid.to_string());
    }
    args
}

/// Runs the stack to the end; a run the shared-memory transport failed to
/// connect is started again (`transport`).
pub fn run(opts: RunOptions) -> Result<RunOutcome, RunError> {
    transport::with_retries(&opts, run_once)
}

fn run_once(opts: &RunOptions) -> Result<RunOutcome, RunError> {
    check_up_front(opts)?;
    let declared = match &opts.controller_cmd {
        Some(command) => external::declared(
            command,
            &opts.plan.scenario.external,
            opts.plan.robot.model.dof(),
        )?,
        None => None,
    };
    let files = RunFiles::write(opts, declared.as_ref())?;
    let prefix = RunPrefix::unique();
    // Domains that killed launchers left behind.
    for stale in RunPrefix::stale_domains(&prefix) {
        let _ = stale.remove_domain_if_unused();
    }
    // And the files of nodes killed while they were being created.
    prefix.remove_leftover_files(false);
    // Before any service is made: a full /dev/shm kills a node with SIGBUS.
    if let Some(reason) = bus::shm_too_small() {
        return Err(RunError::Scenario { reason });
    }
    let bus = Bus::new(&prefix, "launcher")?;
    let status = bus.subscriber::<NodeStatus>()?;
    let control = bus.publisher::<Control>(Delivery::DropWhenFull)?;
    let cpus = crate::node::placement::cpu_count();
    let _off_loop = opts
        .realtime_setup
        .then(|| crate::node::placement::OffLoopCpu::enter(cpus));
    // A node that cannot be started ends the run like any other failure:
    // the ones already started get STOP, and the domain is removed.
    let mut children = Children::default();
    let result = spawn_nodes(opts, &prefix, &files.configs, cpus, &mut children)
        .and_then(|()| supervise(opts, &bus, &status, &control, &mut children));
    let peak_rss_kb = children.peak_rss_kb();
    let node_cpu_s = children.cpu_s();
    // Whatever happened: STOP (the logger then finishes the file), grace,
    // SIGTERM, SIGKILL, reap.
    let end = result
        .as_ref()
        .map_or_else(RunError::run_end, |_| RunEnd::Finished);
    let mut stop = control_msg(CONTROL_STOP, 0);
    stop.code = end.code();
    let _ = control.send(stop);
    let forced = children.stop(STOP_GRACE);
    // What the nodes started, wherever it moved (its own session, a
    // cleared environment): adopted by this process, killed and reaped.
    children.end_descendants();
    let result = result.map_err(|e| e.with_stderr_of(&mut children));
    let logger_exit = children.exit_of(NodeKind::Logger);
    // Close every port of this process, then remove what is left of the
    // run's domain (including what a killed node left behind).
    drop((status, control, bus));
    // And whatever still carries the run's name (adopted by another
    // subreaper, say).
    strays::end_strays(prefix.as_str());
    let _ = prefix.remove_domain_if_unused();
    prefix.remove_leftover_files(true);
    let wall_time_s = result?;
    if let Some((status, stderr)) = logger_exit.filter(|(s, _)| !s.success()) {
        // Killed by the launcher itself after STOP: say so, not "signal 9".
        let how = match forced.iter().rev().find(|(k, _)| *k == NodeKind::Logger) {
            Some((_, sig)) => format!(
                "did not finish its log within {} s of STOP (stopped or hung), so the launcher \
                 sent it {sig}",
                STOP_GRACE.as_secs()
            ),
            None => describe(status),
        };
        return Err(RunError::NodeFailed {
            node: NodeKind::Logger.name(),
            how,
            stderr,
        });
    }
    // One analysis path: the summary comes from the log just written.
    let analysis = analyse_log(&files.log, opts.csv.as_deref())?;
    let contact = !opts.plan.scenario.plant.contact.is_off();
    transport::check_log(&analysis, opts.mode, contact)?;
    Ok(RunOutcome {
        analysis,
        run_dir: files.run_dir,
        log: files.log,
        wall_time_s,
        peak_rss_kb,
        node_cpu_s,
    })
}

/// What can be refused before anything starts: too many joints, an
/// unwritable CSV (not after the run), a controller command that cannot run.
fn check_up_front(opts: &RunOptions) -> Result<(), RunError> {
    let dof = opts.plan.robot.model.dof();
    if dof > MAX_DOF {
        return Err(RunError::TooManyJoints { dof });
    }
    if let Some(path) = &opts.csv {
        File::create(path).map_err(|e| RunError::Output(path.display().to_string(), e))?;
    }
    if let Some(live) = &opts.live {
        if !live.addr.ip().is_loopback() {
            eprintln!(
                "testbed: warning: the live view listens on {}, beyond this machine: anyone \
                 who can reach it can watch the run (127.0.0.1 keeps it local)",
                live.addr
            );
        }
        // Taken now, it would fail the logger after the others started.
        // (Released at once: the logger binds it; a thief in between makes
        // the logger fail, named.)
        std::net::TcpListener::bind(live.addr)
            .map_err(|cause| RunError::LivePort(live.addr, cause))?;
    }
    if opts.controller_cmd.is_none()
        && let Some(key) = opts.plan.scenario.external.keys().next()
    {
        return Err(RunError::Scenario {
            reason: format!(
                "the scenario sets [external] {key}, which only an external controller (--controller-cmd) takes"
            ),
        });
    }
    if let Some(command) = &opts.controller_cmd {
        spawn::check_program(command).map_err(|cause| RunError::Spawn {
            node: NodeKind::Controller.name(),
            command: shell_words::join(command),
            cause,
        })?;
    }
    Ok(())
}

/// Starts every node the launcher owns; says how to start the external ones.
fn spawn_nodes(
    opts: &RunOptions,
    prefix: &RunPrefix,
    configs: &[(NodeKind, PathBuf)],
    cpus: usize,
    children: &mut Children,
) -> Result<(), RunError> {
    let exe = std::env::current_exe().map_err(|cause| RunError::Spawn {
        node: "plant",
        command: String::new(),
        cause,
    })?;
    let me = Some(std::process::id());
    for kind in NODES {
        let external = opts.external.contains(&kind);
        let parent = if external { None } else { me };
        let Some((_, config)) = configs.iter().find(|(k, _)| *k == kind) else {
            unreachable!("write_all writes a config for every node kind");
        };
        let mut args = node_args(prefix, config, opts.mode, parent);
        if opts.verbose {
            args.push("--verbose".into());
        }
        if opts.realtime_setup {
            let mut placement = crate::node::placement::for_node(kind, opts.mode, cpus);
            if kind == NodeKind::Controller && opts.controller_cmd.is_some() {
                placement = crate::node::placement::below_the_plant(placement);
            }
            args.extend(placement.to_args());
        }
        if external {
            eprintln!(
                "testbed: waiting for the {} node; start it with:\n  testbed node {} {}",
                kind.name(),
                kind.name(),
                args.join(" ")
            );
            continue;
        }
        // Beside its config: nodes/<node>.log.
        let output = config.with_extension("log");
        let child = match (&opts.controller_cmd, kind) {
            (Some(command), NodeKind::Controller) => {
                spawn::spawn_command(command, kind, &args, &output)
            }
            _ => spawn::spawn(&exe, kind, &args, &output),
        }
        .map_err(|cause| RunError::Spawn {
            node: kind.name(),
            command: match (&opts.controller_cmd, kind) {
                (Some(c), NodeKind::Controller) => shell_words::join(c),
                _ => String::new(),
            },
            cause,
        })?;
        children.push(child);
    }
    Ok(())
}

/// The run's figures from its log, with one CSV row per step if asked.
fn analyse_log(log: &Path, csv: Option<&Path>) -> Result<LogAnalysis, RunError> {
    let mut csv_file = match csv {
        Some(path) => {
            Some(BufWriter::new(File::create(path).map_err(|e| {
                RunError::Output(path.display().to_string(), e)
            })?))
        }
        None => None,
    };
    let csv_name = csv.map(|p| p.display().to_string()).unwrap_or_default();
    Ok(analyse(
        log,
        AnalyseOptions {
            csv: csv_file
                .as_mut()
                .map(|w| (csv_name.as_str(), w as &mut dyn std::io::Write)),
            ..AnalyseOptions::default()
        },
    )?)
}

fn control_msg(command: u32, epoch_wall_ns: u64) -> Control {
    Control {
        header: Header {
            seq: 0,
            t_ns: 0,
            wall_ns: monotonic_ns(),
        },
        command,
        code: 0,
        epoch_wall_ns,
    }
}
