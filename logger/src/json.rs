//! Messages as JSON for the log, and their JSON schemas.
//!
//! Each message type lists its fields once ([`LogMessage::fields`]); the
//! JSON object, the schema and the way back ([`LogMessage::from_fields`])
//! all follow from that list, so they cannot drift apart. Per-joint arrays
//! are written with `dof` entries (not the wire's padding); non-finite
//! numbers are written as `null` (JSON has no NaN) and read back as NaN.

use serde_json::{Map, Value, json};
use wire::{
    Command, ControllerDiagnostics, Header, JointState, Joints, MAX_DOF, ReferenceSample, Timing,
    joints,
};

/// One field's value.
#[derive(Debug, Clone, Copy)]
pub enum Field<'a> {
    /// Unsigned integer.
    U(u64),
    /// Signed integer.
    I(i64),
    /// Real number.
    F(f64),
    /// Per-joint reals (already trimmed to `dof`).
    J(&'a [f64]),
}

/// A message type as it appears in the log.
pub trait LogMessage: Sized + Copy + Default {
    /// MCAP topic.
    const TOPIC: &'static str;
    /// Schema name.
    const SCHEMA: &'static str;
    /// One-line description for the schema.
    const ABOUT: &'static str;
    /// The message's header.
    fn header(&self) -> Header;
    /// Every field but the header, in order.
    fn fields(&self) -> Vec<(&'static str, Field<'_>)>;
    /// Rebuilds the message from a JSON object.
    fn from_fields(header: Header, m: &Fields<'_>) -> Result<Self, String>;

    /// The JSON object.
    fn to_json(&self) -> Value {
        let h = self.header();
        let mut o = Map::new();
        o.insert("seq".into(), h.seq.into());
        o.insert("t_ns".into(), h.t_ns.into());
        o.insert("wall_ns".into(), h.wall_ns.into());
        o.insert("t".into(), number(h.t_ns as f64 / 1e9));
        for (name, f) in self.fields() {
            let v = match f {
                Field::U(x) => x.into(),
                Field::I(x) => x.into(),
                Field::F(x) => number(x),
                Field::J(xs) => Value::Array(xs.iter().map(|x| number(*x)).collect()),
            };
            o.insert(name.into(), v);
        }
        Value::Object(o)
    }

    /// The message back from its JSON object.
    fn parse(v: &Value) -> Result<Self, String> {
        let m = Fields(v.as_object().ok_or("not a JSON object")?);
        let header = Header {
            seq: m.u("seq")?,
            t_ns: m.u("t_ns")?,
            wall_ns: m.u("wall_ns")?,
        };
        Self::from_fields(header, &m)
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
        let example = Self::default();
        for (name, f) in example.fields() {
            let s = match f {
                Field::U(_) | Field::I(_) => json!({"type": "integer"}),
                Field::F(_) => json!({"type": ["number", "null"]}),
                Field::J(_) => json!({
                    "type": "array",
                    "items": {"type": ["number", "null"]},
                    "description": "one entry per joint, in joint order"
                }),
            };
            props.insert(name.into(), s);
        }
        let required: Vec<Value> = props.keys().map(|k| Value::String(k.clone())).collect();
        json!({
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": Self::SCHEMA,
            "description": Self::ABOUT,
            "type": "object",
            "properties": props,
            "required": required,
            "additionalProperties": false
        })
    }
}

fn number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Field access on a parsed JSON object.
pub struct Fields<'a>(&'a Map<String, Value>);

impl Fields<'_> {
    fn get(&self, k: &str) -> Result<&Value, String> {
        self.0
            .get(k)
            .ok_or_else(|| format!("field '{k}' is missing"))
    }
    /// An unsigned integer.
    pub fn u(&self, k: &str) -> Result<u64, String> {
        self.get(k)?
            .as_u64()
            .ok_or_else(|| format!("field '{k}' is not an unsigned integer"))
    }
    /// A u32.
    pub fn u32(&self, k: &str) -> Result<u32, String> {
        u32::try_from(self.u(k)?).map_err(|_| format!("field '{k}' is out of range"))
    }
    /// A signed integer.
    pub fn i(&self, k: &str) -> Result<i64, String> {
        self.get(k)?
            .as_i64()
            .ok_or_else(|| format!("field '{k}' is not an integer"))
    }
    /// A real; null means NaN.
    pub fn f(&self, k: &str) -> Result<f64, String> {
        real(self.get(k)?).ok_or_else(|| format!("field '{k}' is not a number"))
    }
    /// A per-joint array.
    pub fn j(&self, k: &str) -> Result<Joints, String> {
        let a = self
            .get(k)?
            .as_array()
            .ok_or_else(|| format!("field '{k}' is not an array"))?;
        if a.len() > MAX_DOF {
            return Err(format!(
                "field '{k}' has {} entries (at most {MAX_DOF})",
                a.len()
            ));
        }
        let v: Option<Vec<f64>> = a.iter().map(real).collect();
        Ok(joints(&v.ok_or_else(|| {
            format!("field '{k}' holds a non-number")
        })?))
    }
}

