//! `testbed robot PATH`: what the testbed makes of an arm.

use std::fmt::Write;
use std::path::Path;

use anyhow::Result;
use scenario::{RobotSource, Scenario};

/// A readable description of the arm at `path`, or the reason it cannot be used.
pub fn describe(path: &Path) -> Result<String> {
    let robot = RobotSource::from_file(path)?;
    let m = &robot.model;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "robot '{}' ({}): {} actuated joints",
        m.name,
        path.display(),
        m.dof()
    );
    let _ = writeln!(out, "\njoint order (q, q̇ and τ index):");
    let _ = writeln!(
        out,
        "  {:>2}  {:<24} {:<11} {:<22} {:<22} {:>10}",
        "i", "joint", "type", "axis", "limits", "effort"
    );
    for (i, &ji) in m.actuated.iter().enumerate() {
        let j = &m.joints[ji];
        let axis = format!("({:.3}, {:.3}, {:.3})", j.axis[0], j.axis[1], j.axis[2]);
        let limits = j
            .limits
            .map_or_else(|| "none".into(), |(lo, hi)| format!("[{lo:.4}, {hi:.4}]"));
        let effort = j.effort.map_or_else(|| "none".into(), |e| format!("{e}"));
        let _ = writeln!(
            out,
            "  {i:>2}  {:<24} {:<11} {axis:<22} {limits:<22} {effort:>10}",
            j.name,
            j.kind.as_str()
        );
    }
    let _ = writeln!(
        out,
        "\nlinks (root '{}' is fixed to the world):",
        m.links[m.root].name
    );
    for l in &m.links {
        let _ = writeln!(out, "  {:<24} {:>9.4} kg", l.name, l.mass);
    }
    let _ = writeln!(out, "  moving mass {:.4} kg", m.moving_mass());
    for merged in &m.merged {
        let _ = writeln!(out, "  merged fixed joint {merged}");
    }
    let s = Scenario::for_arm(m)?;
    let _ = writeln!(
        out,
        "\ndefault scenario (--robot without --scenario): {} s at {} Hz, K1 = {:.3}, K2 = {:.3}",
        s.duration_s, s.rate_hz, s.controller.k1, s.controller.k2
    );
    let _ = writeln!(out, "  initial q = {:?}", s.initial.q);
    Ok(out)
}
