//! A scenario checked against its robot, with its time grid fixed; and
//! loading one from a file with the command line's overrides (applied by
//! `overrides.rs`).

use std::path::{Path, PathBuf};

use plant_rapier::Locks;
use trajectory::Reference;

pub use crate::overrides::Overrides;
use crate::overrides::{apply_set, blame_set, set_locks, with_controller};
use crate::{PAPER_TOML, RobotSource, Scenario, ScenarioError};

/// A scenario checked against its robot: everything a run needs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The scenario as it runs: as loaded, with its seed's `[randomise]`
    /// draws applied.
    pub scenario: Scenario,
    /// The scenario before the draws: what another seed draws from.
    pub undrawn: Scenario,
    /// Where the scenario came from ("built-in paper scenario" or a path).
    pub source: String,
    /// The scenario's TOML text as written by its author, for logs.
    pub toml: String,
    /// The robot.
    pub robot: RobotSource,
    /// The checked reference and envelope.
    pub reference: Reference,
    /// Control period in integer nanoseconds.
    pub period_ns: u64,
    /// Period of the reference samples in integer nanoseconds.
    pub reference_period_ns: u64,
    /// Number of control steps.
    pub steps: u64,
    /// What the testbed changed beyond the files, and why: links of the
    /// URDF that contribute nothing, and, for an arm's default scenario,
    /// the joints it locks, the armature it adds and its warnings.
    pub changes: Vec<String>,
}

impl Plan {
    /// The scenario as it will run (overrides applied, robot path made
    /// absolute), as TOML: what the node processes of a run load.
    pub fn effective_toml(&self) -> Result<String, ScenarioError> {
        let mut s = self.scenario.clone();
        s.robot = self.robot.path.as_ref().map(|p| {
            std::path::absolute(p)
                .unwrap_or_else(|_| p.clone())
                .display()
                .to_string()
        });
        toml::to_string(&s).map_err(|e| ScenarioError::Toml {
            file: self.source.clone(),
            message: format!("cannot write the effective scenario: {e}"),
        })
    }

    /// The scenario as its author wrote it, with `--set` applied (draws
    /// and `--duration` not: another seed draws again), to be written as a
    /// file in `dir`: its robot path is made relative to `dir` (absolute
    /// where no relative path leads there, as across file systems' roots).
    pub fn authored_toml_in(&self, dir: &Path) -> Result<String, ScenarioError> {
        let err = |message: String| ScenarioError::Toml {
            file: self.source.clone(),
            message,
        };
        let mut root: toml::Table = toml::from_str(&self.toml).map_err(|e| err(e.to_string()))?;
        if let Some(robot) = &self.robot.path {
            let at = relative_path(robot, dir)
                .ok_or_else(|| err(format!("{}: no path to it", robot.display())))?;
            root.insert(
                "robot".into(),
                toml::Value::String(at.display().to_string()),
            );
        }
        toml::to_string(&root).map_err(|e| err(format!("cannot write the scenario: {e}")))
    }

    /// What the plant's step machine is built from.
    pub fn plant_config(&self) -> plant_rapier::PlantMachineConfig {
        let s = &self.scenario;
        plant_rapier::PlantMachineConfig {
            model: self.robot.model.clone(),
            plant: s.plant.clone(),
            seed: s.seed,
            period_ns: self.period_ns,
            steps: self.steps,
            initial_q: s.initial.q.clone(),
            initial_qd: s.initial.qd.clone(),
        }
    }

    /// What the controller's step machine is built from: the scenario's
    /// law, with the arm's model only for a model-based law.
    pub fn controller_config(&self) -> controller::ControllerMachineConfig {
        self.controller_config_for(self.scenario.controller.clone())
    }

    /// [`Plan::controller_config`] with other parameters (another law on
    /// the same arm and period).
    pub fn controller_config_for(
        &self,
        params: controller::ControllerParams,
    ) -> controller::ControllerMachineConfig {
        controller::ControllerMachineConfig {
            model: params.law.model_based().then(|| self.robot.model.clone()),
            params,
            dof: self.robot.model.dof(),
            period_ns: self.period_ns,
        }
    }