fn real(v: &Value) -> Option<f64> {
    match v {
        Value::Null => Some(f64::NAN),
        other => other.as_f64(),
    }
}

fn trim(j: &Joints, dof: u32) -> &[f64] {
    &j[..(dof as usize).min(MAX_DOF)]
}

impl LogMessage for JointState {
    const TOPIC: &'static str = "/joint_state";
    const SCHEMA: &'static str = "testbed.JointState";
    const ABOUT: &'static str = "The plant's state at step seq (t = seq x period): q, qd true; \
        q_measured, qd_measured as the sensors report them; effects: bits 0 friction, \
        1 payload, 2 disturbance, 3 saturated, 4 sensor_noise, 5 quantised, 6 delayed, \
        7 command_dropped, 8 command_held.";
    fn header(&self) -> Header {
        self.header
    }
    fn fields(&self) -> Vec<(&'static str, Field<'_>)> {
        let d = self.dof;
        vec![
            ("dof", Field::U(d.into())),
            ("flags", Field::U(self.flags.into())),
            ("q", Field::J(trim(&self.q, d))),
            ("qd", Field::J(trim(&self.qd, d))),
            ("q_measured", Field::J(trim(&self.q_measured, d))),
            ("qd_measured", Field::J(trim(&self.qd_measured, d))),
            ("tau_applied", Field::J(trim(&self.tau_applied, d))),
            ("disturbance", Field::J(trim(&self.disturbance, d))),
            ("effects", Field::U(self.effects.into())),
            ("deadline_misses", Field::U(self.deadline_misses)),
        ]
    }
    fn from_fields(header: Header, m: &Fields<'_>) -> Result<Self, String> {
        Ok(Self {
            header,
            dof: m.u32("dof")?,
            flags: m.u32("flags")?,
            q: m.j("q")?,
            qd: m.j("qd")?,
            q_measured: m.j("q_measured")?,
            qd_measured: m.j("qd_measured")?,
            tau_applied: m.j("tau_applied")?,
            disturbance: m.j("disturbance")?,
            effects: m.u32("effects")?,
            reserved: 0,
            deadline_misses: m.u("deadline_misses")?,
        })
    }
}

impl LogMessage for ReferenceSample {
    const TOPIC: &'static str = "/reference";
    const SCHEMA: &'static str = "testbed.Reference";
    const ABOUT: &'static str = "The reference q_d and the constraint envelope k_c at time t.";
    fn header(&self) -> Header {
        self.header
    }
    fn fields(&self) -> Vec<(&'static str, Field<'_>)> {
        let d = self.dof;
        vec![
            ("dof", Field::U(d.into())),
            ("q_d", Field::J(trim(&self.q_d, d))),
            ("qd_d", Field::J(trim(&self.qd_d, d))),
            ("qdd_d", Field::J(trim(&self.qdd_d, d))),
            ("kc", Field::J(trim(&self.kc, d))),
            ("kc_dot", Field::J(trim(&self.kc_dot, d))),
        ]
    }
    fn from_fields(header: Header, m: &Fields<'_>) -> Result<Self, String> {
        Ok(Self {
            header,
            dof: m.u32("dof")?,
            reserved: 0,
            q_d: m.j("q_d")?,
            qd_d: m.j("qd_d")?,
            qdd_d: m.j("qdd_d")?,
            kc: m.j("kc")?,
            kc_dot: m.j("kc_dot")?,
        })
    }
}

impl LogMessage for Command {
    const TOPIC: &'static str = "/command";
    const SCHEMA: &'static str = "testbed.Command";
    const ABOUT: &'static str = "The controller's torque for the state with the same seq.";
    fn header(&self) -> Header {
        self.header
    }
    fn fields(&self) -> Vec<(&'static str, Field<'_>)> {
        let d = self.dof;
        vec![
            ("dof", Field::U(d.into())),
            ("fault", Field::U(self.fault.into())),
            ("tau", Field::J(trim(&self.tau, d))),
            ("state_wall_ns", Field::U(self.state_wall_ns)),
            ("compute_ns", Field::U(self.compute_ns)),
        ]
    }
    fn from_fields(header: Header, m: &Fields<'_>) -> Result<Self, String> {
        Ok(Self {
            header,
            dof: m.u32("dof")?,
            fault: m.u32("fault")?,
            tau: m.j("tau")?,
            state_wall_ns: m.u("state_wall_ns")?,
            compute_ns: m.u("compute_ns")?,
        })
    }
}

