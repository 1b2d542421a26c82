//! The simulated arm, from a URDF or MJCF file, on one of two engines: the
//! articulated RK4 engine (the equations of motion in joint coordinates,
//! the default) or a Rapier multibody (f64); see [`EngineName`].
//!
//! Where it sits: at the start and the end of each period. The core is the
//! checked [`ArmModel`], the [`Plant`] on either engine and the [`Rig`] around it with
//! what a real arm adds that the controller does not know (friction, a
//! payload, the disturbance d(t), saturation, sensor noise and quantisation,
//! actuation delay, lost commands; see [`PlantConfig`]). [`PlantMachine`]
//! is its step machine in wire messages (command → joint state), driven by
//! the plant node ([`node`], the clock of a multi-process run) and by
//! `testbed sim`. The arm's description is [`arm_model`]'s; the controller
//! never sees the engine (its model-based reference laws evaluate the same
//! URDF with `arm_model::dynamics`, not with the plant's engine).
//!
//! ```
//! use plant_rapier::{ArmModel, Plant, PlantConfig, TWO_LINK_URDF};
//! let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
//! let mut plant = Plant::new(&model, &PlantConfig::default()).unwrap();
//! plant.set_state(&[0.0, 0.0], &[0.0, 0.0]).unwrap();
//! plant.step(&[0.0, 0.0], 1e-3).unwrap();
//! let (q, _qd) = plant.state();
//! assert!(q[0] < 0.0); // a horizontal arm starts to fall
//! ```
//!
//! Conventions: gravity points along -z (URDF is z-up); joint order is tree
//! order from the root (depth-first, siblings in file order); q = 0 is the
//! URDF's zero pose. `<mimic>` joints are coupled to their leader and are
//! not controlled; joints a scenario locks are fixed. Joint damping and dry
//! friction are the URDF's `<dynamics>` (or zero with `urdf_dynamics =
//! false`), armature is the scenario's: nothing of Rapier's defaults.
//!
//! Limitations: contact (`[plant.contact]`) only on the Rapier engine;
//! floating, planar and spherical joints and closed loops are refused.

mod config;
pub mod effects;
mod engine;
mod engine_error;
mod machine;
pub mod node;
mod plant;
mod rig;

pub use arm_model::{
    ArmModel, Geometry, IgnoredLink, JointInfo, JointKind, LinkInfo, LockedJoint, Locks,
    MergedLink, MimicJoint, MimicSpec, ModelError, Origin, TWO_LINK_URDF,
};
pub use config::{
    ActuationConfig, ActuatorConfig, ContactConfig, ContactObject, DisturbanceConfig,
    FrictionConfig, Harmonic, JointActuator, Obstacle, PayloadConfig, PerJoint, PlantConfig,
    SensorConfig, ShapeName, Spring,
};
pub use effects::Effects;
pub use engine::EngineName;
pub use engine_error::EngineError;
pub use machine::{PlantMachine, PlantMachineConfig};
pub use plant::{
    ContactReading, MAX_SUBSTEPS_PER_SECOND, PeriodCost, Plant, StiffCause, check_contact,
};
pub use rig::Rig;

/// Why an arm cannot be built or stepped. Each variant names what is wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PlantError {
    /// The URDF or a lock cannot be read into a model.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Mass or inertia that no rigid body has.
    #[error("link '{link}': {reason}")]
    BadInertia {
        /// The link.
        link: String,
        /// What is wrong.
        reason: String,
    },
    /// Only fixed joints.
    #[error(
        "the model has no actuated joint (URDF revolute, continuous or prismatic; MJCF hinge or slide)"
    )]
    NoActuatedJoints,
    /// A NaN or infinite number.
    #[error("{field}: {value} is not a finite number")]
    NotFinite {
        /// Where it was found.
        field: String,
        /// The value.
        value: f64,
    },
    /// A vector with the wrong number of entries.
    #[error("{field} has {got} entries but the arm has {expected} actuated joints")]
    WrongLength {
        /// Which vector.
        field: &'static str,
        /// Joints of the arm.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// More controlled joints than the wire's messages carry.
    #[error(
        "the arm has {0} controlled joints; the wire carries at most {max}: lock the others in [plant.lock]",
        max = wire::MAX_DOF
    )]
    TooManyJoints(usize),
    /// A plant setting out of range.
    #[error("{key} = {value} is invalid: it must be {need}")]
    InvalidConfig {
        /// The scenario key.
        key: String,
        /// The value.
        value: String,
        /// What it must be.
        need: String,
    },
    /// A scenario whose stiffness needs more integrator substeps than the
    /// testbed runs.
    #[error(
        "{keys}: {why}, which needs {substeps:.0} integrator substeps per {period_s} s period ({per_second:.2e} a simulated second: about {wall:.0} s of wall time per simulated second at a microsecond a substep); the testbed takes at most {max:.0e} a simulated second: lower the stiffness or damping, or raise motor_inertia",
        max = crate::MAX_SUBSTEPS_PER_SECOND,
        wall = .per_second * 1e-6
    )]
    TooStiff {
        /// The scenario keys that make it stiff.
        keys: &'static str,
        /// The rate and the bound a substep keeps.
        why: String,
        /// Substeps a period needs.
        substeps: f64,
        /// The control period, s.
        period_s: f64,
        /// Substeps a simulated second needs.
        per_second: f64,
    },
    /// The engine did something this crate did not expect, or was asked
    /// what it cannot do.
    #[error("physics engine: {0}")]
    Engine(#[from] EngineError),
    /// M(q) is singular at a joint: nothing it moves has inertia about its
    /// axis beyond what the joints before it account for.
    #[error(
        "physics engine: the joint-space inertia is singular at joint '{joint}' (q = {q:?}): nothing it moves has inertia about its axis that the joints before it do not already account for; give the links it moves inertia, add [plant] armature for it, or lock it in [plant.lock]"
    )]
    SingularInertia {
        /// The joint.
        joint: String,
        /// The posture.
        q: Vec<f64>,
    },
}
