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
