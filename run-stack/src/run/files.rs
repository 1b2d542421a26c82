//! The run's folder, written before any node starts: the scenario as it
//! runs, the Foxglove layout for its arm, each node's config, and where the
//! log goes.

use std::path::{Path, PathBuf};

use logger::foxglove_layout;

use crate::node::configs::LoggerOptions;
use wire::NodeKind;

use super::{RunError, RunOptions, run_id};

/// The Foxglove layout's name in a run's folder.
pub const LAYOUT_FILE: &str = "foxglove-layout.json";

/// The run's folder: the scenario it runs, each node's config, the log's path.
pub(super) struct RunFiles {
    pub(super) run_dir: PathBuf,
    pub(super) log: PathBuf,
    pub(super) configs: Vec<(NodeKind, PathBuf)>,
}

/// The most characters of a run folder's name (`--name`).
pub const MAX_RUN_NAME_CHARS: usize = 100;
/// The most bytes of a run folder's name: a file name's limit on Linux.
const MAX_RUN_NAME_BYTES: usize = 255;

/// Why `name` cannot name a run's folder (`--name`), if it cannot: one
/// path component of 1 to [`MAX_RUN_NAME_CHARS`] characters (and at most
/// 255 bytes), no '/', not `.` or `..`, no control or bidirectional
/// formatting character (U+202E made `run\u{202E}txt.mcap` read as
/// another name).
pub fn run_name_problem(name: &str) -> Option<String> {
    let chars = name.chars().count();
    if name.is_empty() || name == "." || name == ".." {
        return Some("1 to 100 characters, not . or ..".into());
    }
    if chars > MAX_RUN_NAME_CHARS {
        return Some(format!("{chars} characters: at most {MAX_RUN_NAME_CHARS}"));
    }
    if name.len() > MAX_RUN_NAME_BYTES {
        return Some(format!(
            "{} bytes in UTF-8: a file name holds at most {MAX_RUN_NAME_BYTES}",
            name.len()
        ));
    }
    if name.contains('/') {
        return Some("one folder name: no '/'".into());
    }
    wire::forbidden_name_char(name).map(|c| {
        format!(
            "it holds {}: no control or bidirectional formatting character",
            wire::describe_char(c)
        )
    })
}

/// Makes the run's folder under `runs_dir`: `name`, or a fresh id (with a
/// suffix when a run of this process made one the same second). A folder
/// is never reused: an earlier run's files stay as they are.
fn new_folder(runs_dir: &Path, name: Option<&str>) -> Result<PathBuf, RunError> {
    let fail = |p: &Path, e: std::io::Error| RunError::Output(p.display().to_string(), e);
    let id = run_id();
    if let Some(why) = name.and_then(run_name_problem) {
        return Err(fail(
            runs_dir,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, format!("--name: {why}")),
        ));
    }
    let tries: Vec<String> = match name {
        Some(n) => vec![n.to_string()],
        None => std::iter::once(id.clone())
            .chain((2..100).map(|k| format!("{id}-{k}")))
            .collect(),
    };
    for t in &tries {
        let dir = std::path::absolute(runs_dir.join(t)).map_err(|e| fail(runs_dir, e))?;
        match std::fs::create_dir(&dir) {
            Ok(()) => return Ok(dir),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && name.is_none() => {}
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let why = "a run folder of that name exists: choose another --name, or remove it";
                return Err(fail(&dir, std::io::Error::new(e.kind(), why)));
            }
            Err(e) => return Err(fail(&dir, e)),
        }
    }
    Err(fail(
        runs_dir,
        std::io::Error::other("no free run folder name: 99 runs this second"),
    ))
}

/// What a log says ran as the controller when it was started by hand.
const BY_HAND: &str = "a controller node started by hand (--external controller)";

impl RunFiles {
    pub(super) fn write(
        opts: &RunOptions,
        declared: Option<&super::external::Declared>,
    ) -> Result<Self, RunError> {
        let plan = &opts.plan;
        let out = |p: &Path| {
            let p = p.display().to_string();
            move |e| RunError::Output(p.clone(), e)
        };
        // A file there (/dev/null) made create_dir_all say "File exists".
        if let Ok(m) = std::fs::metadata(&opts.runs_dir)
            && !m.is_dir()
        {
            return Err(RunError::Output(
                opts.runs_dir.display().to_string(),
                std::io::Error::new(
                    std::io::ErrorKind::NotADirectory,
                    "not a folder: --runs-dir names the folder each run's folder is made in",
                ),
            ));
        }
        std::fs::create_dir_all(&opts.runs_dir).map_err(out(&opts.runs_dir))?;
        let run_dir = new_folder(&opts.runs_dir, opts.name.as_deref())?;
        let scenario_file = run_dir.join("scenario.toml");
        let toml = plan.effective_toml().map_err(|e| {
            RunError::Output(
                scenario_file.display().to_string(),
                std::io::Error::other(e),
            )
        })?;
        std::fs::write(&scenario_file, &toml).map_err(out(&scenario_file))?;
        let layout_file = run_dir.join(LAYOUT_FILE);
        let layout = foxglove_layout(&plan.robot.model.joint_names());
        let layout = serde_json::to_string_pretty(&layout).map_err(|e| {
            RunError::Output(layout_file.display().to_string(), std::io::Error::other(e))
        })?;
        std::fs::write(&layout_file, layout + "\n").map_err(out(&layout_file))?;
        let log = run_dir.join("run.mcap");
        // A controller node started by hand runs what its starter chose: the
        // log must not label it as the scenario's law alone (#39 row 15).
        let by_hand =
            opts.external.contains(&wire::NodeKind::Controller) && opts.controller_cmd.is_none();
        let command = match &opts.controller_cmd {
            Some(c) => Some(shell_words::join(c)),
            None if by_hand => Some(BY_HAND.to_string()),
            None => None,
        };
        let configs = crate::node::configs::write_all(
            &run_dir.join("nodes"),
            plan,
            opts.mode,
            &log,
            &toml,
            LoggerOptions {
                controller_cmd: command.as_deref(),
                declared,
                live: opts.live.as_ref(),
                compression: opts.log_compression,
            },
        )
        .map_err(|e| RunError::Output(run_dir.display().to_string(), std::io::Error::other(e)))?;
        Ok(Self {
            run_dir,
            log,
            configs,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// #48 item 16: the limit counts characters (100 of 'é' is 200 bytes
    /// and a name), and a bidirectional override or a control character
    /// is refused naming it.
    #[test]
    fn a_run_name_is_counted_in_characters_and_plain() {
        assert_eq!(run_name_problem("my-run"), None);
        assert_eq!(run_name_problem(&"é".repeat(100)), None);
        let e = run_name_problem(&"é".repeat(101)).unwrap();
        assert!(e.contains("101 characters: at most 100"), "{e}");
        let e = run_name_problem(&"😀".repeat(70)).unwrap();
        assert!(e.contains("280 bytes"), "{e}");
        let e = run_name_problem("run\u{202E}lmth.mcap").unwrap();
        assert!(e.contains("U+202E"), "{e}");
        let e = run_name_problem("a\tb").unwrap();
        assert!(e.contains("U+0009"), "{e}");
        for bad in ["", ".", "..", "a/b"] {
            assert!(run_name_problem(bad).is_some(), "{bad:?}");
        }
        // The library refuses it too (Python's callers, not only the CLI).
        let dir = tempfile::tempdir().unwrap();
        let e = new_folder(dir.path(), Some("x\u{2066}"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("--name") && e.contains("U+2066"), "{e}");
    }
}
