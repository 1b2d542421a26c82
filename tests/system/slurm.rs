//! `testbed sweep slurm` on a real Slurm: a one-node cluster on localhost
//! (munged, slurmctld, slurmd started here, stopped at the end), a job
//! array of a sweep, and its results against `sweep run` bit for bit.
//! Needs root; installs Debian's slurm-wlm and munge if they are missing.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::util::{ok, testbed};

/// The daemons this test started; stopped on drop, even on a failure.
struct Cluster {
    dir: PathBuf,
    daemons: Vec<(&'static str, Child)>,
    munged_pid: Option<i32>,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for (_, child) in &mut self.daemons {
            let _ = child.kill();
            let _ = child.wait();
        }
        if let Some(pid) = self.munged_pid {
            let _ =
                nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), nix::sys::signal::SIGTERM);
        }
    }
}

impl Cluster {
    fn conf(&self) -> PathBuf {
        self.dir.join("slurm.conf")
    }

    /// The daemons' own words, for a failure message.
    fn logs(&self) -> String {
        let mut out = String::new();
        for name in ["slurmctld.log", "slurmd.log", "slurmctld.out", "slurmd.out"] {
            let text = std::fs::read_to_string(self.dir.join(name)).unwrap_or_default();
            let tail: Vec<&str> = text.lines().rev().take(15).collect();
            out += &format!(
                "--- {name}\n{}\n",
                tail.into_iter().rev().collect::<Vec<_>>().join("\n")
            );
        }
        out
    }

    fn slurm(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", self.conf());
        c
    }
}

fn run(cmd: &mut Command) -> (bool, String) {
    match cmd.output() {
        Ok(o) => (
            o.status.success(),
            format!(
                "{}{}",
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr)
            ),
        ),
        Err(e) => (false, e.to_string()),
    }
}

fn installed() -> bool {
    ["slurmctld", "slurmd", "sbatch", "munged"]
        .iter()
        .all(|p| run(Command::new("sh").args(["-c", &format!("command -v {p}")])).0)
}

