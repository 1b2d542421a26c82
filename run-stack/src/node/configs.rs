//! The launcher's validated plan, cut into what each node needs: the one
//! typed path from `testbed run` to its processes (written as JSON by
//! [`bus::write_config`], read back by the node with the same type).

use std::path::{Path, PathBuf};

use bus::{ConfigError, write_config};
use controller::node::{ControllerNodeConfig, NodeModel};
use logger::live::LiveConfig;
use logger::node::LoggerNodeConfig;
use logger::{LogCompression, RunMetadata};
use plant_rapier::node::PlantNodeConfig;
use scenario::Plan;
use trajectory::node::TrajectoryNodeConfig;
use wire::NodeKind;

use crate::mode::Mode;

/// The plant's part of `plan`.
pub fn plant(plan: &Plan) -> PlantNodeConfig {
    let s = &plan.scenario;
    PlantNodeConfig {
        robot: plan.robot.label(),
        urdf: plan.robot.urdf.clone(),
        plant: s.plant.clone(),
        seed: s.seed,
        period_ns: plan.period_ns,
        steps: plan.steps,
        initial_q: s.initial.q.clone(),
        initial_qd: s.initial.qd.clone(),
    }
}

/// The controller's part: gains and sizes, and the URDF only for a
/// model-based law (the node reads it into the model of
/// [`Plan::controller_config`]).
pub fn controller(plan: &Plan) -> ControllerNodeConfig {
    let params = &plan.scenario.controller;
    ControllerNodeConfig {
        params: params.clone(),
        dof: plan.robot.model.dof(),
        period_ns: plan.period_ns,
        reference_period_ns: plan.reference_period_ns,
        model: params.law.model_based().then(|| NodeModel {
            urdf: plan.robot.urdf.clone(),
            lock: plan.scenario.plant.lock.clone(),
        }),
        own_params: serde_json::Map::new(),
        own_diagnostics: String::new(),
        scenario: scenario_name(&plan.source),
    }
}

/// A scenario's name as a policy's record writes it: the file's stem of a
/// path, the name of a shipped one ("built-in paper scenario": "paper").
fn scenario_name(source: &str) -> String {
    if source.starts_with("built-in") {
        return "paper".into();
    }
    // The label goes on with what changed it ("x.toml with --set …").
    let path = source.split(" with ").next().unwrap_or(source);
    std::path::Path::new(path)
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
}

/// The trajectory's part.
pub fn trajectory(plan: &Plan) -> TrajectoryNodeConfig {
    let m = &plan.robot.model;
    TrajectoryNodeConfig {
        reference: plan.scenario.reference.clone(),
        envelope: plan.scenario.envelope.clone(),
        limits: m.actuated.iter().map(|&j| m.joints[j].limits).collect(),
        joint_names: m.joint_names(),
        period_ns: plan.period_ns,
        reference_period_ns: plan.reference_period_ns,
        horizon_ns: plan.reference_horizon_ns(),
        steps: plan.steps,
    }
}

/// What a run's options, beyond its plan, tell the logger.
#[derive(Debug, Clone, Copy, Default)]
pub struct LoggerOptions<'a> {
    /// The user's command that replaces the controller node (recorded).
    pub controller_cmd: Option<&'a str>,
    /// What that command declared itself to be (its law and parameters).
    pub declared: Option<&'a crate::run::external::Declared>,
    /// Serve the run live.
    pub live: Option<&'a LiveConfig>,
    /// The log's chunk compression.
    pub compression: LogCompression,
}

/// The logger's part: where to write, what the log says about the run,
/// how it is compressed and whether it is served live.
pub fn logger(
    plan: &Plan,
    mode: Mode,
    out: &Path,
    toml: &str,
    opts: LoggerOptions<'_>,
) -> LoggerNodeConfig {
    let mut metadata = metadata(plan, mode, out, toml);
    metadata.controller_cmd = opts.controller_cmd.unwrap_or_default().to_string();
    if let Some(d) = opts.declared {
        metadata.controller_name = d.name.clone();
        metadata.controller_params = d.params_text();
        metadata.controller_diagnostics = d.diagnostics.text();
    }
    LoggerNodeConfig {
        out: out.to_path_buf(),
        metadata,
        urdf: plan.robot.urdf.clone(),
        lock: plan.scenario.plant.lock.clone(),
        compression: opts.compression,
        live: opts.live.cloned(),
        obstacles: drawn_obstacles(&plan.scenario.plant.contact),
        objects: drawn_objects(&plan.scenario.plant.contact),
    }
}

