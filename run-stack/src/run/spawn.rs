//! Node processes: spawning, watching, stopping.
//!
//! Children get their own process group (a Ctrl-C in the terminal reaches
//! only the launcher, which then stops them in order). Their stderr is
//! forwarded line by line with the node's name; stdout and stderr both go
//! to the node's file in the run folder (`nodes/<node>.log`, bounded), and
//! the last lines of either are kept for the error message if the node
//! dies. Whatever path the launcher leaves by,
//! [`Children`]'s `Drop` kills and reaps what is still running.

use std::collections::VecDeque;
use std::io::{BufRead, BufReader};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::Path;
use std::process::{ExitStatus, Stdio};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use nix::sys::signal::Signal;
use nix::unistd::Pid;
use wire::NodeKind;

const TAIL_LINES: usize = 20;
/// A node's stderr line longer than this is cut (a 300 MB line once sat in
/// the launcher's memory whole).
const MAX_LINE_BYTES: usize = 64 * 1024;
/// How long the launcher waits for a node's stderr to close after the node
/// exited.
const FORWARDER_WAIT: Duration = Duration::from_secs(1);
/// Most bytes of a node's output kept in its file (a node that prints
/// without end must not fill the disk).
const MAX_OUTPUT_BYTES: u64 = 16 << 20;

/// A node's output file, shared by its two streams' forwarders.
struct OutputFile {
    file: Option<std::fs::File>,
    written: u64,
}

impl OutputFile {
    fn write_line(&mut self, line: &str) {
        use std::io::Write;
        let Some(f) = self.file.as_mut() else { return };
        let len = line.len() as u64 + 1;
        if self.written + len > MAX_OUTPUT_BYTES {
            let _ = writeln!(f, "[testbed: output cut here at {MAX_OUTPUT_BYTES} bytes]");
            self.file = None;
            return;
        }
        self.written += len;
        // A full disk costs the copy, never the run.
        if writeln!(f, "{line}").is_err() {
            self.file = None;
        }
    }
}

/// One running node process.
pub struct Child {
    /// Which node.
    pub kind: NodeKind,
    process: std::process::Child,
    tail: Arc<Mutex<VecDeque<String>>>,
    forwarders: Vec<JoinHandle<()>>,
    exited: Option<ExitStatus>,
}

impl Child {
    /// The process id.
    pub fn pid(&self) -> u32 {
        self.process.id()
    }

    /// The last lines the node wrote (stdout and stderr).
    pub fn stderr_tail(&self) -> String {
        // Let the forwarder finish reading what the process wrote before it exited.
        let lines = self
            .tail
            .lock()
            .map(|t| t.iter().cloned().collect::<Vec<_>>());
        lines.unwrap_or_default().join("\n")
    }

    /// Signals the node's process group: a node is a group leader, and a
    /// user's command (`--controller-cmd`) may have started helpers of its own.
    fn signal_group(&self, sig: Signal) {
        let _ = nix::sys::signal::killpg(Pid::from_raw(self.pid() as i32), sig);
    }

    fn poll(&mut self) -> Option<ExitStatus> {
        if self.exited.is_none() {
            self.exited = self.process.try_wait().ok().flatten();
        }
        self.exited
    }

    /// Waits for the forwarder to pass on what the node wrote before it
    /// exited, but not for ever: a helper the node started may hold its
    /// stderr open; the node's group is ended first, and after a moment the
    /// forwarder is left to finish alone.
    fn join_forwarder(&mut self) {
        self.signal_group(Signal::SIGKILL);
        let start = Instant::now();
        for h in std::mem::take(&mut self.forwarders) {
            while !h.is_finished() && start.elapsed() < FORWARDER_WAIT {
                std::thread::sleep(Duration::from_millis(5));
            }
            if h.is_finished() {
                let _ = h.join();
            }
        }
    }
}

/// Spawns `testbed node <kind> <args…>` from the running executable; its
/// output goes to `output` too.
pub fn spawn(exe: &Path, kind: NodeKind, args: &[String], output: &Path) -> std::io::Result<Child> {
    let mut argv = vec!["node".to_string(), kind.name().to_string()];
    argv.extend_from_slice(args);
    spawn_program(exe.as_os_str(), &argv, kind, output)
}

/// Spawns a user's command as node `kind` (`--controller-cmd`): its own
/// words, then the node arguments the launcher gives every node.
pub fn spawn_command(
    command: &[String],
    kind: NodeKind,
    args: &[String],
    output: &Path,
) -> std::io::Result<Child> {
    let Some((program, words)) = command.split_first() else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "the command is empty",
        ));
    };
    let mut argv = words.to_vec();
    argv.extend_from_slice(args);
    spawn_program(program.as_ref(), &argv, kind, output)
}

/// Whether `command`'s program can be run: an executable file at its path
/// or, for a bare name, on `PATH` (what the spawn would find).
pub fn check_program(command: &[String]) -> std::io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let program = command.first().map(String::as_str).unwrap_or_default();
    let runnable = |p: &Path| {
        p.metadata()
            .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    };
    let found = if program.contains('/') {
        runnable(Path::new(program))
    } else {
        let path = std::env::var_os("PATH").unwrap_or_default();
        std::env::split_paths(&path).any(|dir| runnable(&dir.join(program)))
    };
    if found {
        Ok(())
    } else {
        Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!("no executable program '{program}' (a path, or a name on PATH)"),
        ))
    }
}

