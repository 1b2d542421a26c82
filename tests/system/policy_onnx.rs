//! A trained policy as a Rust law (issue 51, item 4): a `LinearPolicy`
//! exported to ONNX (`testbed.onnx_export`) and run by the node
//! `testbed-policy` (crate `policy/`, tract) in lockstep is the Gymnasium
//! environment's episode of that policy; it is a row of `compare`; it runs
//! in real time with a verdict; and a run at other gains is refused.

use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

use crate::util::{json, repo_root, testbed};

/// The environment's python with the module (and onnx) built into it.
fn python() -> &'static str {
    static PYTHON: OnceLock<String> = OnceLock::new();
    PYTHON.get_or_init(|| crate::util::venv_python("python/build-module.sh"))
}

fn node(policy: &Path) -> String {
    format!(
        "{} {}",
        crate::util::bin("testbed-policy").display(),
        policy.display()
    )
}

/// The exporter's fixture (policy/tests/fixtures/make.py): a residual on
/// pd for the paper's scenario, 50 Hz decisions, 4 s episodes.
fn fixture() -> std::path::PathBuf {
    repo_root().join("policy/tests/fixtures/linear.onnx")
}

/// Trains nothing: a LinearPolicy with seeded random weights (dense, so
/// that every observation entry counts), exported to ONNX, and the q after
/// each decision of its env episode (seed 0), written as JSON.
const EPISODE: &str = "
import json, sys, gymnasium, numpy as np, testbed
from testbed.policy import LinearPolicy, env_record
kw = dict(scenario='paper', episode_s=0.5, base_law='pd', **json.loads(sys.argv[3]))
env = gymnasium.make(testbed.ENV_ID, **kw)
core = env.unwrapped.core
rng = np.random.default_rng(7)
p = LinearPolicy(0.3 * rng.standard_normal((core.dof, core.obs_dim)),
                 0.1 * rng.standard_normal(core.dof), dict(kw, **env_record(env)))
p.save_onnx(sys.argv[1])
obs, _ = env.reset(seed=0)
qs, actions = [], []
for _ in range(core.decisions):
    a = p.act(obs)
    actions.append(a.tolist())
    obs, *_ = env.step(a)
    qs.append(core.true_state[0].tolist())
json.dump({'q': qs, 'decimation': core.decimation, 'actions': actions}, open(sys.argv[2], 'w'))
";

