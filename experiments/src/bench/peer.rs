//! `testbed bench --peer`: the paper scenario as the one Python loop a user
//! would write instead of the testbed (the numpy law of
//! `python/examples/nac.py` driving MuJoCo, loaded from the same URDF, RK4),
//! measured against the testbed's lockstep stack in the same bench run,
//! alternating, `--repeats` pairs. The script is `python/peer/mujoco_loop.py`;
//! `bash python/setup-venv.sh --peer` installs what it needs.

use std::path::{Path, PathBuf};
use std::process::Command;

use scenario::Plan;
use serde::{Deserialize, Serialize};

use crate::bench::parts::{load, stack};
use crate::bench::types::{BenchError, BenchOptions, Machine, machine, median};
use run_stack::mode::Mode;
use run_stack::node::configs;

/// MuJoCo substeps per control period (RK4): the loop a user would write.
pub const PEER_SUBSTEPS: u32 = 4;

/// What the Python loop is told (the scenario, resolved by the testbed).
#[derive(Debug, Serialize)]
struct PeerConfig<'a> {
    urdf: &'a Path,
    period_s: f64,
    steps: u64,
    substeps: u32,
    initial: &'a scenario::Initial,
    reference: &'a trajectory::ReferenceConfig,
    envelope: &'a trajectory::EnvelopeConfig,
    controller: controller::node::ControllerNodeConfig,
}

/// What the Python loop reports.
#[derive(Debug, Deserialize)]
struct PeerOutput {
    wall_s: f64,
    steps: u64,
    max_abs_error_after_tc: Vec<f64>,
}

/// The comparison.
#[derive(Debug, Clone, Serialize)]
pub struct PeerBench {
    /// Where it ran.
    pub machine: Machine,
    /// The scenario and its simulated time, s.
    pub scenario: String,
    /// Simulated time of one run, s.
    pub sim_s: f64,
    /// MuJoCo substeps per period.
    pub peer_substeps: u32,
    /// The Python loop's own wall time (imports and model loading
    /// excluded), s, run by run.
    pub peer_wall_s: Vec<f64>,
    /// The lockstep stack with the logger, START to last step, s, run by run.
    pub lockstep_wall_s: Vec<f64>,
    /// Median over pairs of peer / lockstep.
    pub speedup: f64,
    /// max |q − q_d| over t ≥ T_c per joint in the first pair, rad: the
    /// testbed's and the loop's, to show they ran the same closed loop.
    pub testbed_max_error_after_tc: Vec<f64>,
    /// The same for the Python + MuJoCo loop.
    pub peer_max_error_after_tc: Vec<f64>,
}

/// Runs `opts.repeats` pairs with `python` running the loop script.
pub fn run(
    opts: &BenchOptions,
    python: &[String],
    mut progress: impl FnMut(&str),
) -> Result<PeerBench, BenchError> {
    let plan = load(None, opts)?;
    let dir = opts.runs_dir.join(format!("peer-{}", std::process::id()));
    let config = write_config(&plan, &dir)?;
    let (mut peer, mut lockstep, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    let (mut testbed_error, mut peer_error_after_tc) = (Vec::new(), Vec::new());
    for pair in 1..=opts.repeats {
        progress(&format!("pair {pair}: lockstep stack"));
        let out = stack(&plan, Mode::Lockstep, opts, None)?;
        progress(&format!("pair {pair}: Python + MuJoCo loop"));
        let p = run_peer(python, &config)?;
        if pair == 1 {
            let joints = &out.analysis.summary.joints;
            testbed_error = joints
                .iter()
                .map(|j| j.max_abs_error_after_tc.unwrap_or(f64::NAN))
                .collect();
            peer_error_after_tc.clone_from(&p.max_abs_error_after_tc);
        }
        if p.steps != plan.steps {
            return Err(peer_error(format!(
                "the loop ran {} steps, the scenario has {}",
                p.steps, plan.steps
            )));
        }
        ratios.push(p.wall_s / out.wall_time_s);
        peer.push(p.wall_s);
        lockstep.push(out.wall_time_s);
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(PeerBench {
        machine: machine(),
        scenario: plan.scenario.name.clone(),
        sim_s: plan.steps as f64 * plan.dt(),
        peer_substeps: PEER_SUBSTEPS,
        peer_wall_s: peer,
        lockstep_wall_s: lockstep,
        speedup: median(ratios),
        testbed_max_error_after_tc: testbed_error,
        peer_max_error_after_tc: peer_error_after_tc,
    })
}

fn peer_error(what: String) -> BenchError {
    BenchError::Peer(what)
}

/// The URDF and the loop's config in `dir`; the config's path.
fn write_config(plan: &Plan, dir: &Path) -> Result<PathBuf, BenchError> {
    let io = |e: std::io::Error| peer_error(format!("{}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(io)?;
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, &plan.robot.urdf).map_err(io)?;
    let s = &plan.scenario;
    let config = PeerConfig {
        urdf: &urdf,
        period_s: plan.dt(),
        steps: plan.steps,
        substeps: PEER_SUBSTEPS,
        initial: &s.initial,
        reference: &s.reference,
        envelope: &s.envelope,
        controller: configs::controller(plan),
    };
    let path = dir.join("peer.json");
    let text = serde_json::to_string_pretty(&config)
        .map_err(|e| peer_error(format!("cannot encode the loop's config: {e}")))?;
    std::fs::write(&path, text).map_err(io)?;
    Ok(path)
}

/// The loop script beside the sources this binary was built from.
pub fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/peer/mujoco_loop.py")
}

fn run_peer(python: &[String], config: &Path) -> Result<PeerOutput, BenchError> {
    let (program, args) = python
        .split_first()
        .ok_or_else(|| peer_error("no Python command".into()))?;
    let out = Command::new(program)
        .args(args)
        .arg(script())
        .arg(config)
        .output()
        .map_err(|e| peer_error(format!("cannot start {program}: {e}")))?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = stderr.lines().rev().take(8).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(peer_error(format!(
            "the Python + MuJoCo loop failed ({}); set it up with `bash python/setup-venv.sh --peer`:\n{}",
            out.status,
            tail.join("\n")
        )));
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().unwrap_or_default();
    serde_json::from_str(line)
        .map_err(|e| peer_error(format!("the loop printed {line:?}, not its figures: {e}")))
}