    /// What the trajectory's step machine is built from.
    pub fn trajectory_config(&self) -> trajectory::TrajectoryMachineConfig {
        trajectory::TrajectoryMachineConfig {
            reference: self.reference.clone(),
            reference_period_ns: self.reference_period_ns,
        }
    }

    /// Control period in seconds (exactly `period_ns` / 1e9).
    pub fn dt(&self) -> f64 {
        self.period_ns as f64 / 1e9
    }

    /// How far ahead of its time the real-time trajectory publishes each
    /// sample, ns (a whole number of reference periods, rounded up).
    pub fn reference_horizon_ns(&self) -> u64 {
        self.scenario.reference.horizon_ns(self.reference_period_ns)
    }
}

/// Loads a scenario file (or the built-in paper scenario when `path` is
/// None), applies `overrides`, loads its robot, and checks that they fit.
pub fn load(path: Option<&Path>, overrides: &Overrides) -> Result<Plan, ScenarioError> {
    let (toml_text, source, base) = match path {
        Some(p) => {
            let text = wire::read_text_file(p, wire::MAX_TEXT_FILE_BYTES).map_err(|cause| {
                ScenarioError::Io {
                    file: p.display().to_string(),
                    cause,
                }
            })?;
            let base = p.parent().map(Path::to_path_buf).unwrap_or_default();
            (text, p.display().to_string(), Some(base))
        }
        None => (
            PAPER_TOML.to_string(),
            "built-in paper scenario".to_string(),
            None,
        ),
    };
    let arm = match &overrides.robot {
        Some(path) => Some(RobotSource::from_file(path, &Locks::new())?),
        None => None,
    };
    let mut default_changes = Vec::new();
    let (scenario, toml_text, source) = match (&arm, path) {
        (Some(arm), None) => {
            let locks = set_locks(&overrides.set);
            let d = crate::ArmDefault::with_locks(&arm.urdf, &locks).map_err(|cause| {
                ScenarioError::Plant {
                    file: arm.label(),
                    cause,
                }
            })?;
            default_changes = d.changes();
            let s = d.scenario;
            let text = toml::to_string(&s).map_err(|e| ScenarioError::Toml {
                file: arm.label(),
                message: format!("cannot write the default scenario: {e}"),
            })?;
            (s, text, format!("default scenario for {}", arm.label()))
        }
        _ => (
            Scenario::from_toml_str(&toml_text, &source)?,
            toml_text,
            source,
        ),
    };
    let (mut scenario, toml_text, source) = if overrides.set.is_empty() {
        (scenario, toml_text, source)
    } else {
        // `--law X --set controller.<X's key>=…`: the law is chosen before
        // the keys are set, so that X's own keys are X's to set.
        let toml_text = match overrides.law {
            Some(law) => with_controller(&toml_text, &source, &scenario.controller.for_law(law))?,
            None => toml_text,
        };
        let (text, said) = apply_set(&toml_text, &source, &overrides.set)?;
        // Relative paths in the file stay relative to it.
        let mut s: Scenario = toml::from_str(&text).map_err(|e| ScenarioError::Toml {
            file: said.clone(),
            message: blame_set(&toml_text, &overrides.set)
                .unwrap_or_else(|| e.to_string().trim_end().to_string()),
        })?;
        s.read_trajectory_files(base.as_deref().unwrap_or(Path::new("")), &said)?;
        s.validate(&said)?;
        (s, text, said)
    };
    // A log must replay without the trajectory files: the scenario it
    // keeps carries their samples.
    let toml_text = if scenario.reference.samples.is_some() || scenario.envelope.samples.is_some() {
        toml::to_string(&scenario).map_err(|e| ScenarioError::Toml {
            file: source.clone(),
            message: format!("cannot write the scenario with its trajectory samples: {e}"),
        })?
    } else {
        toml_text
    };
    if let Some(d) = overrides.duration_s {
        scenario.duration_s = d;
        scenario.validate(&format!("{source} with --duration {d}"))?;
    }
    if let Some(r) = overrides.rate_hz {
        scenario.rate_hz = r;
        scenario.validate(&format!("{source} with --rate {r}"))?;
    }
    if let Some(law) = overrides.law {
        scenario.controller = scenario.controller.for_law(law);
        scenario.validate(&format!("{source} with --law {law}"))?;
    }
    let locks = &scenario.plant.lock;
    let robot = match (arm, &scenario.robot, &base) {
        (Some(arm), _, _) => arm.relocked(locks),
        (None, rel, base) => match (rel, base) {
            (Some(rel), Some(base)) => RobotSource::from_file(&base.join(rel), locks),
            (Some(rel), None) => RobotSource::from_file(Path::new(rel), locks),
            (None, _) => RobotSource::builtin().relocked(locks),
        },
    }
    .map_err(|cause| ScenarioError::Robot {
        file: source.clone(),
        cause: Box::new(cause),
    })?;
    let mut plan = plan(scenario, source, toml_text, robot)?;
    plan.changes.extend(default_changes);
    Ok(plan)
}

