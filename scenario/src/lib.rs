//! The scenario file: one TOML document that says everything about a run.
//!
//! Where it sits: `testbed` reads a scenario (or the built-in paper
//! scenario), validates it against the robot, and hands each process its
//! part: `[plant]` and `[initial]` to the plant, `[reference]` and
//! `[envelope]` to the trajectory, `[controller]` to the controller.
//! Every key is optional and defaults to the paper's value; unknown keys,
//! NaN and out-of-range values are errors naming the key. [`stepper`] is
//! the one loop body a plan runs in process (`sim`, the Gym environment):
//! here, under the role crates, so that a law or the environment needs no
//! run stack.
//!
//! ```
//! let s = scenario::Scenario::from_toml_str("[controller]\nk1 = 20.0\n", "inline").unwrap();
//! assert_eq!(s.controller.k1, controller::Gain::All(20.0));
//! assert_eq!(s.duration_s, 20.0); // the paper's default
//! ```

mod catalogue;
mod default_for_arm;
mod effort;
mod gains;
mod keys;
mod motor_bound;
mod overrides;
mod plan;
mod posture;
mod probe;
mod randomise;
mod robot;
mod seed;
pub mod stepper;
pub mod sweep_file;

use controller::{ControllerError, ControllerParams};
use plant_rapier::{PlantConfig, PlantError};
use serde::{Deserialize, Serialize};
use std::path::Path;

use trajectory::{EnvelopeConfig, Reference, ReferenceConfig, TrajectoryError};

/// Largest trajectory CSV read (10⁶ rows of a few joints).
pub const TRAJECTORY_FILE_BYTES: u64 = 128 << 20;

pub use catalogue::{SHIPPED, Shipped, find as find_shipped};
pub use default_for_arm::{ArmDefault, GRIPPER_LOCK};
pub use effort::{EFFORT_WARNING_FRACTION, effort_warnings};
pub use gains::{ArmatureFor, GainChoice, JointGain};
pub use keys::{KeyError, parse_set};
pub use plan::{Overrides, Plan, load, load_named, plan, resolve_scenario};
pub use probe::{Probe, Prober};
pub use randomise::{Dist, Randomise, drawn};
pub use robot::RobotSource;
pub use wire::ns_to_s;

/// The paper's scenario as shipped in `scenarios/paper.toml`.
pub const PAPER_TOML: &str = include_str!("../../scenarios/paper.toml");

/// Why a scenario cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{file}: {cause}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// The scenario's robot cannot be used.
    #[error("{file}: robot: {cause}")]
    Robot {
        /// The scenario file.
        file: String,
        /// What is wrong with the robot's URDF.
        cause: Box<ScenarioError>,
    },
    /// Not TOML, or a key that does not exist, or a value of the wrong type.
    #[error("{file}: {message}")]
    Toml {
        /// The file.
        file: String,
        /// The parser's message (it names the key and line).
        message: String,
    },
    /// A value out of range.
    #[error("{file}: {key} = {value} is invalid: it must be {need}")]
    Invalid {
        /// The file.
        file: String,
        /// The key.
        key: String,
        /// The value.
        value: String,
        /// What it must be.
        need: String,
    },
    /// A controller parameter is out of range.
    #[error("{file}: {cause}")]
    Controller {
        /// The file.
        file: String,
        /// The cause.
        cause: ControllerError,
    },
    /// The reference or envelope is unusable.
    #[error("{file}: {cause}")]
    Trajectory {
        /// The file.
        file: String,
        /// The cause.
        cause: TrajectoryError,
    },
    /// The arm has more controlled joints than the wire carries.
    #[error(
        "{file}: robot {robot} has {dof} controlled joints; the wire carries at most {max}: lock {excess} of them in [plant.lock] (e.g. {example} = 0.0; the joints past the first {max} are {beyond})",
        max = wire::MAX_DOF,
        excess = dof - wire::MAX_DOF
    )]
    TooManyJoints {
        /// The scenario.
        file: String,
        /// The robot's label.
        robot: String,
        /// Controlled joints after the scenario's locks.
        dof: usize,
        /// A joint the user could lock (the last one).
        example: String,
        /// The joints past [`wire::MAX_DOF`], in joint order.
        beyond: String,
    },
    /// A scenario argument that is neither a file nor a shipped scenario.
    #[error(
        "{name}: no such file, and not a shipped scenario; the shipped ones are {shipped} (`testbed scenarios` describes them)"
    )]
    NotFound {
        /// The argument as given.
        name: String,
        /// The shipped scenarios' names, comma-separated.
        shipped: String,
    },
    /// The plant settings or the robot are unusable.
    #[error("{file}: {cause}")]
    Plant {
        /// The file (the scenario for `[plant]`, the URDF for the robot).
        file: String,
        /// The cause.
        cause: PlantError,
    },
}

