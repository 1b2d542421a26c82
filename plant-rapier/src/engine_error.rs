//! What the physics engine did that this crate did not expect, or asked of
//! an engine that cannot do it: each case as data, so a caller can tell
//! them apart without reading a message.

/// An engine failure ([`crate::PlantError::Engine`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EngineError {
    /// A joint the URDF names is missing from Rapier's multibody.
    #[error("joint '{joint}' is not in the multibody")]
    JointNotInMultibody {
        /// The joint's name.
        joint: String,
    },
    /// Rapier's multibody was gone from its set (`when`: at which stage).
    #[error("the multibody vanished {when}")]
    MultibodyVanished {
        /// The stage that looked for it.
        when: &'static str,
    },
    /// A joint has no child link body.
    #[error("no link for joint '{joint}'")]
    NoLinkForJoint {
        /// The joint's name.
        joint: String,
    },
    /// Rapier would not insert a joint into the multibody.
    #[error("Rapier refused joint '{joint}'")]
    JointRefused {
        /// The joint's name.
        joint: String,
    },
    /// The multibody's degrees of freedom differ from the model's.
    #[error("the multibody has {multibody} degrees of freedom but the URDF {model} moving joints")]
    DofMismatch {
        /// Rapier's count.
        multibody: usize,
        /// The model's moving joints.
        model: usize,
    },
    /// A contact object or the link holding it has no body.
    #[error("object {index} or its link vanished")]
    ObjectVanished {
        /// The object's index in `[[plant.contact.object]]`.
        index: usize,
    },
    /// A link index past the arm's links.
    #[error("no link with index {link}")]
    NoLink {
        /// The index asked for.
        link: usize,
    },
    /// A link without a rigid body.
    #[error("link {link} has no body")]
    LinkWithoutBody {
        /// The link's index.
        link: usize,
    },
    /// Contact objects were asked of a plant without `[plant.contact]`
    /// objects, or of the articulated engine, which has no contact.
    #[error("the {engine} engine has no contact objects here")]
    NoContactObjects {
        /// "Rapier" or "articulated".
        engine: &'static str,
    },
    /// M(q) and h(q, q̇) were asked of the Rapier engine.
    #[error("the Rapier engine does not give M(q) and h(q, q̇); use the articulated engine")]
    NoJointSpaceDynamics,
    /// M(q) at a probed pose cannot be inverted.
    #[error("probing M(q) at {q:?}: M(q) {what}")]
    Probe {
        /// The pose.
        q: Vec<f64>,
        /// What is wrong with it.
        what: &'static str,
    },
}