/// `target` as a path from `dir` (both made absolute first).
fn relative_path(target: &Path, dir: &Path) -> Option<PathBuf> {
    use std::path::Component;
    let clean = |p: &Path| -> Option<Vec<std::ffi::OsString>> {
        let mut out = Vec::new();
        for c in std::path::absolute(p).ok()?.components() {
            match c {
                Component::ParentDir => {
                    out.pop();
                }
                Component::Normal(x) => out.push(x.to_os_string()),
                Component::RootDir | Component::Prefix(_) | Component::CurDir => {}
            }
        }
        Some(out)
    };
    let (t, d) = (clean(target)?, clean(dir)?);
    let common = t.iter().zip(&d).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..d.len() {
        out.push("..");
    }
    for part in &t[common..] {
        out.push(part);
    }
    Some(out)
}

/// A scenario argument as `--scenario` takes it: a file, or else the name
/// of a shipped scenario (with or without `.toml`), as its file.
pub fn resolve_scenario(arg: &Path) -> Result<PathBuf, ScenarioError> {
    if arg.exists() || arg.components().count() > 1 {
        return Ok(arg.to_path_buf());
    }
    match arg.to_str().and_then(crate::find_shipped) {
        Some(s) => Ok(s.path()),
        None => Err(ScenarioError::NotFound {
            name: arg.display().to_string(),
            shipped: crate::SHIPPED
                .iter()
                .map(|s| s.name)
                .collect::<Vec<_>>()
                .join(", "),
        }),
    }
}

/// [`load`] with the scenario given as `--scenario` takes it
/// ([`resolve_scenario`]); None: the built-in paper scenario, or the
/// default scenario of `overrides.robot`.
pub fn load_named(arg: Option<&Path>, overrides: &Overrides) -> Result<Plan, ScenarioError> {
    let path = arg.map(resolve_scenario).transpose()?;
    load(path.as_deref(), overrides)
}