/// The initial joint state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Initial {
    /// q(0) per joint (default: the paper's [0.60, 1.80], rad).
    pub q: Vec<f64>,
    /// q̇(0) per joint (default: zeros, rad/s).
    pub qd: Vec<f64>,
}

impl Default for Initial {
    fn default() -> Self {
        Self {
            q: vec![0.60, 1.80],
            qd: vec![0.0, 0.0],
        }
    }
}

/// A whole scenario. Every table defaults to the paper's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scenario {
    /// A short name for summaries and logs (default: "paper").
    pub name: String,
    /// URDF path relative to the scenario file (default: the built-in two-link arm).
    pub robot: Option<String>,
    /// Length of the run (default: 20, s).
    pub duration_s: f64,
    /// Control and plant rate (default: 1000, Hz).
    pub rate_hz: f64,
    /// Seed of every random effect (sensor noise, disturbance noise, lost
    /// commands); the same seed reproduces a run bit for bit (default: 0;
    /// any u64, above `i64::MAX` written as a decimal string).
    #[serde(with = "seed")]
    pub seed: u64,
    /// Initial state.
    pub initial: Initial,
    /// Reference q_d(t).
    pub reference: ReferenceConfig,
    /// Envelope k_c(t).
    pub envelope: EnvelopeConfig,
    /// Controller parameters (SPEC §11).
    pub controller: ControllerParams,
    /// Plant integration settings and effects.
    pub plant: PlantConfig,
    /// Parameters of an external controller (`run --controller-cmd`), by
    /// the names it declares (`CMD --describe`); checked against that
    /// declaration before the run, passed to it as `own_params`.
    #[serde(skip_serializing_if = "toml::Table::is_empty")]
    pub external: toml::Table,
    /// What each seed varies besides the plant's noise (default: nothing).
    #[serde(skip_serializing_if = "Randomise::is_empty")]
    pub randomise: Randomise,
}

impl Default for Scenario {
    fn default() -> Self {
        Self {
            name: "paper".into(),
            robot: None,
            duration_s: 20.0,
            rate_hz: 1000.0,
            seed: 0,
            initial: Initial::default(),
            reference: ReferenceConfig::paper(),
            envelope: EnvelopeConfig::paper(),
            controller: ControllerParams::default(),
            plant: PlantConfig::default(),
            external: toml::Table::new(),
            randomise: Randomise::default(),
        }
    }
}

