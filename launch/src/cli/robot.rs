//! `testbed robot PATH`: what the testbed makes of an arm, and the default
//! scenario it would run on it, with the reasons for each choice.

use std::fmt::Write;
use std::path::Path;

use anyhow::{Context, Result};
use plant_rapier::{ArmModel, Locks};
use scenario::{ArmDefault, RobotSource};

/// A readable description of the arm at `path`, or the reason it cannot be used.
pub fn describe(path: &Path) -> Result<String> {
    let robot = RobotSource::from_file(path, &Locks::new())?;
    let m = &robot.model;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "robot '{}' ({}): {} actuated joints{}",
        m.name,
        path.display(),
        m.dof(),
        if m.mimic.is_empty() {
            String::new()
        } else {
            format!(" and {} mimic joints", m.mimic.len())
        }
    );
    joints(&mut out, m);
    links(&mut out, m);
    let d = ArmDefault::new(&robot.urdf).map_err(|cause| scenario::ScenarioError::Plant {
        file: robot.label(),
        cause,
    })?;
    default_scenario(&mut out, m, &d);
    let locked = robot.relocked(&d.scenario.plant.lock)?;
    // An arm past the wire's MAX_DOF has no plan (the warnings say so).
    let effort = if locked.model.dof() <= wire::MAX_DOF {
        let plan = scenario::plan(d.scenario.clone(), robot.label(), String::new(), locked)?;
        scenario::effort_warnings(&plan).map_err(|cause| scenario::ScenarioError::Plant {
            file: robot.label(),
            cause,
        })?
    } else {
        Vec::new()
    };
    warnings(&mut out, &d, &effort);
    Ok(out)
}

/// Writes the default scenario for the arm at `path` to `out` as TOML,
/// naming the URDF by its absolute path so the file runs from anywhere.
pub fn write_scenario(path: &Path, out: &Path, force: bool) -> Result<()> {
    super::outputs::refuse_input("--write-scenario", out, &[path.to_path_buf()])?;
    // An edited scenario is work: never lost to a second call, and a link
    // planted at FILE never redirects the write elsewhere (#48 item 16).
    match std::fs::symlink_metadata(out) {
        Ok(m) if m.file_type().is_symlink() => anyhow::bail!(
            "--write-scenario {}: a symbolic link; not written through it (name the file itself)",
            out.display()
        ),
        Ok(m) if !m.is_file() => anyhow::bail!(
            "--write-scenario {}: exists and is not a regular file",
            out.display()
        ),
        Ok(_) if !force => anyhow::bail!(
            "--write-scenario {}: exists; --force replaces it",
            out.display()
        ),
        _ => {}
    }
    let robot = RobotSource::from_file(path, &Locks::new())?;
    let mut s = scenario::Scenario::for_arm(&robot.urdf).map_err(|cause| {
        scenario::ScenarioError::Plant {
            file: robot.label(),
            cause,
        }
    })?;
    let abs = std::path::absolute(path).with_context(|| format!("resolving {}", path.display()))?;
    s.robot = Some(abs.display().to_string());
    let text = toml::to_string(&s).context("writing the default scenario as TOML")?;
    let header = format!(
        "# The default scenario testbed chose for {}\n# (testbed robot {} --write-scenario). Edit it, then: testbed sim --scenario {}\n\n",
        robot.label(),
        path.display(),
        out.display()
    );
    write_new(out, (header + &text).as_bytes(), force)
        .with_context(|| format!("writing {}", out.display()))
}

/// Writes `text` to `out`: a file made afresh (`create_new`, which never
/// follows a link), or with `force` a fresh file beside it renamed over it
/// (the rename replaces a link planted since the check, not its target).
fn write_new(out: &Path, text: &[u8], force: bool) -> std::io::Result<()> {
    use std::io::Write as _;
    let fresh = |p: &Path| {
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(p)
    };
    if !force {
        return fresh(out)?.write_all(text);
    }
    let mut name = out.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".testbed-{}.tmp", std::process::id()));
    let tmp = out.with_file_name(name);
    let written = fresh(&tmp)
        .and_then(|mut f| f.write_all(text))
        .and_then(|()| std::fs::rename(&tmp, out));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// The Foxglove layout (pretty JSON) for the arm at `path`, or the paper's.
