//! Replace the controller node: a PD law on the same topics.
//!
//! `testbed run --external controller` prints the command it waits for;
//! start this binary with the same arguments instead:
//!
//! ```sh
//! testbed run --mode lockstep --external controller &
//! example-pd-controller --prefix … --config runs/<id>/nodes/controller.json --mode lockstep
//! ```
//!
//! It reads the controller's config (joints, period), follows the node
//! protocol (`bus::NodeLink`), and for every joint state publishes a
//! command τ = −Kp (q − q_d) − Kd (q̇ − q̇_d) and the diagnostics the log
//! and the summary are made from. Other arguments the launcher adds (CPU
//! placement) are ignored.
//!
//! Its loop is written out on purpose: it shows an author outside the
//! workspace the whole protocol (the timing stamps, the stale-reference
//! count, checking in every 256 states). Inside the workspace a law
//! serves through `controller::node::serve`, which owns that loop.
//!
//! It is also a law of its own for `testbed run --controller-cmd`: asked
//! `--describe`, it declares its name, its parameters (`kp`, `kd`), which
//! the scenario's `[external]` table may set, and a diagnostic of its own,
//! `error_norm` = ‖q − q_d‖, published on the own-diagnostics topic when
//! the launcher asks for it (docs/python.md explains the declaration; it
//! is the same for any language). As a member of the
//! workspace it builds with the testbed, reusing its build:
//! `cargo build --release --bin example-pd-controller`.

use std::process::ExitCode;
use std::time::Duration;

use bus::{NodeLink, ReferenceWindow, RunPrefix, monotonic_ns, read_config};
use controller::node::ControllerNodeConfig;
use wire::{
    Command, ControllerDiagnostics, JointState, Mode, NodeKind, OwnDiagnostics, STATE_FINAL,
};

/// The declared defaults of the law's own parameters.
const KP: f64 = 400.0;
const KD: f64 = 40.0;

fn main() -> ExitCode {
    if std::env::args().skip(1).eq(["--describe"]) {
        println!(
            r#"{{"name": "pd-example", "params": {{"kp": {KP:?}, "kd": {KD:?}}},
                "diagnostics": {{"error_norm": "scalar"}}}}"#
        );
        return ExitCode::SUCCESS;
    }
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("example-pd-controller: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `--prefix`, `--config` and `--mode` from the command line.
fn args() -> Result<(RunPrefix, std::path::PathBuf, Mode), String> {
    let argv: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        argv.iter()
            .position(|a| a == flag)
            .and_then(|i| argv.get(i + 1))
            .cloned()
            .ok_or(format!("missing {flag}"))
    };
    let prefix = RunPrefix::parse(&value("--prefix")?).map_err(|e| e.to_string())?;
    Ok((
        prefix,
        value("--config")?.into(),
        value("--mode")?
            .parse()
            .map_err(|e: wire::UnknownMode| e.to_string())?,
    ))
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let (prefix, config, mode) = args()?;
    let config: ControllerNodeConfig = read_config(&config)?;
    let n = config.dof;
    // The launcher's values for the declared parameters (defaults when it
    // ran this binary by hand, with --external).
    let own = |key: &str, default: f64| {
        config
            .own_params
            .get(key)
            .and_then(|v| v.as_f64())
            .unwrap_or(default)
    };
    let (kp, kd) = (own("kp", KP), own("kd", KD));
    let mut link = NodeLink::connect(NodeKind::Controller, &prefix, None, mode)?;
    let states = link.bus.subscriber::<JointState>()?;
    let mut references = ReferenceWindow::new(&link, mode, config.reference_period())?;
    let commands = link.bus.publisher::<Command>(mode.delivery())?;
    let diagnostics = link
        .bus
        .publisher::<ControllerDiagnostics>(mode.delivery())?;
    // Its own diagnostic, only when the launcher laid it out (a run by
    // hand with --external declared nothing, and the log expects nothing).
    let own = if config.own_diagnostics == "error_norm:scalar" {
        Some(link.bus.publisher::<OwnDiagnostics>(mode.delivery())?)
    } else {
        None
    };
    link.ready_and_wait_for_start()?;
    let mut handled = 0;
    'run: loop {
        while let Some(s) = states.receive()? {
            if s.flags & STATE_FINAL != 0 {
                break 'run;
            }
            // The same rule as the testbed's controller: the newest sample
            // at or before the state, final in lockstep.
            let started_wall_ns = monotonic_ns();
            let r = references.take(&mut link, s.header.t_ns)?;
            let reference_t_ns = r.map_or(wire::NONE_U64, |r| r.header.t_ns);
            let r = r.unwrap_or_default();
            let mut d = ControllerDiagnostics {
                header: s.header,
                dof: n as u32,
                q_d: r.q_d,
                qd_d: r.qd_d,
                kc_in: r.kc,
                kc_dot: r.kc_dot,
                kc: r.kc,
                ..ControllerDiagnostics::default()
            };
            for i in 0..n {
                d.z1[i] = s.q_measured[i] - r.q_d[i];
                d.z1g[i] = d.z1[i];
                d.z2[i] = s.qd_measured[i] - r.qd_d[i];
                d.tau[i] = -kp * d.z1[i] - kd * d.z2[i];
                d.tau_feedback[i] = d.tau[i];
            }
            d.header.wall_ns = monotonic_ns();
            commands.send(Command {
                header: d.header,
                dof: n as u32,
                fault: 0,
                tau: d.tau,
                state_wall_ns: s.header.wall_ns,
                compute_ns: 0,
                started_wall_ns,
                reference_t_ns,
                stale_references: references.stale_count(),
            })?;
            diagnostics.send(d)?;
            if let Some(own) = &own {
                let mut o = OwnDiagnostics {
                    header: d.header,
                    count: 1,
                    ..OwnDiagnostics::default()
                };
                o.values[0] = d.z1[..n].iter().map(|e| e * e).sum::<f64>().sqrt();
                own.send(o)?;
            }
            handled += 1;
            // The launcher and STOP are checked every 256 states and on a
            // timeout: the check also sends the heartbeat the launcher expects.
            if handled % 256 == 0 {
                link.check()?;
            }
        }
        if !states.wait_event(Duration::from_millis(100))? {
            link.check()?;
        }
        states.drain_events()?;
    }
    link.done_and_wait_for_stop(handled)?;
    Ok(())
}
