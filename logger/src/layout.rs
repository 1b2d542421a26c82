//! A Foxglove layout for a run's arm: the paper's five figures as plots
//! (positions with q_d, velocities, errors with ±k_c, actor weight norms,
//! torques), the loop's timing, and the arm in 3D (with a contact
//! scenario's contact point and objects, `/arm/contact`). Plots use the messages'
//! log time, which is sim time in the log and live alike, so one layout
//! serves both. `testbed run` writes it into each run's folder; the one in
//! `foxglove/` is this function's output for the paper's arm (a test keeps
//! them equal).

use serde_json::{Value, json};

use crate::obstacles::CONTACT_MARKER_TOPIC;
use crate::scene::{SCENE_TOPIC, TRANSFORMS_TOPIC, WORLD_FRAME};

/// One plotted series.
fn series(path: String, label: String) -> Value {
    json!({"value": path, "enabled": true, "timestampMethod": "receiveTime", "label": label})
}

fn plot(title: &str, paths: Vec<Value>) -> Value {
    json!({
        "title": title,
        "paths": paths,
        "xAxisVal": "timestamp",
        "showXAxisLabels": true,
        "showYAxisLabels": true,
        "showLegend": true,
        "legendDisplay": "floating",
        "isSynced": true,
    })
}

/// Per joint `i` (1-based in labels, as in the paper), the series `make` gives.
fn per_joint(joints: &[String], make: impl Fn(usize, &str) -> Vec<Value>) -> Vec<Value> {
    joints
        .iter()
        .enumerate()
        .flat_map(|(i, name)| make(i, name))
        .collect()
}

fn three_d() -> Value {
    let mut topics = serde_json::Map::new();
    topics.insert(SCENE_TOPIC.into(), json!({"visible": true}));
    topics.insert(TRANSFORMS_TOPIC.into(), json!({"visible": true}));
    // The contact point and free objects of a contact scenario (silent,
    // and so empty, in any other).
    topics.insert(CONTACT_MARKER_TOPIC.into(), json!({"visible": true}));
    json!({
        "followTf": WORLD_FRAME,
        "followMode": "follow-pose",
        "scene": {"transforms": {"showLabel": false, "axisScale": 0.5}},
        "transforms": {},
        "topics": topics,
        "layers": {"grid": {"layerId": "foxglove.Grid", "visible": true, "frameId": WORLD_FRAME, "size": 2, "divisions": 20}},
        "cameraState": {"distance": 2.0, "perspective": true, "phi": 60.0, "thetaOffset": 45.0, "targetOffset": [0.0, 0.0, 0.3]},
    })
}

/// The layout for an arm with these controlled joints.
pub fn foxglove_layout(joints: &[String]) -> Value {
    let positions = per_joint(joints, |i, n| {
        vec![
            series(format!("/joint_state.q[{i}]"), format!("q{} {n}", i + 1)),
            series(format!("/reference.q_d[{i}]"), format!("q_d{}", i + 1)),
        ]
    });
    let velocities = per_joint(joints, |i, n| {
        vec![
            series(format!("/joint_state.qd[{i}]"), format!("qd{} {n}", i + 1)),
            series(format!("/reference.qd_d[{i}]"), format!("qd_d{}", i + 1)),
        ]
    });
    let errors = per_joint(joints, |i, _| {
        let d = "/controller/diagnostics";
        vec![
            series(format!("{d}.z1[{i}]"), format!("z1{}", i + 1)),
            series(format!("{d}.kc[{i}]"), format!("+kc{}", i + 1)),
            series(format!("{d}.kc[{i}].@negative"), format!("-kc{}", i + 1)),
        ]
    });
    let mut weights = per_joint(joints, |i, _| {
        vec![series(
            format!("/controller/diagnostics.wa_norm[{i}]"),
            format!("||W_a{}||", i + 1),
        )]
    });
    weights.push(series(
        "/controller/diagnostics.wc_norm".into(),
        "||W_c||".into(),
    ));
    let torques = per_joint(joints, |i, _| {
        vec![series(
            format!("/command.tau[{i}]"),
            format!("tau{}", i + 1),
        )]
    });
    let timing = ["round_trip_ns", "controller_compute_ns", "wake_late_ns"]
        .iter()
        .map(|f| series(format!("/timing.{f}"), (*f).into()))
        .collect();
    json!({
        "configById": {
            "3D!arm": three_d(),
            "Plot!positions": plot("Joint positions q and q_d (rad)", positions),
            "Plot!velocities": plot("Joint velocities qd and qd_d (rad/s)", velocities),
            "Plot!errors": plot("Tracking errors z1 within +-kc (rad)", errors),
            "Plot!weights": plot("Actor and critic weight norms", weights),
            "Plot!torques": plot("Torques tau (N m)", torques),
            "Plot!timing": plot("Loop timing (ns)", timing),
        },
        "globalVariables": {},
        "userNodes": {},
        "playbackConfig": {"speed": 1},
        "layout": {
            "direction": "row",
            "splitPercentage": 40,
            "first": {"direction": "column", "first": "3D!arm", "second": "Plot!timing", "splitPercentage": 65},
            "second": {
                "direction": "column",
                "first": {"direction": "row", "first": "Plot!positions", "second": "Plot!velocities"},
                "second": {
                    "direction": "column",
                    "first": {"direction": "row", "first": "Plot!errors", "second": "Plot!torques"},
                    "second": "Plot!weights",
                    "splitPercentage": 60,
                },
                "splitPercentage": 35,
            },
        },
    })
}