pub fn layout(path: Option<&Path>) -> Result<String> {
    let model = match path {
        Some(p) => RobotSource::from_file(p, &Locks::new())?.model,
        None => ArmModel::from_urdf_str(plant_rapier::TWO_LINK_URDF)?,
    };
    let layout = logger::foxglove_layout(&model.joint_names());
    Ok(serde_json::to_string_pretty(&layout)? + "\n")
}

fn joints(out: &mut String, m: &ArmModel) {
    let _ = writeln!(
        out,
        "\njoint order (q, q̇ and τ index; tree order from the root):"
    );
    let _ = writeln!(
        out,
        "  {:>2}  {:<26} {:<11} {:<22} {:<22} {:>9} {:>9} {:>9}",
        "i", "joint", "type", "axis", "limits", "effort", "damping", "friction"
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
            "  {i:>2}  {:<26} {:<11} {axis:<22} {limits:<22} {effort:>9} {:>9} {:>9}",
            j.name,
            j.kind.as_str(),
            j.damping,
            j.friction
        );
    }
    for c in &m.mimic {
        let j = &m.joints[c.joint];
        let _ = writeln!(
            out,
            "  mimic joint {} ({}) = {} × {} + {} (coupled, not controlled)",
            j.name,
            j.kind.as_str(),
            c.multiplier,
            m.joints[m.actuated[c.leader]].name,
            c.offset
        );
    }
    if m.has_urdf_dynamics() {
        let _ = writeln!(
            out,
            "  joint damping and friction (URDF <dynamics>, MJCF damping and frictionloss) act in the plant ([plant] urdf_dynamics = false turns them off)"
        );
    }
}

fn links(out: &mut String, m: &ArmModel) {
    let _ = writeln!(
        out,
        "\nlinks (root '{}' is fixed to the world; its mass properties do not matter):",
        m.links[m.root].name
    );
    for l in &m.links {
        let _ = writeln!(
            out,
            "  {:<26} {:>9.4} kg{}",
            l.name,
            l.mass,
            collision_summary(l)
        );
    }
    let _ = writeln!(out, "  moving mass {:.4} kg", m.moving_mass());
    for merged in &m.merged {
        let _ = writeln!(out, "  merged fixed joint {merged}");
    }
    for ig in &m.ignored {
        let _ = writeln!(out, "  ignored link {}: {}", ig.name, ig.reason);
    }
    for note in &m.notes {
        let _ = writeln!(out, "  note: {note}");
    }
}

/// A link's collision geometry, as `[plant.contact]` takes it: primitive
/// shapes counted by kind, meshes (never contact shapes) named.
fn collision_summary(l: &plant_rapier::LinkInfo) -> String {
    use plant_rapier::Geometry;
    let mut kinds: Vec<(&str, usize)> = Vec::new();
    for c in &l.collisions {
        let kind = match c.geometry {
            Geometry::Box { .. } => "box",
            Geometry::Cylinder { .. } => "cylinder",
            Geometry::Sphere { .. } => "sphere",
            Geometry::Capsule { .. } => "capsule",
        };
        match kinds.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, n)) => *n += 1,
            None => kinds.push((kind, 1)),
        }
    }
    let mut parts: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} {k}")).collect();
    if !l.skipped_collisions.is_empty() {
        // Each reads "link 'l' collision k: mesh 'm'"; the mesh is what
        // this line is about.
        let meshes: Vec<&str> = (l.skipped_collisions.iter())
            .map(|c| c.rsplit(": ").next().unwrap_or(c))
            .collect();
        parts.push(format!("{} (not contact shapes)", meshes.join(", ")));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!("   collision: {}", parts.join(", "))
    }
}

