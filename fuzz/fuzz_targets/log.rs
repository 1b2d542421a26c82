//! A log file, read and every message decoded as `replay` does: any bytes
//! give the log's contents (perhaps cut short) or a named error.
#![no_main]

use libfuzzer_sys::fuzz_target;
use logger::{Decode, LogMessage};
use wire::{Command, ControllerDiagnostics, JointState, ReferenceSample, Timing};

fuzz_target!(|data: &[u8]| {
    let mut decode = |topic: &str, e: logger::Encoding, v: &[u8]| {
        let _ = match topic {
            t if t == JointState::LOG_TOPIC => JointState::decode_as(e, v).map(|_| ()),
            t if t == ReferenceSample::LOG_TOPIC => ReferenceSample::decode_as(e, v).map(|_| ()),
            t if t == Command::LOG_TOPIC => Command::decode_as(e, v).map(|_| ()),
            t if t == ControllerDiagnostics::LOG_TOPIC => ControllerDiagnostics::decode_as(e, v).map(|_| ()),
            t if t == Timing::LOG_TOPIC => Timing::decode_as(e, v).map(|_| ()),
            _ => logger::check_message(e, v),
        };
        Ok(())
    };
    let _ = logger::read_log_bytes(data, std::path::Path::new("fuzz.mcap"), Some(&mut decode));
});
