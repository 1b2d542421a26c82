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

impl RunFiles {
    pub(super) fn write(opts: &RunOptions) -> Result<Self, RunError> {
        let plan = &opts.plan;
        let out = |p: &Path| {
            let p = p.display().to_string();
            move |e| RunError::Output(p.clone(), e)
        };
        let run_dir =
            std::path::absolute(opts.runs_dir.join(run_id())).map_err(out(&opts.runs_dir))?;
        std::fs::create_dir_all(&run_dir).map_err(out(&run_dir))?;
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
        let command = opts.controller_cmd.as_ref().map(shell_words::join);
        let configs = crate::node::configs::write_all(
            &run_dir.join("nodes"),
            plan,
            opts.mode,
            &log,
            &toml,
            LoggerOptions {
                controller_cmd: command.as_deref(),
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
