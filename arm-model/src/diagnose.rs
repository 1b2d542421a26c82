//! Where a URDF the reader refused goes wrong. `urdf-rs` reports only
//! "missing field `inertia`" or "invalid float literal", not which link or
//! joint; so when it refuses a file, the file's elements are walked again
//! (with `quick-xml`, the reader under `urdf-rs`) against the fields
//! `urdf-rs` requires and the attributes that hold numbers, and the error
//! names the element, its link or joint, and what to write.

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

/// Attributes an element must have (`urdf-rs`'s fields without a default).
const REQUIRED_ATTRIBUTES: &[(&str, &[&str])] = &[
    ("link", &["name"]),
    ("joint", &["name", "type"]),
    ("mass", &["value"]),
    ("inertia", &["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]),
    ("parent", &["link"]),
    ("child", &["link"]),
    ("axis", &["xyz"]),
    ("mimic", &["joint"]),
    ("safety_controller", &["k_velocity"]),
    ("color", &["rgba"]),
    ("box", &["size"]),
    ("cylinder", &["radius", "length"]),
    ("capsule", &["radius", "length"]),
    ("sphere", &["radius"]),
];

/// Child elements an element must have.
const REQUIRED_CHILDREN: &[(&str, &[&str])] = &[
    ("inertial", &["mass", "inertia"]),
    ("joint", &["parent", "child"]),
    ("visual", &["geometry"]),
    ("collision", &["geometry"]),
];

/// Attributes that hold numbers, and how many (0: one or more).
const NUMBERS: &[(&str, &[(&str, usize)])] = &[
    ("mass", &[("value", 1)]),
    ("origin", &[("xyz", 3), ("rpy", 3)]),
    (
        "inertia",
        &[
            ("ixx", 1),
            ("ixy", 1),
            ("ixz", 1),
            ("iyy", 1),
            ("iyz", 1),
            ("izz", 1),
        ],
    ),
    ("axis", &[("xyz", 3)]),
    (
        "limit",
        &[("lower", 1), ("upper", 1), ("effort", 1), ("velocity", 1)],
    ),
    ("dynamics", &[("damping", 1), ("friction", 1)]),
    ("mimic", &[("multiplier", 1), ("offset", 1)]),
    ("color", &[("rgba", 4)]),
    ("box", &[("size", 3)]),
    ("cylinder", &[("radius", 1), ("length", 1)]),
    ("capsule", &[("radius", 1), ("length", 1)]),
    ("sphere", &[("radius", 1)]),
    ("mesh", &[("scale", 3)]),
];

/// The robot-level elements `urdf-rs` reads; what is inside anything else
/// (`<transmission>`, `<gazebo>`, whose `<joint>` is another element) is
/// not checked.
const READ: [&str; 3] = ["link", "joint", "material"];

/// One open element: its name, the link or joint it is in, whether
/// `urdf-rs` reads it, the children seen so far.
struct Open {
    name: String,
    owner: String,
    read: bool,
    children: Vec<String>,
}

/// What is wrong, if the walk finds what `reader_error` says: a missing
/// field it names, or a number it could not read. None otherwise (the
/// reader's own message stands).
pub(super) fn diagnose(text: &str, reader_error: &str) -> Option<String> {
    let missing = reader_error
        .split("missing field `")
        .nth(1)
        .and_then(|r| r.split('`').next());
    let wanted = |p: &Problem| match missing {
        Some(field) => p.field == field,
        // Only the shape the reader names: `type="bogus"` on a joint is an
        // unknown variant too, and its own message stands.
        None if reader_error.contains("unknown variant") => {
            p.field == "variant"
                && unknown_variant(reader_error).is_some_and(|v| {
                    p.message.contains(&format!("<{v}>")) || p.message.contains(&format!("\"{v}\""))
                })
        }
        None if p.empty => reader_error.contains("found EndElement"),
        None => {
            p.number && (reader_error.contains("float") || reader_error.contains("element count"))
        }
    };
    let mut found = Found {
        wanted: &wanted,
        first: None,
        more: 0,
    };
    walk(text, &mut found);
    found.first.map(|first| match found.more {
        0 => first,
        more => format!("{first} (and {more} more like it)"),
    })
}

/// What the walk keeps: the first problem of the kind the reader named and
/// how many more there are. Only one message is kept, so a file with
/// 150 000 bad numbers is diagnosed in constant memory (keeping them all
/// took 966 MB, #48 item 8).
struct Found<'a> {
    wanted: &'a dyn Fn(&Problem) -> bool,
    first: Option<String>,
    more: usize,
}

impl Found<'_> {
    fn push(&mut self, p: Problem) {
        if (self.wanted)(&p) {
            match self.first {
                None => self.first = Some(p.message),
                Some(_) => self.more += 1,
            }
        }
    }
}

