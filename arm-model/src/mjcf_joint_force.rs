//! A joint's `actuatorfrcrange` (MuJoCo ≥ 3.0: the clamp on the total
//! actuator force at a joint), which `mjcf-rs` does not read: found here
//! in the document itself, through the default classes as MuJoCo resolves
//! them (the joint's `class`, else its body's inherited `childclass`,
//! else `main`; a class without the attribute takes its parent's).

use std::collections::HashMap;

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use crate::ModelError;

/// What one element (a joint, or a class's `<joint>`) says.
#[derive(Clone, Default)]
struct Said {
    range: Option<[f64; 2]>,
    /// `actuatorfrclimited`: "true", "false" or "auto".
    limited: Option<String>,
}

impl Said {
    fn over(&self, below: &Said) -> Said {
        Said {
            range: self.range.or(below.range),
            limited: self.limited.clone().or_else(|| below.limited.clone()),
        }
    }
}

fn refuse(element: &str, reason: String) -> ModelError {
    ModelError::MjcfRefused {
        element: element.to_string(),
        reason,
    }
}

fn attr(e: &BytesStart, name: &str) -> Option<String> {
    e.attributes()
        .flatten()
        .find(|a| a.key.as_ref() == name.as_bytes())
        .and_then(|a| a.unescape_value().ok().map(|v| v.into_owned()))
}

fn said(e: &BytesStart, element: &str) -> Result<Said, ModelError> {
    let range = match attr(e, "actuatorfrcrange") {
        None => None,
        Some(text) => {
            let v: Vec<f64> = text
                .split_whitespace()
                .map(str::parse)
                .collect::<Result<_, _>>()
                .map_err(|_| {
                    refuse(
                        element,
                        format!("actuatorfrcrange '{text}' is not two numbers"),
                    )
                })?;
            match v[..] {
                [lo, hi] if lo.is_finite() && hi.is_finite() && lo <= hi => Some([lo, hi]),
                _ => {
                    return Err(refuse(
                        element,
                        format!("actuatorfrcrange '{text}' is not two finite numbers, low to high"),
                    ));
                }
            }
        }
    };
    Ok(Said {
        range,
        limited: attr(e, "actuatorfrclimited"),
    })
}

/// Joint name → the largest |force| its `actuatorfrcrange` allows, for
/// every named joint whose range is in force (`actuatorfrclimited` true,
/// or auto with `autolimits`).
pub(crate) fn joint_force_limits(
    text: &str,
    autolimits: bool,
) -> Result<HashMap<String, f64>, ModelError> {
    let mut reader = Reader::from_str(text);
    // Classes: name → (parent, what its <joint> says).
    let mut classes: HashMap<String, (Option<String>, Said)> = HashMap::new();
    // Open <default> classes, innermost last.
    let mut default_stack: Vec<String> = Vec::new();
    // Open <body> (and <worldbody>) childclasses, innermost last.
    let mut body_stack: Vec<Option<String>> = Vec::new();
    let mut joints: Vec<(String, String, Said)> = Vec::new();
    loop {
        let ev = reader
            .read_event()
            .map_err(|e| ModelError::MjcfParse(format!("reading actuatorfrcrange: {e}")))?;
        let (e, open) = match &ev {
            Event::Start(e) => (e, true),
            Event::Empty(e) => (e, false),
            Event::End(e) => {
                match e.name().as_ref() {
                    b"default" => {
                        default_stack.pop();
                    }
                    b"body" | b"worldbody" | b"frame" => {
                        body_stack.pop();
                    }
                    _ => {}
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        match e.name().as_ref() {
            b"default" => {
                let name = attr(e, "class").unwrap_or_else(|| "main".into());
                let parent = default_stack.last().cloned();
                classes
                    .entry(name.clone())
                    .or_insert((parent, Said::default()));
                if open {
                    default_stack.push(name);
                }
            }
            b"joint" if !default_stack.is_empty() => {
                let class = default_stack.last().cloned().unwrap_or_default();
                let s = said(e, &format!("<default class='{class}'><joint>"))?;
                if let Some(entry) = classes.get_mut(&class) {
                    entry.1 = s.over(&entry.1);
                }
            }
            b"body" | b"worldbody" | b"frame" => {
                let inherited = body_stack.last().cloned().flatten();
                if open {
                    body_stack.push(attr(e, "childclass").or(inherited));
                }
            }
            b"joint" if !body_stack.is_empty() => {
                let Some(name) = attr(e, "name") else {
                    continue;
                };
                let class = attr(e, "class")
                    .or_else(|| body_stack.last().cloned().flatten())
                    .unwrap_or_else(|| "main".into());
                let s = said(e, &format!("<joint name='{name}'>"))?;
                joints.push((name, class, s));
            }
            _ => {}
        }
    }
    let mut out = HashMap::new();
    for (name, class, own) in joints {
        let mut s = own;
        let mut at = Some(class);
        // Classes nest no deeper than the document; the bound stops a cycle.
        let mut steps = 0;
        while let Some(c) = at.take() {
            let Some((parent, says)) = classes.get(&c) else {
                break;
            };
            s = s.over(says);
            at = parent.clone();
            steps += 1;
            if steps > classes.len() {
                break;
            }
        }
        let limited = match s.limited.as_deref() {
            Some("true") => true,
            Some("false") => false,
            _ => autolimits,
        };
        if let (true, Some([lo, hi])) = (limited, s.range) {
            out.insert(name, lo.abs().max(hi.abs()));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_comes_from_the_joint_its_class_or_the_class_above() {
        let text = r#"<mujoco><default><joint actuatorfrcrange="-9 9"/>
            <default class="arm"><joint damping="1"/>
              <default class="wrist"><joint actuatorfrcrange="-2 3"/></default></default></default>
            <worldbody><body childclass="arm"><joint name="a"/>
              <body><joint name="b" class="wrist"/><joint name="c" actuatorfrcrange="-5 4"/>
              <joint name="d" class="wrist" actuatorfrclimited="false"/></body></body>
            <body><joint name="e"/></body></worldbody></mujoco>"#;
        let f = joint_force_limits(text, true).unwrap();
        assert_eq!(f.get("a"), Some(&9.0), "from main through arm");
        assert_eq!(f.get("b"), Some(&3.0));
        assert_eq!(f.get("c"), Some(&5.0));
        assert_eq!(f.get("d"), None, "actuatorfrclimited false");
        assert_eq!(f.get("e"), Some(&9.0));
        assert!(
            joint_force_limits(text, false).unwrap().is_empty(),
            "auto without autolimits"
        );
    }

    #[test]
    fn a_bad_range_is_refused_by_name() {
        let text = r#"<mujoco><worldbody><body><joint name="j" actuatorfrcrange="3 -3"/></body></worldbody></mujoco>"#;
        let e = joint_force_limits(text, true).unwrap_err().to_string();
        assert!(e.contains("'j'") && e.contains("actuatorfrcrange"), "{e}");
    }
}
