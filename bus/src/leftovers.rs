//! Files a run's nodes leave in iceoryx2's folders when one is killed while
//! it is being created (`kill -9` during start-up): iceoryx2 does not list
//! such a half-made node, so neither its own clean-up nor the removal of the
//! run's domain reaches them. A run whose launcher is gone and whose prefix
//! no process carries on its command line any more can have them removed.

use std::path::{Path, PathBuf};

use iceoryx2::prelude::*;

use crate::topics::RunPrefix;

/// iceoryx2's node and service folders (of the default configuration,
/// which every run's configuration shares but for the prefix).
fn folders() -> Vec<PathBuf> {
    let global = Config::default().global.clone();
    [global.node_dir(), global.service_dir()]
        .iter()
        .map(|p| PathBuf::from(String::from_utf8_lossy(p.as_bytes()).to_string()))
        .collect()
}

/// How long the scan of /proc may take before the run's files are kept.
const SCAN_LIMIT: std::time::Duration = std::time::Duration::from_secs(2);

/// Whether a process alive now was started with `--prefix <prefix>`.
/// Reading a process's `/proc/<pid>/cmdline` takes its memory lock, which
/// a real-time hog on its CPU can keep for as long as it runs: the scan
/// runs beside the caller and, past [`SCAN_LIMIT`], counts as "in use"
/// (the files stay; nothing waits on it).
fn prefix_in_use(prefix: &RunPrefix) -> bool {
    let wanted = prefix.as_str().as_bytes().to_vec();
    within(SCAN_LIMIT, true, move || {
        let Ok(entries) = std::fs::read_dir("/proc") else {
            return true;
        };
        entries.flatten().any(|e| {
            let cmdline = std::fs::read(e.path().join("cmdline")).unwrap_or_default();
            cmdline.split(|b| *b == 0).any(|arg| arg == wanted)
        })
    })
}

/// `f()` if it returns within `limit`, else `otherwise` (the thread running
/// `f` is left to end on its own).
fn within<T: Send + 'static>(
    limit: std::time::Duration,
    otherwise: T,
    f: impl FnOnce() -> T + Send + 'static,
) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("leftover-scan".into())
        .spawn(move || {
            let _ = tx.send(f());
        });
    match spawned {
        Ok(_) => rx.recv_timeout(limit).unwrap_or(otherwise),
        Err(_) => otherwise,
    }
}

/// The files below `dir` (one level of folders deep, as iceoryx2 keeps
/// them) whose name starts with a testbed run prefix.
fn run_files(dir: &Path) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    for e in entries.flatten() {
        let path = e.path();
        if path.is_dir() {
            out.extend(
                std::fs::read_dir(&path)
                    .into_iter()
                    .flatten()
                    .flatten()
                    .map(|f| (f.file_name().to_string_lossy().to_string(), f.path())),
            );
        } else {
            out.push((e.file_name().to_string_lossy().to_string(), path));
        }
    }
    out.retain(|(name, _)| name.starts_with(RunPrefix::STEM));
    out
}

impl RunPrefix {
    /// Whether this run is over for good: its launcher is gone (or it is
    /// `own`, the caller's run, once its nodes are reaped) and no process
    /// carries the prefix.
    fn finished(&self, own: bool) -> bool {
        let launcher_gone = own
            || self
                .launcher_pid()
                .is_some_and(|pid| !Path::new(&format!("/proc/{pid}")).exists());
        launcher_gone && !prefix_in_use(self)
    }

    /// Removes iceoryx2 files left by runs that are over for good (see the
    /// module), this run's own included when `own` is true (call it once its
    /// nodes have ended). Returns how many files were removed.
    pub fn remove_leftover_files(&self, own: bool) -> usize {
        let mut removed = 0;
        for dir in folders() {
            let mut checked: Vec<(RunPrefix, bool)> = Vec::new();
            for (name, path) in run_files(&dir) {
                let Some(end) = name.find('_') else { continue };
                let Ok(prefix) = RunPrefix::parse(&name[..=end]) else {
                    continue;
                };
                let is_own = prefix == *self;
                if is_own && !own {
                    continue;
                }
                let over = match checked.iter().find(|(p, _)| *p == prefix) {
                    Some((_, over)) => *over,
                    None => {
                        let over = prefix.finished(is_own);
                        checked.push((prefix, over));
                        over
                    }
                };
                if over && std::fs::remove_file(&path).is_ok() {
                    removed += 1;
                    // A node's folder goes with its last file (fails if not empty).
                    if let Some(parent) = path.parent().filter(|p| *p != dir) {
                        let _ = std::fs::remove_dir(parent);
                    }
                }
            }
        }
        removed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// #39 row 9: a scan that never returns (a cmdline read blocked by a
    /// real-time hog) is given up after the limit, keeping the files.
    #[test]
    fn a_scan_that_hangs_is_given_up() {
        let (_keep, blocked) = std::sync::mpsc::channel::<()>();
        let start = std::time::Instant::now();
        let r = within(std::time::Duration::from_millis(50), true, move || {
            let _ = blocked.recv();
            false
        });
        assert!(r, "a hung scan counts as in use");
        assert!(start.elapsed() < std::time::Duration::from_secs(30));
        assert!(!within(SCAN_LIMIT, true, || false));
    }
}
