//! The shipped scenarios and the plant effects they turn on, end to end.
use crate::util::{assert_same_csv, csv_of, fails, json, ok, repo_root, testbed};

/// Every shipped scenario, as listed by `testbed scenarios`.
fn shipped() -> Vec<String> {
    let out = ok(testbed().arg("scenarios"));
    let text = String::from_utf8(out.stdout).unwrap();
    text.lines()
        .filter(|l| !l.starts_with(' ') && !l.is_empty() && !l.starts_with("Run "))
        .map(str::to_string)
        .collect()
}

#[test]
fn scenarios_lists_every_file_with_what_it_shows() {
    let listed = shipped();
    let mut files: Vec<String> = std::fs::read_dir(repo_root().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter_map(|f| f.strip_suffix(".toml").map(str::to_string))
        .collect();
    files.sort();
    let mut sorted = listed.clone();
    sorted.sort();
    assert_eq!(sorted, files);
    let text = String::from_utf8(ok(testbed().arg("scenarios")).stdout).unwrap();
    assert!(text.contains("payload_pickup") && text.contains("2 kg mass"));
}

/// The controller keeps every shipped scenario inside its envelope after
/// T_c, with finite signals, and each scenario's effects show in the
/// summary. Runs by name, as the README says.
#[test]
fn every_shipped_scenario_keeps_its_envelope() {
    for name in shipped() {
        let s = json(&ok(testbed().args(["sim", "--json", "--scenario", &name])));
        assert_eq!(s["finite"], true, "{name}: {s}");
        assert_eq!(s["constraint_satisfied_after_tc"], true, "{name}: {s}");
        let active: Vec<&str> = s["effects"]["active"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        let want: &[&str] = match name.as_str() {
            "payload_pickup" => &["payload"],
            "friction_noise" => &["friction", "sensor_noise", "quantised"],
            "disturbance" => &["disturbance"],
            "actuation_delay" => &["delayed", "command_dropped", "command_held"],
            "tight_envelope" => &["disturbance"],
            "saturation_slow_reference" => &["saturated"],
            "paper_randomised" => &["sensor_noise", "disturbance"],
            "ur5_randomised" => &["disturbance"],
            "iiwa_actuators" => &["motor_lag", "backlash", "cogging", "elastic"],
            "paper_obstacle" => &["contact"],
            "paper_pick_place" => &["contact", "payload"],
            _ => &[],
        };
        for w in want {
            assert!(active.contains(w), "{name}: {w} not in {active:?}");
        }
    }
}

/// Every random effect at once (sensor noise, quantisation, disturbance
/// noise, lost commands, delay, friction, a payload picked up), on motors
/// that lag, cog and drive through elastic gears with backlash: the four
/// processes in lockstep give the in-process loop's bits; the same seed
/// gives the same run; another seed another run.
#[test]
fn seeded_effects_reproduce_exactly_across_processes_and_seeds_differ() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = |seed: u64| {
        let path = dir.path().join(format!("all_effects_{seed}.toml"));
        std::fs::write(
            &path,
            format!(
                "name = \"all_effects\"\nseed = {seed}\nduration_s = 3.0\n\
                 [reference]\nrate_hz = 250.0\njoints = [{{ sin = 1.0, omega = 2.0 }}, {{ cos = 1.0, omega = 1.0 }}]\n\
                 [plant.friction]\nviscous = 0.2\ncoulomb = 0.3\n\
                 [plant.payload]\nlink = \"link2\"\nmass = 0.5\noffset = [0.31, 0.0, 0.0]\nattach_at_s = 1.5\n\
                 [plant.disturbance]\nnoise_std = 0.5\nsin_amplitude = 1.0\n\
                 [plant.sensor]\nq_noise_std = 0.0005\nqd_noise_std = 0.01\nq_resolution = 0.001\n\
                 [plant.actuation]\ndelay_periods = 1\ndrop_probability = 0.1\n\
                 [plant.actuator]\nbandwidth_hz = 50.0\nslew_rate = 2000.0\nstiffness = 3000.0\n\
                 damping = 3.0\nmotor_inertia = 0.05\nbacklash = 0.001\n\
                 [[plant.actuator.cogging]]\norder = 20.0\namplitude = 0.1\n"
            ),
        )
        .unwrap();
        path.display().to_string()
    };
    let (s1, s2) = (scenario(1), scenario(2));
    let sim1 = csv_of(&["sim", "--scenario", &s1], dir.path(), "sim1.csv");
    let again = csv_of(&["sim", "--scenario", &s1], dir.path(), "again.csv");
    let sim2 = csv_of(&["sim", "--scenario", &s2], dir.path(), "sim2.csv");
    assert!(sim1 == again, "the same seed gave a different run");
    assert!(sim1 != sim2, "seeds 1 and 2 gave the same run");
    let runs = dir.path().join("runs");
    let lockstep_csv = dir.path().join("lockstep.csv");
    let run = json(&ok(testbed()
        .args(["run", "--mode", "lockstep", "--json", "--scenario", &s1])
        .arg("--runs-dir")
        .arg(&runs)
        .arg("--csv")
        .arg(&lockstep_csv)));
    assert_same_csv(
        "sim vs lockstep",
        &sim1,
        &std::fs::read(&lockstep_csv).unwrap(),
    );
    // The controller, re-driven from the logged measurements, gives the
    // logged torques exactly.
    let verify = json(&ok(testbed()
        .args(["replay", "--verify", "--json"])
        .arg(run["log"].as_str().unwrap())));
    assert_eq!(verify["max_abs_torque_diff"], 0.0, "{verify}");
    // Every effect left its mark in the rows.
    let text = String::from_utf8(sim1).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "effects").unwrap();
    let seen = lines
        .map(|l| l.split(',').nth(col).unwrap().parse::<u32>().unwrap())
        .fold(0, |a, b| a | b);
    // friction, payload, disturbance, sensor noise, quantised, delayed,
    // command dropped, command held, motor lag, backlash, cogging, elastic.
    let all = 0b1_1111_1111_0111;
    assert_eq!(seen & all, all, "{seen:b}");
}

