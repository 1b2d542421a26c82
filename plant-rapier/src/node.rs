//! The plant process: the [`PlantMachine`] behind the bus. It is the clock
//! of the run: it publishes state k, applies a command, steps, publishes
//! state k+1. In lockstep it waits for each command; in real time it steps
//! on an absolute-deadline grid and holds the newest command it has.

use std::time::Duration;

use bus::clock;
use bus::{NodeError, NodeLink, TopicPublisher, TopicSubscriber, monotonic_ns};
use serde::{Deserialize, Serialize};
use wire::{Command, ContactState, JointState, Mode, NODE_RUNNING, Timing};

use crate::{ArmModel, PlantConfig, PlantError, PlantMachine, PlantMachineConfig};

/// Steps between progress reports on the status topic.
const PROGRESS_EVERY: u64 = 256;

/// What the launcher hands the plant node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantNodeConfig {
    /// The robot's label for messages (its path).
    pub robot: String,
    /// The URDF text.
    pub urdf: String,
    /// Plant settings (locks included).
    pub plant: PlantConfig,
    /// Seed of every random effect.
    pub seed: u64,
    /// Control period, ns.
    pub period_ns: u64,
    /// Steps in the run.
    pub steps: u64,
    /// q(0).
    pub initial_q: Vec<f64>,
    /// q̇(0).
    pub initial_qd: Vec<f64>,
}

impl PlantNodeConfig {
    /// The machine this config describes.
    pub fn machine(&self) -> Result<PlantMachine, PlantError> {
        PlantMachineConfig {
            model: ArmModel::from_urdf_str_locked(&self.urdf, &self.plant.lock)?,
            plant: self.plant.clone(),
            seed: self.seed,
            period_ns: self.period_ns,
            steps: self.steps,
            initial_q: self.initial_q.clone(),
            initial_qd: self.initial_qd.clone(),
        }
        .machine()
    }
}

/// Why the plant node stopped.
#[derive(Debug, thiserror::Error)]
pub enum PlantNodeError {
    /// The node protocol or the bus.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// The plant could not be built or stepped.
    #[error("plant ({robot}): {cause}")]
    Plant {
        /// The robot's label.
        robot: String,
        /// The cause.
        cause: PlantError,
    },
}

impl From<bus::BusError> for PlantNodeError {
    fn from(e: bus::BusError) -> Self {
        Self::Node(e.into())
    }
}

struct Ports {
    state: TopicPublisher<JointState>,
    timing: TopicPublisher<Timing>,
    command: TopicSubscriber<Command>,
    /// Opened only when the plant simulates contact.
    contact: Option<TopicPublisher<ContactState>>,
}

impl Ports {
    /// State k, and what contact did on the way to it when the plant has
    /// contact (sent first, so the logger has it when the state arrives).
    fn send_state(&self, m: &PlantMachine, state: JointState) -> Result<(), LoopError> {
        if let Some(p) = &self.contact
            && let Some(c) = m.contact(state.header.seq, state.header.wall_ns)
        {
            p.send(c)?;
        }
        self.state.send(state)?;
        Ok(())
    }
}

/// Runs the plant node to the end of the run.
pub fn run(
    link: &mut NodeLink,
    config: &PlantNodeConfig,
    mode: Mode,
) -> Result<(), PlantNodeError> {
    let plant_err = |cause| PlantNodeError::Plant {
        robot: config.robot.clone(),
        cause,
    };
    let mut m = config.machine().map_err(plant_err)?;
    let ports = Ports {
        state: link.bus.publisher(mode.delivery())?,
        timing: link.bus.publisher(mode.delivery())?,
        command: link.bus.subscriber()?,
        contact: match m.has_contact() {
            true => Some(link.bus.publisher(mode.delivery())?),
            false => None,
        },
    };
    let epoch = link.ready_and_wait_for_start()?;
    match mode {
        Mode::Lockstep => lockstep(link, &ports, &mut m).map_err(|e| e.with(&config.robot))?,
        Mode::Realtime => {
            realtime(link, &ports, &mut m, epoch).map_err(|e| e.with(&config.robot))?
        }
    }
    Ok(link.done_and_wait_for_stop(m.steps())?)
}

/// A loop's failure before the robot's label is attached.
enum LoopError {
    Node(NodeError),
    Plant(PlantError),
}

impl LoopError {
    fn with(self, robot: &str) -> PlantNodeError {
        match self {
            LoopError::Node(e) => PlantNodeError::Node(e),
            LoopError::Plant(cause) => PlantNodeError::Plant {
                robot: robot.to_string(),
                cause,
            },
        }
    }
}

impl From<NodeError> for LoopError {
    fn from(e: NodeError) -> Self {
        LoopError::Node(e)
    }
}

impl From<bus::BusError> for LoopError {
    fn from(e: bus::BusError) -> Self {
        LoopError::Node(e.into())
    }
}

