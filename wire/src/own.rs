//! What an external controller's own diagnostics are: names and shapes it
//! declares (`CMD --describe`), laid out one after another in
//! [`crate::OwnDiagnostics::values`]. The launcher checks a declaration and
//! writes it as text ([`OwnLayout::text`]) into the controller's config and
//! the log's metadata (`controller_diagnostics`); the controller fills the
//! values in that order, and the analysis names the CSV columns and the
//! summary's entries from the same text.

use crate::MAX_OWN_DIAGNOSTICS;

/// Why a declaration of own diagnostics is refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OwnLayoutError {
    /// A shape other than the two there are.
    #[error("shape {0:?}: \"scalar\" or \"joints\"")]
    Shape(String),
    /// A name that cannot name a CSV column or a field.
    #[error("diagnostic {0:?}: 1 to 40 of a-z, 0-9 and '_', starting with a letter")]
    Name(String),
    /// A name declared twice.
    #[error("diagnostic {0:?} is declared twice")]
    Twice(String),
    /// More values a step than the message holds.
    #[error(
        "the diagnostics declared take {len} values a step for {dof} joints; at most {MAX_OWN_DIAGNOSTICS} fit"
    )]
    TooMany {
        /// Values a step.
        len: usize,
        /// Joints.
        dof: usize,
    },
    /// Two diagnostics that would name one CSV column and summary entry
    /// (`a:joints` and `a1:scalar` both give `a1`).
    #[error(
        "diagnostics {first:?} and {second:?} both name the column {column:?} (a per-joint \
         diagnostic's columns are its name and each joint's index): rename one"
    )]
    SameColumn {
        /// The column.
        column: String,
        /// The diagnostic declared first.
        first: String,
        /// The one declared after it.
        second: String,
    },
    /// An entry of the text that is not `name:shape`.
    #[error("{0:?} is not name:shape")]
    Entry(String),
}

/// How many values one diagnostic has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OwnShape {
    /// One number a step.
    Scalar,
    /// One number per controlled joint.
    Joints,
}

impl OwnShape {
    /// Its spelling in a declaration.
    pub fn as_str(self) -> &'static str {
        match self {
            OwnShape::Scalar => "scalar",
            OwnShape::Joints => "joints",
        }
    }

    /// From its spelling.
    pub fn parse(s: &str) -> Result<Self, OwnLayoutError> {
        match s {
            "scalar" => Ok(OwnShape::Scalar),
            "joints" => Ok(OwnShape::Joints),
            other => Err(OwnLayoutError::Shape(other.into())),
        }
    }

    fn len(self, dof: usize) -> usize {
        match self {
            OwnShape::Scalar => 1,
            OwnShape::Joints => dof,
        }
    }
}

/// The declared diagnostics, in their order in the values.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct OwnLayout {
    entries: Vec<(String, OwnShape)>,
}

/// Whether `name` may name a diagnostic: 1 to 40 of a-z, 0-9 and `_`,
/// starting with a letter (it names CSV columns and message fields).
pub fn is_diagnostic_name(name: &str) -> bool {
    name.len() <= 40
        && name.starts_with(|c: char| c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

impl OwnLayout {
    /// A layout of `entries`, checked for `dof` joints: valid, distinct
    /// names, and at most [`MAX_OWN_DIAGNOSTICS`] values a step.
    pub fn new(entries: Vec<(String, OwnShape)>, dof: usize) -> Result<Self, OwnLayoutError> {
        for (i, (name, _)) in entries.iter().enumerate() {
            if !is_diagnostic_name(name) {
                return Err(OwnLayoutError::Name(name.clone()));
            }
            if entries[..i].iter().any(|(n, _)| n == name) {
                return Err(OwnLayoutError::Twice(name.clone()));
            }
        }
        let layout = Self { entries };
        let len = layout.len(dof);
        if len > MAX_OWN_DIAGNOSTICS {
            return Err(OwnLayoutError::TooMany { len, dof });
        }
        // Columns are what the CSV and the summary know a value by: two of
        // one name once gave two `own.a1` (#48 item 13, D16).
        let mut seen = std::collections::HashMap::new();
        for (name, shape) in &layout.entries {
            let one = Self {
                entries: vec![(name.clone(), *shape)],
            };
            for column in one.columns(dof) {
                if let Some(first) = seen.insert(column.clone(), name) {
                    return Err(OwnLayoutError::SameColumn {
                        column,
                        first: first.clone(),
                        second: name.clone(),
                    });
                }
            }
        }
        Ok(layout)
    }

    /// Reads [`OwnLayout::text`] back (`""`: none declared).
    pub fn parse(text: &str, dof: usize) -> Result<Self, OwnLayoutError> {
        let entries = text
            .split(',')
            .filter(|e| !e.is_empty())
            .map(|e| {
                let (name, shape) = e
                    .split_once(':')
                    .ok_or_else(|| OwnLayoutError::Entry(e.into()))?;
                Ok((name.to_string(), OwnShape::parse(shape)?))
            })
            .collect::<Result<Vec<_>, OwnLayoutError>>()?;
        Self::new(entries, dof)
    }

    /// `name:shape,name:shape` (empty when none is declared).
    pub fn text(&self) -> String {
        self.entries
            .iter()
            .map(|(n, s)| format!("{n}:{}", s.as_str()))
            .collect::<Vec<_>>()
            .join(",")
    }

    /// True when nothing is declared.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Values a step for `dof` joints.
    pub fn len(&self, dof: usize) -> usize {
        self.entries.iter().map(|(_, s)| s.len(dof)).sum()
    }

    /// Each diagnostic's name and its values' range.
    pub fn spans(&self, dof: usize) -> Vec<(&str, std::ops::Range<usize>)> {
        let mut at = 0;
        self.entries
            .iter()
            .map(|(n, s)| {
                let r = at..at + s.len(dof);
                at = r.end;
                (n.as_str(), r)
            })
            .collect()
    }

    /// One name per value: a scalar's own name, a per-joint one's name
    /// with the joint's index (`integral0`, `integral1`, …).
    pub fn columns(&self, dof: usize) -> Vec<String> {
        self.entries
            .iter()
            .flat_map(|(n, s)| match s {
                OwnShape::Scalar => vec![n.clone()],
                OwnShape::Joints => (0..dof).map(|i| format!("{n}{i}")).collect(),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn text_reads_back_and_names_columns() {
        let l = OwnLayout::parse("integral:joints,windup:scalar", 3).unwrap();
        assert_eq!(l.text(), "integral:joints,windup:scalar");
        assert_eq!(l.len(3), 4);
        assert_eq!(
            l.columns(3),
            ["integral0", "integral1", "integral2", "windup"]
        );
        assert_eq!(l.spans(3)[1], ("windup", 3..4));
        assert!(OwnLayout::parse("", 3).unwrap().is_empty());
    }

    #[test]
    fn bad_declarations_are_named() {
        for (text, says) in [
            ("a:joints,b:joints", "at most 32"),
            ("Integral:scalar", "starting with a letter"),
            ("x:scalar,x:joints", "declared twice"),
            (
                "a:joints,a1:scalar",
                "diagnostics \"a\" and \"a1\" both name the column \"a1\"",
            ),
            (
                "a12:scalar,a1:joints",
                "diagnostics \"a12\" and \"a1\" both name the column \"a12\"",
            ),
            ("x:vector", "\"scalar\" or \"joints\""),
            ("x", "not name:shape"),
        ] {
            let e = OwnLayout::parse(text, 20).unwrap_err().to_string();
            assert!(e.contains(says), "{text}: {e}");
        }
    }
}
