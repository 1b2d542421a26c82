//! A node's config file (JSON, as the launcher writes it for each node):
//! any bytes give a node's machine or a named error, never a panic (#31:
//! `dof: 100` once indexed past a 12-joint array).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The first byte picks the node; the rest is its config.
    let Some((&which, json)) = data.split_first() else {
        return;
    };
    match which % 3 {
        0 => {
            if let Ok(c) = serde_json::from_slice::<controller::node::ControllerNodeConfig>(json) {
                let _ = c.machine();
            }
        }
        1 => {
            if let Ok(c) = serde_json::from_slice::<trajectory::node::TrajectoryNodeConfig>(json) {
                let _ = c.machine();
            }
        }
        _ => {
            if let Ok(c) = serde_json::from_slice::<plant_rapier::node::PlantNodeConfig>(json) {
                let _ = c.machine();
            }
        }
    }
});