/// Everything the default scenario had to change or could not fix, together
/// at the end where a user looks: each a line starting "warning:".
fn warnings(out: &mut String, d: &ArmDefault, effort: &[String]) {
    let mut lines: Vec<String> = Vec::new();
    let controlled = d.gains.joints.len();
    if controlled > wire::MAX_DOF {
        // Described all the same: the joint list is what the user needs to
        // choose which joints to lock.
        lines.push(format!(
            "{controlled} controlled joints; the wire carries at most {}: sim and run refuse this arm until {} joints are locked in [plant.lock]",
            wire::MAX_DOF,
            controlled - wire::MAX_DOF
        ));
    }
    for (name, why) in &d.locked {
        if !why.starts_with(scenario::GRIPPER_LOCK) {
            lines.push(format!("locked {name}: {why}"));
        }
    }
    for (name, a, _) in &d.armature {
        lines.push(format!(
            "armature {a:.3e} added to {name}, which the URDF does not have"
        ));
    }
    lines.extend(d.warnings.iter().cloned());
    lines.extend(effort.iter().cloned());
    if !lines.is_empty() {
        let _ = writeln!(out);
    }
    for l in lines {
        let _ = writeln!(out, "warning: {l}");
    }
}

fn default_scenario(out: &mut String, m: &ArmModel, d: &ArmDefault) {
    let s = &d.scenario;
    let g = &d.gains;
    let _ = writeln!(
        out,
        "\ndefault scenario (--robot without --scenario): {} s at {} Hz, {} controlled joints",
        s.duration_s,
        s.rate_hz,
        g.joints.len()
    );
    for (name, why) in &d.locked {
        let at = s.plant.lock.get(name).copied().unwrap_or(0.0);
        let _ = writeln!(out, "  locked {name} at {at:.4}: {why}");
    }
    for (name, a, why) in &d.armature {
        let _ = writeln!(
            out,
            "  armature {a:.3e} added to {name} ([plant] armature): {why}"
        );
    }
    let _ = writeln!(
        out,
        "  {:>2}  {:<26} {:>9} {:>10} {:>11} {:>9} {:>8} {:<3}  why K1",
        "i", "joint", "K1", "K2", "max M⁻¹_ii", "load", "effort", ""
    );
    for (i, j) in g.joints.iter().enumerate() {
        let effort = j.effort.map_or_else(|| "none".into(), |e| format!("{e}"));
        // Load and effort are forces on a slide, torques on a hinge.
        let unit = (m.joints.iter().find(|mj| mj.name == j.name))
            .map_or("N m", |mj| mj.kind.effort_unit());
        let _ = writeln!(
            out,
            "  {i:>2}  {:<26} {:>9.3} {:>10.4} {:>11.4} {:>9.3} {:>8} {unit:<3}  {}",
            j.name, j.k1, j.k2, j.minv_diag, j.load, effort, j.k1_reason
        );
    }
    let _ = writeln!(
        out,
        "  K2_i = 1/(Δt·max M⁻¹_ii), scaled so that Δt·λmax(K2^½ M⁻¹ K2^½) = {:.3} (< 2 is stable) at the worst of {} postures along the reference and on the way to it",
        g.stability_number, g.postures_checked
    );
    let below = g.below_half();
    if !below.is_empty() {
        let _ = writeln!(
            out,
            "  K2_i below the analysis's 1/2 (allowed, SPEC §7; [plant] armature raises it): {}",
            below.join(", ")
        );
    }
    let from = if d.from_home {
        " (the model's home pose: its MJCF keyframe, inside the limits)"
    } else {
        ""
    };
    let _ = writeln!(out, "  initial q = {:?}{from}", s.initial.q);
}
