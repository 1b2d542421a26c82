//! The sweep file: a base scenario, axes over any scenario key, seeds and
//! laws; expanded into one resolved [`Plan`] per run, all checked before
//! anything runs.

use std::path::{Path, PathBuf};

use crate::{Overrides, Plan, RobotSource, Scenario};
use controller::LawName;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

pub(crate) mod checks;
pub use crate::keys::MAX_KEY_PARTS;
use crate::keys::set_key;
use checks::{check_distinct, check_key, count_runs};

/// Files a sweep reads (sweep files, manifests, results) larger than this
/// are refused rather than read.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// Why a sweep file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SweepFileError {
    /// The sweep file is malformed or names an unknown key.
    #[error("{file}: {reason}")]
    File {
        /// The sweep file.
        file: String,
        /// What is wrong.
        reason: String,
    },
    /// A run's scenario is invalid.
    #[error("{file}: {cause}")]
    Scenario {
        /// The sweep file.
        file: String,
        /// The cause.
        cause: Box<crate::ScenarioError>,
    },
    /// Reading it failed.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        cause: std::io::Error,
    },
}

/// Sweeps larger than this are refused. Every run is resolved (its plan
/// and the hash that names it on disk) before the first starts, so that
/// a resumed or Slurm-split sweep agrees on each run's identity, and the
/// manifest lists every run. A run's plan is about 13 kB and resolving it
/// about 0.6 ms: 10⁵ runs took 1.28 GB and 64 s before the first began
/// (#48, D14), so the cap is 10⁴ (about 130 MB and 6 s). A larger study
/// is several sweeps.
pub const MAX_RUNS: usize = 10_000;

/// A sweep file as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// A name for reports (default: the file's stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Base scenario: a shipped name or a path relative to the sweep file
    /// (default: the paper's).
    #[serde(default)]
    pub scenario: Option<String>,
    /// An arm (URDF, relative to the sweep file) instead of the scenario's;
    /// with no `scenario`, the arm's default scenario.
    #[serde(default)]
    pub robot: Option<String>,
    /// Seeds per cell: the scenario's seed, +1, … (default: 1).
    #[serde(default = "one")]
    pub seeds: u64,
    /// The laws, each a cell of its own (default: the scenario's law).
    #[serde(default)]
    pub laws: Vec<LawName>,
    /// Fixed values for every run, by dotted scenario key.
    #[serde(default)]
    pub set: toml::Table,
    /// The axes, in order: the grid is their product.
    #[serde(default)]
    pub axis: Vec<Axis>,
}

fn one() -> u64 {
    1
}

/// One axis: a scenario key and its values.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    /// Dotted scenario key, e.g. `controller.k1` or `plant.payload.mass`.
    pub key: String,
    /// The values as listed.
    #[serde(default)]
    pub values: Option<Vec<toml::Value>>,
    /// `num` evenly spaced values from `start` to `stop`, both included.
    #[serde(default)]
    pub range: Option<Range>,
    /// `draws` values drawn uniformly from [min, max) with `seed`.
    #[serde(default)]
    pub random: Option<RandomDraws>,
}

/// Evenly spaced values.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Range {
    /// First value.
    pub start: f64,
    /// Last value.
    pub stop: f64,
    /// How many (≥ 1).
    pub num: usize,
}

/// Seeded uniform draws.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomDraws {
    /// Lower bound.
    pub min: f64,
    /// Upper bound (above `min`).
    pub max: f64,
    /// How many (≥ 1).
    pub draws: usize,
    /// The draws' own seed (default: 0).
    #[serde(default)]
    pub seed: u64,
}

/// One run of a sweep, resolved.
#[derive(Debug, Clone)]
pub struct RunSpec {
    /// Position in the sweep (cells in axis order, then laws, then seeds).
    pub index: usize,
    /// Hash of the run's resolved scenario and URDF: its identity on disk.
    pub key: String,
    /// The axis values of its cell, in axis order.
    pub cell: Vec<(String, toml::Value)>,
    /// The law.
    pub law: LawName,
    /// The seed of every random effect.
    pub seed: u64,
    /// What `testbed sim` would run.
    pub plan: Plan,
}