/// Exports EPISODE's policy with the env options `kw` (JSON) to `dir`,
/// runs it in lockstep, and checks the run's q after each decision is its
/// env episode's; returns the policy file.
fn lockstep_is_the_env_episode(dir: &Path, kw: &str) -> std::path::PathBuf {
    let policy = dir.join("policy.onnx");
    let episode = dir.join("episode.json");
    let out = Command::new(python())
        .args(["-c", EPISODE])
        .arg(&policy)
        .arg(&episode)
        .arg(kw)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let env: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&episode).unwrap()).unwrap();
    let csv = dir.join("run.csv");
    let out = testbed()
        .args(["run", "--mode", "lockstep", "--duration", "0.5", "--json"])
        .arg("--runs-dir")
        .arg(dir)
        .arg("--csv")
        .arg(&csv)
        .args(["--controller-cmd", &node(&policy)])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = json(&out);
    assert_eq!(r["controller_law"]["name"], "onnx-policy", "{r}");

    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (q0, q1) = (col("q0"), col("q1"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let d = env["decimation"].as_u64().unwrap() as usize;
    assert_eq!(d, 20);
    let qs = env["q"].as_array().unwrap();
    // Decision j leaves the state of plant period d·(j + 1); the last is
    // past the run's rows.
    let mut worst = 0.0f64;
    let mut differing = 0;
    for (j, q) in qs.iter().enumerate().take(qs.len() - 1) {
        let row = &rows[d * (j + 1)];
        for (i, c) in [q0, q1].into_iter().enumerate() {
            let want = q[i].as_f64().unwrap();
            if row[c].to_bits() != want.to_bits() {
                differing += 1;
            }
            worst = worst.max((row[c] - want).abs());
        }
    }
    // tract's f64 matrix product may sum W·obs in another order than
    // numpy's: the same to round-off (measured: see docs/python.md),
    // never a different trajectory.
    assert!(
        worst <= 1e-12,
        "q differs by up to {worst:e} ({differing} values not bit for bit)"
    );
    eprintln!(
        "lockstep against the env ({kw}): {differing} values differ in their bits, max |Δq| {worst:e}"
    );
    policy
}

#[test]
fn onnx_policy_in_lockstep_is_the_env_episode_and_a_row_of_compare() {
    let dir = tempfile::tempdir().unwrap();
    let policy = lockstep_is_the_env_episode(dir.path(), "{}");

    let out = testbed()
        .args(["compare", "--scenario", "paper", "--duration", "0.5"])
        .args(["--seeds", "1", "--laws", "pd", "--json"])
        .arg("--runs-dir")
        .arg(dir.path())
        .args(["--controller-cmd", &format!("ppo={}", node(&policy))])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = json(&out);
    let names: Vec<&str> = table["laws"]
        .as_array()
        .unwrap()
        .iter()
        .map(|row| row["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["pd", "ppo"], "{table}");
    let row = &table["laws"][1];
    assert_eq!(row["external"]["declared"]["name"], "onnx-policy", "{row}");
    let run = &row["runs"][0];
    assert_eq!(run["summary"]["steps"], 500, "{run}");
    assert!(run["summary"]["finite"].as_bool().unwrap(), "{run}");
}

/// #59 item 1: the node ramps the torque and observes the last action as
/// the environment does (the smoothing's own bits are pinned in-process
/// by policy/tests/smoothing.rs; here numpy and tract may sum W·obs in
/// another order).
#[test]
fn a_ramped_policy_observing_its_last_action_in_lockstep_is_the_env_episode() {
    let dir = tempfile::tempdir().unwrap();
    lockstep_is_the_env_episode(
        dir.path(),
        r#"{"smoothing": "ramp", "observe_action": true, "action_rate_weight": 0.1}"#,
    );
    let dir = tempfile::tempdir().unwrap();
    lockstep_is_the_env_episode(
        dir.path(),
        r#"{"smoothing": "low-pass", "smoothing_tau_s": 0.005}"#,
    );
}

#[test]
fn onnx_policy_runs_in_realtime_with_a_verdict() {
    let dir = tempfile::tempdir().unwrap();
    let out = testbed()
        .args(["run", "--json", "--duration", "1"])
        .arg("--runs-dir")
        .arg(dir.path())
        .args(["--controller-cmd", &node(&fixture())])
        .output()
        .unwrap();
    let code = out.status.code();
    assert!(
        matches!(code, Some(0 | 3)),
        "exit {code:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = json(&out);
    assert_eq!(r["timing"]["cycles"], 1000, "{r}");
    assert_eq!(r["run_end"], "finished", "{r}");
    let verdict = r["timing"]["verdict"].as_str().unwrap_or_default();
    assert_eq!(
        code == Some(0),
        verdict == "clean",
        "{verdict} with exit {code:?}"
    );
    assert_eq!(r["controller_law"]["name"], "onnx-policy", "{r}");
}

#[test]
fn onnx_policy_is_refused_at_other_gains_naming_both_values() {
    let dir = tempfile::tempdir().unwrap();
    let out = testbed()
        .args(["run", "--mode", "lockstep", "--duration", "0.1"])
        .args(["--set", "controller.tc=1.5"])
        .arg("--runs-dir")
        .arg(dir.path())
        .args(["--controller-cmd", &node(&fixture())])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("controller.tc = 2.0") && err.contains("controller.tc is 1.5"),
        "{err}"
    );
}
