//! The architecture recipe "Add a field to a message", checked: a log
//! stores each message's schema, and the reader decodes its CDR by that
//! schema, handing fields over by name. So a log written before a field was
//! added reads with the field at the value its declaration gives older logs,
//! a field since dropped is read past, and a required field a log lacks is
//! named, without a new log format.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "test code: a broken expectation should fail loudly"
)]

use logger::cdr::CdrWriter;
use logger::cdr_decode;
use logger::msg_schema::{MsgSchema, SchemaKind};
use logger::ros2;
use wire::{FieldRef, JointState, MessageFields, NONE_U64};

/// `M`'s schema text with the lines of `drop` removed and `add` appended to
/// the main message (before the definitions it uses).
fn edited_schema(text: &str, drop: &[&str], add: &str) -> String {
    let (main, deps) = text.split_at(text.find("\n====").expect("a dependency section"));
    let mut out: String = main
        .lines()
        .filter(|l| {
            !drop
                .iter()
                .any(|d| l.split('#').next().unwrap().trim().ends_with(d))
        })
        .map(|l| format!("{l}\n"))
        .collect();
    out.push_str(add);
    out.push_str(deps);
    out
}

/// `m` as CDR laid out by `schema`: each field by name from `m`; a field
/// `m` lacks is written as `extra`.
fn encode_by(schema: &MsgSchema, m: &JointState, extra: f64) -> Vec<u8> {
    let mut out = Vec::new();
    let mut w = CdrWriter::new(&mut out);
    for f in &schema.fields {
        let mine = |want: &str| {
            let mut v = None;
            m.visit(&mut |name, field| {
                if name == want {
                    v = Some(match field {
                        FieldRef::U32(x) => vec![f64::from(x)],
                        FieldRef::U(x) => vec![x as f64],
                        FieldRef::I(x) => vec![x as f64],
                        FieldRef::F(x) => vec![x],
                        FieldRef::J(xs) | FieldRef::V(xs) => xs.to_vec(),
                    });
                }
            });
            v
        };
        match (f.name.as_str(), f.kind) {
            (_, SchemaKind::Header) => w.header(m.header.t_ns, ""),
            ("seq", _) => w.u64(m.header.seq),
            ("wall_ns", _) => w.u64(m.header.wall_ns),
            (name, SchemaKind::U32) => w.u32(mine(name).map_or(extra, |v| v[0]) as u32),
            (name, SchemaKind::U64) => w.u64(mine(name).map_or(extra, |v| v[0]) as u64),
            (name, SchemaKind::I64) => w.i64(mine(name).map_or(extra, |v| v[0]) as i64),
            (name, SchemaKind::F64) => w.f64(mine(name).map_or(extra, |v| v[0])),
            (name, SchemaKind::F64s) => w.f64s(&mine(name).unwrap_or_else(|| vec![extra; 2])),
        }
    }
    out
}

fn state() -> JointState {
    let mut s = JointState::default();
    s.header.seq = 7;
    s.header.t_ns = 7_000_000;
    s.header.wall_ns = 123;
    s.dof = 2;
    s.q[0] = 0.25;
    s.q[1] = -0.5;
    s.command_seq = 6;
    s.applied_wall_ns = 99;
    s
}

fn schema_of(text: &str) -> MsgSchema {
    MsgSchema::parse(&ros2::type_name::<JointState>(), text.as_bytes()).unwrap()
}

#[test]
fn a_log_written_before_a_field_was_added_reads_with_its_declared_default() {
    // A JointState as logs had it before `command_seq` and
    // `applied_wall_ns` were added (`=> U64 | NONE_U64`, `=> U64 | 0`).
    let text = ros2::schema_text::<JointState>();
    let older = schema_of(&edited_schema(
        &text,
        &["command_seq", "applied_wall_ns"],
        "",
    ));
    assert_eq!(older.fields.len() + 2, schema_of(&text).fields.len());
    let data = encode_by(&older, &state(), 0.0);
    let back: JointState = cdr_decode::decode_by(&older, &data).unwrap();
    assert_eq!(back.command_seq, NONE_U64);
    assert_eq!(back.applied_wall_ns, 0);
    assert_eq!(
        (back.header, back.dof, back.q[1]),
        (state().header, 2, -0.5)
    );
}

#[test]
fn a_field_the_log_has_and_this_build_dropped_is_read_past() {
    let text = ros2::schema_text::<JointState>();
    let newer = schema_of(&edited_schema(
        &text,
        &[],
        "float64[] future_field  # added by a later build\nuint64 future_count\n",
    ));
    let data = encode_by(&newer, &state(), 4.0);
    let back: JointState = cdr_decode::decode_by(&newer, &data).unwrap();
    assert_eq!(back, {
        let mut s = state();
        // Padding is not logged.
        s.reserved = back.reserved;
        s
    });
}

#[test]
fn a_required_field_the_log_lacks_is_named() {
    let text = ros2::schema_text::<JointState>();
    let without = schema_of(&edited_schema(&text, &[" q"], ""));
    let data = encode_by(&without, &state(), 0.0);
    let e = cdr_decode::decode_by::<JointState>(&without, &data)
        .unwrap_err()
        .to_string();
    assert_eq!(e, "field 'q' is missing");
}

#[test]
fn a_field_of_another_type_is_refused_by_name() {
    let text = ros2::schema_text::<JointState>();
    let changed = schema_of(&edited_schema(
        &text,
        &["deadline_misses"],
        "float64 deadline_misses\n",
    ));
    let data = encode_by(&changed, &state(), 0.0);
    let e = cdr_decode::decode_by::<JointState>(&changed, &data)
        .unwrap_err()
        .to_string();
    assert!(e.contains("deadline_misses"), "{e}");
}

#[test]
fn the_schema_this_build_writes_decodes_what_it_encodes() {
    let own = ros2::msg_schema::<JointState>().unwrap();
    let mut data = Vec::new();
    ros2::encode(&state(), &mut data);
    assert_eq!(data, encode_by(&own, &state(), 0.0));
    let back: JointState = cdr_decode::decode_by(&own, &data).unwrap();
    assert_eq!(back.command_seq, 6);
    assert_eq!(back.applied_wall_ns, 99);
}
