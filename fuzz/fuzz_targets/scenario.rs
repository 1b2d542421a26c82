//! A scenario file, parsed and checked against the paper's arm: any text
//! gives a plan or a named error, never a panic or a huge allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use scenario::{RobotSource, Scenario};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(s) = Scenario::from_toml_str(text, "fuzz.toml") {
        let robot = RobotSource::builtin().relocked(&s.plant.lock);
        if let Ok(robot) = robot {
            let _ = scenario::plan(s, "fuzz.toml".into(), text.into(), robot);
        }
    }
});
