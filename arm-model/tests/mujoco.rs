//! The dynamics of MJCF arms against MuJoCo's own (issue #47): M(q) with
//! armature, the bias forces C q̇ + G, and the accelerations under a torque
//! with joint damping, at random states, within 1e-9 relative. MuJoCo runs
//! from the `mujoco` wheel in the venv `python/setup-mujoco-venv.sh` makes
//! (once); the test fails, saying why, when it cannot be made.

// The helpers outside #[test] fail the test on bad input too.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::{Path, PathBuf};
use std::process::Command;

use arm_model::{ArmModel, Locks, dynamics::Dynamics};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{Value, json};

/// The hand-written arms MuJoCo can load (in tests/data); `arms()` adds
/// every shipped MuJoCo Menagerie arm. `TESTBED_MJCF_ARMS` adds more: MJCF files, or
/// folders searched for them, separated by ':' (a Menagerie checkout's
/// arms, say; a file that includes others is given, not its includes).
const ARMS: [&str; 5] = [
    "arm-model/tests/data/two_link_hinge.xml",
    "arm-model/tests/data/geom_inertia.xml",
    "arm-model/tests/data/slide_armature.xml",
    "arm-model/tests/data/includes_defaults.xml",
    "arm-model/tests/data/body_include.xml",
];

const STATES: usize = 8;
const TOLERANCE: f64 = 1e-9;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// The `.xml` files in a folder, sorted.
fn xml_in(dir: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    found.sort();
    found
}

