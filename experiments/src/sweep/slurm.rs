//! `testbed sweep slurm`: the manifest and an `sbatch` job-array script.
//! Each array task runs its share of the runs (`sweep run --index
//! $SLURM_ARRAY_TASK_ID --tasks N`) into the shared results folder and
//! skips what is done, so resubmitting the same script runs only what is
//! missing.

use std::path::{Path, PathBuf};

use super::SweepError;
use super::results::{Manifest, open_folder, read_results};
use scenario::sweep_file::Sweep;

/// How the job array is laid out.
#[derive(Debug, Clone)]
pub struct SlurmOptions {
    /// Array tasks (None: one per run, at most 1000).
    pub tasks: Option<usize>,
    /// Tasks running at once (`%M`).
    pub max_running: usize,
    /// CPUs per task (each task runs its share on that many threads).
    pub cpus_per_task: usize,
    /// `--partition`.
    pub partition: Option<String>,
    /// `--time` limit per task.
    pub time: Option<String>,
    /// The `testbed` binary the tasks run (must be visible to the nodes).
    pub testbed: PathBuf,
}

/// What was written.
#[derive(Debug, Clone)]
pub struct SlurmScript {
    /// The script's path.
    pub path: PathBuf,
    /// Array tasks.
    pub tasks: usize,
    /// Runs still missing in the folder.
    pub missing: usize,
}

/// Writes `DIR/manifest.json` and `DIR/sweep.sbatch`.
pub fn write(sweep: &Sweep, dir: &Path, opts: &SlurmOptions) -> Result<SlurmScript, SweepError> {
    if opts.max_running == 0 || opts.cpus_per_task == 0 || opts.tasks == Some(0) {
        return Err(SweepError::Options(
            "--tasks, --max-running and --cpus-per-task must be at least 1".into(),
        ));
    }
    check_values(opts, dir)?;
    open_folder(dir, &Manifest::of(sweep))?;
    let (done, _) = read_results(dir)?;
    let missing = sweep
        .runs
        .iter()
        .filter(|r| !done.contains_key(&r.key))
        .count();
    let tasks = opts.tasks.unwrap_or(sweep.runs.len().clamp(1, 1000));
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (file, out, bin) = (abs(&sweep.path), abs(dir), abs(&opts.testbed));
    let mut s = String::from("#!/bin/bash\n");
    s += &format!(
        "#SBATCH --job-name=testbed-sweep-{}\n",
        sanitize(&sweep.name)
    );
    s += &format!("#SBATCH --array=0-{}%{}\n", tasks - 1, opts.max_running);
    s += &format!("#SBATCH --cpus-per-task={}\n", opts.cpus_per_task);
    s += &format!("#SBATCH --output={}/slurm-%A_%a.out\n", out.display());
    if let Some(p) = &opts.partition {
        s += &format!("#SBATCH --partition={p}\n");
    }
    if let Some(t) = &opts.time {
        s += &format!("#SBATCH --time={t}\n");
    }
    s += &format!(
        "# {} runs in {} tasks; {} missing when written. Resubmit to run what is missing.\n",
        sweep.runs.len(),
        tasks,
        missing
    );
    s += "set -euo pipefail\n";
    s += &format!(
        "exec {} sweep run {} --out {} --index \"$SLURM_ARRAY_TASK_ID\" --tasks {} \\\n    --threads \"${{SLURM_CPUS_PER_TASK:-1}}\" --no-progress\n",
        quote(&bin),
        quote(&file),
        quote(&out),
        tasks
    );
    let path = dir.join("sweep.sbatch");
    std::fs::write(&path, s).map_err(|cause| SweepError::Io {
        path: path.display().to_string(),
        cause,
    })?;
    Ok(SlurmScript {
        path,
        tasks,
        missing,
    })
}

/// A job name Slurm takes as written.
/// The values pasted into `#SBATCH` lines, which a shell quote cannot
/// protect: each must be what Slurm takes (a line break once injected
/// shell lines and dropped `--time`).
fn check_values(opts: &SlurmOptions, dir: &Path) -> Result<(), SweepError> {
    let ok = |v: &str, extra: &[char]| {
        !v.is_empty()
            && v.len() <= 200
            && v.chars()
                .all(|c| c.is_ascii_alphanumeric() || extra.contains(&c))
    };
    if let Some(p) = &opts.partition
        && !ok(p, &['_', '-', '.', ','])
    {
        return Err(SweepError::Options(format!(
            "--partition {p:?}: a partition name (letters, digits, '_', '-', '.'; several \
             separated by commas)"
        )));
    }
    if let Some(t) = &opts.time
        && !ok(t, &[':', '-'])
    {
        return Err(SweepError::Options(format!(
            "--time {t:?}: a Slurm time limit such as 30, 2:00:00 or 1-12:00:00"
        )));
    }
    if dir.to_string_lossy().chars().any(char::is_control) {
        return Err(SweepError::Options(format!(
            "--out {}: a folder name with a control character cannot go into #SBATCH --output",
            dir.display()
        )));
    }
    Ok(())
}

fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A path as one shell word.
fn quote(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', "'\\''"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_quoted_for_the_shell() {
        assert_eq!(quote(Path::new("/a b/it's")), "'/a b/it'\\''s'");
        assert_eq!(sanitize("paper gains!"), "paper_gains_");
    }
}
