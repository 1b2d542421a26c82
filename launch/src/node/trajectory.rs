//! The trajectory process: publishes q_d, q̇_d, q̈_d, k_c and k̇_c.
//!
//! In real time it runs on its own absolute-deadline timer from the epoch
//! the launcher gives, one period ahead of the plant, so the sample for t_k
//! is there when state k arrives. In lockstep it follows the plant in
//! batches (every 10 ms) and is never on the critical path: the controller
//! evaluates the same pure function itself.

use std::time::Duration;

use scenario::ns_to_s;
use trajectory::ReferenceSample as RefBuf;
use wire::{
    Delivery, Header, JointState, ReferenceSample, Topic, TopicPublisher, joints, monotonic_ns,
};

use super::{NodeContext, NodeError};
use crate::clock;
use crate::mode::Mode;

/// Runs the trajectory node.
pub fn run(ctx: &mut NodeContext) -> Result<(), NodeError> {
    let plan = ctx.plan.clone();
    let n = plan.robot.model.dof();
    let delivery = match ctx.mode {
        Mode::Lockstep => Delivery::Lossless,
        Mode::Realtime => Delivery::DropWhenFull,
    };
    let out = ctx
        .bus
        .publisher::<ReferenceSample>(Topic::Reference, delivery)?;
    let states = match ctx.mode {
        Mode::Lockstep => Some(
            ctx.bus
                .polling_subscriber::<JointState>(Topic::JointState)?,
        ),
        Mode::Realtime => None,
    };
    let mut buf = RefBuf::new(n);
    // Sample j describes t_j = j × the reference period (the control period
    // unless the scenario sets `reference.rate_hz`).
    let ref_period = plan.reference_period_ns;
    let mut publish = |j: u64| -> Result<(), NodeError> {
        let t_ns = j * ref_period;
        plan.reference.sample_into(ns_to_s(t_ns), &mut buf);
        send(&out, &buf, j, t_ns)
    };
    let epoch = ctx.ready_and_wait_for_start()?;
    let end_ns = plan.t_ns(plan.steps);
    let last = end_ns / ref_period; // samples for t_0 … the end of the run
    match states {
        None => {
            clock::tighten_timer_slack();
            publish(0)?;
            for j in 1..=last {
                // Each sample goes out one control period before its time.
                let due = (j * ref_period).saturating_sub(plan.period_ns);
                clock::sleep_until(epoch + due);
                publish(j)?;
                if j % 32 == 0 {
                    ctx.check()?;
                }
            }
        }
        Some(states) => {
            let mut next = 0u64;
            while next <= last {
                let mut newest = None;
                while let Some(s) = states.receive()? {
                    newest = Some(s.header.t_ns);
                }
                states.drain_events()?;
                if let Some(t_ns) = newest {
                    while next <= last && next * ref_period <= t_ns {
                        publish(next)?;
                        next += 1;
                    }
                }
                if next <= last {
                    ctx.bus.wait(Duration::from_millis(10))?;
                    ctx.check()?;
                }
            }
        }
    }
    ctx.done_and_wait_for_stop(last + 1)
}

fn send(
    out: &TopicPublisher<ReferenceSample>,
    r: &RefBuf,
    seq: u64,
    t_ns: u64,
) -> Result<(), NodeError> {
    out.send(ReferenceSample {
        header: Header {
            seq,
            t_ns,
            wall_ns: monotonic_ns(),
        },
        dof: r.q_d.len() as u32,
        reserved: 0,
        q_d: joints(&r.q_d),
        qd_d: joints(&r.qd_d),
        qdd_d: joints(&r.qdd_d),
        kc: joints(&r.kc),
        kc_dot: joints(&r.kc_dot),
    })?;
    Ok(())
}