/// A sweep file read and expanded.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// Its name.
    pub name: String,
    /// The file it came from.
    pub path: PathBuf,
    /// The file's text (kept in the manifest).
    pub text: String,
    /// Axis keys, in order.
    pub axes: Vec<String>,
    /// Every run.
    pub runs: Vec<RunSpec>,
}

impl Axis {
    /// How many values the axis has, read without making them (None:
    /// not exactly one of values, range and random).
    fn count(&self) -> Option<usize> {
        match (&self.values, &self.range, &self.random) {
            (Some(v), None, None) => Some(v.len()),
            (None, Some(r), None) => Some(r.num),
            (None, None, Some(d)) => Some(d.draws),
            _ => None,
        }
    }

    /// The axis's values; exactly one of values, range and random is given.
    fn expand(&self, file: &str) -> Result<Vec<toml::Value>, SweepFileError> {
        let bad = |reason: String| SweepFileError::File {
            file: file.to_string(),
            reason: format!("axis {}: {reason}", self.key),
        };
        let out = match (&self.values, &self.range, &self.random) {
            (Some(v), None, None) => v.clone(),
            (None, Some(r), None) => {
                if r.num == 0 || !r.start.is_finite() || !r.stop.is_finite() {
                    return Err(bad("range needs finite start and stop and num ≥ 1".into()));
                }
                let step = if r.num > 1 {
                    (r.stop - r.start) / (r.num - 1) as f64
                } else {
                    0.0
                };
                (0..r.num)
                    .map(|i| toml::Value::Float(r.start + step * i as f64))
                    .collect()
            }
            (None, None, Some(d)) => {
                if d.draws == 0 || !(d.min.is_finite() && d.max.is_finite() && d.min < d.max) {
                    return Err(bad("random needs finite min < max and draws ≥ 1".into()));
                }
                let mut rng = ChaCha8Rng::seed_from_u64(d.seed);
                (0..d.draws)
                    .map(|_| toml::Value::Float(rng.random_range(d.min..d.max)))
                    .collect()
            }
            _ => return Err(bad("give exactly one of values, range, random".into())),
        };
        if out.is_empty() {
            return Err(bad("no values".into()));
        }
        // Two equal values would be two identical cells. By their text
        // (−0.0 as 0.0, as == has it), in one pass: comparing each value
        // with every earlier one was quadratic in the axis's length.
        let mut seen = std::collections::HashSet::with_capacity(out.len());
        for v in &out {
            let text = match v {
                toml::Value::Float(x) if *x == 0.0 => "0.0".to_string(),
                other => other.to_string(),
            };
            if !seen.insert(text) {
                return Err(bad(format!("value {v} is listed twice")));
            }
        }
        Ok(out)
    }
}

/// Reads and expands the sweep file at `path`: every run's plan is built
/// (and so validated) here.
pub fn load(path: &Path) -> Result<Sweep, SweepFileError> {
    let text = wire::read_text_file(path, MAX_FILE_BYTES).map_err(|cause| SweepFileError::Io {
        path: path.display().to_string(),
        cause,
    })?;
    from_text(path, text)
}

/// How many runs the sweep file `text` (at `path`) makes, counted without
/// making them.
pub fn planned_runs(path: &Path, text: &str) -> Result<usize, SweepFileError> {
    let file = path.display().to_string();
    let spec = parse(text, &file)?;
    check_distinct(&spec, &file)?;
    count_runs(&spec, spec.laws.len(), &file)
}

fn parse(text: &str, file: &str) -> Result<SweepFile, SweepFileError> {
    toml::from_str(text).map_err(|e| SweepFileError::File {
        file: file.to_string(),
        reason: e.to_string().trim_end().to_string(),
    })
}