/// #38 item 2: a pick and place (grasp and release included) runs the same
/// bits in `sim` and in lockstep.
#[test]
fn a_pick_and_place_runs_the_same_in_sim_and_lockstep() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["--scenario", "paper_pick_place", "--duration", "6"];
    let sim = csv_of(&[&["sim"][..], &args].concat(), dir.path(), "sim.csv");
    let lockstep_csv = dir.path().join("lockstep.csv");
    let run = json(&ok(testbed()
        .args(["run", "--mode", "lockstep", "--json"])
        .args(args)
        .arg("--runs-dir")
        .arg(dir.path().join("runs"))
        .arg("--csv")
        .arg(&lockstep_csv)));
    assert_same_csv(
        "sim vs lockstep",
        &sim,
        &std::fs::read(&lockstep_csv).unwrap(),
    );
    // The ball's pose comes with every contact sample: on the table until
    // taken at 2.1 s, carried (lifted) after, and drawn on /arm/contact
    // every 20 ms of sim time.
    let (mut z, mut markers) = (Vec::new(), 0u64);
    let mut on_message = |m: &logger::RawMessage<'_>| {
        markers += u64::from(m.topic == logger::obstacles::CONTACT_MARKER_TOPIC);
        if let Some(wire::Logged::ContactState(c)) = logger::decode_logged(m)? {
            assert_eq!(c.count, 7, "{c:?}");
            z.push(c.objects[2]);
        }
        Ok(())
    };
    logger::read_log(
        std::path::Path::new(run["log"].as_str().unwrap()),
        Some(&mut on_message),
    )
    .unwrap();
    assert_eq!(z.len(), 6001);
    assert!((z[1000] + 0.47).abs() < 2e-3, "resting: z = {}", z[1000]);
    let carried = z[2100..5400].iter().copied().fold(f64::MIN, f64::max);
    assert!(carried > z[2100] + 0.05, "never lifted: max z {carried}");
    assert!((299..=301).contains(&markers), "{markers} object markers");
}

/// #38 item 2: the arm striking a table runs the same bits in `sim` and in
/// lockstep (Rapier's contact solver is deterministic), and the controller
/// re-driven from the log gives the logged torques exactly.
#[test]
fn a_contact_scenario_runs_the_same_in_sim_and_lockstep() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["--scenario", "paper_obstacle", "--duration", "2.5"];
    let sim = csv_of(&[&["sim"][..], &args].concat(), dir.path(), "sim.csv");
    let lockstep_csv = dir.path().join("lockstep.csv");
    let run = json(&ok(testbed()
        .args(["run", "--mode", "lockstep", "--json"])
        .args(args)
        .arg("--runs-dir")
        .arg(dir.path().join("runs"))
        .arg("--csv")
        .arg(&lockstep_csv)));
    assert_same_csv(
        "sim vs lockstep",
        &sim,
        &std::fs::read(&lockstep_csv).unwrap(),
    );
    assert!(
        run["effects"]["contact_steps"].as_u64().unwrap() > 100,
        "{}",
        run["effects"]
    );
    let verify = json(&ok(testbed()
        .args(["replay", "--verify", "--json"])
        .arg(run["log"].as_str().unwrap())));
    assert_eq!(verify["max_abs_torque_diff"], 0.0, "{verify}");
    assert_eq!(
        verify["effects"]["contact_steps"],
        run["effects"]["contact_steps"]
    );
    // The log's /contact: one sample per state, the force where the state
    // says contact, the point on the table's top (z = -0.5 m) under the arm.
    let (mut samples, mut touching, mut markers) = (0u64, 0u64, 0u64);
    let mut on_message = |m: &logger::RawMessage<'_>| {
        markers += u64::from(m.topic == logger::obstacles::CONTACT_MARKER_TOPIC);
        if let Some(wire::Logged::ContactState(c)) = logger::decode_logged(m)? {
            samples += 1;
            if c.points > 0 {
                touching += 1;
                assert!(c.force.is_finite() && c.force >= 0.0, "{c:?}");
                assert!((c.point_z + 0.5).abs() < 0.05 && c.point_x > 0.0, "{c:?}");
            }
        }
        Ok(())
    };
    logger::read_log(
        std::path::Path::new(run["log"].as_str().unwrap()),
        Some(&mut on_message),
    )
    .unwrap();
    assert_eq!(samples, run["steps"].as_u64().unwrap() + 1);
    assert!(touching > 100, "{touching} samples in contact");
    // The 3D view's contact point: every 20 ms of sim time in contact.
    assert!(
        markers >= touching / 20 && markers <= touching / 20 + 10,
        "{markers} contact markers for {touching} samples in contact"
    );
}

