//! A sweep file: any text gives its runs or a named error, never a panic,
//! an abort or an allocation the file's size does not explain (#31).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use scenario::sweep_file;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("/nonexistent/fuzz-sweep.toml");
    // Counting is bounded for any input; building every run is not meant
    // to be quick for a million of them, so large sweeps stop at the count.
    if sweep_file::planned_runs(path, text).is_ok_and(|n| n <= 64) {
        let _ = sweep_file::from_text(path, text.to_string());
    }
});