/// The most characters of a value a message quotes: a 16 MB attribute is
/// not repeated whole.
const QUOTED: usize = 80;

/// `v`, cut to [`QUOTED`] characters (with "…" and its length when cut).
fn cut(v: &str) -> String {
    match v.char_indices().nth(QUOTED) {
        None => v.to_string(),
        Some((at, _)) => format!("{}… ({} bytes in all)", &v[..at], v.len()),
    }
}

/// The variant in "unknown variant `plane`, expected …".
fn unknown_variant(reader_error: &str) -> Option<&str> {
    reader_error
        .split("unknown variant `")
        .nth(1)
        .and_then(|r| r.split('`').next())
}

struct Problem {
    field: String,
    number: bool,
    /// An element the reader needs something inside of, found empty.
    empty: bool,
    message: String,
}

fn walk(text: &str, out: &mut Found) {
    let mut reader = Reader::from_str(text);
    let mut stack: Vec<Open> = Vec::new();
    loop {
        match reader.read_event() {
            Ok(Event::Start(e)) => {
                let open = opened(&e, &mut stack, out);
                stack.push(open);
            }
            Ok(Event::Empty(e)) => {
                let open = opened(&e, &mut stack, out);
                closed(&open, out);
            }
            Ok(Event::End(_)) => {
                if let Some(open) = stack.pop() {
                    closed(&open, out);
                }
            }
            Ok(Event::Eof) | Err(_) => return,
            Ok(_) => {}
        }
    }
}

/// A start tag: recorded as its parent's child, and, where `urdf-rs`
/// reads it, its attributes checked.
fn opened(e: &BytesStart, stack: &mut [Open], out: &mut Found) -> Open {
    let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
    let parent = stack.last_mut();
    let (parent_owner, parent_read) = parent.as_ref().map_or_else(
        || ("the robot".to_string(), false),
        |o| (o.owner.clone(), o.read),
    );
    if let Some(parent) = parent {
        parent.children.push(name.clone());
    }
    let read = match stack.len() {
        0 => false,
        1 => READ.contains(&name.as_str()),
        _ => parent_read,
    };
    let attrs = attributes(e, &name);
    let owner = match (name.as_str(), attr(&attrs, "name"), stack.len()) {
        ("link" | "joint" | "material", Some(n), 1) => format!("{name} '{}'", cut(n)),
        _ => parent_owner,
    };
    if read {
        check_attributes(&format!("{owner}: <{name}>"), &name, &attrs, out);
    }
    Open {
        name,
        owner,
        read,
        children: Vec::new(),
    }
}

/// The attributes of tag `name` the walk looks at (its name, a joint's
/// type, what it requires and its numbers), names without prefix, values
/// unescaped. quick-xml's duplicate check compares each attribute with
/// every one before it, which made a tag of 100 000 attributes take
/// minutes (#48 item 8); the reader under `urdf-rs` has already refused
/// duplicates, so it is off, and only the attributes looked at are kept.
fn attributes(e: &BytesStart, name: &str) -> Vec<(String, String)> {
    let required = REQUIRED_ATTRIBUTES
        .iter()
        .filter(|(el, _)| *el == name)
        .flat_map(|(_, fields)| fields.iter().copied());
    let numbers = NUMBERS
        .iter()
        .filter(|(el, _)| *el == name)
        .flat_map(|(_, fields)| fields.iter().map(|(f, _)| *f));
    let looked_at: Vec<&str> = ["name", "type"]
        .into_iter()
        .chain(required)
        .chain(numbers)
        .collect();
    e.attributes()
        .with_checks(false)
        .flatten()
        .filter(|a| {
            std::str::from_utf8(a.key.local_name().as_ref()).is_ok_and(|k| looked_at.contains(&k))
        })
        .map(|a| {
            let key = String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned();
            let value = a.unescape_value().map_or_else(
                |_| String::from_utf8_lossy(&a.value).into_owned(),
                |v| v.into_owned(),
            );
            (key, value)
        })
        .collect()
}

