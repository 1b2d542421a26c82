//! The scenarios shipped in `scenarios/`, embedded so that `testbed
//! scenarios` can list them and `--scenario NAME` can find them.

use std::path::PathBuf;

/// A scenario file shipped with the testbed.
#[derive(Debug, Clone, Copy)]
pub struct Shipped {
    /// Its name: the file name without `.toml`.
    pub name: &'static str,
    /// The file's text.
    pub toml: &'static str,
}

macro_rules! shipped {
    ($($name:literal),* $(,)?) => {
        &[$(Shipped {
            name: $name,
            toml: include_str!(concat!("../../scenarios/", $name, ".toml")),
        }),*]
    };
}

/// Every file in `scenarios/`, the paper's first.
pub const SHIPPED: &[Shipped] = shipped![
    "paper",
    "payload_pickup",
    "friction_noise",
    "disturbance",
    "actuation_delay",
    "tight_envelope",
    "saturation_slow_reference",
    "three_link_limits",
    "paper_per_input",
    "iiwa_waypoints",
    "iiwa_csv",
    "paper_randomised",
    "ur5_randomised",
    "iiwa14_randomised",
    "iiwa_actuators",
    "paper_obstacle",
    "paper_pick_place",
    "iiwa_wall",
];

impl Shipped {
    /// What it demonstrates: the file's opening comment as one paragraph.
    pub fn about(&self) -> String {
        self.toml
            .lines()
            .take_while(|l| l.starts_with('#'))
            .map(|l| l.trim_start_matches('#').trim())
            .take_while(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// Where the file is in the source tree this binary was built from.
    pub fn path(&self) -> PathBuf {
        let crate_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        crate_dir
            .parent()
            .unwrap_or(crate_dir)
            .join("scenarios")
            .join(format!("{}.toml", self.name))
    }
}

/// The shipped scenario called `name` (with or without `.toml`).
pub fn find(name: &str) -> Option<&'static Shipped> {
    let name = name.strip_suffix(".toml").unwrap_or(name);
    SHIPPED.iter().find(|s| s.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The list above and the folder cannot drift apart.
    #[test]
    fn every_file_in_scenarios_is_listed() {
        let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios"));
        let mut files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| {
                let name = e.unwrap().file_name().to_string_lossy().to_string();
                name.strip_suffix(".toml").map(str::to_string)
            })
            .collect();
        files.sort();
        let mut listed: Vec<String> = SHIPPED.iter().map(|s| s.name.to_string()).collect();
        listed.sort();
        assert_eq!(files, listed);
    }

    #[test]
    fn every_shipped_scenario_says_what_it_shows_and_loads() {
        for s in SHIPPED {
            assert!(s.about().len() > 40, "{}: {:?}", s.name, s.about());
            let plan = crate::load(Some(&s.path()), &crate::Overrides::default())
                .unwrap_or_else(|e| panic!("{}: {e}", s.name));
            assert_eq!(plan.scenario.name, s.name, "name key of {}", s.name);
        }
        assert!(find("payload_pickup.toml").is_some());
        assert!(find("nope").is_none());
    }
}