impl Scenario {
    /// Parses TOML; `file` names the source in errors.
    pub fn from_toml_str(text: &str, file: &str) -> Result<Self, ScenarioError> {
        let mut s: Scenario = toml::from_str(text).map_err(|e| ScenarioError::Toml {
            file: file.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        // Trajectory files are named relative to the scenario file.
        let base = Path::new(file).parent().unwrap_or(Path::new(""));
        s.read_trajectory_files(base, file)?;
        s.validate(file)?;
        Ok(s)
    }

    /// Parses the TOML a log keeps: never reads a file it names (a log is
    /// data from anyone; its scenario carries its trajectory samples), and
    /// a trajectory named by file without its samples is an error.
    pub fn from_log_toml(text: &str, file: &str) -> Result<Self, ScenarioError> {
        let s: Scenario = toml::from_str(text).map_err(|e| ScenarioError::Toml {
            file: file.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        for (key, named, samples) in [
            (
                "reference.file",
                &s.reference.file,
                s.reference.samples.is_some(),
            ),
            (
                "envelope.file",
                &s.envelope.file,
                s.envelope.samples.is_some(),
            ),
        ] {
            if named.is_some() && !samples {
                return Err(ScenarioError::Toml {
                    file: file.to_string(),
                    message: format!(
                        "{key} names a file but the scenario has none of its samples: \
                         a log's scenario must carry them (replay never reads files a log names)"
                    ),
                });
            }
        }
        s.validate(file)?;
        Ok(s)
    }

    /// Reads `reference.file` and `envelope.file` (relative to `base`) into
    /// their `samples`, unless they hold samples already.
    pub fn read_trajectory_files(&mut self, base: &Path, file: &str) -> Result<(), ScenarioError> {
        let slots = [
            (&self.reference.file, &mut self.reference.samples),
            (&self.envelope.file, &mut self.envelope.samples),
        ];
        for (name, samples) in slots {
            let (Some(name), None) = (name, &samples) else {
                continue;
            };
            let path = base.join(name);
            let text = wire::read_text_file(&path, TRAJECTORY_FILE_BYTES).map_err(|cause| {
                ScenarioError::Io {
                    file: format!("{file}: {}", path.display()),
                    cause,
                }
            })?;
            let read = trajectory::Samples::from_csv(&text, &path.display().to_string()).map_err(
                |cause| ScenarioError::Trajectory {
                    file: file.to_string(),
                    cause,
                },
            )?;
            *samples = Some(read);
        }
        Ok(())
    }

    /// Checks the values that do not depend on the robot.
    pub fn validate(&self, file: &str) -> Result<(), ScenarioError> {
        let invalid = |key: &str, value: f64, need: &str| ScenarioError::Invalid {
            file: file.to_string(),
            key: key.to_string(),
            value: value.to_string(),
            need: need.to_string(),
        };
        // The name reaches terminals, file names and logs: printable text only.
        // A bidirectional override makes it read as another name.
        if wire::forbidden_name_char(&self.name).is_some() || self.name.chars().count() > 200 {
            return Err(ScenarioError::Invalid {
                file: file.to_string(),
                key: "name".into(),
                value: format!("{:?}", self.name.chars().take(60).collect::<String>()),
                need: "at most 200 characters, none of them control or bidirectional \
                       formatting characters"
                    .into(),
            });
        }
        if !(self.duration_s.is_finite() && self.duration_s > 0.0 && self.duration_s <= 1e6) {
            return Err(invalid(
                "duration_s",
                self.duration_s,
                "a number of seconds in (0, 1e6]",
            ));
        }
        if !(self.rate_hz >= 1.0 && self.rate_hz <= 100_000.0) {
            return Err(invalid(
                "rate_hz",
                self.rate_hz,
                "a rate from 1 to 100000 Hz",
            ));
        }
        if let Some(r) = self.reference.rate_hz
            && !(1.0..=100_000.0).contains(&r)
        {
            return Err(invalid(
                "reference.rate_hz",
                r,
                "a rate from 1 to 100000 Hz",
            ));
        }
        if let (Some(r), Some(need)) = (
            self.reference.rate_hz,
            self.reference.rate_fault(self.rate_hz),
        ) {
            return Err(invalid("reference.rate_hz", r, &need));
        }
        if let Some(need) = self.reference.horizon_fault(self.rate_hz) {
            return Err(invalid(
                "reference.horizon_s",
                self.reference.horizon_s,
                &need,
            ));
        }
        for (key, v) in [
            ("initial.q", &self.initial.q),
            ("initial.qd", &self.initial.qd),
        ] {
            if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(invalid(&format!("{key}[{i}]"), *x, "a finite number"));
            }
        }
        self.controller
            .validate()
            .map_err(|cause| ScenarioError::Controller {
                file: file.to_string(),
                cause,
            })?;
        self.randomise.validate(file)?;
        self.plant
            .validate()
            .map_err(|cause| ScenarioError::Plant {
                file: file.to_string(),
                cause,
            })?;
        // With the envelope from the limits, the robot is needed to check it
        // (see `plan`); and a trajectory file's columns are matched to the
        // joints by name there, before reference and envelope are compared
        // (a missing joint is named, not counted).
        let from_file = self.reference.samples.is_some() || self.envelope.samples.is_some();
        let checked = if self.envelope.from_limits || from_file {
            self.reference.validate()
        } else {
            Reference::new(&self.reference, &self.envelope).map(|_| ())
        };
        checked.map_err(|cause| ScenarioError::Trajectory {
            file: file.to_string(),
            cause,
        })?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// #39 row 4: a log's scenario that names a file is never read from it.
    #[test]
    fn a_logs_scenario_never_reads_the_files_it_names() {
        for key in ["reference", "envelope"] {
            let text = format!("[{key}]\nfile = \"/etc/passwd\"\n");
            let e = Scenario::from_log_toml(&text, "log.mcap")
                .unwrap_err()
                .to_string();
            assert!(e.contains(&format!("{key}.file names a file")), "{e}");
            assert!(!e.contains("root:"), "{e}");
        }
        assert!(Scenario::from_log_toml(PAPER_TOML, "log.mcap").is_ok());
    }

    /// #48 item 16: a seed is any u64; TOML's integers stop at i64::MAX,
    /// so above it the seed is a decimal string (`--set` reads the bare
    /// digits so), written back the same way; a negative seed is refused
    /// naming the key.
    #[test]
    fn a_seed_above_i64_max_is_a_seed() {
        let set = |v: &str| Overrides {
            set: vec![crate::parse_set(&format!("seed={v}")).unwrap()],
            ..Default::default()
        };
        for (given, want) in [
            ("18446744073709551615", u64::MAX),
            ("9223372036854775808", 1 << 63),
            ("\"18446744073709551615\"", u64::MAX),
            ("7", 7),
        ] {
            let plan = load(None, &set(given)).unwrap();
            assert_eq!(plan.scenario.seed, want, "{given}");
            let text = toml::to_string(&plan.scenario).unwrap();
            let back = Scenario::from_toml_str(&text, "written.toml").unwrap();
            assert_eq!(back.seed, want, "{text}");
        }
        // A seed TOML holds stays an integer in the written text.
        let text = toml::to_string(&load(None, &set("7")).unwrap().scenario).unwrap();
        assert!(text.contains("seed = 7\n"), "{text}");
        for bad in ["-1", "18446744073709551616", "\"12a\"", "1.5"] {
            let e = load(None, &set(bad)).unwrap_err().to_string();
            assert!(e.contains("seed"), "{bad}: {e}");
        }
    }

    /// #48 item 16: obstacle and object names each name one body, in
    /// plain text: a name twice (across obstacles and objects, or an
    /// unnamed one's "obstacle N"), a control or bidirectional formatting
    /// character, is refused naming the field.
    #[test]
    fn contact_names_are_one_each_and_plain() {
        let body = |kind: &str, name: &str| {
            let extra = if kind == "object" {
                "mass = 0.1\nlink = \"link2\"\ngrasp_at_s = 1.0\n"
            } else {
                ""
            };
            format!(
                "[[plant.contact.{kind}]]\nname = {}\nshape = \"sphere\"\nsize = [0.05]\n\
                 xyz = [0.0, 0.0, -0.9]\n{extra}",
                toml::Value::from(name)
            )
        };
        let check = |bodies: &[String]| {
            let text = format!("[plant]\nengine = \"rapier\"\n{}", bodies.concat());
            Scenario::from_toml_str(&text, "s.toml")
                .and_then(|s| s.validate("s.toml"))
                .map_err(|e| e.to_string())
        };
        check(&[body("obstacle", "table"), body("object", "cup")]).unwrap();
        for (bodies, key) in [
            (
                vec![body("obstacle", "table"), body("obstacle", "table")],
                "plant.contact.obstacle[1].name",
            ),
            (
                vec![body("obstacle", "cup"), body("object", "cup")],
                "plant.contact.object[0].name",
            ),
            (
                vec![body("obstacle", ""), body("obstacle", "obstacle 1")],
                "plant.contact.obstacle[1].name",
            ),
            (
                vec![body("obstacle", "tab\nle")],
                "plant.contact.obstacle[0].name",
            ),
            (
                vec![body("obstacle", "a"), body("object", "cup\u{202E}")],
                "plant.contact.object[0].name",
            ),
        ] {
            let e = check(&bodies).unwrap_err();
            assert!(e.contains(key), "{key}: {e}");
        }
        let e = check(&[body("obstacle", &"x".repeat(65))]).unwrap_err();
        assert!(e.contains("at most 64 characters"), "{e}");
        let e = Scenario::from_toml_str("name = \"paper\\u202E\"\n", "s.toml")
            .and_then(|s| s.validate("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("name"), "{e}");
    }

    #[test]
    fn shipped_paper_toml_is_the_default() {
        let s = Scenario::from_toml_str(PAPER_TOML, "paper.toml").unwrap();
        assert_eq!(s, Scenario::default());
        let plan = load(None, &Overrides::default()).unwrap();
        assert_eq!((plan.period_ns, plan.steps), (1_000_000, 20_000));
        assert_eq!(plan.robot.model.joint_names(), ["joint1", "joint2"]);
    }

    #[test]
    fn empty_file_is_the_paper_scenario() {
        assert_eq!(
            Scenario::from_toml_str("", "x").unwrap(),
            Scenario::default()
        );
    }

    fn err(text: &str) -> String {
        Scenario::from_toml_str(text, "bad.toml")
            .unwrap_err()
            .to_string()
    }

    /// #48 item 12 (D12): `[reference] rate_hz = 50000` against a 1 kHz
    /// loop flooded a real-time run until the logger starved and was blamed
    /// ("not heard from"). A reference faster than the control rate is
    /// refused before anything starts, naming both rates; the control rate
    /// itself and slower are taken.
    #[test]
    fn a_reference_faster_than_the_control_rate_is_refused() {
        let e = err("[reference]\nrate_hz = 50000.0\n");
        assert!(
            e.starts_with("bad.toml")
                && e.contains("reference.rate_hz = 50000 is invalid")
                && e.contains("at most the control rate, rate_hz = 1000 Hz"),
            "{e}"
        );
        let e = err("rate_hz = 500.0\n[reference]\nrate_hz = 1000.0\n");
        assert!(e.contains("rate_hz = 500 Hz"), "{e}");
        for ok in [
            "[reference]\nrate_hz = 1000.0\n",
            "[reference]\nrate_hz = 250.0\n",
        ] {
            Scenario::from_toml_str(ok, "ok.toml").unwrap();
        }
    }

    #[test]
    fn errors_name_the_file_and_key() {
        assert!(err("[controller]\nk3 = 1.0\n").contains("unknown field `k3`"));
        assert!(err("[controller]\nk3 = 1.0\n").starts_with("bad.toml"));
        assert!(err("duration_s = nan\n").contains("duration_s = NaN is invalid"));
        assert!(err("rate_hz = 0.0\n").contains("rate_hz"));
        assert!(err("[controller]\nbeta = -1.0\n").contains("controller.beta"));
        assert!(err("[controller]\nbeta = \"ten\"\n").contains("beta"));
        assert!(err("[initial]\nq = [0.6, inf]\n").contains("initial.q[1]"));
        assert!(err("[plant]\nsubsteps = 0\n").contains("plant.substeps"));
        assert!(err("[envelope]\njoints = [{offset = 0.05, sin = 0.1, omega = 1.0}, {offset = 1.0}]\n[reference]\njoints = [{}, {}]\n")
            .contains("envelope.joints[0]"));
        assert!(err("[controller]\nintegrator = \"rk45\"\n").contains("integrator"));
    }

    #[test]
    fn lengths_are_checked_against_the_robot() {
        let s = Scenario::from_toml_str(
            "[initial]\nq = [0.1, 0.2, 0.3]\nqd = [0, 0, 0]\n",
            "three.toml",
        )
        .unwrap();
        let e = plan(
            s,
            "three.toml".into(),
            String::new(),
            RobotSource::builtin(),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "three.toml: initial.q = 3 entries is invalid: it must be one entry per actuated joint of built-in two_link.urdf (2: joint1, joint2)"
        );
    }

    #[test]
    fn missing_robot_file_names_the_path() {
        let dir = std::env::temp_dir().join(format!("scenario-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("s.toml");
        std::fs::write(&f, "robot = \"nope.urdf\"\n").unwrap();
        let e = load(Some(&f), &Overrides::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("nope.urdf"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
