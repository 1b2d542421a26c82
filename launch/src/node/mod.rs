//! The node processes: each is a thin shell that connects a pure library
//! (plant, trajectory, controller) to the bus.
//!
//! Every node follows the same protocol: create its ports, report READY on
//! the status topic, wait for START (which carries the wall-clock epoch of
//! step 0), run, report DONE, and exit when the launcher sends STOP. It also
//! exits by itself when its launcher disappears or a SIGINT/SIGTERM arrives.

pub mod controller;
pub mod logger;
pub mod placement;
pub mod plant;
pub mod trajectory;

use std::path::PathBuf;
use std::time::Duration;

use scenario::{Overrides, Plan};
use wire::{
    Bus, CONTROL_START, CONTROL_STOP, Control, Delivery, Header, NODE_DONE, NODE_READY,
    NODE_RUNNING, NodeKind, NodeStatus, RunPrefix, Topic, TopicPublisher, TopicSubscriber,
    WireError, monotonic_ns,
};

use crate::mode::Mode;

/// What every node is started with (`testbed node <name> …`).
#[derive(Debug, Clone, clap::Args)]
pub struct NodeArgs {
    /// The run's shared-memory prefix (the launcher prints it; a node started
    /// by hand must use the same one).
    #[arg(long)]
    pub prefix: String,
    /// The scenario file of the run.
    #[arg(long, value_name = "FILE")]
    pub scenario: PathBuf,
    /// Timing mode.
    #[arg(long, value_enum)]
    pub mode: Mode,
    /// Exit when this process (the launcher) is gone.
    #[arg(long, value_name = "PID")]
    pub parent_pid: Option<u32>,
    /// Logger only: the MCAP file to write.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Logger only: where the scenario originally came from (for the log's metadata).
    #[arg(long, value_name = "TEXT")]
    pub source: Option<String>,
    /// CPUs, scheduling and memory locking.
    #[command(flatten)]
    pub placement: placement::Placement,
}

