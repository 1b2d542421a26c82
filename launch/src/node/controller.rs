//! The controller process: the paper's law behind the bus. It wakes on each
//! joint state, computes the torque, and publishes the command and the
//! diagnostics of that step.

use std::time::{Duration, Instant};

use controller::{Controller, ControllerInput, Diagnostics};
use scenario::ns_to_s;
use trajectory::ReferenceSample as RefBuf;
use wire::{
    Command, ControllerDiagnostics, Delivery, Header, JointState, ReferenceSample, STATE_FINAL,
    Topic, TopicSubscriber, joints, monotonic_ns,
};

use super::{NodeContext, NodeError};
use crate::mode::Mode;

/// Where the reference comes from.
///
/// Lockstep: the reference is a pure function of time, evaluated here so
/// that the trajectory process stays off the critical path. Real time: the
/// samples the trajectory process publishes on its own timer; the newest one
/// not later than the state is used.
struct RefSource {
    buf: RefBuf,
    topic: Option<(TopicSubscriber<ReferenceSample>, Vec<ReferenceSample>)>,
}

impl RefSource {
    /// Fills the reference for sim time `t_ns`; false if none is available.
    fn fill(&mut self, plan: &scenario::Plan, t_ns: u64) -> Result<bool, NodeError> {
        let Some((sub, recent)) = self.topic.as_mut() else {
            plan.reference.sample_into(ns_to_s(t_ns), &mut self.buf);
            return Ok(true);
        };
        while let Some(r) = sub.receive()? {
            recent.push(r);
        }
        // Keep a short history: the newest sample at or before t wins.
        recent.sort_by_key(|r| r.header.t_ns);
        let pick = recent.iter().rev().find(|r| r.header.t_ns <= t_ns).copied();
        let keep_from = recent.len().saturating_sub(8);
        recent.drain(..keep_from);
        let Some(r) = pick else {
            return Ok(false);
        };
        let b = &mut self.buf;
        let n = b.q_d.len();
        b.t = ns_to_s(r.header.t_ns);
        b.q_d.copy_from_slice(&r.q_d[..n]);
        b.qd_d.copy_from_slice(&r.qd_d[..n]);
        b.qdd_d.copy_from_slice(&r.qdd_d[..n]);
        b.kc.copy_from_slice(&r.kc[..n]);
        b.kc_dot.copy_from_slice(&r.kc_dot[..n]);
        Ok(true)
    }
}

/// Runs the controller node.
pub fn run(ctx: &mut NodeContext) -> Result<(), NodeError> {
    let plan = ctx.plan.clone();
    let n = plan.robot.model.dof();
    let mut law = Controller::new(plan.scenario.controller.clone(), n)?;
    let mut diag = law.diagnostics();
    let delivery = match ctx.mode {
        Mode::Lockstep => Delivery::Lossless,
        Mode::Realtime => Delivery::DropWhenFull,
    };
    let states = ctx.bus.subscriber::<JointState>(Topic::JointState)?;
    let commands = ctx.bus.publisher::<Command>(Topic::Command, delivery)?;
    let diagnostics = ctx
        .bus
        .publisher::<ControllerDiagnostics>(Topic::Diagnostics, delivery)?;
    let mut reference = RefSource {
        buf: RefBuf::new(n),
        topic: match ctx.mode {
            Mode::Lockstep => None,
            Mode::Realtime => Some((
                ctx.bus.subscriber(Topic::Reference)?,
                Vec::with_capacity(64),
            )),
        },
    };
    let dt = plan.dt();
    ctx.ready_and_wait_for_start()?;

    let mut handled = 0u64;
    loop {
        let mut finished = false;
        while let Some(s) = states.receive()? {
            if s.flags & STATE_FINAL != 0 {
                finished = true;
                continue;
            }
            let started = Instant::now();
            if reference.fill(&plan, s.header.t_ns)? {
                let r = &reference.buf;
                let input = ControllerInput {
                    t: ns_to_s(s.header.t_ns),
                    q: &s.q[..n],
                    qd: &s.qd[..n],
                    q_d: &r.q_d,
                    qd_d: &r.qd_d,
                    kc: &r.kc,
                    kc_dot: &r.kc_dot,
                };
                law.step(dt, &input, &mut diag);
            } else {
                no_reference(&mut diag);
            }
            let compute_ns = started.elapsed().as_nanos() as u64;
            let header = Header {
                seq: s.header.seq,
                t_ns: s.header.t_ns,
                wall_ns: monotonic_ns(),
            };
            commands.send(Command {
                header,
                dof: n as u32,
                fault: diag.fault.map_or(0, |f| f.code()),
                tau: joints(&diag.tau),
                state_wall_ns: s.header.wall_ns,
                compute_ns,
            })?;
            diagnostics.send(diag_msg(header, &diag, &reference.buf, compute_ns))?;
            handled += 1;
        }
        if finished {
            break;
        }
        states.wait_event(Duration::from_millis(100))?;
        states.drain_events()?;
        ctx.check()?;
    }
    ctx.done_and_wait_for_stop(handled)
}

/// No reference sample yet (real time, before the trajectory's first one
/// arrived): publish zero torque with a fault, as for any unusable input.
fn no_reference(diag: &mut Diagnostics) {
    diag.fault = Some(::controller::Fault::NoReference);
    diag.tau.iter_mut().for_each(|x| *x = 0.0);
}

fn diag_msg(header: Header, d: &Diagnostics, r: &RefBuf, compute_ns: u64) -> ControllerDiagnostics {
    ControllerDiagnostics {
        header,
        dof: d.tau.len() as u32,
        fault: d.fault.map_or(0, |f| f.code()),
        barrier_breached: u32::from(d.barrier_breached),
        reserved: 0,
        compute_ns,
        gamma: d.gamma,
        gamma_dot: d.gamma_dot,
        j_hat: d.j_hat,
        delta: d.delta,
        r: d.r,
        wc_norm: d.wc_norm,
        q_d: joints(&r.q_d),
        qd_d: joints(&r.qd_d),
        kc_in: joints(&r.kc),
        kc_dot: joints(&r.kc_dot),
        z1: joints(&d.z1),
        z1g: joints(&d.z1g),
        z2: joints(&d.z2),
        alpha: joints(&d.alpha),
        kc: joints(&d.kc),
        d: joints(&d.d),
        tau: joints(&d.tau),
        tau_actor: joints(&d.tau_actor),
        tau_feedback: joints(&d.tau_feedback),
        tau_barrier: joints(&d.tau_barrier),
        wa_norm: joints(&d.wa_norm),
    }
}
