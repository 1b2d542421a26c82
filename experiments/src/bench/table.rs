//! What `testbed bench` prints as a table.

use std::fmt::Write;

use analysis::report::percentiles;

/// A readable bench report.
pub fn bench_table(b: &crate::bench::types::BenchReport) -> String {
    let mut out = String::new();
    let m = &b.machine;
    let _ = writeln!(
        out,
        "machine: {} ({} CPUs), kernel {}; medians of {} runs",
        m.cpu, m.cores, m.kernel, b.repeats
    );
    let _ = writeln!(
        out,
        "placement: {}",
        if b.realtime_setup {
            "plant and controller pinned to one CPU, SCHED_FIFO and locked memory in real time"
        } else {
            "left to the OS (--no-realtime-setup)"
        }
    );
    let _ = writeln!(
        out,
        "iceoryx2 ping-pong: {:.2} us a round trip (two processes, state out, command back; \
         {} rounds)",
        b.pingpong.round_trip_us, b.pingpong.rounds
    );
    for a in &b.arms {
        let _ = writeln!(
            out,
            "\n{} ({} joints, {} s sim):",
            a.scenario, a.dof, a.sim_s
        );
        let _ = writeln!(out, "  in process      {:8.3} s wall", a.inprocess_wall_s);
        let _ = writeln!(
            out,
            "  lockstep + log  {:8.3} s wall = {:.1}x real time, {:.2}x the in-process wall",
            a.lockstep_wall_s, a.lockstep_realtime_factor, a.lockstep_to_inprocess_ratio
        );
        let _ = writeln!(
            out,
            "  lockstep floor  {:8.3} s = steps x ping-pong + in process; lockstep is {:.2}x it",
            a.lockstep_floor_s, a.lockstep_to_floor_ratio
        );
        let _ = writeln!(
            out,
            "  per step        controller {:.2} us, plant {:.2} us",
            a.controller_step_us, a.plant_step_us
        );
        let r = &a.realtime;
        let _ = writeln!(
            out,
            "  real time       {} cycles, {} deadline misses, {} wake-ups late by a period, \
             {} samples dropped by the logger",
            r.cycles, r.deadline_misses, r.late_wakeups, r.logger_dropped
        );
        jitter_and_round_trip(&mut out, r);
        let f = &a.timer_floor;
        let _ = writeln!(
            out,
            "  timer floor     bare sleep loop beside it, same window, CPU and priority: \
             {} cycles, {} late by a whole period",
            f.cycles, f.deadline_misses
        );
        let _ = writeln!(
            out,
            "    period jitter us  {}",
            percentiles(&f.period_jitter_us)
        );
        for refused in &f.placement_refused {
            let _ = writeln!(out, "    refused: {refused}");
        }
        let rss: Vec<String> = a
            .peak_rss_kb
            .iter()
            .map(|(n, kb)| format!("{n} {:.1} MB", *kb as f64 / 1024.0))
            .collect();
        let _ = writeln!(out, "  peak memory     {}", rss.join(", "));
        let cpu: Vec<String> = (a.lockstep_node_cpu_s.iter())
            .map(|(n, s)| format!("{n} {s:.3} s"))
            .collect();
        let _ = writeln!(out, "  lockstep CPU    {}", cpu.join(", "));
    }
    out
}

/// A real-time run's period jitter and round trip, a line each.
fn jitter_and_round_trip(out: &mut String, r: &crate::bench::types::RealtimeFigures) {
    let _ = writeln!(
        out,
        "    period jitter us  {}",
        percentiles(&r.period_jitter_us)
    );
    let _ = writeln!(
        out,
        "    round trip us     {}",
        percentiles(&r.round_trip_us)
    );
}

/// The lockstep stack against the Python + MuJoCo loop, pair by pair.
pub fn peer_table(b: &crate::bench::peer::PeerBench) -> String {
    let mut s = format!(
        "{} scenario, {:.1} s simulated; Python + MuJoCo (RK4, {} substeps) against `testbed run --mode lockstep` (logger on)\n",
        b.scenario, b.sim_s, b.peer_substeps
    );
    let _ = writeln!(
        s,
        "{:<6} {:>14} {:>14} {:>8}",
        "pair", "lockstep, s", "Python, s", "ratio"
    );
    for (i, (l, p)) in b.lockstep_wall_s.iter().zip(&b.peer_wall_s).enumerate() {
        let _ = writeln!(s, "{:<6} {l:>14.3} {p:>14.3} {:>7.1}×", i + 1, p / l);
    }
    let _ = writeln!(
        s,
        "median ratio: {:.1}× (lockstep {:.0}× real time)",
        b.speedup,
        b.sim_s / crate::bench::types::median(b.lockstep_wall_s.clone())
    );
    let _ = writeln!(
        s,
        "max |q − q_d| after T_c: testbed {:?}, Python loop {:?} rad",
        b.testbed_max_error_after_tc, b.peer_max_error_after_tc
    );
    s
}

/// The two controllers' figures, pair by pair.
pub fn controller_table(b: &crate::bench::controller::ControllerBench) -> String {
    let mut out = String::new();
    let m = &b.machine;
    let _ = writeln!(
        out,
        "machine: {} ({} CPUs), kernel {}\n{} with law {} in real time at {} Hz, {} pair(s) of {} s runs",
        m.cpu, m.cores, m.kernel, b.scenario, b.law, b.rate_hz, b.pairs, b.realtime_s
    );
    for (i, pair) in b.testbed.iter().zip(&b.command).enumerate() {
        let _ = writeln!(out, "\npair {}:", i + 1);
        for c in [pair.0, pair.1] {
            let r = &c.realtime;
            let _ = writeln!(
                out,
                "  {}\n    {} cycles, {} deadline misses, {} wake-ups late by a period \
                 (timer floor beside it: {} late)",
                c.controller,
                r.cycles,
                r.deadline_misses,
                r.late_wakeups,
                c.timer_floor.deadline_misses
            );
            jitter_and_round_trip(&mut out, r);
            let _ = writeln!(out, "    compute us        {}", percentiles(&c.compute_us));
            let _ = writeln!(
                out,
                "    floor jitter us   {}",
                percentiles(&c.timer_floor.period_jitter_us)
            );
        }
    }
    out
}