impl LogMessage for ControllerDiagnostics {
    const TOPIC: &'static str = "/controller/diagnostics";
    const SCHEMA: &'static str = "testbed.ControllerDiagnostics";
    const ABOUT: &'static str = "Everything the controller computed at step seq (SPEC section 12).";
    fn header(&self) -> Header {
        self.header
    }
    fn fields(&self) -> Vec<(&'static str, Field<'_>)> {
        let d = self.dof;
        vec![
            ("dof", Field::U(d.into())),
            ("fault", Field::U(self.fault.into())),
            ("barrier_breached", Field::U(self.barrier_breached.into())),
            ("compute_ns", Field::U(self.compute_ns)),
            ("gamma", Field::F(self.gamma)),
            ("gamma_dot", Field::F(self.gamma_dot)),
            ("j_hat", Field::F(self.j_hat)),
            ("delta", Field::F(self.delta)),
            ("r", Field::F(self.r)),
            ("wc_norm", Field::F(self.wc_norm)),
            ("q_d", Field::J(trim(&self.q_d, d))),
            ("qd_d", Field::J(trim(&self.qd_d, d))),
            ("kc_in", Field::J(trim(&self.kc_in, d))),
            ("kc_dot", Field::J(trim(&self.kc_dot, d))),
            ("z1", Field::J(trim(&self.z1, d))),
            ("z1g", Field::J(trim(&self.z1g, d))),
            ("z2", Field::J(trim(&self.z2, d))),
            ("alpha", Field::J(trim(&self.alpha, d))),
            ("kc", Field::J(trim(&self.kc, d))),
            ("d", Field::J(trim(&self.d, d))),
            ("tau", Field::J(trim(&self.tau, d))),
            ("tau_actor", Field::J(trim(&self.tau_actor, d))),
            ("tau_feedback", Field::J(trim(&self.tau_feedback, d))),
            ("tau_barrier", Field::J(trim(&self.tau_barrier, d))),
            ("wa_norm", Field::J(trim(&self.wa_norm, d))),
        ]
    }
    fn from_fields(header: Header, m: &Fields<'_>) -> Result<Self, String> {
        Ok(Self {
            header,
            dof: m.u32("dof")?,
            fault: m.u32("fault")?,
            barrier_breached: m.u32("barrier_breached")?,
            reserved: 0,
            compute_ns: m.u("compute_ns")?,
            gamma: m.f("gamma")?,
            gamma_dot: m.f("gamma_dot")?,
            j_hat: m.f("j_hat")?,
            delta: m.f("delta")?,
            r: m.f("r")?,
            wc_norm: m.f("wc_norm")?,
            q_d: m.j("q_d")?,
            qd_d: m.j("qd_d")?,
            kc_in: m.j("kc_in")?,
            kc_dot: m.j("kc_dot")?,
            z1: m.j("z1")?,
            z1g: m.j("z1g")?,
            z2: m.j("z2")?,
            alpha: m.j("alpha")?,
            kc: m.j("kc")?,
            d: m.j("d")?,
            tau: m.j("tau")?,
            tau_actor: m.j("tau_actor")?,
            tau_feedback: m.j("tau_feedback")?,
            tau_barrier: m.j("tau_barrier")?,
            wa_norm: m.j("wa_norm")?,
        })
    }
}

impl LogMessage for Timing {
    const TOPIC: &'static str = "/timing";
    const SCHEMA: &'static str = "testbed.Timing";
    const ABOUT: &'static str = "Timing of the plant cycle that consumed the command for step seq.";
    fn header(&self) -> Header {
        self.header
    }
    fn fields(&self) -> Vec<(&'static str, Field<'_>)> {
        vec![
            ("wake_late_ns", Field::I(self.wake_late_ns)),
            ("period_ns", Field::I(self.period_ns)),
            ("round_trip_ns", Field::I(self.round_trip_ns)),
            (
                "controller_compute_ns",
                Field::I(self.controller_compute_ns),
            ),
            ("deadline_missed", Field::U(self.deadline_missed.into())),
            ("deadline_misses", Field::U(self.deadline_misses)),
        ]
    }
    fn from_fields(header: Header, m: &Fields<'_>) -> Result<Self, String> {
        Ok(Self {
            header,
            wake_late_ns: m.i("wake_late_ns")?,
            period_ns: m.i("period_ns")?,
            round_trip_ns: m.i("round_trip_ns")?,
            controller_compute_ns: m.i("controller_compute_ns")?,
            deadline_missed: m.u32("deadline_missed")?,
            reserved: 0,
            deadline_misses: m.u("deadline_misses")?,
        })
    }
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
        for (bit, name) in plant_rapier::Effects::all_names().enumerate() {
            assert!(
                about.contains(&format!("{bit} {name}")),
                "{bit} {name}: {about}"
            );
        }
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
        let back = JointState::parse(&s.to_json()).unwrap();
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
            Command::parse(&v).unwrap_err(),
            "field 'tau' is not an array"
        );
        v.as_object_mut().unwrap().remove("seq");
        assert_eq!(Command::parse(&v).unwrap_err(), "field 'seq' is missing");
    }
}
