//! A log file, read and every message decoded as `replay` does: any bytes
//! give the log's contents (perhaps cut short) or a named error.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Every logged message of the wire's list, as the analysis decodes
    // them; the standard views checked as replay checks them.
    let mut decode = |topic: &str, e: logger::Encoding, v: &[u8]| {
        let _ = match logger::decode_logged(topic, e, v) {
            Ok(Some(_)) => Ok(()),
            Ok(None) => logger::check_message(e, v),
            Err(e) => Err(e),
        };
        Ok(())
    };
    let _ = logger::read_log_bytes(data, std::path::Path::new("fuzz.mcap"), Some(&mut decode));
});
