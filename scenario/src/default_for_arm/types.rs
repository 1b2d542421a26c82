//! The default scenario of an arm and why it is what it is: the data the
//! other files of this folder fill in and read.

use crate::Scenario;
use crate::gains::GainChoice;

/// The default scenario for an arm and why it is what it is.
#[derive(Debug, Clone)]
pub struct ArmDefault {
    /// The scenario.
    pub scenario: Scenario,
    /// Joints the scenario locks, with the reason.
    pub locked: Vec<(String, String)>,
    /// Armature the scenario adds per joint (kg m² or kg), with the reason.
    pub armature: Vec<(String, f64, String)>,
    /// The gains and the reasons for them.
    pub gains: GainChoice,
    /// What a user should know: loads beyond effort limits, joints the
    /// scenario could not hold, envelopes it widened.
    pub warnings: Vec<String>,
    /// The start is the file's home pose (an MJCF keyframe `home`, kept
    /// 2 % of each range inside the limits), not one chosen for the arm.
    pub from_home: bool,
}
