//! Bad input is refused by name, before anything runs: networks, tables,
//! URDFs and settings out of bounds, special files, escape codes, Slurm
//! options, node configs, a law's keys, a policy path that is no file.

use std::process::Command;
use std::process::Stdio;

use crate::util::{ended, fails, ok, testbed};

fn scenario(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// #18 row 3 and the neurons part of row 4: no panic, no huge allocation.
#[test]
fn a_huge_network_is_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    for n in ["18446744073709551615", "1000000000", "1001"] {
        let f = scenario(
            dir.path(),
            "n.toml",
            &format!("[controller]\nneurons = {n}\n"),
        );
        let e = fails(testbed().arg("sim").arg("--scenario").arg(&f));
        assert!(
            e.contains(&format!("controller.neurons = {n} is invalid")),
            "{e}"
        );
        let out = testbed()
            .arg("sim")
            .arg("--scenario")
            .arg(&f)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{n}");
    }
}

/// #18 row 7: every key is optional, in a partial table too.
#[test]
fn partial_reference_and_envelope_tables_take_the_papers_values() {
    let dir = tempfile::tempdir().unwrap();
    for text in [
        "[reference]\nrate_hz = 500.0\n",
        "[envelope]\n",
        "[envelope]\nfrom_limits = false\n",
    ] {
        let f = scenario(dir.path(), "p.toml", text);
        ok(testbed()
            .args(["sim", "--duration", "0.2", "--scenario"])
            .arg(&f));
    }
}

/// #18 row 12: a duration shorter than one period is refused, not run as 0 steps.
#[test]
fn a_run_of_no_steps_is_refused() {
    let e = fails(testbed().args(["sim", "--duration", "1e-9"]));
    assert!(
        e.contains("duration_s = 0.000000001 is invalid: it must be at least one control period"),
        "{e}"
    );
    let e = fails(testbed().args(["run", "--mode", "lockstep", "--duration", "1e-9"]));
    assert!(e.contains("duration_s"), "{e}");
}

/// #18 row 8: a prismatic joint without `<limit>` and a negative effort are
/// named, with the file and the joint.
#[test]
fn prismatic_without_limit_and_negative_effort_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = |limit: &str| {
        format!(
            r#"<robot name="p"><link name="base"/><link name="a"><inertial><mass value="1"/>
<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
<joint name="j1" type="prismatic"><parent link="base"/><child link="a"/><axis xyz="1 0 0"/>{limit}</joint></robot>"#
        )
    };
    let cases = [
        ("", "joint 'j1' <limit> = lower = upper = 0 is invalid"),
        (
            r#"<limit lower="-1" upper="1" effort="-5" velocity="1"/>"#,
            "joint 'j1' limit effort = -5 is invalid",
        ),
    ];
    for (limit, want) in cases {
        let f = scenario(dir.path(), "p.urdf", &urdf(limit));
        for cmd in [vec!["robot"], vec!["sim", "--robot"]] {
            let e = fails(testbed().args(&cmd).arg(&f));
            assert!(e.contains("p.urdf") && e.contains(want), "{cmd:?}: {e}");
        }
    }
    let f = scenario(
        dir.path(),
        "ok.urdf",
        &urdf(r#"<limit lower="-0.5" upper="0.5" effort="50" velocity="1"/>"#),
    );
    ok(testbed()
        .args(["sim", "--duration", "0.2", "--robot"])
        .arg(&f));
}

/// #18 row 4, files: a device or a FIFO is refused at once, never read or waited on.
#[test]
fn special_files_are_refused_without_reading_them() {
    let dir = tempfile::tempdir().unwrap();
    let robot = scenario(dir.path(), "zero.toml", "robot = \"/dev/zero\"\n");
    let fifo = dir.path().join("fifo");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let cases: Vec<Vec<std::ffi::OsString>> = vec![
        vec!["sim".into(), "--scenario".into(), "/dev/zero".into()],
        vec!["sim".into(), "--scenario".into(), robot.into()],
        vec!["sim".into(), "--robot".into(), "/dev/zero".into()],
        vec!["replay".into(), "/dev/zero".into()],
        vec!["replay".into(), fifo.clone().into()],
    ];
    for args in cases {
        let e = fails(testbed().args(&args));
        assert!(e.contains("not a regular file"), "{args:?}: {e}");
    }
}

