//! The paper's reinforcement-learning neuroadaptive controller under deferred
//! constraints, as pure math (SPEC §3–§12), and the laws it is compared with
//! (BASELINES.md): its ablations, the classic barrier law, PD, PD with
//! gravity, computed torque and prescribed performance control.
//!
//! Where it sits: between the plant's joint states and its commands. Each
//! law's step ([`Controller::step`] for the paper's, [`Law::step`] for any)
//! is pure: no clock, no I/O, no IPC; the same inputs give the same outputs
//! bit for bit, which is what makes lockstep runs and replays exact. The
//! model-based laws (`pd-gravity`, `ctc`) evaluate the arm's URDF model with
//! `arm_model::dynamics`, never the plant's engine. [`ControllerMachine`]
//! is the step machine in wire
//! messages (state + reference → command + diagnostics) that the controller
//! node ([`node`]), `testbed sim` and `replay --verify` all drive; the node
//! module is the thin shell that puts it on the bus.
//!
//! ```
//! use controller::{Controller, ControllerInput, ControllerParams};
//! let mut c = Controller::new(ControllerParams::default(), 2).unwrap();
//! let mut diag = c.diagnostics();
//! let input = ControllerInput {
//!     t: 0.0, q: &[0.6, 1.8], qd: &[0.0, 0.0],
//!     q_d: &[0.0, 1.0], qd_d: &[2.0, 0.0], qdd_d: &[0.0, -1.0],
//!     kc: &[0.5, 0.55], kc_dot: &[0.05, 0.0],
//! };
//! c.step(1e-3, &input, &mut diag);
//! assert!(diag.tau.iter().all(|t| t.is_finite()));
//! assert!(diag.fault.is_none());
//! ```
//!
//! Limitations: by default the RBF centres lie on the diagonal of the input
//! space, as in the paper (SPEC §8); with them the actor's contribution
//! stays small and the loop behaves as feedback plus barrier. The
//! `per-input` layout ([`RbfLayout`]) covers each input's range instead.

mod dispatch;
mod feedback;
mod gain;
mod law_table;
mod machine;
mod mpc;
mod mpc_polish;
mod nac;
pub mod node;
mod params;
mod params_reference;
mod ppc;
mod rbf;
mod search_range;
mod search_space;
mod shifting;
mod torque_box;
mod weight_update;

pub use dispatch::Law;
pub use feedback::{Feedback, effective_inertia};
pub use gain::Gain;
pub use law_table::{BarrierParts, FeedbackKind, LawDecl, LawKind, LawName};
pub use machine::{ControllerMachine, ControllerMachineConfig};
pub use nac::{Controller, ControllerInput, barrier_lyapunov};
pub use params::{
    BarrierMode, Check, ControllerParams, Integrator, MAX_GAIN, MAX_MPC_HORIZON, MAX_NEURONS,
    MAX_TC_S, ParamDoc, RbfLayout, Tuning,
};
pub use params_reference::reference_markdown;
pub use ppc::{Ppc, XI_LIMIT};
pub use rbf::Rbf;
pub use search_range::{GAIN_SCALE, Range, Role, SearchDim};
pub use search_space::search_space;
pub use shifting::shifting;
pub use weight_update::{advance_euler, advance_exact};

/// Why a controller cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ControllerError {
    /// A parameter is out of range or not a number.
    #[error("{key} = {value} is invalid: it must be {need}")]
    InvalidParameter {
        /// The scenario key, e.g. `controller.beta`.
        key: String,
        /// The value given.
        value: String,
        /// What it must be.
        need: String,
    },
    /// Zero joints.
    #[error("the controller needs at least one joint")]
    NoJoints,
    /// More joints than the wire's messages carry.
    #[error(
        "the controller was given {0} joints; the wire carries at most {max} (lock the others in [plant.lock])",
        max = wire::MAX_DOF
    )]
    TooManyJoints(usize),
    /// A key set that the chosen law does not take.
    #[error("{key} is not a parameter of law '{law}' (it takes {takes})")]
    NotAParameter {
        /// The scenario key, e.g. `controller.beta`.
        key: String,
        /// The chosen law.
        law: LawName,
        /// The keys the law takes.
        takes: String,
    },
    /// A model-based law was built without the arm's model.
    #[error("law '{0}' is model-based and needs the arm's URDF model")]
    NeedsModel(LawName),
}

/// Why a step published zero torque (SPEC §10): its codes are part of
/// the wire contract.
pub use wire::Fault;

/// Everything the controller publishes each step (SPEC §12), except compute
/// time, which the process shell measures. Per-joint vectors have length n.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostics {
    /// Sim time of the joint state acted on, s.
    pub t: f64,
    /// γ(t).
    pub gamma: f64,
    /// γ̇(t).
    pub gamma_dot: f64,
    /// Z1 = q − q_d.
    pub z1: Vec<f64>,
    /// Z1γ = γ Z1.
    pub z1g: Vec<f64>,
    /// Z2 = q̇ − α.
    pub z2: Vec<f64>,
    /// Virtual control α.
    pub alpha: Vec<f64>,
    /// The bound each joint's barrier used (k_c,i, or min_i k_c,i in norm mode).
    pub kc: Vec<f64>,
    /// D before the guard's clamp (negative once the error leaves the envelope).
    pub d: Vec<f64>,
    /// Torque τ = actor + feedback + barrier (zero on a fault).
    pub tau: Vec<f64>,
    /// Actor term (Ŵ_aᵀ S_a)_i.
    pub tau_actor: Vec<f64>,
    /// Feedback term (−K2 Z2_i for the paper's law).
    pub tau_feedback: Vec<f64>,
    /// Barrier term −γ Z1γ_i / (β D_i).
    pub tau_barrier: Vec<f64>,
    /// Model term of a model-based law (zero for the others).
    pub tau_model: Vec<f64>,
    /// Critic value Ĵ = Ŵ_cᵀ S_c.
    pub j_hat: f64,
    /// TD error δ.
    pub delta: f64,
    /// Instantaneous cost r.
    pub r: f64,
    /// ‖Ŵ_a‖ per joint (column norm) before this step's update.
    pub wa_norm: Vec<f64>,
    /// ‖Ŵ_c‖ before this step's update.
    pub wc_norm: f64,
    /// The guard clamped D this step.
    pub barrier_breached: bool,
    /// Set when the step published zero torque.
    pub fault: Option<Fault>,
}

impl Diagnostics {
    /// A zeroed buffer for `n` joints.
    pub fn new(n: usize) -> Self {
        let z = || vec![0.0; n];
        Self {
            t: 0.0,
            gamma: 0.0,
            gamma_dot: 0.0,
            z1: z(),
            z1g: z(),
            z2: z(),
            alpha: z(),
            kc: z(),
            d: z(),
            tau: z(),
            tau_actor: z(),
            tau_feedback: z(),
            tau_barrier: z(),
            tau_model: z(),
            j_hat: 0.0,
            delta: 0.0,
            r: 0.0,
            wa_norm: z(),
            wc_norm: 0.0,
            barrier_breached: false,
            fault: None,
        }
    }
}
