//! The inlined MJCF text checked before `mjcf-rs` reads it (#60): for
//! what that parser would read from disk on its own (an `<include>` the
//! inliner did not see, an `<asset><model file>`), and for orientations
//! it would quietly turn into the identity (a zero `quat`, which MuJoCo
//! refuses).

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use crate::ModelError;

/// Refuses every element `mjcf-rs` would read a file for: the inliner
/// has replaced each `<include>` it reads, so one left (written with a
/// namespace prefix, `<m:include>`) would be read unchecked, from
/// anywhere and without bound; a sub-model for `<attach>` likewise.
pub(crate) fn refuse_parser_reads(text: &str) -> Result<(), ModelError> {
    each_tag(text, |e, at| {
        let reason = match e.local_name().as_ref() {
            b"include" => {
                "an include the inliner does not read (one written with a namespace prefix) \
                 would be read by the parser unchecked: write it <include file=\"…\"/>"
            }
            b"model" => {
                "a sub-model (MuJoCo's <asset><model file> for <attach>) would be read from its \
                 file by the parser, unchecked and outside the model's text: not supported \
                 (copy its bodies into the model)"
            }
            _ => return Ok(()),
        };
        Err(refuse(text, e, at, reason.into()))
    })
}

/// Refuses an orientation that is no rotation: a zero (or non-finite)
/// `quat`, or a zero axis in `axisangle` or `zaxis`. MuJoCo refuses them;
/// `mjcf-rs` reads them as the identity, so a typo turned a body silently.
pub(crate) fn check_orientations(text: &str) -> Result<(), ModelError> {
    each_tag(text, |e, at| {
        for (name, axis_len) in [("quat", 4), ("axisangle", 3), ("zaxis", 3)] {
            let Some(value) = attr(e, name) else {
                continue;
            };
            // A value that is not numbers is the parser's to name.
            let Ok(v) = (value.split_whitespace())
                .map(str::parse::<f64>)
                .collect::<Result<Vec<_>, _>>()
            else {
                continue;
            };
            if let Some(why) = degenerate(&v, axis_len) {
                let reason =
                    format!("{name}=\"{value}\" {why}: it is no rotation (MuJoCo refuses it)");
                return Err(refuse(text, e, at, reason));
            }
        }
        Ok(())
    })
}

/// Why the numbers `v` (whose first `axis_len` are the axis or the
/// quaternion) give no rotation, if they do not.
fn degenerate(v: &[f64], axis_len: usize) -> Option<&'static str> {
    if v.iter().any(|x| !x.is_finite()) {
        return Some("holds a number that is not finite");
    }
    let norm = v.iter().take(axis_len).map(|x| x * x).sum::<f64>().sqrt();
    // mjcf-rs makes the identity of a quaternion this short.
    (v.len() >= axis_len && norm <= 1e-15).then_some(if axis_len == 4 {
        "is a zero quaternion"
    } else {
        "has a zero axis"
    })
}

/// Calls `f` on every start (or empty) tag of `text` with its byte offset.
fn each_tag(
    text: &str,
    mut f: impl FnMut(&BytesStart, usize) -> Result<(), ModelError>,
) -> Result<(), ModelError> {
    let mut reader = Reader::from_str(text);
    loop {
        let at = usize::try_from(reader.buffer_position()).unwrap_or(usize::MAX);
        match reader.read_event() {
            Ok(Event::Start(e) | Event::Empty(e)) => f(&e, at)?,
            Ok(Event::Eof) => return Ok(()),
            Ok(_) => {}
            Err(e) => return Err(ModelError::MjcfParse(format!("malformed XML: {e}"))),
        }
    }
}

fn attr(e: &BytesStart, name: &str) -> Option<String> {
    e.attributes()
        .flatten()
        .find(|a| a.key.as_ref() == name.as_bytes())
        .and_then(|a| a.unescape_value().ok().map(|v| v.into_owned()))
}

/// The element by its tag and its name, or its line when it has none
/// (counted only for the message).
fn refuse(text: &str, e: &BytesStart, at: usize, reason: String) -> ModelError {
    let tag: String = String::from_utf8_lossy(e.name().as_ref())
        .chars()
        .take(80)
        .collect();
    let line = 1 + text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count();
    // The line is of the text as read, includes inlined: only an unnamed
    // element needs it to be found.
    let element = match attr(e, "name") {
        Some(name) => format!("<{tag} name='{name}'>"),
        None => format!("<{tag}> (unnamed, line {line} of the model with its includes inlined)"),
    };
    ModelError::MjcfRefused { element, reason }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn an_orientation_that_is_no_rotation_is_refused_by_element_and_line() {
        let e = |text: &str| check_orientations(text).unwrap_err().to_string();
        assert_eq!(
            e("<mujoco>\n<body name='b' quat='0 0 0 0'/></mujoco>"),
            "MJCF <body name='b'>: quat=\"0 0 0 0\" is a zero quaternion: it is no rotation (MuJoCo refuses it)"
        );
        assert!(
            e("<mujoco>\n<body>\n<geom quat='0 0 0 0'/></body></mujoco>")
                .starts_with("MJCF <geom> (unnamed, line 3 of the model"),
            "an unnamed element by its line"
        );
        for bad in [
            "<geom quat='nan 0 0 1'/>",
            "<site axisangle='0 0 0 1'/>",
            "<inertial zaxis='0 0 0'/>",
        ] {
            assert!(check_orientations(bad).is_err(), "{bad}");
        }
        for good in [
            "<body quat='1 0 0 0' axisangle='0 0 1 0' zaxis='0 0 1'/>",
            "<body quat='not numbers'/>",
        ] {
            assert!(check_orientations(good).is_ok(), "{good}");
        }
    }

    #[test]
    fn what_the_parser_would_read_itself_is_refused() {
        let e = refuse_parser_reads(
            "<mujoco xmlns:m='urn:x'><m:include file='/etc/hostname'/></mujoco>",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("MJCF <m:include> (unnamed, line 1 of the model with its includes inlined): an include the inliner"),
            "{e}"
        );
        let e = refuse_parser_reads(
            "<mujoco><asset><model name='a' file='/dev/zero'/></asset></mujoco>",
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("MJCF <model name='a'>: a sub-model"), "{e}");
        assert!(
            refuse_parser_reads(
                "<mujoco model='m'><asset><mesh file='/dev/zero'/></asset></mujoco>"
            )
            .is_ok()
        );
    }
}
