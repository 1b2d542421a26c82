//! The in-process module (`python/inprocess`, `import testbed`): its own
//! tests (sim equal to the CLI bit for bit, the Gymnasium environment and
//! its checker, the learner and the learnt policy back in lockstep and
//! compare), and a learnt policy in a real-time run with its verdict.

use std::process::Command;
use std::sync::OnceLock;

use crate::util::{json, repo_root, testbed};

/// The environment's python with the module built into it
/// (python/build-module.sh; it locks against other test processes).
fn python() -> &'static str {
    static PYTHON: OnceLock<String> = OnceLock::new();
    PYTHON.get_or_init(|| crate::util::venv_python("python/build-module.sh"))
}

#[test]
fn python_in_process_module_passes_its_tests() {
    let out = Command::new(python())
        .args(["-m", "unittest", "discover", "-v", "-s", "tests"])
        .env("TESTBED_BIN", crate::util::bin("testbed"))
        .current_dir(repo_root().join("python/inprocess"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // Every test ran: none skipped for want of the binary.
    assert!(!err.contains("skipped"), "{err}");
    assert!(err.contains("\nOK"), "{err}");
}

/// A policy learnt in process (random search, residual on pd) runs as the
/// controller node of a 2 s real-time run at 1 kHz, which ends with its
/// timing verdict (clean or degraded is the machine's to say; never invalid).
#[test]
fn a_learnt_policy_runs_in_realtime_with_a_verdict() {
    let dir = tempfile::tempdir().unwrap();
    let policy = dir.path().join("policy.npz");
    let train = format!(
        "import gymnasium, testbed\n\
         from testbed.policy import LinearPolicy, env_record, random_search\n\
         kw = dict(scenario='paper', duration=0.5, base_law='pd')\n\
         env = gymnasium.make(testbed.ENV_ID, **kw)\n\
         c = env.unwrapped.core\n\
         p = LinearPolicy.zeros(c.dof, c.obs_dim, dict(kw, **env_record(env)))\n\
         random_search(env, p, iterations=2, directions=4, top=2).save({:?})\n",
        policy.display().to_string()
    );
    let out = Command::new(python())
        .args(["-c", &train])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cmd = format!(
        "{} -m testbed.policy_node --policy {}",
        python(),
        policy.display()
    );
    let out = testbed()
        .args(["run", "--json", "--duration", "2", "--controller-cmd", &cmd])
        .arg("--runs-dir")
        .arg(dir.path())
        .output()
        .unwrap();
    let code = out.status.code();
    assert!(
        matches!(code, Some(0 | 3)),
        "exit {code:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = json(&out);
    assert_eq!(r["timing"]["cycles"], 2000, "{r}");
    assert_eq!(r["run_end"], "finished", "{r}");
    let verdict = r["timing"]["verdict"].as_str().unwrap_or_default();
    assert_eq!(
        code == Some(0),
        verdict == "clean",
        "{verdict} with exit {code:?}"
    );
    assert!(["clean", "degraded"].contains(&verdict), "{r}");
    assert_eq!(r["controller_law"]["name"], "policy", "{r}");
}
