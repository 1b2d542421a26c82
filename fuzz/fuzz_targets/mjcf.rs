//! An MJCF (MuJoCo) document, loaded as an arm: any text gives a model or
//! a named error (#47). The `urdf` target reaches the MJCF reader only
//! when an input starts `<mujoco`; here every input is read as MJCF (the
//! root is added when it is missing), from MJCF seeds.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if text.trim_start().starts_with("<mujoco") {
            let _ = arm_model::ArmModel::from_urdf_str(text);
        } else {
            let _ = arm_model::ArmModel::from_urdf_str(&format!("<mujoco>{text}</mujoco>"));
        }
    }
});
