//! A log file, read and every message decoded as `replay` does: any bytes
//! give the log's contents (perhaps cut short) or a named error.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Every logged message of the wire's list decoded by the schema its
    // log stores, as the analysis does; the standard views checked as
    // replay checks them.
    let mut decode = |m: &logger::RawMessage<'_>| {
        let _ = match logger::decode_logged(m) {
            Ok(Some(_)) => Ok(()),
            Ok(None) => logger::check_message(m.encoding, m.data),
            Err(e) => Err(e),
        };
        Ok(())
    };
    let _ = logger::read_log_bytes(data, std::path::Path::new("fuzz.mcap"), Some(&mut decode));
});
