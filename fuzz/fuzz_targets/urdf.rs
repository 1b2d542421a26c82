//! A URDF, loaded as an arm: any text gives a model or a named error.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = arm_model::ArmModel::from_urdf_str(text);
    }
});