fn ensure_installed() {
    if installed() {
        return;
    }
    let apt = |args: &[&str]| {
        run(Command::new("apt-get")
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive"))
    };
    let (done, out) = apt(&["install", "-y", "slurm-wlm", "munge"]);
    if !done {
        let (_, upd) = apt(&["update"]);
        let (done, out2) = apt(&["install", "-y", "slurm-wlm", "munge"]);
        assert!(
            done,
            "cannot install slurm-wlm and munge:\n{out}\n{upd}\n{out2}"
        );
    }
}

/// munged running (ours or already there), with a key.
fn ensure_munge() -> Option<i32> {
    let works = || run(Command::new("sh").args(["-c", "munge -n | unmunge"])).0;
    if works() {
        return None;
    }
    let key = Path::new("/etc/munge/munge.key");
    if !key.exists() {
        let (done, out) = run(Command::new("sh").args([
            "-c",
            "mkdir -p /etc/munge && dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 \
             && chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key",
        ]));
        assert!(done, "cannot create the munge key: {out}");
    }
    let (done, out) = run(Command::new("sh").args([
        "-c",
        "mkdir -p /run/munge /var/log/munge /var/lib/munge && \
         chown munge:munge /run/munge /var/log/munge /var/lib/munge && \
         runuser -u munge -- /usr/sbin/munged",
    ]));
    assert!(done, "munged did not start: {out}");
    let deadline = Instant::now() + Duration::from_secs(20);
    while !works() {
        assert!(
            Instant::now() < deadline,
            "munged started but munge -n | unmunge fails"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    std::fs::read_to_string("/run/munge/munged.pid")
        .ok()
        .and_then(|s| s.trim().parse().ok())
}

fn start_cluster(dir: &Path) -> Cluster {
    ensure_installed();
    let munged_pid = ensure_munge();
    for sub in ["ctld", "d"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let d = dir.display();
    let conf = format!(
        "ClusterName=testbed\nSlurmctldHost=localhost\nSlurmUser=root\nSlurmdUser=root\n\
         AuthType=auth/munge\nProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
         SchedulerType=sched/backfill\nSelectType=select/cons_tres\nSelectTypeParameters=CR_Core\n\
         StateSaveLocation={d}/ctld\nSlurmdSpoolDir={d}/d\nSlurmctldPidFile={d}/slurmctld.pid\n\
         SlurmdPidFile={d}/slurmd.pid\nSlurmctldLogFile={d}/slurmctld.log\nSlurmdLogFile={d}/slurmd.log\n\
         ReturnToService=2\nNodeName=localhost CPUs={cpus} State=UNKNOWN\n\
         PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP\n"
    );
    std::fs::write(dir.join("slurm.conf"), conf).unwrap();
    let mut cluster = Cluster {
        dir: dir.to_path_buf(),
        daemons: Vec::new(),
        munged_pid,
    };
    for (name, args) in [
        ("slurmctld", vec!["-D", "-i"]),
        ("slurmd", vec!["-D", "-N", "localhost"]),
    ] {
        let out = std::fs::File::create(dir.join(format!("{name}.out"))).unwrap();
        let child = cluster
            .slurm(name)
            .args(&args)
            .arg("-f")
            .arg(cluster.conf())
            .stdout(Stdio::null())
            .stderr(out)
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {name}: {e}"));
        cluster.daemons.push((name, child));
    }
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (_, state) = run(cluster.slurm("sinfo").args(["-h", "-o", "%T"]));
        if state.trim() == "idle" {
            return cluster;
        }
        let exited = cluster
            .daemons
            .iter_mut()
            .find_map(|(name, c)| Some((*name, c.try_wait().ok()??)));
        if let Some((name, status)) = exited {
            panic!("{name} exited ({status}):\n{}", cluster.logs());
        }
        assert!(
            Instant::now() < deadline,
            "the one-node cluster is not idle after 60 s (sinfo: {state}):\n{}",
            cluster.logs()
        );
        std::thread::sleep(Duration::from_millis(250));
    }
}

/// Result lines by key, without the compute-time metrics (they are timing).
fn results_by_key(dir: &Path) -> std::collections::BTreeMap<String, serde_json::Value> {
    let mut out = std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if !(name.starts_with("results-") && name.ends_with(".jsonl")) {
            continue;
        }
        for line in std::fs::read_to_string(&p).unwrap().lines() {
            let mut v: serde_json::Value = serde_json::from_str(line).unwrap();
            let m = v["metrics"].as_object_mut().unwrap();
            m.retain(|k, _| !k.starts_with("compute"));
            let key = v["key"].as_str().unwrap().to_string();
            assert!(out.insert(key, v).is_none(), "a run was done twice");
        }
    }
    out
}

#[test]
fn slurm_job_array_equals_a_local_sweep_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = tmp.path().join("s.toml");
    std::fs::write(
        &sweep,
        "name = \"slurm_test\"\nscenario = \"friction_noise\"\nseeds = 2\nlaws = [\"nac\", \"pd\"]\n\
         [set]\nduration_s = 2.5\n[[axis]]\nkey = \"controller.k1\"\nvalues = [12.0, 18.0]\n",
    )
    .unwrap();
    let local = tmp.path().join("local");
    ok(testbed()
        .args(["sweep", "run", "--no-progress", "--out"])
        .arg(&local)
        .arg(&sweep));
    let cluster = start_cluster(&tmp.path().join("cluster"));
    let shared = tmp.path().join("shared");
    let script = String::from_utf8(
        ok(testbed()
            .args([
                "sweep",
                "slurm",
                "--tasks",
                "4",
                "--max-running",
                "2",
                "--out",
            ])
            .arg(&shared)
            .arg(&sweep))
        .stdout,
    )
    .unwrap();
    let (submitted, id) = run(cluster.slurm("sbatch").args(["--parsable", script.trim()]));
    assert!(submitted, "sbatch failed: {id}\n{}", cluster.logs());
    let id = id.trim().to_string();
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let (_, queue) = run(cluster.slurm("squeue").args(["-h", "-j", &id]));
        if queue.trim().is_empty() {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "job {id} still queued after 300 s:\n{queue}\n{}",
            cluster.logs()
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    let (a, b) = (results_by_key(&local), results_by_key(&shared));
    assert_eq!(a.len(), 8);
    assert_eq!(a, b, "the array's results differ from the local sweep's");
    // Resubmitting runs nothing: every task finds its runs done.
    let again = ok(testbed()
        .args([
            "sweep",
            "run",
            "--no-progress",
            "--index",
            "0",
            "--tasks",
            "4",
            "--out",
        ])
        .arg(&shared)
        .arg(&sweep));
    let said = String::from_utf8_lossy(&again.stderr);
    assert!(said.contains("2 done before, 0 run now"), "{said}");
    let report = crate::util::json(&ok(testbed()
        .args(["sweep", "report", "--json"])
        .arg(&shared)));
    assert_eq!(report["found_runs"], 8);
    drop(cluster);
}