/// [`load`] of a sweep file's `text`, read from `path` (which relative
/// paths in it start from).
pub fn from_text(path: &Path, text: String) -> Result<Sweep, SweepFileError> {
    let file = path.display().to_string();
    let spec = parse(&text, &file)?;
    if spec.seeds == 0 {
        return Err(SweepFileError::File {
            file,
            reason: "seeds = 0: a sweep needs at least one seed".into(),
        });
    }
    check_distinct(&spec, &file)?;
    count_runs(&spec, spec.laws.len(), &file)?;
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let base = base_plan(&spec, &base_dir, &file)?;
    let mut axes_values = Vec::new();
    for axis in &spec.axis {
        axes_values.push((axis.key.clone(), axis.expand(&file)?));
    }
    let sets = spec.set.iter().map(|(k, v)| ("set", k.clone(), v.clone()));
    // Every axis value, not only the first: a bad one is named here, at
    // the user's file, not at a line of a generated scenario.
    let values = axes_values
        .iter()
        .flat_map(|(k, v)| v.iter().map(move |x| ("axis", k.clone(), x.clone())));
    for (what, key, value) in sets.chain(values) {
        check_key(&base, what, &key, value, &file)?;
    }
    let laws = if spec.laws.is_empty() {
        vec![base.scenario.controller.law]
    } else {
        spec.laws.clone()
    };
    let cells = cartesian(&axes_values);
    let total = cells
        .len()
        .saturating_mul(laws.len())
        .saturating_mul(spec.seeds as usize);
    if total > MAX_RUNS {
        return Err(SweepFileError::File {
            file,
            reason: format!("{total} runs: at most {MAX_RUNS} per sweep"),
        });
    }
    let mut runs = Vec::with_capacity(total);
    for cell in &cells {
        for &law in &laws {
            for s in 0..spec.seeds {
                let index = runs.len();
                let plan = resolve(&base, &spec, cell, law, s, &base_dir, &file)?;
                runs.push(RunSpec {
                    index,
                    key: run_key(&plan)?,
                    cell: cell.clone(),
                    // The law that runs, whatever set it.
                    law: plan.scenario.controller.law,
                    seed: plan.scenario.seed,
                    plan,
                });
            }
        }
    }
    let mut seen = std::collections::HashMap::new();
    for r in &runs {
        if let Some(first) = seen.insert(r.key.as_str(), r.index) {
            return Err(SweepFileError::File {
                file,
                reason: format!(
                    "runs {first} and {} are the same run (same scenario, law and seed): \
                     an axis or [set] value changes nothing",
                    r.index
                ),
            });
        }
    }
    let name = spec.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map_or_else(|| "sweep".into(), |s| s.to_string_lossy().to_string())
    });
    // The name becomes a folder name: letters, digits, '-', '_', '.' only.
    let plain = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    if name.is_empty() || name.starts_with('.') || name.len() > 100 || !name.chars().all(plain) {
        return Err(SweepFileError::File {
            file,
            reason: format!(
                "name = {name:?}: use up to 100 letters, digits, '-', '_' or '.' (not first)"
            ),
        });
    }
    Ok(Sweep {
        name,
        path: path.to_path_buf(),
        text,
        axes: spec.axis.iter().map(|a| a.key.clone()).collect(),
        runs,
    })
}

fn base_plan(spec: &SweepFile, dir: &Path, file: &str) -> Result<Plan, SweepFileError> {
    let scenario = spec.scenario.as_ref().map(|s| {
        let p = dir.join(s);
        if p.exists() {
            p
        } else {
            crate::find_shipped(s).map_or(p, |sh| sh.path())
        }
    });
    let overrides = Overrides {
        robot: spec.robot.as_ref().map(|r| dir.join(r)),
        ..Overrides::default()
    };
    crate::load(scenario.as_deref(), &overrides).map_err(|cause| SweepFileError::Scenario {
        file: file.to_string(),
        cause: Box::new(cause),
    })
}

