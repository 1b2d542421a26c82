//! `testbed-policy FILE.onnx`: a trained policy (ONNX) as the controller
//! node of a run, with no Python in the loop.
//!
//! ```sh
//! testbed run --mode lockstep --controller-cmd "testbed-policy runs/policy.onnx"
//! testbed compare --laws nac,pd --controller-cmd ppo="testbed-policy runs/policy.onnx"
//! ```
//!
//! The launcher appends the node arguments (`--prefix`, `--config`,
//! `--mode`, `--parent-pid`, CPU placement); asked `--describe` it says
//! it is the law `onnx-policy`. Before the run starts it refuses a run
//! whose arm, period, T_c, K1 or K2 are not the policy's training
//! scenario's, and warns on stderr (`nodes/controller.log`) about other
//! `[controller]` settings and a run longer than the policy's episode.
//! The law itself is `policy::PolicyLaw`; this file is the bus shell
//! around it, the loop of `examples/pd_controller.rs`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use bus::{NodeLink, RunPrefix, read_config};
use controller::node::{ControllerNodeConfig, ServeError, serve};
use policy::{Policy, PolicyLaw, check_run};
use run_stack::node::placement::Placement;
use wire::{Mode, NodeKind};

/// The law's name in the log, the summary and `replay`.
const NAME: &str = "onnx-policy";

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("testbed-policy: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// The command line: the policy file, then the launcher's node arguments.
struct Args {
    policy: PathBuf,
    describe: bool,
    prefix: Option<String>,
    config: Option<PathBuf>,
    mode: Option<String>,
    parent: Option<u32>,
    /// The launcher's CPU placement (`--cpus`, `--fifo`, `--lock-memory`),
    /// applied as its own nodes apply it.
    placement: Placement,
}

fn args() -> anyhow::Result<Args> {
    let mut a = Args {
        policy: PathBuf::new(),
        describe: false,
        prefix: None,
        config: None,
        mode: None,
        parent: None,
        placement: Placement::default(),
    };
    let mut it = std::env::args().skip(1);
    let mut policy = None;
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--describe" => a.describe = true,
            "--prefix" => a.prefix = it.next(),
            "--config" => a.config = it.next().map(PathBuf::from),
            "--mode" => a.mode = it.next(),
            "--parent-pid" => {
                let v = it.next().unwrap_or_default();
                a.parent = Some(v.parse().with_context(|| format!("--parent-pid {v}"))?);
            }
            "--cpus" => {
                let v = it.next().unwrap_or_default();
                a.placement.cpus = v
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()
                    .with_context(|| format!("--cpus {v}"))?;
            }
            "--fifo" => {
                let v = it.next().unwrap_or_default();
                a.placement.fifo = Some(v.parse().with_context(|| format!("--fifo {v}"))?);
            }
            "--lock-memory" => a.placement.lock_memory = true,
            "-h" | "--help" => {
                println!(
                    "usage: testbed-policy FILE.onnx  (run by testbed run/compare --controller-cmd)"
                );
                std::process::exit(0);
            }
            s if s.starts_with("--") => bail!("unknown option {s}"),
            s if policy.is_none() => policy = Some(PathBuf::from(s)),
            s => bail!("unexpected argument {s:?}: give one policy file"),
        }
    }
    a.policy = policy.context("no policy file: testbed-policy FILE.onnx")?;
    Ok(a)
}

fn run() -> anyhow::Result<()> {
    let a = args()?;
    // Loaded before answering --describe: a file that is not a policy is
    // refused before the run starts, naming the file.
    let policy = Policy::load(&a.policy)?;
    if a.describe {
        println!(r#"{{"name": "{NAME}", "params": {{}}}}"#);
        return Ok(());
    }
    let prefix = a
        .prefix
        .context("missing --prefix (run me through --controller-cmd)")?;
    let prefix = RunPrefix::parse(&prefix).map_err(|e| anyhow::anyhow!("{e}"))?;
    let config_path = a.config.context("missing --config")?;
    let mode: Mode = a
        .mode
        .context("missing --mode")?
        .parse()
        .map_err(|e: wire::UnknownMode| anyhow::anyhow!("{e}"))?;
    let config: ControllerNodeConfig =
        read_config(&config_path).with_context(|| format!("reading {}", config_path.display()))?;
    for note in check_run(policy.record(), &config)? {
        eprintln!("testbed-policy: warning: {note}");
    }
    for refused in a.placement.apply() {
        eprintln!("testbed-policy: warning: {refused}");
    }
    let steps = policy.record().steps;
    let mut law = PolicyLaw::new(policy, &config).context("the policy's base law")?;

    let mut link = NodeLink::connect(NodeKind::Controller, &prefix, a.parent, mode)?;
    let served = serve(&mut link, mode, config.reference_period(), |s, r| {
        if s.header.seq == steps {
            // Past its episode the time feature exceeds 1: never seen.
            eprintln!(
                "testbed-policy: warning: the run has passed the policy's episode of \
                 {steps} steps (env.steps); it acts on times it never saw"
            );
        }
        // A failed step publishes zero torque with the fault flag; the run
        // then stops with the reason, as a Python controller's exception does.
        law.step(s, r)
    });
    match served {
        Ok(()) => Ok(()),
        Err(ServeError::Node(e)) => Err(e.into()),
        Err(ServeError::Step(e)) => Err(e.into()),
    }
}