fn spawn_program(
    program: &std::ffi::OsStr,
    argv: &[String],
    kind: NodeKind,
    output: &Path,
) -> std::io::Result<Child> {
    let file = std::fs::File::create(output)?;
    // The run's name, inherited by whatever the node starts (strays.rs).
    let run = argv
        .windows(2)
        .find(|w| w[0] == "--prefix")
        .map_or("", |w| w[1].as_str());
    let mut process = std::process::Command::new(program)
        .args(argv)
        .env(super::strays::RUN_ENV, run)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0)
        .spawn()?;
    let tail = Arc::new(Mutex::new(VecDeque::with_capacity(TAIL_LINES)));
    let file = Arc::new(Mutex::new(OutputFile {
        file: Some(file),
        written: 0,
    }));
    let name = kind.name();
    let mut forwarders = Vec::new();
    if let Some(stderr) = process.stderr.take() {
        forwarders.push(forward(stderr, Some(name), &tail, &file));
    }
    if let Some(stdout) = process.stdout.take() {
        forwarders.push(forward(stdout, None, &tail, &file));
    }
    Ok(Child {
        kind,
        process,
        tail,
        forwarders,
        exited: None,
    })
}

/// Passes a node's stream on, line by line: to its file, to the tail, and
/// (stderr, with the node's `name`) to the launcher's stderr.
fn forward(
    stream: impl std::io::Read + Send + 'static,
    name: Option<&'static str>,
    tail: &Arc<Mutex<VecDeque<String>>>,
    file: &Arc<Mutex<OutputFile>>,
) -> JoinHandle<()> {
    let (tail, file) = (Arc::clone(tail), Arc::clone(file));
    std::thread::spawn(move || {
        let mut reader = BufReader::new(stream);
        while let Some(line) = read_line_bounded(&mut reader) {
            if let Some(name) = name {
                eprintln!("[{name}] {line}");
            }
            if let Ok(mut f) = file.lock() {
                f.write_line(&line);
            }
            if let Ok(mut t) = tail.lock() {
                if t.len() == TAIL_LINES {
                    t.pop_front();
                }
                t.push_back(line);
            }
        }
    })
}

/// The next line of `r` as text: bytes that are not UTF-8 are replaced
/// (one such line once stopped the forwarder, and the node's next write
/// failed), and a line longer than [`MAX_LINE_BYTES`] is cut, the rest of
/// it skipped. None at the end of the stream.
fn read_line_bounded(r: &mut impl BufRead) -> Option<String> {
    let mut line = Vec::new();
    let mut cut = false;
    loop {
        let buf = match r.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(_) => &[],
        };
        if buf.is_empty() {
            return (!line.is_empty() || cut).then(|| finish_line(&line, cut));
        }
        let (chunk, done) = match buf.iter().position(|b| *b == b'\n') {
            Some(i) => (&buf[..i], i + 1),
            None => (buf, buf.len()),
        };
        let room = MAX_LINE_BYTES.saturating_sub(line.len());
        line.extend_from_slice(&chunk[..chunk.len().min(room)]);
        cut |= chunk.len() > room;
        let newline = done > chunk.len();
        r.consume(done);
        if newline {
            return Some(finish_line(&line, cut));
        }
    }
}

fn finish_line(bytes: &[u8], cut: bool) -> String {
    let text = String::from_utf8_lossy(bytes);
    if cut {
        format!("{text} … (line cut at {} KiB)", MAX_LINE_BYTES / 1024)
    } else {
        text.into_owned()
    }
}

/// How a process ended, in words.
pub fn describe(status: ExitStatus) -> String {
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("exited with status {code}"),
        (None, Some(sig)) => match Signal::try_from(sig) {
            // The one way a full /dev/shm shows itself to a node.
            Ok(s @ Signal::SIGBUS) => format!(
                "was killed by signal {sig} ({}: a shared-memory page could not be had; \
                 {} had {} bytes free)",
                s.as_str(),
                bus::SHM_DIR,
                bus::shm_free_bytes().map_or("?".into(), |b| b.to_string())
            ),
            Ok(s) => format!("was killed by signal {sig} ({})", s.as_str()),
            Err(_) => format!("was killed by signal {sig}"),
        },
        _ => "ended".to_string(),
    }
}

/// All node processes of a run, and the run's process tree below them.
#[derive(Default)]
pub struct Children(Vec<Child>, super::strays::RunTree);

impl Children {
    /// Adds a spawned child.
    pub fn push(&mut self, child: Child) {
        self.0.push(child);
    }

    /// The first child that has exited, with its status and stderr tail.
    pub fn first_exited(&mut self) -> Option<(NodeKind, ExitStatus, String)> {
        for c in &mut self.0 {
            if let Some(status) = c.poll() {
                c.join_forwarder();
                return Some((c.kind, status, c.stderr_tail()));
            }
        }
        None
    }

