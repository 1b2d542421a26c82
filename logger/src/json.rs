//! Messages as JSON, as logs of formats 1 and 2 hold them (format 3 is
//! CDR, [`crate::ros2`]): the reader decodes them with [`LogMessage::parse`];
//! the writer side (`to_json`, `encode`, `schema`) stays for tools and tests
//! that want a message as JSON.
//!
//! Each message type lists its fields once, where the wire defines it
//! ([`wire::data_message!`]); the JSON object, the schema and the way back
//! all follow from that list, so they cannot drift apart. Per-joint arrays
//! are written with `dof` entries (not the wire's padding); non-finite
//! numbers are written as `null` (JSON has no NaN) and read back as NaN.

use serde_json::{Map, Value, json};

use crate::decode_error::DecodeError;
use wire::{
    Bound, Command, ContactState, ControllerDiagnostics, FieldRef, FieldSource, Header, JointState,
    OwnDiagnostics, ReferenceSample, Timing,
};

/// A message type as it appears in the log.
pub trait LogMessage: Bound {
    /// MCAP topic: the message's log channel in the wire's binding table.
    const LOG_TOPIC: &'static str = match <Self as Bound>::CHANNEL {
        Some(c) => c,
        None => "",
    };
    /// Schema name, from the same table.
    const LOG_SCHEMA: &'static str = <Self as Bound>::SCHEMA;
    /// One-line description for the schema.
    const ABOUT: &'static str;

    /// The JSON object.
    fn to_json(&self) -> Value {
        let h = self.header();
        let mut o = Map::new();
        o.insert("seq".into(), h.seq.into());
        o.insert("t_ns".into(), h.t_ns.into());
        o.insert("wall_ns".into(), h.wall_ns.into());
        o.insert("t".into(), number(h.t_ns as f64 / 1e9));
        self.visit(&mut |name, f| {
            let v = match f {
                FieldRef::U32(x) => x.into(),
                FieldRef::U(x) => x.into(),
                FieldRef::I(x) => x.into(),
                FieldRef::F(x) => number(x),
                FieldRef::J(xs) | FieldRef::V(xs) => {
                    Value::Array(xs.iter().map(|x| number(*x)).collect())
                }
            };
            o.insert(name.into(), v);
        });
        Value::Object(o)
    }

    /// The JSON object's text appended to `out`, the same object as
    /// [`LogMessage::to_json`] without building it (the logger's hot path;
    /// keys in field order instead of sorted).
    fn encode(&self, out: &mut Vec<u8>) {
        let h = self.header();
        out.push(b'{');
        key(out, "seq", true);
        write_int(out, h.seq);
        key(out, "t_ns", false);
        write_int(out, h.t_ns);
        key(out, "wall_ns", false);
        write_int(out, h.wall_ns);
        key(out, "t", false);
        write_real(out, h.t_ns as f64 / 1e9);
        self.visit(&mut |name, f| {
            key(out, name, false);
            match f {
                FieldRef::U32(x) => write_int(out, x),
                FieldRef::U(x) => write_int(out, x),
                FieldRef::I(x) => write_int(out, x),
                FieldRef::F(x) => write_real(out, x),
                FieldRef::J(xs) | FieldRef::V(xs) => {
                    out.push(b'[');
                    for (i, x) in xs.iter().enumerate() {
                        if i > 0 {
                            out.push(b',');
                        }
                        write_real(out, *x);
                    }
                    out.push(b']');
                }
            }
        });
        out.push(b'}');
    }

    /// The message back from its JSON text (a logged message's data).
    fn parse(text: &[u8]) -> Result<Self, DecodeError> {
        let m = crate::json_object::JsonObject::parse(text)?;
        let header = || -> Result<Header, wire::FieldError> {
            Ok(Header {
                seq: m.u("seq")?,
                t_ns: m.u("t_ns")?,
                wall_ns: m.u("wall_ns")?,
            })
        };
        header()
            .and_then(|h| Self::decode(h, &m))
            .map_err(DecodeError::from)
    }

    /// The JSON schema (draft 2020-12, `jsonschema` encoding in MCAP).
    fn schema() -> Value {
        let mut props = Map::new();
        let int = |d: &str| json!({"type": "integer", "description": d});
        props.insert(
            "seq".into(),
            int("sequence number (the control step for step-aligned topics)"),
        );
        props.insert("t_ns".into(), int("sim time, ns"));
        props.insert("wall_ns".into(), int("CLOCK_MONOTONIC when published, ns"));
        props.insert(
            "t".into(),
            json!({"type": ["number", "null"], "description": "sim time, s"}),
        );
        Self::default().visit(&mut |name, f| {
            let s = match f {
                FieldRef::U32(_) | FieldRef::U(_) | FieldRef::I(_) => json!({"type": "integer"}),
                FieldRef::F(_) => json!({"type": ["number", "null"]}),
                FieldRef::J(_) => json!({
                    "type": "array",
                    "items": {"type": ["number", "null"]},
                    "description": "one entry per joint, in joint order"
                }),
                FieldRef::V(_) => json!({
                    "type": "array",
                    "items": {"type": ["number", "null"]},
                }),
            };
            props.insert(name.into(), s);
        });
        let required: Vec<Value> = props.keys().map(|k| Value::String(k.clone())).collect();
        json!({
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": Self::LOG_SCHEMA,
            "description": Self::ABOUT,
            "type": "object",
            "properties": props,
            "required": required,
            "additionalProperties": false
        })
    }
}

