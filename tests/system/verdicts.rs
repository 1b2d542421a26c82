//! A run is judged only on what it shows: one shorter than T_c is not
//! judged, a law every run of which failed fails the comparison, and a
//! failing policy's traceback goes to its log, not into the table.

use std::path::Path;

use crate::util::{fails, testbed};

/// #31 row 20: runs that end before T_c say nothing about the constraint: the
/// sweep report calls them "not judged", not a 0 % success.
#[test]
fn runs_shorter_than_tc_are_not_judged() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("short.toml");
    std::fs::write(&file, "[set]\nduration_s = 0.5\n").unwrap();
    let out = dir.path().join("res");
    crate::util::ok(
        testbed()
            .args(["sweep", "run", "--no-progress", "--out"])
            .arg(&out)
            .arg(&file),
    );
    let text = crate::util::ok(testbed().args(["sweep", "report"]).arg(&out)).stdout;
    assert!(
        String::from_utf8_lossy(&text).contains("not judged"),
        "{}",
        String::from_utf8_lossy(&text)
    );
    let json = crate::util::ok(testbed().args(["sweep", "report", "--json"]).arg(&out)).stdout;
    let r: serde_json::Value = serde_json::from_slice(&json).unwrap();
    assert!(r["cells"][0]["success_rate"].is_null(), "{r}");
}

#[test]
fn compare_fails_when_every_run_of_a_law_failed() {
    let err = fails(testbed().args([
        "compare",
        "--seeds",
        "2",
        "--duration",
        "0.2",
        "--laws",
        "nac",
        "--controller-cmd",
        "broken=/bin/false",
    ]));
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.contains("every run of broken failed"),
        "last line: {last}\n{err}"
    );
}

/// Every file under `dir`.
fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// Item 16: a user's controller (a policy) that raises fails its row
/// with one line, the exception, not the traceback with its file paths,
/// which stay in the run's nodes/controller.log.
#[test]
fn a_failing_policys_traceback_stays_out_of_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("policy.sh");
    std::fs::write(
        &script,
        "case \"$1\" in --describe) exit 1;; esac\n\
         printf 'Traceback (most recent call last):\\n' >&2\n\
         printf '  File \"/home/me/secret/policy.py\", line 3, in <module>\\n' >&2\n\
         printf 'ValueError: bad weights\\n' >&2\n\
         exit 1\n",
    )
    .unwrap();
    let cmd = format!("pol=sh {}", script.display());
    let out = testbed()
        .args([
            "compare",
            "--duration",
            "0.1",
            "--seeds",
            "1",
            "--laws",
            "pd",
        ])
        .args(["--json", "--controller-cmd", &cmd, "--runs-dir"])
        .arg(dir.path())
        .output()
        .unwrap();
    let c = crate::util::json(&out);
    let row = c["laws"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "pol")
        .unwrap_or_else(|| panic!("no row pol: {c}"));
    let why = row["runs"][0]["failed"].as_str().unwrap_or_default();
    assert!(why.contains("ValueError: bad weights"), "{why}");
    assert!(
        !why.contains("/home/me/secret") && !why.contains("Traceback") && !why.contains('\n'),
        "{why}"
    );
    // The whole text is in the node's log.
    let logs: Vec<String> = walk(dir.path())
        .into_iter()
        .filter(|p| p.ends_with("nodes/controller.log"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    assert!(
        logs.iter().any(|l| l.contains("/home/me/secret/policy.py")),
        "{logs:?}"
    );
}