/// The scenario's obstacles as the 3D view draws them (checked with the
/// scenario: one that does not check is not drawn).
fn drawn_obstacles(contact: &plant_rapier::ContactConfig) -> Vec<logger::obstacles::DrawnObstacle> {
    contact
        .obstacle
        .iter()
        .enumerate()
        .filter_map(|(i, o)| {
            let g = o.geometry(i).ok()?;
            Some(logger::obstacles::DrawnObstacle::new(&o.origin(), &g))
        })
        .collect()
}

/// The scenario's free objects' shapes, in order (poses come with the
/// plant's contact samples).
fn drawn_objects(contact: &plant_rapier::ContactConfig) -> Vec<logger::obstacles::DrawnShape> {
    contact
        .object
        .iter()
        .enumerate()
        .map(|(i, o)| {
            // Checked with the scenario; a dot keeps the order if not.
            o.geometry(i).map_or(
                logger::obstacles::DrawnShape::Sphere { radius: 0.01 },
                |g| logger::obstacles::DrawnShape::of(&g),
            )
        })
        .collect()
}

/// The `testbed.run` record of a run of `plan` logged to `out`.
pub fn metadata(plan: &Plan, mode: Mode, out: &Path, toml: &str) -> RunMetadata {
    let m = &plan.robot.model;
    let n = m.dof();
    let gains = |g: &controller::Gain| format!("{:?}", g.resolve("gain", n).unwrap_or_default());
    let (locked, mimic) = joint_roles(plan);
    let law = analysis::law_info::LawInfo::of(&plan.scenario.controller);
    RunMetadata {
        law: law.law.to_string(),
        model_based: law.model_based,
        law_parameters: law.parameters_text(),
        run_id: out
            .parent()
            .and_then(|p| p.file_name())
            .map_or_else(String::new, |n| n.to_string_lossy().to_string()),
        mode: mode.as_str().to_string(),
        rate_hz: plan.scenario.rate_hz,
        scenario_toml: toml.to_string(),
        scenario_source: plan.source.clone(),
        robot: plan.robot.label(),
        joint_names: m.joint_names(),
        seed: plan.scenario.seed,
        plant_effects: plan
            .scenario
            .plant
            .configured_effects()
            .names()
            .into_iter()
            .map(String::from)
            .collect(),
        k1: gains(&plan.scenario.controller.k1),
        k2: gains(&plan.scenario.controller.k2),
        locked_joints: locked,
        mimic_joints: mimic,
        urdf_dynamics: plan.scenario.plant.urdf_dynamics,
        start_time_unix_ns: 0,
        controller_cmd: String::new(),
        controller_name: String::new(),
        controller_params: String::new(),
        controller_diagnostics: String::new(),
    }
}

/// The locked and the mimic joints, as the log's metadata writes them.
fn joint_roles(plan: &Plan) -> (String, String) {
    let m = &plan.robot.model;
    let locked = m
        .locked
        .iter()
        .map(|l| match &l.follows {
            Some(f) => format!("{}={} (mimics {f})", l.name, l.position),
            None => format!("{}={}", l.name, l.position),
        })
        .collect::<Vec<_>>()
        .join(",");
    let mimic = m
        .mimic
        .iter()
        .map(|c| {
            format!(
                "{}={}*{}+{}",
                m.joints[c.joint].name, c.multiplier, m.joints[m.actuated[c.leader]].name, c.offset
            )
        })
        .collect::<Vec<_>>()
        .join(",");
    (locked, mimic)
}

/// Writes every node's config under `dir` (`<dir>/<node>.json`) and
/// returns the paths, in [`NodeKind::ALL`] order.
pub fn write_all(
    dir: &Path,
    plan: &Plan,
    mode: Mode,
    log: &Path,
    toml: &str,
    logger_opts: LoggerOptions<'_>,
) -> Result<Vec<(NodeKind, PathBuf)>, ConfigError> {
    std::fs::create_dir_all(dir).map_err(|cause| ConfigError::Io {
        path: dir.display().to_string(),
        cause,
    })?;
    let mut out = Vec::new();
    for kind in NodeKind::ALL {
        let path = dir.join(format!("{}.json", kind.name()));
        match kind {
            NodeKind::Plant => write_config(&path, &plant(plan))?,
            NodeKind::Controller => {
                let mut c = controller(plan);
                if let Some(d) = logger_opts.declared {
                    c.own_params = d.params.clone();
                    c.own_diagnostics = d.diagnostics.text();
                }
                write_config(&path, &c)?
            }
            NodeKind::Trajectory => write_config(&path, &trajectory(plan))?,
            NodeKind::Logger => write_config(&path, &logger(plan, mode, log, toml, logger_opts))?,
        }
        out.push((kind, path));
    }
    Ok(out)
}
