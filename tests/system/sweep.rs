//! `testbed sweep run|report` as a user runs them: results, resume after
//! kill -9 and Ctrl-C, failing runs, named errors.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

use crate::util::{fails, json, ok, testbed, wait_bounded};

/// 2 axes × 2 values × 5 seeds = 20 runs of the paper scenario with sensor noise.
const GRID: &str = "name = \"grid\"\nseeds = 5\n[set]\nduration_s = 3.0\n\
\"plant.sensor.q_noise_std\" = 0.001\n\
[[axis]]\nkey = \"controller.k1\"\nvalues = [10.0, 20.0]\n\
[[axis]]\nkey = \"controller.k2\"\nrange = { start = 10.0, stop = 15.0, num = 2 }\n";

fn lines(dir: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with("results-"))
        .map(|e| {
            std::fs::read_to_string(e.path())
                .unwrap_or_default()
                .lines()
                .filter(|l| serde_json::from_str::<serde_json::Value>(l).is_ok())
                .count()
        })
        .sum()
}

/// The report without the compute-time metrics (timing, not results).
fn report(dir: &Path) -> serde_json::Value {
    let mut r = json(&ok(testbed().args(["sweep", "report", "--json"]).arg(dir)));
    for cell in r["cells"].as_array_mut().unwrap() {
        cell["metrics"]
            .as_array_mut()
            .unwrap()
            .retain(|m| !m["metric"].as_str().unwrap().starts_with("compute"));
    }
    r
}

fn start(file: &Path, out: &Path) -> std::process::Child {
    testbed()
        .args(["sweep", "run", "--no-progress", "--threads", "1", "--out"])
        .arg(out)
        .arg(file)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits (watchdog: 120 s) until `n` results are written.
fn wait_for_lines(dir: &Path, n: usize, child: &mut std::process::Child) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while lines(dir) < n {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the sweep ended before {n} results"
        );
        assert!(Instant::now() < deadline, "no {n} results after 120 s");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_sweep_resumes_after_kill_9_and_reports_as_if_uninterrupted() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("grid.toml");
    std::fs::write(&file, GRID).unwrap();
    let (cut, whole) = (dir.path().join("cut"), dir.path().join("whole"));
    let mut child = start(&file, &cut);
    wait_for_lines(&cut, 3, &mut child);
    kill(Pid::from_raw(child.id() as i32), Signal::SIGKILL).unwrap();
    wait_bounded(&mut child, 30);
    let before = lines(&cut);
    assert!((3..20).contains(&before), "{before} results at the kill");
    let out = ok(testbed()
        .args(["sweep", "run", "--no-progress", "--out"])
        .arg(&cut)
        .arg(&file));
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains(&format!("{before} done before, {} run now", 20 - before)),
        "{said}"
    );
    assert_eq!(lines(&cut), 20, "every run exactly once");
    ok(testbed()
        .args(["sweep", "run", "--no-progress", "--out"])
        .arg(&whole)
        .arg(&file));
    let (a, b) = (report(&cut), report(&whole));
    assert_eq!(a["cells"], b["cells"]);
    assert_eq!(a["found_runs"], 20);
    let cells = a["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 4);
    assert_eq!(cells[0]["cell"]["controller.k1"], 10.0);
    assert_eq!(cells[0]["success_rate"], 1.0);
    // Seeds differ, so the IQR is a real one.
    let iae = &cells[0]["metrics"][0];
    assert_eq!(iae["metric"], "iae");
    assert!(
        iae["q1"].as_f64().unwrap() < iae["q3"].as_f64().unwrap(),
        "{iae}"
    );
}

#[test]
fn ctrl_c_stops_a_sweep_keeping_what_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("grid.toml");
    std::fs::write(&file, GRID).unwrap();
    let out = dir.path().join("out");
    let mut child = start(&file, &out);
    wait_for_lines(&out, 1, &mut child);
    kill(Pid::from_raw(child.id() as i32), Signal::SIGINT).unwrap();
    let status = wait_bounded(&mut child, 60);
    assert_eq!(status.code(), Some(130));
    let kept = lines(&out);
    assert!((1..20).contains(&kept), "{kept}");
    ok(testbed()
        .args(["sweep", "run", "--no-progress", "--out"])
        .arg(&out)
        .arg(&file));
    assert_eq!(lines(&out), 20);
}

