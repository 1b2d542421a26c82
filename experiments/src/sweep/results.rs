//! A sweep's results folder: `manifest.json` (the sweep and every run's
//! key) and `results-*.jsonl`, one JSON line per finished run, appended by
//! each process that runs some (one file per process, so that Slurm tasks
//! sharing the folder never interleave). A run whose key has a line is
//! done; a line cut short by a kill is ignored and its run done again.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::SweepError;
use scenario::sweep_file::{ManifestRun, Sweep, cell_json};

/// The manifest of a results folder.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The sweep's name.
    pub name: String,
    /// The sweep file, absolute.
    pub file: String,
    /// Its text when the folder was made.
    pub text: String,
    /// Axis keys, in order.
    pub axes: Vec<String>,
    /// Every run.
    pub runs: Vec<ManifestRun>,
}

impl Manifest {
    /// The manifest of `sweep`.
    pub fn of(sweep: &Sweep) -> Self {
        Self {
            name: sweep.name.clone(),
            file: std::path::absolute(&sweep.path)
                .unwrap_or_else(|_| sweep.path.clone())
                .display()
                .to_string(),
            text: sweep.text.clone(),
            axes: sweep.axes.clone(),
            runs: sweep
                .runs
                .iter()
                .map(|r| ManifestRun {
                    index: r.index,
                    key: r.key.clone(),
                    law: r.law,
                    seed: r.seed,
                    cell: cell_json(&r.cell),
                })
                .collect(),
        }
    }
}

/// One finished run, as a line of `results-*.jsonl`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ResultLine {
    /// The run's key (hash of its resolved scenario and URDF).
    pub key: String,
    /// Position in the sweep.
    pub index: usize,
    /// The law.
    pub law: String,
    /// The seed.
    pub seed: u64,
    /// Axis values.
    pub cell: serde_json::Map<String, serde_json::Value>,
    /// "ok", "diverged" (non-finite values or faults) or "failed" (the
    /// loop stopped: the reason says why).
    pub status: String,
    /// Why it diverged or failed.
    pub reason: Option<String>,
    /// |e| < k_c for every t ≥ T_c, every value finite, and the run whole.
    pub kept_envelope: bool,
    /// Every metric of `compare` (null: missing, counted as the worst).
    pub metrics: serde_json::Map<String, serde_json::Value>,
    /// The whole summary, as `testbed sim --json` prints it.
    pub summary: serde_json::Value,
}

/// Writes `manifest.json` into `dir` (created), or checks that the one
/// there describes the same runs.
pub fn open_folder(dir: &Path, manifest: &Manifest) -> Result<(), SweepError> {
    std::fs::create_dir_all(dir).map_err(|cause| io(dir, cause))?;
    let path = dir.join("manifest.json");
    if path.exists() {
        let old = read_manifest(dir)?;
        if old.runs != manifest.runs {
            return Err(SweepError::Folder {
                dir: dir.display().to_string(),
                reason: format!(
                    "it holds another sweep ({}, {} runs); use another --out or remove it",
                    old.name,
                    old.runs.len()
                ),
            });
        }
        return Ok(());
    }
    let text = serde_json::to_string_pretty(manifest).map_err(|e| SweepError::Folder {
        dir: dir.display().to_string(),
        reason: e.to_string(),
    })?;
    // Written whole, then renamed: a kill never leaves half a manifest.
    let tmp = dir.join(format!(".manifest.{}.tmp", std::process::id()));
    std::fs::write(&tmp, text).map_err(|cause| io(&tmp, cause))?;
    std::fs::rename(&tmp, &path).map_err(|cause| io(&path, cause))
}

/// The manifest in `dir`.
pub fn read_manifest(dir: &Path) -> Result<Manifest, SweepError> {
    let path = dir.join("manifest.json");
    let text = super::read_limited(&path)?;
    serde_json::from_str(&text).map_err(|e| SweepError::Folder {
        dir: dir.display().to_string(),
        reason: format!("manifest.json: {e}"),
    })
}

/// Every complete result line in `dir`, by key (the first line of a key
/// wins), and how many lines were cut short or unreadable.
pub fn read_results(dir: &Path) -> Result<(BTreeMap<String, ResultLine>, usize), SweepError> {
    let mut out = BTreeMap::new();
    let mut bad = 0;
    for path in result_files(dir)? {
        let text = super::read_limited(&path)?;
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            match serde_json::from_str::<ResultLine>(line) {
                Ok(r) => {
                    out.entry(r.key.clone()).or_insert(r);
                }
                Err(_) => bad += 1,
            }
        }
    }
    Ok((out, bad))
}

fn result_files(dir: &Path) -> Result<Vec<PathBuf>, SweepError> {
    let entries = std::fs::read_dir(dir).map_err(|cause| io(dir, cause))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("results-") && n.ends_with(".jsonl"))
        })
        .collect();
    files.sort();
    Ok(files)
}

/// Appends result lines to this process's own file.
pub struct ResultWriter {
    path: PathBuf,
    file: std::fs::File,
}

impl ResultWriter {
    /// `results-<worker>.jsonl` in `dir`, appended to.
    pub fn open(dir: &Path, worker: &str) -> Result<Self, SweepError> {
        let path = dir.join(format!("results-{worker}.jsonl"));
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|cause| io(&path, cause))?;
        Ok(Self { path, file })
    }

    /// Writes one line and flushes it to the OS (one `write` per line).
    pub fn append(&mut self, line: &ResultLine) -> Result<(), SweepError> {
        let mut text = serde_json::to_string(line).map_err(|e| SweepError::Folder {
            dir: self.path.display().to_string(),
            reason: e.to_string(),
        })?;
        text.push('\n');
        self.file
            .write_all(text.as_bytes())
            .and_then(|_| self.file.flush())
            .map_err(|cause| io(&self.path, cause))?;
        self.check_still_there()
    }

    /// Whether the file written to is still the one at its path: a results
    /// folder removed (or replaced) while the sweep ran once left every
    /// result in an unlinked file and the sweep said "results in …".
    pub fn check_still_there(&self) -> Result<(), SweepError> {
        use std::os::unix::fs::MetadataExt;
        let same = match (std::fs::metadata(&self.path), self.file.metadata()) {
            (Ok(on_disk), Ok(open)) => on_disk.dev() == open.dev() && on_disk.ino() == open.ino(),
            _ => false,
        };
        if same {
            Ok(())
        } else {
            Err(SweepError::Folder {
                dir: self.path.display().to_string(),
                reason: "was removed or replaced while the sweep ran: the results written \
                         since are lost (run the sweep again; it does only what is missing)"
                    .into(),
            })
        }
    }
}

fn io(path: &Path, cause: std::io::Error) -> SweepError {
    SweepError::Io {
        path: path.display().to_string(),
        cause,
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// #39 row 16: the final check (made after the last line, where no
    /// run's timing can place a removal) finds a folder removed or
    /// replaced after the writer opened its file, and passes one left
    /// alone.
    #[test]
    fn a_folder_removed_or_replaced_after_the_last_line_is_found() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("sweep");
        for replace in [false, true] {
            std::fs::create_dir_all(&dir).unwrap();
            let w = ResultWriter::open(&dir, "w0").unwrap();
            w.check_still_there().unwrap();
            std::fs::remove_dir_all(&dir).unwrap();
            if replace {
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(dir.join("results-w0.jsonl"), "").unwrap();
            }
            let e = w.check_still_there().unwrap_err().to_string();
            assert!(e.contains("removed or replaced while the sweep ran"), "{e}");
        }
    }
}
