//! `testbed bindings python`: the wire contract as a Python module of
//! ctypes structures and constants, generated from the Rust definitions
//! ([`crate::all_layouts`], the topics, the protocol codes), so that a
//! controller written in Python speaks exactly what the Rust nodes speak.
//! The generated file is committed (`python/testbed_controller/wire.py`);
//! a test fails when it no longer equals what this module writes.

use std::fmt::Write;

use crate::{Fault, FieldType, MAX_DOF, NodeKind, RunEnd, Topic, TypeLayout};

/// Where the Python package keeps the generated module, from the repository root.
pub const PYTHON_WIRE_PATH: &str = "python/testbed_controller/wire.py";

/// The whole generated Python module.
pub fn python() -> String {
    let mut out = String::new();
    header(&mut out);
    constants(&mut out);
    for t in crate::all_layouts() {
        structure(&mut out, &t);
    }
    topics(&mut out);
    out
}

fn header(out: &mut String) {
    out.push_str(
        "\"\"\"The testbed's wire contract: message layouts, topics and protocol codes.\n\
         \n\
         Generated from the Rust definitions (crate `wire`) by\n\
         \n\
         \x20   cargo run --release -- bindings python --out python/testbed_controller/wire.py\n\
         \n\
         Do not edit: a test of the Rust workspace fails when this file no longer\n\
         matches the Rust types, and importing it checks every size and offset.\n\
         \"\"\"\n\
         \n\
         # fmt: off\n\
         import ctypes\n\n",
    );
}

fn constants(out: &mut String) {
    let mut c = |name: &str, value: String, doc: &str| {
        let _ = writeln!(out, "{name} = {value}  # {doc}");
    };
    c("MAX_DOF", MAX_DOF.to_string(), "joints a message carries");
    c(
        "SUBSCRIBER_BUFFER",
        crate::SUBSCRIBER_BUFFER.to_string(),
        "samples a subscriber holds",
    );
    c(
        "MAX_SUBSCRIBERS",
        crate::MAX_SUBSCRIBERS.to_string(),
        "subscribers (and listeners) per topic",
    );
    c(
        "MAX_NODES",
        crate::MAX_NODES.to_string(),
        "nodes per service",
    );
    c(
        "LOSSLESS_TIMEOUT_S",
        crate::LOSSLESS_TIMEOUT.as_secs().to_string(),
        "a lockstep publisher gives up on a full reader after this",
    );
    c(
        "HEARTBEAT_NS",
        crate::HEARTBEAT.as_nanos().to_string(),
        "a node repeats its status at least this often while it runs",
    );
    c(
        "SILENT_AFTER_S",
        crate::SILENT_AFTER.as_secs().to_string(),
        "the launcher names a node not heard from for this long",
    );
    c(
        "RUN_PREFIX_STEM",
        format!("{:?}", crate::RUN_PREFIX_STEM),
        "every run's shared-memory prefix starts so",
    );
    c(
        "STATE_FINAL",
        crate::STATE_FINAL.to_string(),
        "JointState.flags: the last state, no command expected",
    );
    c(
        "NONE_U64",
        crate::NONE_U64.to_string(),
        "JointState.command_seq, Command.reference_t_ns: none",
    );
    c(
        "CONTROL_START",
        crate::CONTROL_START.to_string(),
        "Control.command",
    );
    c(
        "CONTROL_STOP",
        crate::CONTROL_STOP.to_string(),
        "Control.command",
    );
    for (name, v) in [
        ("NODE_READY", crate::NODE_READY),
        ("NODE_RUNNING", crate::NODE_RUNNING),
        ("NODE_DONE", crate::NODE_DONE),
        ("NODE_FAILED", crate::NODE_FAILED),
    ] {
        c(name, v.to_string(), "NodeStatus.state");
    }
    for k in NodeKind::ALL {
        let name = format!("NODE_KIND_{}", k.name().to_uppercase());
        c(&name, (k as u32).to_string(), "NodeStatus.node");
    }
    for m in [crate::Mode::Realtime, crate::Mode::Lockstep] {
        let name = format!("MODE_{}", m.as_str().to_uppercase());
        c(&name, m.code().to_string(), "Control.code with START");
    }
    for (name, end) in [
        ("RUN_END_FINISHED", RunEnd::Finished),
        ("RUN_END_INTERRUPTED", RunEnd::Interrupted),
        ("RUN_END_FAILED", RunEnd::Failed),
    ] {
        c(name, end.code().to_string(), "Control.code with STOP");
    }
    let lost = RunEnd::LostNode(NodeKind::Plant).code() - NodeKind::Plant as u32;
    c(
        "RUN_END_LOST_NODE_BASE",
        lost.to_string(),
        "Control.code with STOP: this + the lost node's kind",
    );
    for f in Fault::ALL {
        let name = format!("FAULT_{}", f.constant_name());
        c(&name, f.code().to_string(), "Command.fault (0: none)");
    }
    out.push('\n');
}

