//! The floor of any lockstep over events: two processes bouncing a joint
//! state and a command over iceoryx2, with the same topics, buffers,
//! lossless delivery and event wake-ups as the plant and the controller,
//! and nothing else (no physics, no law, no logger, no reference). A
//! lockstep step is one such round trip plus the step's own work, so
//! `steps × round trip + the in-process loop's time` is as fast as any
//! lockstep stack on this machine can go; `bench` reports lockstep's ratio
//! to it.
//!
//! The other process is the `testbed` binary itself (`testbed bench-pong`,
//! hidden from the help), so nothing else needs building. Placed as
//! lockstep places the plant and the controller (both on the loop's CPU),
//! unless the bench runs with `--no-realtime-setup`.

use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use bus::{Bus, RunPrefix};
use wire::{Command, Delivery, JointState, STATE_FINAL};

use crate::bench::types::{BenchError, PingPong};
use run_stack::mode::Mode;
use run_stack::node::placement::{self, Placement};
use wire::NodeKind;

/// The hidden subcommand the other process runs.
pub const PONG_COMMAND: &str = "bench-pong";

/// How long either side waits for the other before giving up.
const PATIENCE: Duration = Duration::from_secs(10);

fn err(what: impl std::fmt::Display) -> BenchError {
    BenchError::PingPong(what.to_string())
}

/// Waits for the command answering `seq`.
fn answer(
    commands: &bus::TopicSubscriber<Command>,
    seq: u64,
    pong: &mut Child,
) -> Result<(), BenchError> {
    let start = Instant::now();
    loop {
        while let Some(c) = commands.receive().map_err(err)? {
            if c.header.seq == seq {
                return Ok(());
            }
        }
        if start.elapsed() > PATIENCE || pong.try_wait().map_err(err)?.is_some() {
            return Err(err(format!("no answer to round {seq}")));
        }
        commands
            .wait_event(Duration::from_millis(100))
            .map_err(err)?;
    }
}

/// Where lockstep puts `kind` (nowhere in particular without `pinned`).
fn lockstep_placement(kind: NodeKind, pinned: bool) -> Placement {
    if pinned {
        placement::for_node(kind, Mode::Lockstep, placement::cpu_count())
    } else {
        Placement::default()
    }
}

/// One ping-pong of `rounds` timed round trips on a thread of its own
/// (placed as lockstep's plant): µs per round trip.
fn once(rounds: u64, pinned: bool) -> Result<f64, BenchError> {
    std::thread::scope(|s| {
        s.spawn(|| {
            // What the system refuses only makes the floor less like
            // lockstep's; the figures are still a floor.
            let _ = lockstep_placement(NodeKind::Plant, pinned).apply();
            ping(rounds, pinned)
        })
        .join()
        .unwrap_or_else(|_| Err(err("the ping thread panicked")))
    })
}

fn ping(rounds: u64, pinned: bool) -> Result<f64, BenchError> {
    let prefix = RunPrefix::unique();
    let bus = Bus::new(&prefix, "bench-ping").map_err(err)?;
    let states = bus
        .publisher::<JointState>(Delivery::Lossless)
        .map_err(err)?;
    let commands = bus.subscriber::<Command>().map_err(err)?;
    let exe = std::env::current_exe().map_err(err)?;
    let mut pong = std::process::Command::new(exe)
        .args([PONG_COMMAND, "--prefix", prefix.as_str()])
        .args(lockstep_placement(NodeKind::Controller, pinned).to_args())
        .stdin(Stdio::null())
        .spawn()
        .map_err(err)?;
    let result = (|| {
        // Round 0 connects: sent until the other side has subscribed.
        let start = Instant::now();
        let mut s = JointState {
            dof: 2,
            ..JointState::default()
        };
        while states.send(s).map_err(err)? == 0 {
            if start.elapsed() > PATIENCE || pong.try_wait().map_err(err)?.is_some() {
                return Err(err("the other process never subscribed"));
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        answer(&commands, 0, &mut pong)?;
        let start = Instant::now();
        for k in 1..=rounds {
            s.header.seq = k;
            s.header.wall_ns = bus::monotonic_ns();
            states.send(s).map_err(err)?;
            answer(&commands, k, &mut pong)?;
        }
        let per_round = start.elapsed().as_secs_f64() / rounds.max(1) as f64;
        s.flags = STATE_FINAL;
        s.header.seq = rounds + 1;
        states.send(s).map_err(err)?;
        Ok(per_round * 1e6)
    })();
    if result.is_err() {
        let _ = pong.kill();
    }
    let status = pong.wait().map_err(err)?;
    let us = result?;
    if !status.success() {
        return Err(err(format!("the other process ended with {status}")));
    }
    Ok(us)
}

/// The median of `repeats` ping-pongs of `rounds` round trips each, both
/// sides placed as lockstep's plant and controller if `pinned`.
pub fn measure(rounds: u64, repeats: usize, pinned: bool) -> Result<PingPong, BenchError> {
    let mut us = Vec::new();
    for _ in 0..repeats.max(1) {
        us.push(once(rounds, pinned)?);
    }
    Ok(PingPong {
        rounds,
        round_trip_us: crate::bench::types::median(us),
    })
}

/// The other process: answers every joint state with a command of the same
/// header until the final one.
pub fn pong(prefix: &str, placement: &Placement) -> anyhow::Result<()> {
    let _ = placement.apply();
    let prefix = RunPrefix::parse(prefix)?;
    let bus = Bus::new(&prefix, "bench-pong")?;
    let states = bus.subscriber::<JointState>()?;
    let commands = bus.publisher::<Command>(Delivery::Lossless)?;
    let mut last = Instant::now();
    loop {
        while let Some(s) = states.receive()? {
            if s.flags & STATE_FINAL != 0 {
                return Ok(());
            }
            commands.send(Command {
                header: s.header,
                dof: s.dof,
                ..Command::default()
            })?;
            last = Instant::now();
        }
        if last.elapsed() > PATIENCE {
            anyhow::bail!("bench-pong: no joint state for {} s", PATIENCE.as_secs());
        }
        states.wait_event(Duration::from_millis(100))?;
    }
}