/// #18 row 9: a value that would overflow the run is refused up front, shortly.
#[test]
fn an_overflowing_setting_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    for (table, key) in [
        ("plant.sensor", "q_noise_std"),
        ("plant.disturbance", "noise_std"),
    ] {
        let f = scenario(
            dir.path(),
            "big.toml",
            &format!("[{table}]\n{key} = 1e308\n"),
        );
        let e = fails(testbed().arg("sim").arg("--scenario").arg(&f));
        assert!(
            e.contains(&format!(
                "{table}.{key} = 1e308 is invalid: it must be a number from 0 to 1e9"
            )),
            "{e}"
        );
    }
}

/// #18 row 12: control characters in the name never reach the terminal.
#[test]
fn a_name_with_escape_codes_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let f = scenario(dir.path(), "ansi.toml", "name = \"a\\u001b[31mred\"\n");
    let e = fails(testbed().arg("sim").arg("--scenario").arg(&f));
    assert!(
        e.contains("name = \"a\\u{1b}[31mred\" is invalid") && !e.contains('\u{1b}'),
        "{e}"
    );
}

/// #18 row 13: a URDF the size of a scene is refused at once, in a short message.
#[test]
fn a_urdf_of_thousands_of_links_is_refused_quickly() {
    let dir = tempfile::tempdir().unwrap();
    let links: String = (0..5000)
        .map(|i| format!("<link name=\"l{i}\"/>"))
        .collect();
    let f = scenario(
        dir.path(),
        "scene.urdf",
        &format!("<robot name=\"s\">{links}</robot>"),
    );
    let e = fails(testbed().arg("robot").arg(&f));
    assert!(
        e.contains("5000 links, 0 joints is invalid: it must be at most 1000"),
        "{e}"
    );
    assert!(e.len() < 500, "{} bytes of error", e.len());
}

/// #31 row 15: a URDF of 50 000 nested elements (350 KB) is refused by name, not
/// a stack overflow.
#[test]
fn a_deeply_nested_urdf_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = dir.path().join("deep.urdf");
    let text = format!(
        "<robot name=\"deep\">{}{}</robot>",
        "<link name=\"a\">".repeat(50_000),
        "</link>".repeat(50_000)
    );
    std::fs::write(&urdf, text).unwrap();
    for args in [&["robot"][..], &["sim", "--robot"][..]] {
        let err = crate::util::fails(testbed().args(args).arg(&urdf));
        assert!(
            err.contains("deep.urdf") && err.contains("nested more than 100 deep"),
            "{err}"
        );
    }
}

/// #31 row 18: values pasted into `#SBATCH` lines are checked, not pasted: a
/// line break in `--partition` once injected shell lines.
#[test]
fn slurm_options_cannot_inject_lines() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("s.toml");
    std::fs::write(&sweep, "[set]\nduration_s = 0.01\n").unwrap();
    for (flag, value) in [
        ("--partition", "x\necho X"),
        ("--time", "1:00\n#SBATCH --x"),
    ] {
        let out = dir.path().join(flag.trim_start_matches('-'));
        let err = crate::util::fails(
            testbed()
                .args(["sweep", "slurm"])
                .arg(&sweep)
                .arg("--out")
                .arg(&out)
                .args([flag, value]),
        );
        assert!(err.contains(flag), "{err}");
        assert!(!out.join("sweep.sbatch").exists());
    }
}