fn ctype(ty: FieldType) -> String {
    match ty {
        FieldType::U32 => "ctypes.c_uint32".into(),
        FieldType::U64 => "ctypes.c_uint64".into(),
        FieldType::I64 => "ctypes.c_int64".into(),
        FieldType::F64 => "ctypes.c_double".into(),
        FieldType::Joints => "ctypes.c_double * MAX_DOF".into(),
        FieldType::Header => "Header".into(),
    }
}

fn structure(out: &mut String, t: &TypeLayout) {
    let _ = writeln!(out, "\nclass {}(ctypes.Structure):", t.name);
    let _ = writeln!(out, "    _fields_ = [");
    for f in &t.fields {
        let _ = writeln!(out, "        ({:?}, {}),", f.name, ctype(f.ty));
    }
    let _ = writeln!(out, "    ]");
    let _ = writeln!(out, "    SIZE = {}", t.size);
    let _ = writeln!(out, "    ALIGN = {}", t.align);
    let offsets: Vec<String> = t
        .fields
        .iter()
        .map(|f| format!("{:?}: {}", f.name, f.offset))
        .collect();
    let _ = writeln!(out, "    OFFSETS = {{{}}}", offsets.join(", "));
    let joints: Vec<String> = t
        .fields
        .iter()
        .filter(|f| f.ty == FieldType::Joints)
        .map(|f| format!("{:?}", f.name))
        .collect();
    let _ = writeln!(out, "    JOINT_FIELDS = ({})", tuple_body(&joints));
    if !t.type_name.is_empty() {
        let _ = writeln!(out, "\n    @staticmethod");
        let _ = writeln!(out, "    def type_name() -> str:");
        let _ = writeln!(out, "        return {:?}", t.type_name);
    }
    out.push('\n');
}

fn tuple_body(items: &[String]) -> String {
    match items.len() {
        0 => String::new(),
        1 => format!("{},", items[0]),
        _ => items.join(", "),
    }
}

fn topics(out: &mut String) {
    let _ = writeln!(
        out,
        "\n# Topic name -> (service name, message type, max publishers, max notifiers,\n\
         # whether readers block on its events). Every service lives under the run's prefix."
    );
    let _ = writeln!(out, "TOPICS = {{");
    for &t in Topic::ALL {
        let _ = writeln!(
            out,
            "    {:?}: ({:?}, {}, {}, {}, {}),",
            t.name().trim_start_matches("testbed/"),
            t.name(),
            crate::struct_of(t),
            t.max_publishers(),
            t.max_notifiers(),
            if t.has_waiters() { "True" } else { "False" },
        );
    }
    let _ = writeln!(out, "}}\n");
    let names: Vec<String> = crate::all_layouts()
        .iter()
        .map(|t| format!("{:?}", t.name))
        .collect();
    let _ = writeln!(out, "STRUCTURES = ({})", tuple_body(&names));
    out.push_str(LAYOUT_CHECK);
}

/// Appended to the module: ctypes must lay every structure out as Rust does.
const LAYOUT_CHECK: &str = r#"

def _check_layouts() -> None:
    for name in STRUCTURES:
        s = globals()[name]
        if ctypes.sizeof(s) != s.SIZE or ctypes.alignment(s) != s.ALIGN:
            raise ImportError(
                f"{name}: ctypes lays it out in {ctypes.sizeof(s)} bytes aligned to "
                f"{ctypes.alignment(s)}, Rust in {s.SIZE} aligned to {s.ALIGN}"
            )
        for field, offset in s.OFFSETS.items():
            if getattr(s, field).offset != offset:
                raise ImportError(f"{name}.{field}: ctypes offset {getattr(s, field).offset}, Rust {offset}")


_check_layouts()
"#;

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// The committed Python module is what the Rust types generate today:
    /// change a message and forget to regenerate, and this fails.
    #[test]
    fn committed_python_bindings_are_up_to_date() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(PYTHON_WIRE_PATH);
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == python(),
            "{} is stale: regenerate it with\n  cargo run --release -- bindings python --out {}",
            path.display(),
            PYTHON_WIRE_PATH
        );
    }

    #[test]
    fn every_message_and_topic_is_generated() {
        let py = python();
        for t in crate::all_layouts() {
            assert!(py.contains(&format!("class {}(ctypes.Structure)", t.name)));
        }
        let name = <crate::JointState as crate::WireLayout>::TYPE_NAME;
        assert!(py.contains(&format!("return \"{name}\"")));
        assert!(py.contains("\"joint_state\": (\"testbed/joint_state\", JointState, 1, 2, True)"));
        assert!(py.contains("FAULT_NO_REFERENCE = 5"));
        assert!(py.contains("RUN_END_LOST_NODE_BASE = 10"));
    }
}