/// A reference published at 100 Hz under a 1 kHz loop, in real time: the
/// controller holds each sample and never runs without one.
#[test]
fn a_slower_reference_is_held_in_real_time() {
    let dir = tempfile::tempdir().unwrap();
    let s = json(&crate::util::ran(
        testbed()
            .args([
                "run",
                "--scenario",
                "saturation_slow_reference",
                "--duration",
                "1",
                "--json",
                "--runs-dir",
            ])
            .arg(dir.path()),
    ));
    assert_eq!(s["fault_steps"], 0, "{s}");
    assert_eq!(s["finite"], true, "{s}");
    assert_eq!(s["steps"], 1000);
    // The log's reference topic holds one sample per 10 ms: 0 … 1 s.
    let buf = std::fs::read(s["log"].as_str().unwrap()).unwrap();
    let refs = mcap::MessageStream::new(&buf)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/reference")
        .count();
    assert_eq!(refs, 101);
}

/// The seed and every effect setting travel with the log.
#[test]
fn the_log_records_the_seed_and_the_effects() {
    let dir = tempfile::tempdir().unwrap();
    let s = json(&ok(testbed()
        .args([
            "run",
            "--mode",
            "lockstep",
            "--scenario",
            "friction_noise",
            "--duration",
            "0.3",
            "--json",
            "--runs-dir",
        ])
        .arg(dir.path())));
    let buf = std::fs::read(s["log"].as_str().unwrap()).unwrap();
    let summary = mcap::Summary::read(&buf).unwrap().unwrap();
    let idx = summary
        .metadata_indexes
        .iter()
        .find(|m| m.name == "testbed.run")
        .unwrap();
    let meta = mcap::read::metadata(&buf, idx).unwrap().metadata;
    assert_eq!(meta["seed"], "7");
    assert_eq!(meta["plant_effects"], "friction,sensor_noise,quantised");
    let toml = &meta["scenario_toml"];
    for key in [
        "seed = 7",
        "[plant.friction]",
        "coulomb = [1.0, 0.5]",
        "q_noise_std = 0.0005",
    ] {
        assert!(toml.contains(key), "scenario_toml lacks {key}:\n{toml}");
    }
    // And each logged state says what acted on it.
    let state = mcap::MessageStream::new(&buf)
        .unwrap()
        .map(|m| m.unwrap())
        .find(|m| m.channel.topic == "/joint_state")
        .unwrap();
    let s = <wire::JointState as logger::Decode>::decode_as(logger::Encoding::Cdr, &state.data)
        .unwrap();
    assert_eq!(s.effects, 0b11_0001);
    assert_ne!(s.q, s.q_measured);
}

#[test]
fn bad_effect_settings_name_the_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    for (text, key) in [
        (
            "[plant.payload]\nlink = \"hand\"\nmass = 1.0\n",
            "plant.payload.link",
        ),
        (
            "[plant.payload]\nlink = \"link2\"\nmass = -1.0\n",
            "plant.payload.mass",
        ),
        (
            "[plant.friction]\nviscous = [0.1, 0.2, 0.3]\n",
            "plant.friction.viscous",
        ),
        (
            "[plant.friction]\ncoulomb = nan\n",
            "plant.friction.coulomb",
        ),
        (
            "[plant.sensor]\nq_noise_std = -0.1\n",
            "plant.sensor.q_noise_std",
        ),
        (
            "[plant.actuation]\ndrop_probability = 1.5\n",
            "plant.actuation.drop_probability",
        ),
        (
            "[plant.disturbance]\nnoise_bandwidth_hz = 0.0\n",
            "plant.disturbance.noise_bandwidth_hz",
        ),
        (
            "[plant]\neffort_limit = [1.0, inf]\n",
            "plant.effort_limit[1]",
        ),
        (
            "[reference]\nrate_hz = 0.5\njoints = [{}, {}]\n",
            "reference.rate_hz",
        ),
        ("[plant.sensor]\nnoise = 1.0\n", "noise"),
    ] {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, text).unwrap();
        let err = fails(testbed().args(["sim", "--scenario"]).arg(&path));
        assert!(
            err.contains("bad.toml") && err.contains(key),
            "{text}: {err}"
        );
    }
}
