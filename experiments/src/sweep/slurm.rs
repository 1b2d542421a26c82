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
    /// What was changed from the options given (more tasks than runs).
    pub note: Option<String>,
}

/// The most CPUs a task asks for: more than a node has is a typo, and
/// Slurm would keep such a job pending for ever.
pub const MAX_CPUS_PER_TASK: usize = 1024;

/// Writes `DIR/manifest.json` and `DIR/sweep.sbatch`.
pub fn write(sweep: &Sweep, dir: &Path, opts: &SlurmOptions) -> Result<SlurmScript, SweepError> {
    if opts.max_running == 0 || opts.cpus_per_task == 0 || opts.tasks == Some(0) {
        return Err(SweepError::Options(
            "--tasks, --max-running and --cpus-per-task must be at least 1".into(),
        ));
    }
    if opts.cpus_per_task > MAX_CPUS_PER_TASK {
        return Err(SweepError::Options(format!(
            "--cpus-per-task {}: at most {MAX_CPUS_PER_TASK} (CPUs of one node)",
            opts.cpus_per_task
        )));
    }
    check_values(opts, dir)?;
    open_folder(dir, &Manifest::of(sweep))?;
    let (done, _) = read_results(dir)?;
    let missing = sweep
        .runs
        .iter()
        .filter(|r| !done.contains_key(&r.key))
        .count();
    let runs = sweep.runs.len().max(1);
    // A task beyond the runs would run nothing (100 000 tasks for 3 runs
    // asked Slurm for 99 997 empty jobs).
    let (tasks, note) = match opts.tasks {
        None => (runs.min(1000), None),
        Some(n) if n > runs => (
            runs,
            Some(format!(
                "--tasks {n} is more than the sweep's {runs} runs: {runs} tasks, one run each"
            )),
        ),
        Some(n) => (n, None),
    };
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
        note,
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

    /// #48 item 16: more tasks than runs are cut to the runs, said in a
    /// note (100 000 tasks for 3 runs were written as asked), and
    /// `--cpus-per-task` past [`MAX_CPUS_PER_TASK`] is refused naming the flag.
    #[test]
    fn tasks_are_at_most_the_runs_and_cpus_bounded() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("s.toml");
        std::fs::write(&file, "name = \"three\"\nscenario = \"paper\"\nseeds = 3\n").unwrap();
        let sweep = scenario::sweep_file::load(&file).unwrap();
        assert_eq!(sweep.runs.len(), 3);
        let opts = |tasks: Option<usize>, cpus: usize| SlurmOptions {
            tasks,
            max_running: 16,
            cpus_per_task: cpus,
            partition: None,
            time: None,
            testbed: PathBuf::from("/bin/testbed"),
        };
        let out = dir.path().join("out");
        let w = write(&sweep, &out, &opts(Some(100_000), 1)).unwrap();
        assert_eq!(w.tasks, 3);
        assert!(w.note.unwrap().contains("--tasks 100000"));
        let script = std::fs::read_to_string(&w.path).unwrap();
        assert!(
            script.contains("--array=0-2%16") && script.contains("--tasks 3"),
            "{script}"
        );
        let w = write(&sweep, &out, &opts(Some(2), 1)).unwrap();
        assert_eq!((w.tasks, w.note), (2, None));
        let e = write(&sweep, &out, &opts(None, 99_999_999_999))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--cpus-per-task 99999999999: at most 1024"),
            "{e}"
        );
        assert!(write(&sweep, &out, &opts(None, MAX_CPUS_PER_TASK)).is_ok());
    }
}