impl From<PlantError> for LoopError {
    fn from(e: PlantError) -> Self {
        LoopError::Plant(e)
    }
}

fn lockstep(link: &mut NodeLink, ports: &Ports, m: &mut PlantMachine) -> Result<(), LoopError> {
    let mut state = m.state(0, monotonic_ns());
    ports.send_state(m, state)?;
    for k in 0..m.steps() {
        let cmd = wait_for_command(link, &ports.command, k)?;
        let taken_wall = monotonic_ns();
        m.step(Some(&cmd))?;
        ports.timing.send(Timing {
            header: wire::Header {
                seq: k,
                t_ns: state.header.t_ns,
                wall_ns: monotonic_ns(),
            },
            round_trip_ns: cmd.header.wall_ns as i64 - state.header.wall_ns as i64,
            controller_compute_ns: cmd.compute_ns as i64,
            floor_late_wakeups: wire::NONE_U64,
            ..Timing::default()
        })?;
        state = m.state(k + 1, monotonic_ns());
        state.applied_wall_ns = taken_wall;
        ports.send_state(m, state)?;
        if (k + 1) % PROGRESS_EVERY == 0 {
            link.report(NODE_RUNNING, k + 1)?;
            link.check()?;
        }
    }
    Ok(())
}

/// Blocks until the command answering state `k` arrives.
fn wait_for_command(
    link: &mut NodeLink,
    sub: &TopicSubscriber<Command>,
    k: u64,
) -> Result<Command, NodeError> {
    loop {
        while let Some(c) = sub.receive()? {
            if c.header.seq == k {
                return Ok(c);
            }
            if c.header.seq > k {
                return Err(NodeError::Protocol(format!(
                    "command for step {} arrived while waiting for step {k}",
                    c.header.seq
                )));
            }
        }
        // The launcher and the signals are checked when the wait times out
        // and every PROGRESS_EVERY steps, not on each wake-up: a check costs
        // syscalls on the critical path.
        // The wait takes every pending wake-up with it: no drain after it
        // (that cost a few syscalls per step).
        if !sub.wait_event(Duration::from_millis(100))? {
            link.check()?;
        }
    }
}

/// The newest command seen and the newest one taken, with when.
#[derive(Default)]
struct Held {
    latest: Option<Command>,
    taken_seq: Option<u64>,
    taken_wall_ns: u64,
}

fn realtime(
    link: &mut NodeLink,
    ports: &Ports,
    m: &mut PlantMachine,
    epoch: u64,
) -> Result<(), LoopError> {
    clock::tighten_timer_slack();
    // Started from this thread: the floor shares its CPU and priority.
    let floor = clock::TimerFloor::start(epoch, m.period_ns(), m.steps());
    clock::sleep_until(epoch);
    let mut state = m.state(0, monotonic_ns());
    ports.send_state(m, state)?;
    let mut last_wake = monotonic_ns();
    let mut held = Held::default();
    for k in 1..=m.steps() {
        let deadline = epoch + k * m.period_ns();
        clock::sleep_until(deadline);
        let wake = monotonic_ns();
        // Newest command wins; the one for step k−1 is on time.
        while let Some(c) = ports.command.receive()? {
            if held.latest.is_none_or(|l| c.header.seq >= l.header.seq) {
                held.latest = Some(c);
            }
        }
        let on_time = held.latest.filter(|c| c.header.seq == k - 1);
        let missed = on_time.is_none();
        if missed {
            m.misses += 1;
        }
        // A command not taken before goes to the actuators; without one
        // they hold the last (zero-order hold).
        let fresh = held
            .latest
            .filter(|c| held.taken_seq.is_none_or(|s| c.header.seq > s));
        if let Some(c) = fresh {
            held.taken_seq = Some(c.header.seq);
            held.taken_wall_ns = wake;
        }
        m.step(fresh.as_ref())?;
        ports.timing.send(Timing {
            header: wire::Header {
                seq: k - 1,
                t_ns: state.header.t_ns,
                wall_ns: wake,
            },
            wake_late_ns: wake as i64 - deadline as i64,
            period_ns: wake as i64 - last_wake as i64,
            round_trip_ns: on_time.map_or(-1, |c| {
                c.header.wall_ns as i64 - state.header.wall_ns as i64
            }),
            controller_compute_ns: on_time.map_or(-1, |c| c.compute_ns as i64),
            deadline_missed: u32::from(missed),
            reserved: 0,
            deadline_misses: m.misses,
            floor_late_wakeups: floor.late_wakeups().unwrap_or(wire::NONE_U64),
        })?;
        state = m.state(k, monotonic_ns());
        state.applied_wall_ns = held.taken_wall_ns;
        ports.send_state(m, state)?;
        last_wake = wake;
        if k % 32 == 0 {
            link.check()?;
        }
        if k % PROGRESS_EVERY == 0 {
            link.report(NODE_RUNNING, k)?;
        }
    }
    Ok(())
}