/// Checks a parsed scenario against a robot and fixes the time grid.
pub fn plan(
    scenario: Scenario,
    source: String,
    toml: String,
    robot: RobotSource,
) -> Result<Plan, ScenarioError> {
    let dof = robot.model.dof();
    // Checked first: every later step (and every node) assumes it fits.
    if dof > wire::MAX_DOF {
        let names = robot.model.joint_names();
        return Err(ScenarioError::TooManyJoints {
            file: source,
            robot: robot.label(),
            dof,
            example: names.last().cloned().unwrap_or_default(),
            beyond: names
                .iter()
                .skip(wire::MAX_DOF)
                .cloned()
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    // A trajectory file's columns are the arm's joints by name, in the
    // arm's order from here on (the log keeps them so).
    let mut scenario = scenario;
    let joints = robot.model.joint_names();
    for s in [
        &mut scenario.reference.samples,
        &mut scenario.envelope.samples,
    ]
    .into_iter()
    .flatten()
    {
        *s = s
            .by_joint_names(&joints)
            .map_err(|cause| ScenarioError::Trajectory {
                file: source.clone(),
                cause,
            })?;
    }
    let mismatch = |key: &str, got: usize| ScenarioError::Invalid {
        file: source.clone(),
        key: key.to_string(),
        value: format!("{got} entries"),
        need: format!(
            "one entry per actuated joint of {} ({dof}: {})",
            robot.label(),
            robot.model.joint_names().join(", ")
        ),
    };
    for (key, len) in [
        ("initial.q", scenario.initial.q.len()),
        ("initial.qd", scenario.initial.qd.len()),
        ("reference.joints", scenario.reference.dof()),
        ("envelope.joints", scenario.envelope.dof()),
    ] {
        if len != dof && !(key == "envelope.joints" && scenario.envelope.from_limits) {
            return Err(mismatch(key, len));
        }
    }
    let mut changes: Vec<String> = robot
        .model
        .ignored
        .iter()
        .map(|l| format!("link '{}' dropped from the dynamics: {}", l.name, l.reason))
        .collect();
    // What reading the URDF took otherwise than written (a tensor replaced,
    // a limit read as none): said before every run, as `robot` says it.
    changes.extend(robot.model.notes.iter().cloned());
    if !scenario.plant.contact.is_off() {
        changes.extend(
            robot
                .model
                .links
                .iter()
                .flat_map(|l| &l.skipped_collisions)
                .map(|why| format!("contact: {why}: skipped")),
        );
    }
    let undrawn = scenario.clone();
    let scenario = crate::drawn(&scenario, dof);
    if scenario != undrawn {
        scenario.validate(&format!("{source} (seed {} drawn)", scenario.seed))?;
    }
    let c = &scenario.controller;
    for (key, gain) in [("controller.k1", &c.k1), ("controller.k2", &c.k2)] {
        gain.resolve(key, dof)
            .map_err(|cause| ScenarioError::Controller {
                file: source.clone(),
                cause,
            })?;
    }
    let model = &robot.model;
    let limits: Vec<Option<(f64, f64)>> = model
        .actuated
        .iter()
        .map(|&j| model.joints[j].limits)
        .collect();
    let reference = Reference::with_limits(
        &scenario.reference,
        &scenario.envelope,
        &limits,
        &model.joint_names(),
    )
    .map_err(|cause| ScenarioError::Trajectory {
        file: source.clone(),
        cause,
    })?;
    scenario
        .plant
        .check_for(dof, &model.link_names())
        .and_then(|()| {
            plant_rapier::check_contact(model, &scenario.plant.contact, &scenario.initial.q)
        })
        .map_err(|cause| ScenarioError::Plant {
            file: source.clone(),
            cause,
        })?;
    let period_ns = (1e9 / scenario.rate_hz).round() as u64;
    let reference_period_ns = match scenario.reference.rate_hz {
        Some(r) => (1e9 / r).round() as u64,
        None => period_ns,
    };
    let steps = (scenario.duration_s * 1e9 / period_ns as f64).round() as u64;
    if steps == 0 {
        return Err(ScenarioError::Invalid {
            file: source.clone(),
            key: "duration_s".into(),
            value: scenario.duration_s.to_string(),
            need: format!("at least one control period ({} s)", period_ns as f64 / 1e9),
        });
    }
    let mut plan = Plan {
        scenario,
        undrawn,
        source,
        toml,
        robot,
        reference,
        period_ns,
        reference_period_ns,
        steps,
        changes,
    };
    if let Some(warning) = stiffness_warning(&plan)? {
        plan.changes.push(warning);
    }
    Ok(plan)
}

/// Where stiff springs or friction make the plant take more substeps than
/// the scenario asks (the articulated engine only): refused past the
/// engine's bound, and said before the run when the plant alone would be
/// slower than real time. Other faults of building the plant are left to
/// the run, which reports them as it always has.
fn stiffness_warning(plan: &Plan) -> Result<Option<String>, ScenarioError> {
    let p = &plan.scenario.plant;
    let stiff =
        p.actuator.elastic() || !p.friction.viscous.is_zero() || !p.friction.coulomb.is_zero();
    if p.engine != plant_rapier::EngineName::Articulated || !stiff {
        return Ok(None);
    }
    let err = |cause| ScenarioError::Plant {
        file: plan.source.clone(),
        cause,
    };
    match plan.plant_config().machine() {
        Ok(machine) => machine.speed_warning().map_err(err),
        Err(cause @ plant_rapier::PlantError::TooStiff { .. }) => Err(err(cause)),
        Err(_) => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    fn overrides(law: Option<&str>, set: &[&str]) -> Overrides {
        Overrides {
            duration_s: None,
            rate_hz: None,
            robot: None,
            law: law.map(|l| l.parse().unwrap()),
            set: set.iter().map(|s| crate::parse_set(s).unwrap()).collect(),
        }
    }

    /// #38 item 4: the remedy for more joints than a sample carries works
    /// as the error says: `--set plant.lock.J=…` on an arm's default
    /// scenario locks J before the scenario is chosen.
    #[test]
    fn locking_by_set_brings_a_34_joint_arm_to_32() {
        let mut urdf = String::from(
            r#"<robot name="chain"><link name="l0"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>"#,
        );
        for i in 1..=34 {
            urdf += &format!(
                r#"<link name="l{i}"><inertial><origin xyz="0.05 0 0"/><mass value="0.2"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link><joint name="j{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/><origin xyz="0.1 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="100" velocity="1"/></joint>"#,
                p = i - 1
            );
        }
        urdf += "</robot>";
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("chain.urdf");
        std::fs::write(&path, urdf).unwrap();
        let with = |set: &[&str]| {
            let mut o = overrides(None, set);
            o.robot = Some(path.clone());
            load(None, &o)
        };
        let e = with(&[]).unwrap_err().to_string();
        assert!(e.contains("at most 32") && e.contains("plant.lock"), "{e}");
        let plan = with(&["plant.lock.j33=0", "plant.lock.j34=0.5"]).unwrap();
        assert_eq!(plan.robot.model.dof(), 32);
        assert_eq!(plan.scenario.plant.lock.get("j34"), Some(&0.5));
    }

    /// #39 row 15: `--law X --set controller.<X's key>` sets X's key.
    #[test]
    fn a_law_chosen_on_the_command_line_takes_its_own_keys() {
        let plan = load(
            None,
            &overrides(
                Some("mpc"),
                &["controller.mpc_horizon=5", "controller.k1=10"],
            ),
        )
        .unwrap();
        let c = &plan.scenario.controller;
        assert_eq!(c.law, controller::LawName::Mpc);
        assert_eq!(
            (c.mpc_horizon, c.k1.clone()),
            (5, controller::Gain::All(10.0))
        );
        // The paper's own keys are gone, as without --set.
        assert_eq!(c.beta, controller::ControllerParams::default().beta);
        // A key the law does not take is still refused, by name.
        let e = load(None, &overrides(Some("pd"), &["controller.beta=3"]))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("controller.beta is not a parameter of law 'pd'"),
            "{e}"
        );
    }

    /// A `--set` the scenario cannot read is named with its own words, not
    /// a line of the merged document it never saw; the set before it,
    /// which is fine, is not blamed.
    #[test]
    fn a_bad_set_is_named_not_a_line_of_the_merged_scenario() {
        let bad = |set: &[&str]| load(None, &overrides(None, set)).unwrap_err().to_string();
        let e = bad(&["plant.engine=rapier", "controller.k1=[1,"]);
        assert!(
            e.contains("--set controller.k1=\"[1,\": a number, or a list")
                && e.contains("'[1,' is not a TOML value, so it was read as a string")
                && !e.contains("line "),
            "{e}"
        );
        // A later set replaces an earlier bad one: the bad one still in
        // force is named.
        let e = bad(&[
            "plant.engine=bogus",
            "plant.engine=rapier",
            "controller.k1=abc",
        ]);
        assert!(e.contains("--set controller.k1=\"abc\": a number"), "{e}");
        let e = bad(&["duration_s=1e400"]);
        assert!(e.contains("out of TOML's range"), "{e}");
        let e = bad(&["plant.engine=nope"]);
        assert!(
            e.contains("unknown variant `nope`") && !e.contains("read as a string"),
            "{e}"
        );
        let e = bad(&["plant.nonsense=3"]);
        assert!(
            e.contains("--set plant.nonsense=3: unknown field `nonsense`") && !e.contains("line "),
            "{e}"
        );
    }

    /// #48 item 9 (N7): a refused `--set` quotes its value cut to 80
    /// characters (a 2 M-entry one made a 10 MB message).
    #[test]
    fn a_refused_set_quotes_its_value_cut() {
        let long = format!("controller.k1=[{}\"x\"]", "1,".repeat(100_000));
        let e = load(None, &overrides(None, &[&long]))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--set controller.k1=[1, 1,")
                && e.contains("bytes in all)")
                && e.len() < 2000,
            "{} bytes: {}",
            e.len(),
            &e[..e.len().min(2000)]
        );
    }

    /// #48 item 7 (N3): a spring too stiff to integrate in time is refused
    /// when the scenario is loaded, before any node starts, naming the
    /// keys; one under the bound but slower than real time is said among
    /// the notes printed before the run.
    #[test]
    fn a_plant_too_stiff_for_its_period_is_refused_or_said() {
        let e = load(
            None,
            &overrides(
                None,
                &[
                    "plant.actuator.stiffness=1e9",
                    "plant.actuator.motor_inertia=1e-6",
                ],
            ),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("plant.actuator.stiffness") && e.contains("at most 1e7 a simulated second"),
            "{e}"
        );
        let plan = load(
            None,
            &overrides(
                None,
                &[
                    "plant.actuator.stiffness=1.28e6",
                    "plant.actuator.motor_inertia=1e-6",
                ],
            ),
        )
        .unwrap();
        assert!(
            plan.changes.iter().any(|c| c.contains("× real time")),
            "{:?}",
            plan.changes
        );
    }

    /// #48 item 11 (D11): a trajectory file's columns are the joints by
    /// name: `t,joint2,joint1` drives joint1 with its own column (it drove
    /// it with joint2's), and the iiwa's names on the two-link arm are
    /// refused naming the file, row, column and the arm's joints, as is a
    /// file missing a joint (not counted against the envelope).
    #[test]
    fn a_trajectory_file_is_matched_to_the_joints_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let with = |csv: &str| {
            let path = dir.path().join("traj.csv");
            std::fs::write(&path, csv).unwrap();
            let set = format!("reference.file={:?}", path.display().to_string());
            load(None, &overrides(None, &[set.as_str()]))
        };
        let plan = with("t,joint2,joint1\n0,0.2,0.1\n1,0.4,0.3\n").unwrap();
        let s = plan.scenario.reference.samples.as_ref().unwrap();
        assert_eq!(s.columns, ["joint1", "joint2"]);
        assert_eq!(s.values, [vec![0.1, 0.3], vec![0.2, 0.4]]);
        assert_eq!(plan.reference.sample(0.0).q_d, [0.1, 0.2]);
        let e = with("t,iiwa_joint_1,iiwa_joint_2\n0,0,0\n1,0,0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("traj.csv: row 1, column 2 ('iiwa_joint_1')")
                && e.contains("joint1, joint2"),
            "{e}"
        );
        let e = with("t,joint2\n0,0\n1,0\n").unwrap_err().to_string();
        assert!(e.contains("no column for joint joint1"), "{e}");
    }

    /// #48 item 16: a file that opens with a UTF-8 byte-order mark (a
    /// Windows editor's) reads as without it: the CSV's first column is
    /// `t`, not `'\u{feff}t'`, and the scenario's first key its own.
    #[test]
    fn a_path_from_a_folder_climbs_to_the_common_part() {
        let p = relative_path(
            Path::new("/a/b/robots/x.urdf"),
            Path::new("/a/b/scenarios/tuned"),
        );
        assert_eq!(p.unwrap(), Path::new("../../robots/x.urdf"));
        let p = relative_path(Path::new("/a/b/../c/x.urdf"), Path::new("/a/c"));
        assert_eq!(p.unwrap(), Path::new("x.urdf"));
    }

    #[test]
    fn a_byte_order_mark_opens_no_name() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("traj.csv");
        std::fs::write(&csv, "\u{feff}t,joint1,joint2\n0,0.1,0.2\n1,0.3,0.4\n").unwrap();
        let set = format!("reference.file={:?}", csv.display().to_string());
        let plan = load(None, &overrides(None, &[set.as_str()])).unwrap();
        assert_eq!(plan.reference.sample(0.0).q_d, [0.1, 0.2]);
        let toml = dir.path().join("s.toml");
        std::fs::write(&toml, "\u{feff}name = \"bom\"\nduration_s = 1.0\n").unwrap();
        let plan = load(Some(&toml), &overrides(None, &[])).unwrap();
        assert_eq!(plan.scenario.name, "bom");
    }
}
