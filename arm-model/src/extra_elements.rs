//! Elements `urdf-rs` refuses or misreads that urdfdom and PyBullet read
//! past: a second copy of an element a joint or link holds once (Ghost
//! Robotics' Spirit, in pybullet_data, lists `<axis>` twice on a knee),
//! anything after the shape inside a `<geometry>` (the MIT racecar's
//! `<material>` there), and an element of another namespace (`<gz:axis>`,
//! which `urdf-rs` would take for the `<axis>` by its local name). urdfdom
//! matches whole names, reads the first `<axis>` and the first shape, and
//! ignores the rest; so does the testbed, which removes them before parsing
//! and says which.

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

/// Per element: the children it holds at most once (urdfdom reads each
/// with `FirstChildElement`).
const ONCE: [(&str, &[&str]); 6] = [
    (
        "joint",
        &[
            "origin",
            "parent",
            "child",
            "axis",
            "limit",
            "dynamics",
            "mimic",
            "calibration",
            "safety_controller",
        ],
    ),
    ("link", &["inertial"]),
    ("inertial", &["origin", "mass", "inertia"]),
    ("visual", &["origin", "geometry", "material"]),
    ("collision", &["origin", "geometry"]),
    ("material", &["color", "texture"]),
];

/// The elements right under `<robot>` whose insides `urdf-rs` reads.
const READ: [&str; 3] = ["joint", "link", "material"];

/// What a `<geometry>` holds one of.
const SHAPES: [&str; 5] = ["box", "cylinder", "sphere", "capsule", "mesh"];

/// One open element.
struct Open {
    name: String,
    /// "joint 'j'" or "link 'l'": what a note names.
    owner: String,
    children: Vec<String>,
    /// Offset of its `<`, where it is to be removed.
    drop_from: Option<usize>,
}

/// `text` without the elements urdfdom reads past, and one note for each
/// kind removed (none when nothing is).
pub(super) fn remove_extra(text: &str) -> (std::borrow::Cow<'_, str>, Vec<String>) {
    let (spans, notes) = extra_spans(text);
    if spans.is_empty() {
        return (std::borrow::Cow::Borrowed(text), notes);
    }
    let mut out = String::with_capacity(text.len());
    let mut copied = 0;
    for (from, to) in spans {
        out.push_str(&text[copied..from]);
        copied = to;
    }
    out.push_str(&text[copied..]);
    (std::borrow::Cow::Owned(out), notes)
}

/// The byte spans to remove, in order, and the notes. A document the
/// reader cannot walk to its end is left whole (the parser names its fault).
fn extra_spans(text: &str) -> (Vec<(usize, usize)>, Vec<String>) {
    let mut reader = Reader::from_str(text);
    let (mut stack, mut spans, mut notes): (Vec<Open>, Vec<(usize, usize)>, Vec<String>) =
        (Vec::new(), Vec::new(), Vec::new());
    loop {
        let at = reader.buffer_position() as usize;
        let event = reader.read_event();
        let end = reader.buffer_position() as usize;
        match event {
            Ok(Event::Start(e)) => {
                let open = opened(&e, at, &mut stack, &mut notes);
                stack.push(open);
            }
            Ok(Event::Empty(e)) => {
                if let Some(from) = opened(&e, at, &mut stack, &mut notes).drop_from {
                    spans.push((from, end));
                }
            }
            Ok(Event::End(_)) => {
                if let Some(from) = stack.pop().and_then(|o| o.drop_from) {
                    spans.push((from, end));
                }
            }
            Ok(Event::Eof) => break,
            Err(_) => return (Vec::new(), Vec::new()),
            Ok(_) => {}
        }
    }
    let mut seen = std::collections::HashSet::new();
    notes.retain(|n| seen.insert(n.clone()));
    (spans, notes)
}