/// #31 row 19: a node's config is checked like a scenario, and read only if it
/// is a regular file of a sane size.
#[test]
fn node_configs_are_checked_and_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("controller.json");
    std::fs::write(
        &config,
        r#"{"params": {}, "dof": 100, "period_ns": 1000000}"#,
    )
    .unwrap();
    let prefix = format!("cfgtest{}_", std::process::id());
    let node = |config: &std::path::Path| {
        crate::util::fails(
            testbed()
                .args([
                    "node",
                    "controller",
                    "--mode",
                    "lockstep",
                    "--prefix",
                    &prefix,
                    "--config",
                ])
                .arg(config),
        )
    };
    let err = node(&config);
    assert!(err.contains("dof") && err.contains("100 joints"), "{err}");
    let err = node(std::path::Path::new("/dev/zero"));
    assert!(
        err.contains("/dev/zero") && err.contains("not a regular file"),
        "{err}"
    );
    assert!(crate::util::shm_files(&prefix).is_empty());
}

/// #39 row 15: `--law X --set controller.<X's key>=…` sets X's key.
#[test]
fn a_law_on_the_command_line_takes_its_own_keys_from_set() {
    let out = ok(testbed().args([
        "sim",
        "--duration",
        "0.2",
        "--law",
        "mpc",
        "--set",
        "controller.mpc_horizon=5",
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["law"]["law"], "mpc", "{}", v["law"]);
    let e = fails(testbed().args([
        "sim",
        "--duration",
        "0.2",
        "--law",
        "pd",
        "--set",
        "controller.beta=3",
    ]));
    assert!(
        e.contains("controller.beta is not a parameter of law 'pd'"),
        "{e}"
    );
}

/// Item 13 (D15): two rows of one name (`--laws pd,pd`, one label given
/// to two `--controller-cmd`s, a label that is a default row's law) are
/// refused by name before any run, not shown as two rows no reader can
/// tell apart.
#[test]
fn compare_refuses_two_rows_of_one_name() {
    let ext = format!(
        "ext={}",
        crate::util::bin("example-pd-controller").display()
    );
    let nac = format!(
        "nac={}",
        crate::util::bin("example-pd-controller").display()
    );
    let compare = || {
        let mut cmd = testbed();
        cmd.args(["compare", "--duration", "0.1", "--seeds", "1", "--json"]);
        cmd
    };
    let e = crate::util::fails(compare().args(["--laws", "pd,pd"]));
    assert!(e.contains("--laws names pd twice"), "{e}");
    let e = crate::util::fails(compare().args([
        "--laws",
        "pd",
        "--controller-cmd",
        &ext,
        "--controller-cmd",
        &ext,
    ]));
    assert!(e.contains("--controller-cmd ext=… is given twice"), "{e}");
    let e = crate::util::fails(compare().args(["--controller-cmd", &nac]));
    assert!(e.contains("nac is a built-in law's name"), "{e}");
}

#[test]
fn a_policy_path_that_is_a_fifo_or_a_device_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("p.onnx");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    for path in [fifo.display().to_string(), "/dev/zero".to_string()] {
        let cmd = format!("{} {path}", crate::util::bin("testbed-policy").display());
        let mut child = testbed()
            .args([
                "run",
                "--mode",
                "lockstep",
                "--duration",
                "0.2",
                "--runs-dir",
            ])
            .arg(dir.path().join("runs"))
            .args(["--controller-cmd", &cmd])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Ends by itself (a watchdog, not a sleep: it used to hang here).
        let (status, _, err) = ended(&mut child, 60);
        assert!(!status.success(), "{path}: {err}");
        assert!(err.contains("not a regular file"), "{path}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        // Nothing of it is left running.
        let left = std::process::Command::new("pgrep")
            .args(["-f", &format!("testbed-policy {path}")])
            .output()
            .unwrap();
        assert!(
            left.stdout.is_empty(),
            "left running: {}",
            String::from_utf8_lossy(&left.stdout)
        );
    }
}