/// Every combination of the axes' values, the first axis slowest.
fn cartesian(axes: &[(String, Vec<toml::Value>)]) -> Vec<Vec<(String, toml::Value)>> {
    let mut cells = vec![Vec::new()];
    for (key, values) in axes {
        cells = cells
            .into_iter()
            .flat_map(|c| {
                values.iter().map(move |v| {
                    let mut c = c.clone();
                    c.push((key.clone(), v.clone()));
                    c
                })
            })
            .collect();
    }
    cells
}

/// The plan of one run: the base scenario for `law`, the `set` values,
/// the cell's values and seed base + s, validated against the robot.
fn resolve(
    base: &Plan,
    spec: &SweepFile,
    cell: &[(String, toml::Value)],
    law: LawName,
    s: u64,
    dir: &Path,
    file: &str,
) -> Result<Plan, SweepFileError> {
    let mut scenario = base.undrawn.clone();
    scenario.controller = scenario.controller.for_law(law);
    scenario.seed = base.undrawn.seed.wrapping_add(s);
    let cannot = |e: String| SweepFileError::File {
        file: file.to_string(),
        reason: format!("cannot write the base scenario: {e}"),
    };
    let mut tree = match toml::Value::try_from(&scenario).map_err(|e| cannot(e.to_string()))? {
        toml::Value::Table(t) => t,
        _ => return Err(cannot("not a table".into())),
    };
    let sets = spec.set.iter().map(|(k, v)| (k.clone(), v.clone()));
    let what = |key: &str, reason: String| SweepFileError::File {
        file: file.to_string(),
        reason: format!("{key}: {reason}"),
    };
    for (key, value) in sets.chain(cell.iter().cloned()) {
        set_key(&mut tree, &key, value).map_err(|r| what(&key, r.to_string()))?;
    }
    let label = format!("{file} ({law}, seed {})", scenario.seed);
    let toml_text = toml::to_string(&tree).map_err(|e| what("scenario", e.to_string()))?;
    let scenario =
        Scenario::from_toml_str(&toml_text, &label).map_err(|cause| SweepFileError::Scenario {
            file: file.to_string(),
            cause: Box::new(cause),
        })?;
    let robot = match &scenario.robot {
        Some(r) if scenario.robot != base.scenario.robot => {
            RobotSource::from_file(&dir.join(r), &scenario.plant.lock)
        }
        _ => base.robot.relocked(&scenario.plant.lock),
    }
    .map_err(|cause| SweepFileError::Scenario {
        file: file.to_string(),
        cause: Box::new(cause),
    })?;
    crate::plan(scenario, label, toml_text, robot).map_err(|cause| SweepFileError::Scenario {
        file: file.to_string(),
        cause: Box::new(cause),
    })
}

/// A run's identity: SHA-256 of its resolved scenario and its URDF.
fn run_key(plan: &Plan) -> Result<String, SweepFileError> {
    let mut s = plan.scenario.clone();
    s.robot = None;
    let text = toml::to_string(&s).map_err(|e| SweepFileError::File {
        file: plan.source.clone(),
        reason: format!("cannot write the scenario: {e}"),
    })?;
    let mut h = Sha256::new();
    h.update(text.as_bytes());
    h.update(b"\0urdf\0");
    h.update(plan.robot.urdf.as_bytes());
    let digest = h.finalize();
    Ok(digest.iter().take(8).map(|b| format!("{b:02x}")).collect())
}

/// A cell's values as JSON, for result lines and reports.
pub fn cell_json(cell: &[(String, toml::Value)]) -> serde_json::Map<String, serde_json::Value> {
    cell.iter()
        .map(|(k, v)| {
            let j = serde_json::to_value(v).unwrap_or(serde_json::Value::Null);
            (k.clone(), j)
        })
        .collect()
}

