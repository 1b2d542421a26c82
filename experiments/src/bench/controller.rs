//! `testbed bench --controller-cmd CMD`: a user's controller node (a
//! Python controller, say) against the testbed's own, in real time at the
//! scenario's rate, one after the other in one bench run, each beside the
//! timer floor measured in its own window. Round trip, deadline misses and
//! compute time side by side say what the other language costs.

use serde::Serialize;

use crate::bench::parts::{load, realtime_part};
use crate::bench::types::{
    BenchError, BenchOptions, Machine, RealtimeFigures, TimerFloor, machine,
};
use analysis::timing::Percentiles;

/// One controller's real-time figures.
#[derive(Debug, Clone, Serialize)]
pub struct ControllerFigures {
    /// What ran as the controller node: "testbed" or the command.
    pub controller: String,
    /// The plant's view: misses, jitter, round trip.
    pub realtime: RealtimeFigures,
    /// The controller's own compute time per step, µs.
    pub compute_us: Percentiles,
    /// The bare sleep loop over the same window.
    pub timer_floor: TimerFloor,
}

/// The comparison.
#[derive(Debug, Clone, Serialize)]
pub struct ControllerBench {
    /// Where it ran.
    pub machine: Machine,
    /// The scenario.
    pub scenario: String,
    /// The law the testbed's controller ran (and whose parameters the
    /// command was given).
    pub law: String,
    /// Control rate, Hz.
    pub rate_hz: f64,
    /// Length of each real-time run, s.
    pub realtime_s: f64,
    /// Pairs measured (the testbed's controller, then the command, each time).
    pub pairs: usize,
    /// The testbed's controller node, pair by pair.
    pub testbed: Vec<ControllerFigures>,
    /// The command, pair by pair.
    pub command: Vec<ControllerFigures>,
}

/// Runs `opts.repeats` pairs on the paper scenario (or `opts.law` on it).
pub fn run(
    opts: &BenchOptions,
    command: &[String],
    mut progress: impl FnMut(&str),
) -> Result<ControllerBench, BenchError> {
    let plan = load(None, opts)?;
    let label = shell_words::join(command);
    let (mut testbed, mut external) = (Vec::new(), Vec::new());
    for pair in 1..=opts.repeats {
        for (cmd, out) in [(None, &mut testbed), (Some(command), &mut external)] {
            let who = cmd.map_or("testbed", |_| label.as_str()).to_string();
            progress(&format!(
                "pair {pair}: {who}, real time, {} s",
                opts.realtime_s
            ));
            let (realtime, timer_floor, compute_us) = realtime_part(&plan, opts, cmd)?;
            out.push(ControllerFigures {
                controller: who,
                realtime,
                compute_us,
                timer_floor,
            });
        }
    }
    Ok(ControllerBench {
        machine: machine(),
        scenario: plan.scenario.name.clone(),
        law: plan.scenario.controller.law.to_string(),
        rate_hz: plan.scenario.rate_hz,
        realtime_s: opts.realtime_s,
        pairs: opts.repeats,
        testbed,
        command: external,
    })
}