/// `"name":`, after a comma unless it is the first key. Field names are
/// Rust identifiers: nothing to escape.
fn key(out: &mut Vec<u8>, name: &str, first: bool) {
    if !first {
        out.push(b',');
    }
    out.push(b'"');
    out.extend_from_slice(name.as_bytes());
    out.extend_from_slice(b"\":");
}

/// An integer as serde_json writes it. Writing a number into a Vec cannot
/// fail (serde_json's only errors here are the writer's).
fn write_int(out: &mut Vec<u8>, x: impl serde::Serialize) {
    let _ = serde_json::to_writer(&mut *out, &x);
}

/// A real as serde_json writes it: shortest round-trip digits, `null` when
/// not finite (JSON has no NaN).
fn write_real(out: &mut Vec<u8>, x: f64) {
    if x.is_finite() {
        let _ = serde_json::to_writer(&mut *out, &x);
    } else {
        out.extend_from_slice(b"null");
    }
}

fn number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

impl LogMessage for JointState {
    const ABOUT: &'static str = "The plant's state at step seq (t = seq x period): q, qd true; \
        q_measured, qd_measured as the sensors report them; effects: bits 0 friction, \
        1 payload, 2 disturbance, 3 saturated, 4 sensor_noise, 5 quantised, 6 delayed, \
        7 command_dropped, 8 command_held, 9 motor_lag, 10 backlash, 11 cogging, 12 elastic, 13 contact.";
}

impl LogMessage for ReferenceSample {
    const ABOUT: &'static str = "The reference q_d and the constraint envelope k_c at time t.";
}

impl LogMessage for Command {
    const ABOUT: &'static str = "The controller's torque for the state with the same seq.";
}

impl LogMessage for ControllerDiagnostics {
    const ABOUT: &'static str = "Everything the controller computed at step seq (SPEC section 12).";
}

impl LogMessage for OwnDiagnostics {
    const ABOUT: &'static str = "An external controller's own diagnostics at step seq: the values \
        of what it declared, in the order the run's metadata (controller_diagnostics) lists them.";
}

impl LogMessage for ContactState {
    const ABOUT: &'static str = "What contact did over the period that led to the state with the \
        same seq: contact points, the mean contact force on the arm (N) and the deepest point \
        (world frame, m). Only a plant with [plant.contact] publishes it.";
}

impl LogMessage for Timing {
    const ABOUT: &'static str = "Timing of the plant cycle that consumed the command for step seq.";
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The schema's legend of the effect bits follows the plant's own list.
    #[test]
    fn effect_bits_are_described_as_the_plant_defines_them() {
        let about = JointState::ABOUT
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        for (bit, name) in wire::Effects::all_names().enumerate() {
            assert!(
                about.contains(&format!("{bit} {name}")),
                "{bit} {name}: {about}"
            );
        }
    }

    #[test]
    fn encode_writes_the_same_object_as_to_json() {
        let mut d = ControllerDiagnostics {
            header: Header {
                seq: 7,
                t_ns: 1_234_567,
                wall_ns: 99,
            },
            ..ControllerDiagnostics::default()
        };
        d.tau[0] = 0.1 + 0.2;
        d.tau[1] = f64::NAN;
        d.wa_norm[0] = -1e-300;
        let mut out = Vec::new();
        d.encode(&mut out);
        let parsed: Value = serde_json::from_slice(&out).unwrap();
        assert_eq!(parsed, d.to_json());
    }

    #[test]
    fn round_trip_keeps_every_bit_and_nan() {
        let mut s = JointState {
            header: Header {
                seq: 7,
                t_ns: 7_000_000,
                wall_ns: u64::MAX - 3,
            },
            dof: 2,
            ..JointState::default()
        };
        s.q[0] = 0.1 + 0.2;
        s.q[1] = -1e-300;
        s.qd[0] = f64::NAN;
        let back = JointState::parse(s.to_json().to_string().as_bytes()).unwrap();
        assert_eq!(back.header, s.header);
        assert_eq!(back.q[0].to_bits(), s.q[0].to_bits());
        assert_eq!(back.q[1].to_bits(), s.q[1].to_bits());
        assert!(back.qd[0].is_nan());
        assert_eq!(s.to_json()["q"].as_array().unwrap().len(), 2);
    }

    #[test]
    fn schema_lists_every_field_as_required() {
        let schema = ControllerDiagnostics::schema();
        let req = schema["required"].as_array().unwrap();
        let obj = ControllerDiagnostics::default().to_json();
        assert_eq!(req.len(), obj.as_object().unwrap().len());
        assert_eq!(schema["type"], "object");
    }

    #[test]
    fn malformed_json_is_an_error_naming_the_field() {
        let mut v = Command::default().to_json();
        v["tau"] = json!("x");
        assert_eq!(
            Command::parse(v.to_string().as_bytes())
                .unwrap_err()
                .to_string(),
            "field 'tau' is not an array"
        );
        v.as_object_mut().unwrap().remove("seq");
        assert_eq!(
            Command::parse(v.to_string().as_bytes())
                .unwrap_err()
                .to_string(),
            "field 'seq' is missing"
        );
    }
}