/// The value of attribute `key`.
fn attr<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// The attributes element `name` (at `at`) must have, and its numbers.
fn check_attributes(at: &str, name: &str, attrs: &[(String, String)], out: &mut Found) {
    for (element, required) in REQUIRED_ATTRIBUTES {
        if *element == name {
            for field in required.iter().filter(|f| attr(attrs, f).is_none()) {
                out.push(Problem {
                    field: field.to_string(),
                    number: false,
                    empty: false,
                    message: format!("{at} has no {field}=\"…\", which the URDF format requires"),
                });
            }
        }
    }
    if name == "joint"
        && let Some(kind) = attr(attrs, "type")
        && !JOINT_TYPES.contains(&kind)
    {
        out.push(Problem {
            field: "variant".into(),
            number: false,
            empty: false,
            message: format!(
                "{at} type=\"{}\" is not a URDF joint type; write one of {}",
                cut(kind),
                JOINT_TYPES.join(", ")
            ),
        });
    }
    for (element, numbers) in NUMBERS {
        if *element != name {
            continue;
        }
        for (field, count) in *numbers {
            if let Some(v) = attr(attrs, field)
                && let Some(why) = not_numbers(v, *count)
            {
                out.push(Problem {
                    field: field.to_string(),
                    number: true,
                    empty: false,
                    message: format!("{at} {field}=\"{}\": {why}", cut(v)),
                });
            }
        }
    }
}

/// The joint types URDF has.
const JOINT_TYPES: [&str; 7] = [
    "revolute",
    "continuous",
    "prismatic",
    "fixed",
    "floating",
    "planar",
    "spherical",
];

/// The shapes a `<geometry>` holds one of.
const SHAPES: [&str; 5] = ["box", "cylinder", "sphere", "capsule", "mesh"];

/// Checks that a closing element had the children it needs.
fn closed(open: &Open, out: &mut Found) {
    if !open.read {
        return;
    }
    let first = open.children.first().map(String::as_str);
    if open.name == "geometry"
        && let Some(other) = first.filter(|c| !SHAPES.contains(c))
    {
        out.push(Problem {
            field: "variant".into(),
            number: false,
            empty: false,
            message: format!(
                "{}: <geometry> holds <{other}>, which is not a URDF shape; write one of <{}> (<plane> and <cdf> are PyBullet's own)",
                open.owner,
                SHAPES.join(">, <")
            ),
        });
    }
    if open.name == "geometry" && !open.children.iter().any(|c| SHAPES.contains(&c.as_str())) {
        out.push(Problem {
            field: "geometry".into(),
            number: false,
            empty: true,
            message: format!(
                "{}: a <geometry> holds no shape; write one of <{}>",
                open.owner,
                SHAPES.join(">, <")
            ),
        });
    }
    for (element, required) in REQUIRED_CHILDREN {
        if *element == open.name {
            for child in required
                .iter()
                .filter(|c| !open.children.iter().any(|h| h == *c))
            {
                out.push(Problem {
                    field: child.to_string(),
                    number: false,
                    empty: false,
                    message: format!(
                        "{}: <{}> has no <{child}>, which the URDF format requires{}",
                        open.owner,
                        open.name,
                        hint(&open.name, child)
                    ),
                });
            }
        }
    }
}

/// What to write for a missing child.
fn hint(element: &str, child: &str) -> &'static str {
    match (element, child) {
        ("inertial", "inertia") => {
            " (write ixx … izz; zeros make the link a point mass, or leave out <inertial> for a massless link)"
        }
        ("inertial", "mass") => {
            " (write <mass value=\"…\"/>, or leave out <inertial> for a massless link)"
        }
        _ => "",
    }
}