/// The hand-written arms, every arm in robots/menagerie/ (one folder
/// each), then those `TESTBED_MJCF_ARMS` names.
fn arms() -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = ARMS.iter().map(|a| root().join("..").join(a)).collect();
    let mut shipped: Vec<PathBuf> = std::fs::read_dir(root().join("../robots/menagerie"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    shipped.sort();
    out.extend(shipped.iter().flat_map(|d| xml_in(d)));
    let extra = std::env::var("TESTBED_MJCF_ARMS").unwrap_or_default();
    for item in extra.split(':').filter(|s| !s.is_empty()) {
        let path = PathBuf::from(item);
        if path.is_dir() {
            out.extend(xml_in(&path));
        } else {
            out.push(path);
        }
    }
    out
}

/// A path for messages: the repository's own relative to its root.
fn label(path: &Path) -> String {
    let base = root().join("..");
    path.strip_prefix(&base)
        .map_or_else(|_| path.display().to_string(), |p| p.display().to_string())
}

/// The venv's python, made by the setup script when missing.
fn mujoco_python() -> PathBuf {
    let script = root().join("../python/setup-mujoco-venv.sh");
    let out = Command::new("bash")
        .arg(&script)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", script.display()));
    assert!(
        out.status.success(),
        "{} failed, so MuJoCo cannot be compared with: {}",
        script.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    PathBuf::from(String::from_utf8_lossy(&out.stdout).trim())
}

/// Random states inside each joint's limits (±π for one without).
fn states(model: &ArmModel, rng: &mut ChaCha8Rng) -> Vec<Value> {
    (0..STATES)
        .map(|_| {
            let q: Vec<f64> = (model.actuated.iter())
                .map(|&ji| {
                    let (lo, hi) = model.joints[ji]
                        .limits
                        .unwrap_or((-std::f64::consts::PI, std::f64::consts::PI));
                    rng.random_range(lo..hi)
                })
                .collect();
            let qd: Vec<f64> = q.iter().map(|_| rng.random_range(-3.0..3.0)).collect();
            let tau: Vec<f64> = q.iter().map(|_| rng.random_range(-5.0..5.0)).collect();
            json!({"q": q, "qd": qd, "tau": tau})
        })
        .collect()
}

fn vector(v: &Value) -> Vec<f64> {
    (v.as_array().expect("an array of numbers").iter())
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

/// The largest |ours − theirs| over the largest |theirs|, or over `floor`
/// where theirs is smaller: a vector zero but for rounding (the bias of a
/// door hinged on the vertical) has no scale of its own.
fn relative(ours: &[f64], theirs: &[f64], floor: f64) -> f64 {
    let scale = theirs
        .iter()
        .fold(0.0_f64, |m, x| m.max(x.abs()))
        .max(floor)
        .max(1e-12);
    (ours.iter().zip(theirs))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / scale
}

/// The testbed's M (row-major), bias and accelerations at one state.
fn ours(model: &ArmModel, dynamics: &mut Dynamics, s: &Value) -> [Vec<f64>; 3] {
    let (q, qd, tau) = (vector(&s["q"]), vector(&s["qd"]), vector(&s["tau"]));
    let n = q.len();
    let g = dynamics.gravity(&q).to_vec();
    let mut m = DMatrix::zeros(n, n);
    for i in 0..n {
        let mut e = vec![0.0; n];
        e[i] = 1.0;
        let column = dynamics.inverse(&q, &vec![0.0; n], &e);
        for r in 0..n {
            m[(r, i)] = column[r] - g[r];
        }
    }
    let bias = dynamics.inverse(&q, &qd, &vec![0.0; n]).to_vec();
    let rhs = DVector::from_iterator(
        n,
        (0..n).map(|i| tau[i] - bias[i] - model.joints[model.actuated[i]].damping * qd[i]),
    );
    let qacc = m.clone().lu().solve(&rhs).expect("M(q) is invertible");
    [
        m.transpose().as_slice().to_vec(),
        bias,
        qacc.as_slice().to_vec(),
    ]
}

#[test]
fn mjcf_dynamics_equal_mujocos() {
    let python = mujoco_python();
    let dir = std::env::temp_dir().join(format!("arm-model-mujoco-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(47);
    let mut worst = [0.0_f64; 3];
    for (k, path) in arms().iter().enumerate() {
        let arm = label(path);
        let model = ArmModel::from_mjcf_file(path, &Locks::new())
            .unwrap_or_else(|e| panic!("{arm} is not read: {e}"));
        let states = states(&model, &mut rng);
        let spec = dir.join(format!("{k}.json"));
        let names = model.joint_names();
        std::fs::write(&spec, json!({"names": names, "states": states}).to_string()).unwrap();
        let out = Command::new(&python)
            .arg(root().join("tests/mujoco_dynamics.py"))
            .arg(path)
            .arg(&spec)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "MuJoCo on {arm}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let theirs: Vec<Value> = serde_json::from_slice(&out.stdout).unwrap();
        let mut dynamics = Dynamics::new(&model, 1.0);
        let mut arm_worst = [0.0_f64; 3];
        for (s, t) in states.iter().zip(&theirs) {
            let mine = ours(&model, &mut dynamics, s);
            let m_theirs: Vec<f64> = (t["M"].as_array().unwrap().iter())
                .flat_map(vector)
                .collect();
            // The bias forces' own scale: M's largest entry times 1 m/s²
            // (a tenth of gravity's pull on the arm's reach, about).
            let m_scale = m_theirs.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            let errors = [
                relative(&mine[0], &m_theirs, 0.0),
                relative(&mine[1], &vector(&t["bias"]), m_scale),
                relative(&mine[2], &vector(&t["qacc"]), 0.0),
            ];
            for (k, what) in ["M(q)", "bias", "qacc"].iter().enumerate() {
                assert!(
                    errors[k] <= TOLERANCE,
                    "{arm}: {what} differs from MuJoCo's by {:.3e} relative at {s}",
                    errors[k]
                );
                worst[k] = worst[k].max(errors[k]);
                arm_worst[k] = arm_worst[k].max(errors[k]);
            }
        }
        println!(
            "{arm}: {} joints, largest relative difference M {:.2e}, bias {:.2e}, qacc {:.2e}",
            model.dof(),
            arm_worst[0],
            arm_worst[1],
            arm_worst[2]
        );
    }
    println!(
        "largest relative difference from MuJoCo: M {:.2e}, bias {:.2e}, qacc {:.2e}",
        worst[0], worst[1], worst[2]
    );
    std::fs::remove_dir_all(&dir).ok();
}
