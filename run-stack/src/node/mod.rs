//! `testbed node <role>`: one process of a run. The role's own crate holds
//! the node (`plant_rapier::node`, `trajectory::node`, `controller::node`,
//! `logger::node`); this shell sets up the process (CPU placement,
//! scheduling), connects it to the run and reads the config the launcher
//! wrote for it, then hands over.

pub mod configs;
pub mod placement;

use std::path::PathBuf;

use bus::{NodeError, NodeLink, RunPrefix, read_config};
use wire::NodeKind;

use crate::mode::Mode;

/// What every node is started with (`testbed node <name> …`).
#[derive(Debug, Clone, clap::Args)]
pub struct NodeArgs {
    /// The run's shared-memory prefix (the launcher prints it; a node started
    /// by hand must use the same one).
    #[arg(long)]
    pub prefix: String,
    /// The node's config, as the launcher wrote it (`runs/<id>/nodes/<name>.json`).
    #[arg(long, value_name = "FILE")]
    pub config: PathBuf,
    /// Timing mode: realtime or lockstep.
    #[arg(long, value_parser = crate::mode::parse)]
    pub mode: Mode,
    /// Exit when this process (the launcher) is gone.
    #[arg(long, value_name = "PID")]
    pub parent_pid: Option<u32>,
    /// CPUs, scheduling and memory locking.
    #[command(flatten)]
    pub placement: placement::Placement,
}

/// Why a node stopped.
#[derive(Debug, thiserror::Error)]
pub enum NodeRunError {
    /// The config file is missing or is not this node's.
    #[error(transparent)]
    Config(#[from] bus::ConfigError),
    /// The bus could not be joined.
    #[error(transparent)]
    Wire(#[from] bus::BusError),
    /// The plant node failed.
    #[error(transparent)]
    Plant(#[from] plant_rapier::node::PlantNodeError),
    /// The controller node failed.
    #[error(transparent)]
    Controller(#[from] controller::node::ControllerNodeError),
    /// The trajectory node failed.
    #[error(transparent)]
    Trajectory(#[from] trajectory::node::TrajectoryNodeError),
    /// The logger node failed.
    #[error(transparent)]
    Logger(#[from] logger::node::LoggerNodeError),
    /// The launcher was gone before the node started.
    #[error(transparent)]
    Node(#[from] NodeError),
}

impl NodeRunError {
    /// STOP from the launcher: the run is over (or was cut short by the
    /// launcher, which then reports why).
    fn is_stop(&self) -> bool {
        matches!(
            self,
            NodeRunError::Plant(plant_rapier::node::PlantNodeError::Node(NodeError::Stopped))
                | NodeRunError::Controller(controller::node::ControllerNodeError::Node(
                    NodeError::Stopped
                ))
                | NodeRunError::Trajectory(trajectory::node::TrajectoryNodeError::Node(
                    NodeError::Stopped
                ))
                | NodeRunError::Logger(logger::node::LoggerNodeError::Node(NodeError::Stopped))
        )
    }
}

/// Runs node `kind` to completion.
pub fn run(kind: NodeKind, args: &NodeArgs) -> Result<(), NodeRunError> {
    if let Some(parent) = args.parent_pid {
        // SIGTERM when the launcher dies, however it dies: the node then
        // stops as on Ctrl-C, even where its own checks would come late.
        // Not the logger: it notices by itself within 10 ms and must
        // finish the log, saying the launcher vanished.
        if kind != NodeKind::Logger {
            let _ = nix::sys::prctl::set_pdeathsig(nix::sys::signal::Signal::SIGTERM);
        }
        if nix::sys::signal::kill(nix::unistd::Pid::from_raw(parent as i32), None).is_err() {
            return Err(NodeError::ParentGone(parent).into());
        }
    }
    for refused in args.placement.apply() {
        eprintln!("testbed node {}: warning: {refused}", kind.name());
    }
    let prefix = RunPrefix::parse(&args.prefix)?;
    let mode = args.mode;
    let result = match kind {
        NodeKind::Plant => {
            let config = read_config(&args.config)?;
            let mut link = NodeLink::connect(kind, &prefix, args.parent_pid, args.mode)?;
            plant_rapier::node::run(&mut link, &config, mode).map_err(NodeRunError::from)
        }
        NodeKind::Controller => {
            let config = read_config(&args.config)?;
            let mut link = NodeLink::connect(kind, &prefix, args.parent_pid, args.mode)?;
            controller::node::run(&mut link, &config, mode).map_err(NodeRunError::from)
        }
        NodeKind::Trajectory => {
            let config = read_config(&args.config)?;
            let mut link = NodeLink::connect(kind, &prefix, args.parent_pid, args.mode)?;
            trajectory::node::run(&mut link, &config, mode).map_err(NodeRunError::from)
        }
        NodeKind::Logger => {
            let config = read_config(&args.config)?;
            let mut link = NodeLink::connect(kind, &prefix, args.parent_pid, args.mode)?;
            logger::node::run(&mut link, &config).map_err(NodeRunError::from)
        }
    };
    // A node started by hand may be the last of its domain (no launcher to
    // remove it): then it removes the domain, whichever way it ended.
    if args.parent_pid.is_none() {
        let _ = prefix.remove_domain_if_unused();
    }
    match result {
        Err(e) if e.is_stop() => Ok(()),
        other => other,
    }
}
