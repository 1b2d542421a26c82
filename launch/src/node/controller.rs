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
            let t_ref = plan.reference_t_ns(t_ns);
            plan.reference.sample_into(ns_to_s(t_ref), &mut self.buf);
            return Ok(true);
        };
        while let Some(r) = sub.receive()? {
            recent.push(r);
        }
        let Some(r) = pick_reference(recent, t_ns) else {
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

/// The newest sample at or before `t_ns`, dropping the older ones. Samples
/// after `t_ns` are kept: when the plant runs late, the trajectory's timer is
/// ahead of it and those samples are needed for the next states.
fn pick_reference(recent: &mut Vec<ReferenceSample>, t_ns: u64) -> Option<ReferenceSample> {
    recent.sort_by_key(|r| r.header.t_ns);
    let i = recent.iter().rposition(|r| r.header.t_ns <= t_ns)?;
    let r = recent[i];
    recent.drain(..i);
    Some(r)
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
                    q: &s.q_measured[..n],
                    qd: &s.qd_measured[..n],
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
        // Checked on a timeout and every 256 states, not on every wake-up.
        if !states.wait_event(Duration::from_millis(100))? || handled.is_multiple_of(256) {
            ctx.check()?;
        }
        states.drain_events()?;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t_ns: u64) -> ReferenceSample {
        ReferenceSample {
            header: Header {
                seq: t_ns,
                t_ns,
                wall_ns: 0,
            },
            dof: 1,
            reserved: 0,
            q_d: [0.0; wire::MAX_DOF],
            qd_d: [0.0; wire::MAX_DOF],
            qdd_d: [0.0; wire::MAX_DOF],
            kc: [1.0; wire::MAX_DOF],
            kc_dot: [0.0; wire::MAX_DOF],
        }
    }

    #[test]
    fn newest_sample_not_after_the_state_wins() {
        let mut recent: Vec<_> = [3, 1, 2, 5].map(sample).to_vec();
        assert_eq!(pick_reference(&mut recent, 4).unwrap().header.t_ns, 3);
        assert_eq!(
            recent.iter().map(|r| r.header.t_ns).collect::<Vec<_>>(),
            [3, 5]
        );
        assert!(pick_reference(&mut vec![sample(7)], 6).is_none());
    }

    /// Regression: with the plant 20 periods behind the trajectory, the
    /// controller once kept only the newest 8 samples, all later than the
    /// state, and faulted with no reference.
    #[test]
    fn reference_is_found_when_the_plant_runs_late() {
        let mut recent: Vec<_> = (0..40).map(sample).collect();
        for k in 0..40 {
            assert_eq!(pick_reference(&mut recent, k).unwrap().header.t_ns, k);
        }
    }
}