/// Why `v` is not `count` numbers (0: any positive count), if it is not.
fn not_numbers(v: &str, count: usize) -> Option<String> {
    // Counted, not collected: a value may be megabytes of numbers.
    let mut n = 0usize;
    for part in v.split_whitespace() {
        if part.parse::<f64>().is_err() {
            let xacro = if part.contains("$(") || part.contains("${") {
                " (a xacro expression: run `xacro` on the file to get a URDF)"
            } else {
                ""
            };
            return Some(format!("'{}' is not a number{xacro}", cut(part)));
        }
        n += 1;
    }
    match (count, n) {
        (0, 0) => Some("no number".into()),
        (0, _) => None,
        (c, n) if c != n => Some(format!("{n} numbers where {c} belong")),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use crate::ArmModel;
    use proptest::prelude::*;

    fn refusal(body: &str) -> String {
        let text = format!(r#"<robot name="t"><link name="base"/>{body}</robot>"#);
        match ArmModel::from_urdf_str(&text) {
            Ok(_) => panic!("accepted: {text}"),
            Err(e) => e.to_string(),
        }
    }

    const LINK_A: &str = r#"<link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>"#;

    fn joint(inner: &str) -> String {
        format!(r#"{LINK_A}<joint name="j" type="revolute">{inner}<axis xyz="0 0 1"/></joint>"#)
    }

    /// Each refusal names the link or joint, the element and what is wrong.
    #[test]
    fn a_refused_urdf_names_the_element_at_fault() {
        for (body, want) in [
            (
                r#"<link name="a"><inertial><mass value="1"/></inertial></link>"#.to_string(),
                "link 'a': <inertial> has no <inertia>, which the URDF format requires (write ixx",
            ),
            (
                r#"<link name="a"><inertial><mass value="MASS"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>"#.into(),
                "link 'a': <mass> value=\"MASS\": 'MASS' is not a number",
            ),
            (
                joint(r#"<parent link="base"/><origin xyz="0 0"/><child link="a"/><limit effort="1" velocity="1"/>"#),
                "joint 'j': <origin> xyz=\"0 0\": 2 numbers where 3 belong",
            ),
            (
                joint(r#"<child link="a"/><limit effort="1" velocity="1"/>"#),
                "joint 'j': <joint> has no <parent>",
            ),
            (
                r#"<link name="a"/><joint name="j" type="bogus"><parent link="base"/><child link="a"/></joint>"#.into(),
                "joint 'j': <joint> type=\"bogus\" is not a URDF joint type; write one of revolute",
            ),
            (
                joint(r#"<parent link="base"/><origin xyz="$(optenv IMU_XYZ 0 0 0)"/><child link="a"/><limit effort="1" velocity="1"/>"#),
                "joint 'j': <origin> xyz=\"$(optenv IMU_XYZ 0 0 0)\": '$(optenv' is not a number (a xacro expression: run `xacro`",
            ),
            (
                r#"<link name="a"><collision><geometry><plane normal="0 0 1"/></geometry></collision></link>"#.into(),
                "link 'a': <geometry> holds <plane>, which is not a URDF shape; write one of <box>",
            ),
        ] {
            let got = refusal(&body);
            assert!(got.contains(want), "{got}\n  wanted: {want}");
        }
    }

    /// A `<joint>` inside a `<transmission>` is not the robot's: a typo
    /// elsewhere keeps the reader's own message, not a false one about it.
    #[test]
    fn elements_urdf_rs_does_not_read_are_not_blamed() {
        let body = format!(
            r#"{}<transmission name="t"><joint name="j"><hardwareInterface>x</hardwareInterface></joint></transmission>"#,
            joint(r#"<parent link="base"/><child link="a"/><limit effort="1" velocity="1"/>"#)
                .replace("revolute", "continous")
        );
        let got = refusal(&body);
        assert!(
            got.contains("continous") && !got.contains("has no"),
            "{got}"
        );
    }

    /// Every bad number after the first is counted, not kept: 150 000 of
    /// them took 966 MB (#48 item 8).
    #[test]
    fn only_the_first_problem_is_kept_and_the_rest_counted() {
        let links: String = (0..3)
            .map(|i| {
                format!(r#"<link name="l{i}"><inertial><mass value="X{i}"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>"#)
            })
            .collect();
        let got = refusal(&links);
        assert!(
            got.contains("link 'l0': <mass> value=\"X0\"") && got.ends_with("(and 2 more like it)"),
            "{got}"
        );
    }

    /// A long bad value is quoted cut to 80 characters.
    #[test]
    fn a_long_bad_value_is_quoted_cut() {
        let long = "Y".repeat(100_000);
        let got = refusal(&format!(
            r#"<link name="a"><inertial><mass value="{long}"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>"#
        ));
        assert!(
            got.contains("(100000 bytes in all)") && got.len() < 400,
            "{got}"
        );
    }

    /// Only the attributes the walk looks at are kept from a tag.
    #[test]
    fn only_the_attributes_looked_at_are_kept() {
        let extra: String = (0..1000).map(|i| format!(r#" x{i}="{i}""#)).collect();
        let tag = format!(r#"<mass value="1"{extra} name="m"/>"#);
        let mut reader = quick_xml::Reader::from_str(&tag);
        let Ok(quick_xml::events::Event::Empty(e)) = reader.read_event() else {
            panic!("not an empty tag: {tag}");
        };
        let kept = super::attributes(&e, "mass");
        assert_eq!(
            kept,
            vec![
                ("value".to_string(), "1".to_string()),
                ("name".into(), "m".into())
            ]
        );
    }

    proptest! {
        /// Any text is walked without a panic.
        #[test]
        fn any_text_is_walked_without_panic(text in "[<>/=\"' a-z:!?-]{0,80}") {
            let _ = super::diagnose(&text, "missing field `mass`");
            let _ = super::diagnose(&text, "invalid float literal");
        }
    }
}