/// Why a node stopped.
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// The bus failed.
    #[error(transparent)]
    Wire(#[from] WireError),
    /// The scenario could not be loaded.
    #[error(transparent)]
    Scenario(#[from] scenario::ScenarioError),
    /// The plant failed.
    #[error("plant: {0}")]
    Plant(#[from] plant_rapier::PlantError),
    /// The controller could not be built.
    #[error("controller: {0}")]
    Controller(#[from] ::controller::ControllerError),
    /// The launcher is gone.
    #[error("the launcher (pid {0}) is gone")]
    ParentGone(u32),
    /// The launcher sent STOP before the node finished.
    #[error("stopped by the launcher")]
    Stopped,
    /// Something arrived that the protocol does not allow.
    #[error("{0}")]
    Protocol(String),
}

/// Ports and state every node has.
pub struct NodeContext {
    pub(crate) bus: Bus,
    pub(crate) plan: Plan,
    pub(crate) mode: Mode,
    kind: NodeKind,
    status: TopicPublisher<NodeStatus>,
    control: TopicSubscriber<Control>,
    parent_pid: Option<u32>,
    status_seq: u64,
    stop_seen: bool,
}

impl NodeContext {
    /// Loads the scenario and connects to the run.
    pub fn new(kind: NodeKind, args: &NodeArgs) -> Result<Self, NodeError> {
        let plan = scenario::load(Some(&args.scenario), &Overrides::default())?;
        let prefix = RunPrefix::parse(&args.prefix)?;
        let bus = Bus::new(&prefix, kind.name())?;
        let status = bus.publisher(Topic::Status, Delivery::DropWhenFull)?;
        let control = bus.subscriber(Topic::Control)?;
        Ok(Self {
            bus,
            plan,
            mode: args.mode,
            kind,
            status,
            control,
            parent_pid: args.parent_pid,
            status_seq: 0,
            stop_seen: false,
        })
    }

    /// Publishes this node's state.
    pub fn report(&mut self, state: u32, step: u64) -> Result<(), NodeError> {
        let msg = NodeStatus {
            header: Header {
                seq: self.status_seq,
                t_ns: 0,
                wall_ns: monotonic_ns(),
            },
            node: self.kind as u32,
            state,
            pid: std::process::id(),
            reserved: 0,
            step,
        };
        self.status_seq += 1;
        self.status.send(msg)?;
        Ok(())
    }

    /// Errors if the launcher is gone, a termination signal arrived, or
    /// STOP was received.
    pub fn check(&mut self) -> Result<(), NodeError> {
        self.bus.wait(Duration::ZERO)?;
        if let Some(pid) = self.parent_pid
            && std::os::unix::process::parent_id() != pid
        {
            return Err(NodeError::ParentGone(pid));
        }
        while let Some(c) = self.control.receive()? {
            if c.command == CONTROL_STOP {
                self.stop_seen = true;
            }
        }
        if self.stop_seen {
            return Err(NodeError::Stopped);
        }
        Ok(())
    }

    /// Reports READY and blocks until START; returns the epoch of step 0.
    pub fn ready_and_wait_for_start(&mut self) -> Result<u64, NodeError> {
        self.report(NODE_READY, 0)?;
        let mut last_report = monotonic_ns();
        loop {
            self.control.wait_event(Duration::from_millis(50))?;
            self.control.drain_events()?;
            if let Some(c) = self.control.receive()? {
                match c.command {
                    CONTROL_START => {
                        self.report(NODE_RUNNING, 0)?;
                        return Ok(c.epoch_wall_ns);
                    }
                    CONTROL_STOP => return Err(NodeError::Stopped),
                    other => {
                        return Err(NodeError::Protocol(format!(
                            "unknown control command {other}"
                        )));
                    }
                }
            }
            self.check()?;
            // READY again now and then, in case the launcher connected late.
            if monotonic_ns() - last_report > 500_000_000 {
                self.report(NODE_READY, 0)?;
                last_report = monotonic_ns();
            }
        }
    }

    /// Reports DONE and waits for STOP (or the launcher's disappearance).
    pub fn done_and_wait_for_stop(&mut self, steps: u64) -> Result<(), NodeError> {
        self.report(NODE_DONE, steps)?;
        loop {
            match self.check() {
                Err(NodeError::Stopped) => return Ok(()),
                Err(e) => return Err(e),
                Ok(()) => {}
            }
            self.control.wait_event(Duration::from_millis(50))?;
            self.control.drain_events()?;
        }
    }
}

/// Runs node `kind` to completion.
pub fn run(kind: NodeKind, args: &NodeArgs) -> Result<(), NodeError> {
    for refused in args.placement.apply() {
        eprintln!("testbed node {}: warning: {refused}", kind.name());
    }
    let mut ctx = NodeContext::new(kind, args)?;
    let result = match kind {
        NodeKind::Plant => plant::run(&mut ctx),
        NodeKind::Controller => controller::run(&mut ctx),
        NodeKind::Trajectory => trajectory::run(&mut ctx),
        NodeKind::Logger => match &args.out {
            Some(out) => {
                let mut meta = logger_metadata(&ctx, out);
                if let Some(source) = &args.source {
                    meta.scenario_source = source.clone();
                }
                logger::run(&mut ctx, out, meta)
            }
            None => Err(NodeError::Protocol("the logger needs --out FILE".into())),
        },
    };
    match result {
        // STOP means the run is over (or was cut short by the launcher,
        // which then reports why): exit quietly.
        Err(NodeError::Stopped) => Ok(()),
        other => other,
    }
}

/// The `testbed.run` record: what the logger knows about the run.
fn logger_metadata(ctx: &NodeContext, out: &std::path::Path) -> crate::log::RunMetadata {
    let plan = &ctx.plan;
    crate::log::RunMetadata {
        run_id: out
            .parent()
            .and_then(|p| p.file_name())
            .map_or_else(String::new, |n| n.to_string_lossy().to_string()),
        mode: ctx.mode.as_str().to_string(),
        rate_hz: plan.scenario.rate_hz,
        scenario_toml: plan.toml.clone(),
        scenario_source: plan.source.clone(),
        robot: plan.robot.label(),
        joint_names: plan.robot.model.joint_names(),
        seed: plan.scenario.seed,
        plant_effects: plan.scenario.plant.configured_effects().names(),
        k1: gain_list(&plan.scenario.controller.k1, plan.robot.model.dof()),
        k2: gain_list(&plan.scenario.controller.k2, plan.robot.model.dof()),
        locked_joints: joint_roles(plan).0,
        mimic_joints: joint_roles(plan).1,
        urdf_dynamics: plan.scenario.plant.urdf_dynamics,
        start_time_unix_ns: std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64),
    }
}

/// `[a, b, …]`: a gain resolved for the arm's joints.
fn gain_list(g: &::controller::Gain, n: usize) -> String {
    let v = g.resolve("gain", n).unwrap_or_default();
    format!("{v:?}")
}

/// The locked and the mimic joints, as the log's metadata writes them.
fn joint_roles(plan: &Plan) -> (String, String) {
    let m = &plan.robot.model;
    let locked = m
        .locked
        .iter()
        .map(|l| match &l.follows {
            Some(f) => format!("{}={} (mimics {f})", l.name, l.position),
            None => format!("{}={}", l.name, l.position),
        })
        .collect::<Vec<_>>()
        .join(",");
    let mimic = m
        .mimic
        .iter()
        .map(|c| {
            format!(
                "{}={}*{}+{}",
                m.joints[c.joint].name, c.multiplier, m.joints[m.actuated[c.leader]].name, c.offset
            )
        })
        .collect::<Vec<_>>()
        .join(",");
    (locked, mimic)
}
