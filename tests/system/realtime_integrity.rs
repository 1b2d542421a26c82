//! Real time you can trust (#25): every step's reference and command ages
//! counted, the log's recount equal to the live counts, and a verdict that
//! never calls a run clean when timing changed its result.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::util::{ok, testbed};

fn json(out: &std::process::Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "not JSON ({e}): {}\nstderr: {}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// Runs `testbed run` (real time) with `args`; exit 0, 3 or 4 with the
/// JSON summary, whose verdict must match the status.
fn realtime_run(args: &[&str]) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let out = testbed()
        .args(["run", "--json", "--runs-dir"])
        .arg(dir.path())
        .args(args)
        .output()
        .unwrap();
    let code = out.status.code();
    let s = json(&out);
    let verdict = s["timing"]["verdict"]
        .as_str()
        .unwrap_or_default()
        .to_string();
    let expected = match verdict.as_str() {
        "clean" => Some(0),
        "degraded" => Some(3),
        "invalid" => Some(4),
        _ => None,
    };
    assert_eq!(
        code,
        expected,
        "verdict {verdict}, stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The log alone gives the same figures: replay recounts them.
    let log = s["log"].as_str().unwrap();
    let replayed = json(&crate::util::replayed(
        testbed().args(["replay", "--json", log]),
    ));
    for key in [
        "verdict",
        "reasons",
        "deadline_misses",
        "stale_references",
        "recount",
    ] {
        assert_eq!(replayed["timing"][key], s["timing"][key], "{key}");
    }
    s
}

/// The live counts equal the recount from the log's stamps.
fn assert_recount_equals_live(s: &Value) {
    let t = &s["timing"];
    assert_eq!(t["recount"]["deadline_misses"], t["deadline_misses"], "{t}");
    assert_eq!(
        t["recount"]["stale_references"], t["stale_references"],
        "{t}"
    );
}

/// A reference published just in time (horizon 0, a live planner) races
/// the plant's state: stale references are counted, named in the verdict,
/// and the log recounts exactly what the controller counted.
#[test]
fn realtime_stale_references_are_counted_and_recounted() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("just_in_time.toml");
    std::fs::write(
        &scenario,
        "name = \"just in time\"\nduration_s = 2.0\n[reference]\nhorizon_s = 0.0\n",
    )
    .unwrap();
    let s = realtime_run(&["--scenario", scenario.to_str().unwrap()]);
    assert_recount_equals_live(&s);
    let t = &s["timing"];
    let stale = t["stale_references"].as_u64().unwrap();
    if stale > 0 {
        assert_ne!(t["verdict"], "clean", "{t}");
        let reasons = t["reasons"].to_string();
        assert!(
            reasons.contains(&format!("{stale} stale references")),
            "{t}"
        );
    }
    for age in ["state_age_us", "command_age_us"] {
        assert!(t[age]["count"].as_u64().unwrap() > 1900, "{age}: {t}");
    }
}

/// Busy loops on every CPU, ended when dropped (and after `limit` at the
/// latest: the hog is bounded whatever the test does).
struct Hog {
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl Hog {
    fn start(limit: Duration) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let cpus = std::thread::available_parallelism().map_or(2, usize::from);
        let threads = (0..2 * cpus)
            .map(|_| {
                let stop = Arc::clone(&stop);
                std::thread::spawn(move || {
                    let end = Instant::now() + limit;
                    let mut x = 0u64;
                    while !stop.load(Ordering::Relaxed) && Instant::now() < end {
                        for _ in 0..10_000 {
                            x = std::hint::black_box(
                                x.wrapping_mul(6364136223846793005).wrapping_add(1),
                            );
                        }
                    }
                })
            })
            .collect();
        Self { stop, threads }
    }
}

impl Drop for Hog {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// Under a CPU hog on every CPU a real-time run is either as good as the
/// in-process run (errors after T_c within 5 %) or says it is not, with
/// the counts that explain it; never a violated constraint beside a clean
/// verdict.
#[test]
fn realtime_under_a_cpu_hog_is_right_or_says_why() {
    let args = ["--duration", "4"];
    let sim = json(&ok(testbed().args(["sim", "--json"]).args(args)));
    let s = {
        let _hog = Hog::start(Duration::from_secs(90));
        realtime_run(&args)
    };
    assert_recount_equals_live(&s);
    let t = &s["timing"];
    let verdict = t["verdict"].as_str().unwrap();
    if verdict == "clean" {
        assert_eq!(
            s["constraint_satisfied_after_tc"], sim["constraint_satisfied_after_tc"],
            "{t}"
        );
        for (j, (rt, reference)) in s["joints"]
            .as_array()
            .unwrap()
            .iter()
            .zip(sim["joints"].as_array().unwrap())
            .enumerate()
        {
            let (a, b) = (
                rt["max_abs_error_after_tc"].as_f64().unwrap(),
                reference["max_abs_error_after_tc"].as_f64().unwrap(),
            );
            assert!(
                (a - b).abs() <= 0.05 * b,
                "joint {j}: max |e| after T_c {a} in real time against {b} in process, \
                 with a clean verdict: {t}"
            );
        }
    } else {
        let reasons = t["reasons"].as_array().unwrap();
        assert!(!reasons.is_empty(), "{t}");
        let counted = t["deadline_misses"].as_u64().unwrap()
            + t["stale_references"].as_u64().unwrap()
            + t["late_wakeups"].as_u64().unwrap()
            + s["missing_rows"].as_u64().unwrap();
        assert!(counted > 0 || verdict == "invalid", "{t}");
    }
}
