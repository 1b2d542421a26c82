//! The shipped Foxglove layout (`foxglove/testbed-layout.json`): it is the
//! generator's output for the paper's arm, and every series and 3D topic it
//! names is a channel the testbed publishes, with that field in its schema.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::Path;

use arm_model::{ArmModel, TWO_LINK_URDF};
use logger::{channels, foxglove_layout};
use serde_json::Value;

fn shipped() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../foxglove/testbed-layout.json");
    let text = std::fs::read_to_string(&path).unwrap();
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_shipped_layout_is_the_generated_one_for_the_paper_arm() {
    let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
    assert_eq!(
        shipped(),
        foxglove_layout(&model.joint_names()),
        "regenerate it: cargo run -- layout --out foxglove/testbed-layout.json"
    );
}

/// `/topic/name.field[3].@modifier` → (topic, field): the topic is the
/// longest published topic the path starts with.
fn split<'a>(path: &'a str, topics: &[&'static str]) -> Option<(&'static str, &'a str)> {
    let topic = topics
        .iter()
        .filter(|t| path.starts_with(**t) && path[t.len()..].starts_with('.'))
        .max_by_key(|t| t.len())?;
    let rest = &path[topic.len() + 1..];
    let field = rest.split(['[', '.']).next()?;
    Some((topic, field))
}

#[test]
fn the_layout_names_only_published_topics_and_fields() {
    let layout = shipped();
    let chans = channels();
    let topics: Vec<&'static str> = chans.iter().map(|c| c.topic).collect();
    let panels = layout["configById"].as_object().unwrap();
    let mut series = 0;
    for (id, panel) in panels {
        for p in panel["paths"].as_array().into_iter().flatten() {
            let path = p["value"].as_str().unwrap();
            let (topic, field) = split(path, &topics)
                .unwrap_or_else(|| panic!("{id}: {path} names no published topic"));
            let spec = chans.iter().find(|c| c.topic == topic).unwrap();
            // The message's own definition: the schema text up to the
            // first used message; a field is `type name` on its line.
            let own = spec.schema.split("\n====").next().unwrap();
            let declared = own.lines().any(|l| {
                let decl = l.split('#').next().unwrap();
                decl.split_whitespace().nth(1) == Some(field)
            });
            assert!(declared, "{id}: {path}: {topic} has no field {field}");
            series += 1;
        }
        for topic in panel["topics"]
            .as_object()
            .into_iter()
            .flatten()
            .map(|t| t.0)
        {
            assert!(
                topics.contains(&topic.as_str()),
                "{id}: {topic} is not published"
            );
        }
    }
    assert!(series >= 20, "only {series} series");
    // #48 item 17: the 3D panel draws the arm, its frames and a contact
    // scenario's contact point and objects.
    for topic in ["/arm/scene", "/tf", logger::obstacles::CONTACT_MARKER_TOPIC] {
        assert_eq!(
            layout["configById"]["3D!arm"]["topics"][topic]["visible"], true,
            "{topic} is not in the 3D panel"
        );
    }
    // The five figures, the timing and the arm.
    for id in [
        "positions",
        "velocities",
        "errors",
        "weights",
        "torques",
        "timing",
    ] {
        assert!(panels.contains_key(&format!("Plot!{id}")), "no plot {id}");
    }
    assert!(panels.contains_key("3D!arm"));
    // Every panel is placed in the layout tree.
    let text = layout["layout"].to_string();
    for id in panels.keys() {
        assert!(text.contains(&format!("\"{id}\"")), "{id} is not placed");
    }
}