/// What the manifest records of one run.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ManifestRun {
    /// Position in the sweep.
    pub index: usize,
    /// Its key.
    pub key: String,
    /// Its law.
    pub law: LawName,
    /// Its seed.
    pub seed: u64,
    /// Its cell.
    pub cell: serde_json::Map<String, serde_json::Value>,
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// `load` of a sweep file with `text`; the error's text.
    fn refused(text: &str) -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(&path, text).unwrap();
        let e = load(&path).map(|s| s.runs.len()).unwrap_err().to_string();
        assert!(e.contains("s.toml"), "{e}");
        e
    }

    #[test]
    fn huge_axes_are_counted_before_they_are_made() {
        // #31 row 1: these once aborted allocating their values.
        let e = refused(
            "[[axis]]\nkey = \"controller.k1\"\nrange = { start = 1.0, stop = 2.0, num = 1000000000 }\n",
        );
        assert!(e.contains(&format!("at most {MAX_RUNS} per sweep")), "{e}");
        let axis = |k: &str| {
            format!("[[axis]]\nkey = \"{k}\"\nrange = {{ start = 1.0, stop = 2.0, num = 1000 }}\n")
        };
        let e =
            refused(&(axis("controller.k1") + &axis("controller.k2") + &axis("controller.beta")));
        assert!(e.contains("1000000000 runs"), "{e}");
    }

    #[test]
    fn a_key_of_thousands_of_parts_is_refused_at_once() {
        // #31 row 2: 20 000 parts once took 2.8 GB or overflowed the stack.
        let key = vec!["a"; 20_000].join(".");
        let e = refused(&format!("[set]\n\"{key}\" = 1.0\n"));
        assert!(e.contains("more than 8 dotted parts"), "{e}");
    }

    #[test]
    fn a_law_fixed_beside_laws_is_refused() {
        // #31 row 3: ctc ran, labelled nac and pd.
        let e = refused("laws = [\"nac\", \"pd\"]\n[set]\n\"controller.law\" = \"ctc\"\n");
        assert!(e.contains("controller.law is set"), "{e}");
        let e = refused(
            "laws = [\"nac\"]\n[[axis]]\nkey = \"controller.law\"\nvalues = [\"pd\", \"ctc\"]\n",
        );
        assert!(e.contains("controller.law is set"), "{e}");
    }

    #[test]
    fn without_laws_the_label_is_the_law_that_runs() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(
            &path,
            "[set]\nduration_s = 0.01\n\"controller.law\" = \"ctc\"\n",
        )
        .unwrap();
        let s = load(&path).unwrap();
        assert_eq!(s.runs[0].law, LawName::Ctc);
    }

    #[test]
    fn duplicates_are_refused_and_named() {
        // #31 row 4: identical runs counted as distinct seeds.
        let e = refused("seeds = 4\n[set]\nseed = 7\n");
        assert!(e.contains("seed is set"), "{e}");
        let e = refused("laws = [\"pd\", \"pd\"]\n");
        assert!(e.contains("laws lists pd twice"), "{e}");
        let e = refused("[[axis]]\nkey = \"controller.k1\"\nvalues = [2.0, 3.0, 2.0]\n");
        assert!(e.contains("value 2.0 is listed twice"), "{e}");
        let axis = "[[axis]]\nkey = \"controller.k1\"\nvalues = [2.0, 3.0]\n";
        let e = refused(&format!("{axis}{axis}"));
        assert!(e.contains("given twice"), "{e}");
    }
}

#[cfg(test)]
mod later_values {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]

    /// #31 row 20: a bad value that is not an axis's first is named at the
    /// user's file and key, not at a line of a generated scenario.
    #[test]
    fn a_bad_later_axis_value_is_named_at_the_sweep_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(
            &path,
            "[[axis]]\nkey = \"controller.integrator\"\nvalues = [\"exact\", \"rk9\"]\n",
        )
        .unwrap();
        let e = super::load(&path).map(|_| ()).unwrap_err().to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        assert!(
            e.contains("axis controller.integrator") && e.contains("rk9"),
            "{e}"
        );
    }
}