#[test]
fn a_diverging_run_is_recorded_and_the_sweep_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("euler.toml");
    std::fs::write(
        &file,
        "[set]\nduration_s = 2.5\n\"plant.saturate\" = false\n[[axis]]\nkey = \"controller.integrator\"\nvalues = [\"euler\", \"exact\"]\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let run = ok(testbed()
        .args(["sweep", "run", "--no-progress", "--out"])
        .arg(&out)
        .arg(&file));
    assert!(String::from_utf8_lossy(&run.stderr).contains("(1 failed or diverged)"));
    let r = json(&ok(testbed().args(["sweep", "report", "--json"]).arg(&out)));
    let cells = r["cells"].as_array().unwrap();
    assert_eq!(cells[0]["cell"]["controller.integrator"], "euler");
    assert_eq!(
        (
            cells[0]["success_rate"].as_f64(),
            cells[0]["not_ok"].as_u64()
        ),
        (Some(0.0), Some(1))
    );
    assert_eq!(cells[1]["success_rate"], 1.0);
    let text: String = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with("results-"))
        .map(|e| std::fs::read_to_string(e.path()).unwrap())
        .collect();
    assert!(text.contains("\"status\":\"diverged\""), "{text}");
    let csv = dir.path().join("r.csv");
    let figs = dir.path().join("fig");
    Command::new(crate::util::bin("testbed"))
        .args(["sweep", "report"])
        .arg(&out)
        .arg("--csv")
        .arg(&csv)
        .arg("--plots")
        .arg(&figs)
        .output()
        .unwrap();
    let csv = std::fs::read_to_string(&csv).unwrap();
    assert!(csv.starts_with("controller.integrator,law,runs,found,success_rate,iae_median,"));
    assert_eq!(csv.lines().count(), 3);
    assert!(figs.join("sweep_boxes.png").exists() && !figs.join("sweep_heatmap.png").exists());
}

#[test]
fn sweep_errors_name_the_file_and_key_and_run_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "[[axis]]\nkey = \"controller.k3\"\nvalues = [1.0]\n",
            "axis controller.k3: unknown field `k3`",
        ),
        (
            "[set]\n\"plant.nosuch\" = 1\n",
            "set plant.nosuch: unknown field `nosuch`",
        ),
        (
            "laws = [\"pd\"]\n[[axis]]\nkey = \"controller.beta\"\nvalues = [2.0]\n",
            "controller.beta is not a parameter of law 'pd'",
        ),
        (
            "[[axis]]\nkey = \"controller.beta\"\nvalues = [-1.0]\n",
            "controller.beta = -1.0 is invalid",
        ),
        (
            "[[axis]]\nkey = \"controller.k1\"\nrange = { start = 1.0, stop = 2.0, num = 0 }\n",
            "axis controller.k1: range",
        ),
        ("seeds = 0\n", "seeds = 0"),
        ("laws = [\"lqr\"]\n", "unknown variant `lqr`"),
        ("axes = []\n", "unknown field `axes`"),
        (
            "name = \"../escape\"\n",
            "name = \"../escape\": use up to 100 letters",
        ),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let file = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&file, text).unwrap();
        let out = dir.path().join(format!("out{i}"));
        let e = fails(
            testbed()
                .args(["sweep", "run", "--out"])
                .arg(&out)
                .arg(&file),
        );
        assert!(
            e.contains(&format!("bad{i}.toml")) && e.contains(want),
            "{text}: {e}"
        );
        assert!(!out.exists(), "{text}: a folder was made");
    }
    let e = fails(
        testbed()
            .args(["sweep", "report"])
            .arg(dir.path().join("nothing")),
    );
    assert!(e.contains("manifest.json"), "{e}");
}

/// #31 row 5: the results folder removed while the sweep runs: the loss is
/// noticed and the sweep fails, instead of "results in …" with nothing kept.
#[test]
fn a_results_folder_removed_mid_sweep_fails_the_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("long.toml");
    // Long enough (400 runs of 3 s) that the removal lands mid-sweep.
    std::fs::write(
        &file,
        "name = \"long\"\nseeds = 400\n[set]\nduration_s = 3.0\n",
    )
    .unwrap();
    let out = dir.path().join("res");
    let mut child = start(&file, &out);
    wait_for_lines(&out, 1, &mut child);
    std::fs::remove_dir_all(&out).unwrap();
    let status = crate::util::wait_bounded(&mut child, 120);
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    assert!(!status.success(), "{err}");
    assert!(
        err.contains("removed or replaced while the sweep ran"),
        "{err}"
    );
}

/// A sweep of a randomised scenario draws per seed as `compare` does: each
/// run is the `compare` row of its seed, and the seeds differ.
#[test]
fn a_randomised_sweep_draws_per_seed_like_compare() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("r.toml");
    std::fs::write(
        &file,
        "name = \"r\"\nscenario = \"paper_randomised\"\nseeds = 3\nlaws = [\"nac\"]\n\
         [set]\nduration_s = 2.5\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    ok(testbed()
        .args(["sweep", "run", "--no-progress", "--out"])
        .arg(&out)
        .arg(&file));
    let cmp = json(&ok(testbed().args([
        "compare",
        "--scenario",
        "paper_randomised",
        "--duration",
        "2.5",
        "--laws",
        "nac",
        "--seeds",
        "3",
        "--json",
    ])));
    let mut runs: Vec<serde_json::Value> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with("results-"))
        .flat_map(|e| {
            std::fs::read_to_string(e.path())
                .unwrap()
                .lines()
                .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
                .collect::<Vec<_>>()
        })
        .collect();
    runs.sort_by_key(|r| r["seed"].as_u64());
    assert_eq!(runs.len(), 3);
    for (run, row) in runs.iter().zip(cmp["laws"][0]["runs"].as_array().unwrap()) {
        assert_eq!(run["seed"], row["seed"]);
        assert_eq!(
            run["summary"]["metrics"], row["summary"]["metrics"],
            "seed {}",
            run["seed"]
        );
    }
    assert_ne!(runs[0]["summary"]["metrics"], runs[1]["summary"]["metrics"]);
}