    /// Notes what the nodes have started so far (at most every 50 ms),
    /// so that it ends with the run wherever it moves
    /// (the run tree of `strays.rs`).
    pub fn watch(&mut self) {
        let nodes = self.node_pids();
        self.1.note(&nodes, false);
    }

    /// Kills and reaps what is left of the nodes' process tree once they
    /// are gone; how many were killed.
    pub fn end_descendants(&mut self) -> usize {
        let nodes = self.node_pids();
        self.1.end(&nodes)
    }

    fn node_pids(&self) -> Vec<i32> {
        self.0.iter().map(|c| c.pid() as i32).collect()
    }

    /// Each child's process id.
    pub fn pids(&self) -> Vec<(NodeKind, u32)> {
        self.0.iter().map(|c| (c.kind, c.pid())).collect()
    }

    /// Peak resident memory (VmHWM, kB) of each child still running.
    pub fn peak_rss_kb(&self) -> Vec<(NodeKind, u64)> {
        self.0
            .iter()
            .filter_map(|c| peak_rss_kb(c.pid()).map(|kb| (c.kind, kb)))
            .collect()
    }

    /// CPU time each child still running has used so far, s (all its
    /// threads, user and system).
    pub fn cpu_s(&self) -> Vec<(NodeKind, f64)> {
        self.0
            .iter()
            .filter_map(|c| cpu_ns(c.pid()).map(|ns| (c.kind, ns as f64 / 1e9)))
            .collect()
    }

    /// How `kind` ended (status and stderr tail), once it has.
    pub fn exit_of(&mut self, kind: NodeKind) -> Option<(ExitStatus, String)> {
        let c = self.0.iter_mut().find(|c| c.kind == kind)?;
        let status = c.poll()?;
        c.join_forwarder();
        Some((status, c.stderr_tail()))
    }

    /// Waits up to `grace` for every child to exit (after STOP was sent),
    /// then SIGTERM, another `grace`, then SIGKILL. Returns the children
    /// that needed a signal.
    pub fn stop(&mut self, grace: Duration) -> Vec<(NodeKind, &'static str)> {
        // The last look while the nodes' helpers are still below them.
        let nodes = self.node_pids();
        self.1.note(&nodes, true);
        let mut forced = Vec::new();
        if !self.wait_all(grace) {
            for c in &mut self.0 {
                if c.poll().is_none() {
                    c.signal_group(Signal::SIGTERM);
                    forced.push((c.kind, "SIGTERM"));
                }
            }
            if !self.wait_all(grace) {
                for c in &mut self.0 {
                    if c.poll().is_none() {
                        c.signal_group(Signal::SIGKILL);
                        let _ = c.process.kill();
                        let _ = c.process.wait();
                        forced.push((c.kind, "SIGKILL"));
                    }
                }
            }
        }
        for c in &mut self.0 {
            let _ = c.process.wait();
            c.join_forwarder();
        }
        forced
    }

    fn wait_all(&mut self, limit: Duration) -> bool {
        let start = Instant::now();
        loop {
            if self.0.iter_mut().all(|c| c.poll().is_some()) {
                return true;
            }
            if start.elapsed() >= limit {
                return false;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for Children {
    fn drop(&mut self) {
        let nodes = self.node_pids();
        for c in &mut self.0 {
            if c.poll().is_none() {
                c.signal_group(Signal::SIGKILL);
                let _ = c.process.kill();
            }
            let _ = c.process.wait();
            c.join_forwarder();
        }
        self.1.end(&nodes);
    }
}

/// VmHWM of process `pid` in kB, from /proc.
pub fn peak_rss_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// CPU time of process `pid` so far, ns: the sum over its threads of the
/// first field of `/proc/<pid>/task/<tid>/schedstat` (time on a CPU).
pub fn cpu_ns(pid: u32) -> Option<u64> {
    let tasks = std::fs::read_dir(format!("/proc/{pid}/task")).ok()?;
    let mut total = 0;
    for task in tasks.flatten() {
        let stat = std::fs::read_to_string(task.path().join("schedstat")).ok()?;
        total += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_forwarded_lossily_and_bounded() {
        let mut input: Vec<u8> = b"plain\n\xff\xfe bytes\n".to_vec();
        input.extend(std::iter::repeat_n(b'x', 3 * MAX_LINE_BYTES));
        input.extend_from_slice(b"\nlast");
        let mut r = std::io::BufReader::with_capacity(1000, input.as_slice());
        assert_eq!(read_line_bounded(&mut r).as_deref(), Some("plain"));
        assert_eq!(
            read_line_bounded(&mut r).as_deref(),
            Some("\u{fffd}\u{fffd} bytes")
        );
        let long = read_line_bounded(&mut r).unwrap_or_default();
        assert!(long.len() < MAX_LINE_BYTES + 100 && long.ends_with("(line cut at 64 KiB)"));
        assert_eq!(read_line_bounded(&mut r).as_deref(), Some("last"));
        assert_eq!(read_line_bounded(&mut r), None);
    }
}