/// A start tag under `stack`: recorded as its parent's child, and marked
/// to be removed (with a note) if urdfdom would read past it.
fn opened(e: &BytesStart, at: usize, stack: &mut [Open], notes: &mut Vec<String>) -> Open {
    // The whole name: `gz:axis` is not `axis` (urdfdom compares whole names).
    let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
    let inside_dropped = stack.iter().any(|o| o.drop_from.is_some());
    let owner = match (stack.len(), name.as_str()) {
        (1, "joint" | "link" | "material") => {
            let n = e
                .try_get_attribute("name")
                .ok()
                .flatten()
                .map(|a| String::from_utf8_lossy(&a.value).into_owned())
                .unwrap_or_default();
            format!("{name} '{n}'")
        }
        _ => stack.last().map(|o| o.owner.clone()).unwrap_or_default(),
    };
    let read = stack.len() >= 2 && READ.contains(&stack[1].name.as_str());
    let mut drop_from = None;
    if let Some(parent) = stack.last_mut()
        && read
        && !inside_dropped
    {
        // Another namespace's element (Drake's `<drake:rotor_inertia>`)
        // is an extension every reader ignores: removed without a note.
        if name.contains(':') {
            drop_from = Some(at);
        } else if let Some(why) = read_past(&parent.name, &parent.children, &name) {
            notes.push(format!("{owner}: {why}"));
            drop_from = Some(at);
        }
        parent.children.push(name.clone());
    } else if let Some(parent) = stack.last_mut() {
        parent.children.push(name.clone());
    }
    Open {
        name,
        owner,
        children: Vec::new(),
        drop_from,
    }
}

/// Why urdfdom reads past element `name` in `parent` (which holds
/// `children` before it), if it does.
fn read_past(parent: &str, children: &[String], name: &str) -> Option<String> {
    let once = ONCE
        .iter()
        .find(|(p, _)| *p == parent)
        .is_some_and(|(_, c)| c.contains(&name));
    if once && children.iter().any(|c| c == name) {
        Some(format!(
            "a second <{name}> in its <{parent}>: the first is read, as urdfdom and PyBullet do"
        ))
    } else if parent == "geometry" && children.iter().any(|c| SHAPES.contains(&c.as_str())) {
        Some(format!(
            "<{name}> after the shape in a <geometry>: ignored, as urdfdom and PyBullet do"
        ))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Spirit's knee lists `<axis>` twice; the racecar's lidar has a
    /// `<material>` inside its `<geometry>`. Both are read past, as urdfdom
    /// does; the first `<axis>` and the shape stay.
    #[test]
    fn what_urdfdom_reads_past_is_removed_and_said() {
        let text = r#"<robot name="r"><link name="a"><visual><geometry><mesh filename="m.obj"/><material name="grey"/></geometry></visual></link><joint name="knee" type="revolute"><axis xyz="0 1 0"/><parent link="a"/><axis xyz="1 0 0"></axis></joint><gazebo><joint><axis/><axis/></joint></gazebo></robot>"#;
        let (out, notes) = remove_extra(text);
        assert_eq!(
            out,
            r#"<robot name="r"><link name="a"><visual><geometry><mesh filename="m.obj"/></geometry></visual></link><joint name="knee" type="revolute"><axis xyz="0 1 0"/><parent link="a"/></joint><gazebo><joint><axis/><axis/></joint></gazebo></robot>"#
        );
        assert_eq!(
            notes,
            [
                "link 'a': <material> after the shape in a <geometry>: ignored, as urdfdom and PyBullet do",
                "joint 'knee': a second <axis> in its <joint>: the first is read, as urdfdom and PyBullet do",
            ]
        );
        // Another namespace's element is not the URDF one, duplicate or not;
        // a second <material> in a visual, a second <color>, are read past.
        let text = r#"<robot name="r" xmlns:gz="g"><joint name="j"><gz:axis xyz="0 1 0"/><axis xyz="0 0 1"/><limit/><limit/><limit/></joint><link name="l"><visual><material name="a"/><material name="b"/></visual></link><material name="m"><color rgba="1 0 0 1"/><color rgba="0 1 0 1"/></material></robot>"#;
        let (out, notes) = remove_extra(text);
        assert_eq!(
            out,
            r#"<robot name="r" xmlns:gz="g"><joint name="j"><axis xyz="0 0 1"/><limit/></joint><link name="l"><visual><material name="a"/></visual></link><material name="m"><color rgba="1 0 0 1"/></material></robot>"#
        );
        assert_eq!(notes.len(), 3, "{notes:?}");
        assert!(notes[0].starts_with("joint 'j': a second <limit>"));
        assert!(notes[2].starts_with("material 'm': a second <color>"));
        // Repeated <visual> and <collision> are valid: left alone.
        let fine =
            r#"<robot name="r"><link name="a"><visual/><collision/><visual/></link></robot>"#;
        let (same, none) = remove_extra(fine);
        assert!(matches!(same, std::borrow::Cow::Borrowed(_)) && none.is_empty());
    }
}
