//! An output must never be one of the command's inputs: `replay LOG --csv
//! LOG` or `sim --scenario S --csv S` would destroy what they read. The
//! check compares files by device and inode (so a second name of the same
//! file, a link or `./S`, is caught too) before anything is written.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

/// Refuses `output` (given with `flag`) when it is the same file as one of
/// `inputs`. A file that does not exist yet is no input.
pub(crate) fn refuse_input(flag: &str, output: &Path, inputs: &[PathBuf]) -> Result<()> {
    let Ok(out) = std::fs::metadata(output) else {
        return Ok(());
    };
    for input in inputs {
        let same =
            std::fs::metadata(input).is_ok_and(|m| m.dev() == out.dev() && m.ino() == out.ino());
        if same {
            bail!(
                "{flag} {}: that is {}, an input of this command; writing it would destroy it (name another file)",
                output.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// The files a run reads: its scenario file (if any) and its robot's URDF.
pub(crate) fn plan_inputs(scenario: Option<&Path>, plan: &scenario::Plan) -> Vec<PathBuf> {
    let mut inputs: Vec<PathBuf> = scenario
        .and_then(|s| scenario::resolve_scenario(s).ok())
        .into_iter()
        .collect();
    inputs.extend(plan.robot.path.clone());
    inputs
}

/// Every file directly in `dir` (a sweep's results folder: its manifest,
/// results and scenario files).
pub(crate) fn files_in(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .map(|entries| entries.flatten().map(|e| e.path()).collect())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn the_same_file_under_another_name_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("s.toml");
        std::fs::write(&input, "x").unwrap();
        let link = dir.path().join("link.toml");
        std::fs::hard_link(&input, &link).unwrap();
        let e = refuse_input("--csv", &link, std::slice::from_ref(&input))
            .unwrap_err()
            .to_string();
        assert!(e.contains("--csv") && e.contains("s.toml"), "{e}");
        assert!(
            refuse_input(
                "--csv",
                &dir.path().join("new.csv"),
                std::slice::from_ref(&input)
            )
            .is_ok()
        );
        let other = dir.path().join("other.csv");
        std::fs::write(&other, "y").unwrap();
        assert!(refuse_input("--csv", &other, &[input]).is_ok());
    }
}
