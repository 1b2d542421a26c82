//! A testbed message's `ros2msg` schema, as a log stores it beside its
//! channel: the list of fields the CDR that follows was written with.
//!
//! The reader decodes each message by the schema stored in its own log,
//! not by the field list of the build reading it, and hands the fields to
//! the message by name ([`wire::MessageFields::decode`]). A log written
//! before a field was added therefore reads, the field taking the value its
//! declaration gives older logs (`=> U64 | NONE_U64`); a field the log has
//! and this build dropped is skipped. Only the types testbed messages use
//! are read: `std_msgs/Header`, `uint32`, `uint64`, `int64`, `float64` and
//! `float64[]`.

/// Most fields a schema may have (the largest message has 15).
pub const MAX_SCHEMA_FIELDS: usize = 256;

/// The type of one field of a schema.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SchemaKind {
    /// `std_msgs/Header`: a stamp (the sim time) and a frame id.
    Header,
    /// `uint32`.
    U32,
    /// `uint64`.
    U64,
    /// `int64`.
    I64,
    /// `float64`.
    F64,
    /// `float64[]`: one entry per joint (or per declared value).
    F64s,
}

impl SchemaKind {
    fn of(ty: &str) -> Option<Self> {
        Some(match ty {
            "std_msgs/Header" | "std_msgs/msg/Header" | "Header" => Self::Header,
            "uint32" => Self::U32,
            "uint64" => Self::U64,
            "int64" => Self::I64,
            "float64" => Self::F64,
            "float64[]" => Self::F64s,
            _ => return None,
        })
    }
}

/// One field: its name and type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SchemaField {
    /// The field's name.
    pub name: String,
    /// Its type.
    pub kind: SchemaKind,
}

/// A message's fields in the order its CDR holds them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MsgSchema {
    /// The schema's name (`testbed_msgs/msg/JointState`).
    pub name: String,
    /// The fields, in order.
    pub fields: Vec<SchemaField>,
}

/// Why a stored schema cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SchemaError {
    /// A line is not `TYPE NAME`.
    #[error("schema {schema}, line {line}: {text:?} is not a field (TYPE NAME)")]
    NotAField {
        /// The schema's name.
        schema: String,
        /// 1-based line.
        line: usize,
        /// The line (cut to 80 characters).
        text: String,
    },
    /// A type testbed messages do not use.
    #[error(
        "schema {schema}, field '{field}': type {ty} is not one testbed messages use (std_msgs/Header, uint32, uint64, int64, float64, float64[])"
    )]
    UnknownType {
        /// The schema's name.
        schema: String,
        /// The field.
        field: String,
        /// Its type (cut to 80 characters).
        ty: String,
    },
    /// Two fields of one name.
    #[error("schema {schema}: field '{field}' appears twice")]
    Repeated {
        /// The schema's name.
        schema: String,
        /// The field.
        field: String,
    },
    /// Past [`MAX_SCHEMA_FIELDS`].
    #[error("schema {schema}: more than {MAX_SCHEMA_FIELDS} fields")]
    TooMany {
        /// The schema's name.
        schema: String,
    },
    /// Not UTF-8.
    #[error("schema {schema} is not UTF-8 text")]
    NotText {
        /// The schema's name.
        schema: String,
    },
}

impl MsgSchema {
    /// Reads the main message of a `ros2msg` schema text (the part before
    /// the first `====` line, which starts the definitions it uses).
    /// Comments and constants (`TYPE NAME=VALUE`) are not fields.
    pub fn parse(name: &str, text: &[u8]) -> Result<Self, SchemaError> {
        let schema = || name.to_string();
        let text =
            std::str::from_utf8(text).map_err(|_| SchemaError::NotText { schema: schema() })?;
        let mut fields: Vec<SchemaField> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.starts_with("====") {
                break;
            }
            if line.is_empty() || line.contains('=') {
                continue;
            }
            let mut words = line.split_whitespace();
            let (Some(ty), Some(field), None) = (words.next(), words.next(), words.next()) else {
                return Err(SchemaError::NotAField {
                    schema: schema(),
                    line: i + 1,
                    text: line.chars().take(80).collect(),
                });
            };
            let kind = SchemaKind::of(ty).ok_or_else(|| SchemaError::UnknownType {
                schema: schema(),
                field: field.chars().take(80).collect(),
                ty: ty.chars().take(80).collect(),
            })?;
            if fields.iter().any(|f| f.name == field) {
                return Err(SchemaError::Repeated {
                    schema: schema(),
                    field: field.into(),
                });
            }
            if fields.len() == MAX_SCHEMA_FIELDS {
                return Err(SchemaError::TooMany { schema: schema() });
            }
            fields.push(SchemaField {
                name: field.into(),
                kind,
            });
        }
        Ok(Self {
            name: name.into(),
            fields,
        })
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
    fn a_written_schema_reads_back_as_its_field_list() {
        let s = crate::ros2::msg_schema::<wire::JointState>().unwrap();
        assert_eq!(s.name, "testbed_msgs/msg/JointState");
        let names: Vec<&str> = s.fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(&names[..4], ["header", "seq", "wall_ns", "dof"]);
        assert_eq!(s.fields[0].kind, SchemaKind::Header);
        let q = s.fields.iter().find(|f| f.name == "q").unwrap();
        assert_eq!(q.kind, SchemaKind::F64s);
        // The definitions it uses (after ====) are not fields.
        assert!(!names.contains(&"stamp"));
    }

    #[test]
    fn constants_and_comments_are_not_fields() {
        let s = MsgSchema::parse("x", b"# about\nuint8 A=1\nfloat64 y  # metres\n").unwrap();
        assert_eq!(s.fields.len(), 1);
        assert_eq!(s.fields[0].name, "y");
    }

    #[test]
    fn what_testbed_cannot_read_is_named() {
        let e = MsgSchema::parse("x", b"float32 y\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("field 'y': type float32"), "{e}");
        let e = MsgSchema::parse("x", b"float64 y z\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 1"), "{e}");
        let e = MsgSchema::parse("x", b"float64 y\nuint64 y\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("'y' appears twice"), "{e}");
        let many: String = (0..300).map(|i| format!("float64 f{i}\n")).collect();
        let e = MsgSchema::parse("x", many.as_bytes())
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than 256"), "{e}");
        assert!(MsgSchema::parse("x", &[0xff, 0xfe]).is_err());
    }
}
