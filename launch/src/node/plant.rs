//! The plant process: the Rapier arm behind the bus. It is the clock of the
//! run: it publishes state k, applies a command, steps, publishes state k+1.

use std::time::Duration;

use plant_rapier::Rig;
use wire::{
    Command, Delivery, Header, JointState, MAX_DOF, NODE_RUNNING, STATE_FINAL, Timing, Topic,
    TopicPublisher, TopicSubscriber, joints, monotonic_ns,
};

use super::{NodeContext, NodeError};
use crate::clock;
use crate::mode::Mode;

/// Steps between progress reports on the status topic.
const PROGRESS_EVERY: u64 = 256;

struct Ports {
    state: TopicPublisher<JointState>,
    timing: TopicPublisher<Timing>,
    command: TopicSubscriber<Command>,
}

/// What the plant knows at each step.
struct Stepper {
    rig: Rig,
    n: usize,
    period_ns: u64,
    steps: u64,
    q: Vec<f64>,
    qd: Vec<f64>,
    q_meas: Vec<f64>,
    qd_meas: Vec<f64>,
    misses: u64,
}

impl Stepper {
    /// State k as published: the true state, the sensors' reading (drawn
    /// here, once per state) and the effects of the period that led to it.
    fn state_msg(&mut self, k: u64) -> JointState {
        self.rig.true_state_into(&mut self.q, &mut self.qd);
        self.rig.measure_into(&mut self.q_meas, &mut self.qd_meas);
        let first = k == 0;
        JointState {
            header: Header {
                seq: k,
                t_ns: k * self.period_ns,
                wall_ns: monotonic_ns(),
            },
            dof: self.n as u32,
            flags: if k == self.steps { STATE_FINAL } else { 0 },
            q: joints(&self.q),
            qd: joints(&self.qd),
            q_measured: joints(&self.q_meas),
            qd_measured: joints(&self.qd_meas),
            // What the plant really applied: the command after delay, loss
            // and saturation.
            tau_applied: if first {
                [0.0; MAX_DOF]
            } else {
                joints(self.rig.applied_torque())
            },
            disturbance: if first {
                [0.0; MAX_DOF]
            } else {
                joints(self.rig.disturbance())
            },
            effects: self.rig.effects().0,
            reserved: 0,
            deadline_misses: self.misses,
        }
    }

    /// Steps one period with `cmd` (None: no new command, the last is held);
    /// a command the plant cannot apply is a fault.
    fn step(&mut self, cmd: Option<&Command>) -> Result<(), NodeError> {
        if let Some(c) = cmd
            && c.dof as usize != self.n
        {
            return Err(NodeError::Protocol(format!(
                "command {} has {} joints, the arm {}",
                c.header.seq, c.dof, self.n
            )));
        }
        self.rig.step(cmd.map(|c| &c.tau[..self.n]))?;
        Ok(())
    }
}

/// Runs the plant node.
pub fn run(ctx: &mut NodeContext) -> Result<(), NodeError> {
    let plan = ctx.plan.clone();
    let s = &plan.scenario;
    let mut rig = Rig::new(&plan.robot.model, &s.plant, s.seed, plan.period_ns)?;
    rig.set_state(&s.initial.q, &s.initial.qd)?;
    let n = rig.dof();
    let delivery = match ctx.mode {
        Mode::Lockstep => Delivery::Lossless,
        Mode::Realtime => Delivery::DropWhenFull,
    };
    let ports = Ports {
        state: ctx.bus.publisher(Topic::JointState, delivery)?,
        timing: ctx.bus.publisher(Topic::Timing, delivery)?,
        command: ctx.bus.subscriber(Topic::Command)?,
    };
    let mut st = Stepper {
        rig,
        n,
        period_ns: plan.period_ns,
        steps: plan.steps,
        q: vec![0.0; n],
        qd: vec![0.0; n],
        q_meas: vec![0.0; n],
        qd_meas: vec![0.0; n],
        misses: 0,
    };
    let epoch = ctx.ready_and_wait_for_start()?;
    match ctx.mode {
        Mode::Lockstep => lockstep(ctx, &ports, &mut st)?,
        Mode::Realtime => realtime(ctx, &ports, &mut st, epoch)?,
    }
    ctx.done_and_wait_for_stop(st.steps)
}

fn lockstep(ctx: &mut NodeContext, ports: &Ports, st: &mut Stepper) -> Result<(), NodeError> {
    let mut state = st.state_msg(0);
    ports.state.send(state)?;
    for k in 0..st.steps {
        let cmd = wait_for_command(ctx, &ports.command, k)?;
        st.step(Some(&cmd))?;
        ports.timing.send(Timing {
            header: Header {
                seq: k,
                t_ns: state.header.t_ns,
                wall_ns: monotonic_ns(),
            },
            round_trip_ns: cmd.header.wall_ns as i64 - state.header.wall_ns as i64,
            controller_compute_ns: cmd.compute_ns as i64,
            ..Timing::default()
        })?;
        state = st.state_msg(k + 1);
        ports.state.send(state)?;
        if (k + 1) % PROGRESS_EVERY == 0 {
            ctx.report(NODE_RUNNING, k + 1)?;
            ctx.check()?;
        }
    }
    Ok(())
}

/// Blocks until the command answering state `k` arrives.
fn wait_for_command(
    ctx: &mut NodeContext,
    sub: &wire::TopicSubscriber<Command>,
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
        if !sub.wait_event(Duration::from_millis(100))? {
            ctx.check()?;
        }
        sub.drain_events()?;
    }
}

fn realtime(
    ctx: &mut NodeContext,
    ports: &Ports,
    st: &mut Stepper,
    epoch: u64,
) -> Result<(), NodeError> {
    clock::tighten_timer_slack();
    clock::sleep_until(epoch);
    let mut state = st.state_msg(0);
    ports.state.send(state)?;
    let mut last_wake = monotonic_ns();
    let mut latest: Option<Command> = None;
    let mut taken_seq: Option<u64> = None;
    for k in 1..=st.steps {
        let deadline = epoch + k * st.period_ns;
        clock::sleep_until(deadline);
        let wake = monotonic_ns();
        // Newest command wins; the one for step k−1 is on time.
        while let Some(c) = ports.command.receive()? {
            if latest.is_none_or(|l| c.header.seq >= l.header.seq) {
                latest = Some(c);
            }
        }
        let on_time = latest.filter(|c| c.header.seq == k - 1);
        let missed = on_time.is_none();
        if missed {
            st.misses += 1;
        }
        // A command not taken before goes to the actuators; without one
        // they hold the last (zero-order hold).
        let fresh = latest.filter(|c| taken_seq.is_none_or(|s| c.header.seq > s));
        if let Some(c) = fresh {
            taken_seq = Some(c.header.seq);
        }
        st.step(fresh.as_ref())?;
        ports.timing.send(Timing {
            header: Header {
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
            deadline_misses: st.misses,
        })?;
        state = st.state_msg(k);
        ports.state.send(state)?;
        last_wake = wake;
        if k % 32 == 0 {
            ctx.check()?;
        }
        if k % PROGRESS_EVERY == 0 {
            ctx.report(NODE_RUNNING, k)?;
        }
    }
    Ok(())
}
