//! The shipped scenarios and robots found by name, from an installed
//! wheel as from the checkout: `scenario="paper"`, `robot="iiwa14"`.
//!
//! The wheel carries `scenarios/` and `robots/` inside the package
//! (`testbed/scenarios`, `testbed/robots`: symbolic links to the
//! checkout's folders, which maturin's `include` copies into the wheel),
//! so a scenario's relative paths (`robot = "../robots/iiwa14.urdf"`, a
//! CSV beside it) resolve there as they do in the checkout. Without them
//! (a build whose package lost them) the checkout this module was built
//! from is the fallback.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The package's folder (`testbed/`), found when the module loads.
static PACKAGE_DIR: OnceLock<PathBuf> = OnceLock::new();

/// Records the package folder (once; later calls change nothing).
pub fn set_package_dir(dir: PathBuf) {
    let _ = PACKAGE_DIR.set(dir);
}

/// The checkout this module was built from (the fallback).
fn checkout() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `folder/file` in the package, else in the checkout, if it exists;
/// canonical, so that the checkout's files keep the names they have when
/// the `testbed` binary reads them (the package's folders link there).
fn find(folder: &str, file: &str) -> Option<PathBuf> {
    PACKAGE_DIR
        .get()
        .map(|p| p.join(folder).join(file))
        .into_iter()
        .chain([checkout().join(folder).join(file)])
        .find(|p| p.is_file())
        .map(|p| p.canonicalize().unwrap_or(p))
}

/// A bare name (one path component) that is no file here.
fn bare_name(arg: &Path) -> Option<&str> {
    (!arg.exists() && arg.components().count() == 1)
        .then(|| arg.to_str())
        .flatten()
}

/// A scenario argument as `--scenario` takes it (a file, else a shipped
/// scenario's name, with or without `.toml`), as a file when it names a
/// shipped one; else unchanged, for the loader to refuse by name.
pub fn scenario(arg: &Path) -> PathBuf {
    bare_name(arg)
        .and_then(scenario::find_shipped)
        .and_then(|s| find("scenarios", &format!("{}.toml", s.name)))
        .unwrap_or_else(|| arg.to_path_buf())
}

/// The shipped robots' names (the `.urdf` files of `robots/`), sorted.
pub fn robots() -> Vec<String> {
    let dir = PACKAGE_DIR
        .get()
        .map(|p| p.join("robots"))
        .filter(|d| d.is_dir())
        .unwrap_or_else(|| checkout().join("robots"));
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|e| {
            let name = e.ok()?.file_name().to_str()?.to_string();
            name.strip_suffix(".urdf").map(str::to_string)
        })
        .collect();
    names.sort();
    names
}

/// Why a robot argument names nothing.
#[derive(Debug, thiserror::Error)]
#[error(
    "robot {name:?}: no such file, and no shipped robot of that name (the shipped robots: {shipped})"
)]
pub struct NoSuchRobot {
    name: String,
    shipped: String,
}

/// A robot argument: a URDF file, else a shipped robot's name (with or
/// without `.urdf`), as its file.
pub fn robot(arg: &Path) -> Result<PathBuf, NoSuchRobot> {
    let Some(name) = bare_name(arg) else {
        return Ok(arg.to_path_buf());
    };
    let stem = name.strip_suffix(".urdf").unwrap_or(name);
    find("robots", &format!("{stem}.urdf")).ok_or_else(|| NoSuchRobot {
        name: name.to_string(),
        shipped: robots().join(", "),
    })
}
