//! What a robot file is, before a parser is chosen: XML whose root element
//! is `<robot>` (URDF) or `<mujoco>` (MJCF). A committed merge-conflict
//! marker, a file that is not XML, or XML of another kind (a ROS launch
//! file) is named as such, instead of the URDF parser's raw message or
//! "the URDF has no links".

use quick_xml::Reader;
use quick_xml::events::Event;

use crate::ModelError;

/// The root elements a robot file may have.
const ROOTS: [&str; 2] = ["robot", "mujoco"];

/// Ok if `text` is XML whose root is a robot description's; else why not.
/// Malformed XML past the root's start tag is left to the parser, which
/// names the line.
pub(crate) fn check(text: &str) -> Result<(), ModelError> {
    let start = text.trim_start_matches('\u{feff}').trim_start();
    if !start.starts_with('<') || start.starts_with("<<<<<<<") {
        return Err(ModelError::NotXml {
            what: first_line(start),
        });
    }
    let mut reader = Reader::from_str(text);
    loop {
        match reader.read_event() {
            Ok(Event::Start(e) | Event::Empty(e)) => {
                let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
                return match ROOTS.contains(&name.as_str()) {
                    true => Ok(()),
                    false => Err(ModelError::NotARobot {
                        root: name.chars().take(80).collect(),
                    }),
                };
            }
            Ok(Event::Eof) => {
                return Err(ModelError::NotXml {
                    what: "it has no element".into(),
                });
            }
            // The parser names the fault and its line.
            Err(_) => return Ok(()),
            Ok(_) => {}
        }
    }
}

/// What the first line is, for the message: a merge-conflict marker named
/// as one, else the line itself (cut to 60 characters).
fn first_line(text: &str) -> String {
    let line = text.lines().next().unwrap_or("");
    if line.starts_with("<<<<<<<") {
        return format!(
            "line 1 is a merge-conflict marker ({}): resolve the conflict",
            line.chars().take(60).collect::<String>()
        );
    }
    if line.is_empty() {
        return "the file is empty".into();
    }
    format!(
        "it starts with {:?}, not an XML element",
        line.chars().take(60).collect::<String>()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_is_not_a_robot_file_is_named() {
        let e = |t: &str| check(t).unwrap_err().to_string();
        assert!(e("<<<<<<< HEAD\n<robot/>").contains("merge-conflict marker"));
        assert!(e("name: arm\n").contains("not XML"));
        assert!(e("").contains("empty"));
        assert!(e("<?xml version=\"1.0\"?>\n<launch><node/></launch>").contains("<launch>"));
        assert!(check("<?xml version=\"1.0\"?>\n<!-- c -->\n<robot name=\"r\"/>").is_ok());
        assert!(check("\u{feff}<mujoco/>").is_ok());
    }
}
