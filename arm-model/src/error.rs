//! Why a URDF cannot be read into an [`ArmModel`](crate::ArmModel).

/// What is wrong with a URDF or a lock. Each variant names the element.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ModelError {
    /// The text is not a URDF document.
    #[error("not a valid URDF: {0}")]
    Parse(String),
    /// Two links or two joints share a name.
    #[error("two {what}s are named '{name}'")]
    Duplicate {
        /// "link" or "joint".
        what: &'static str,
        /// The shared name.
        name: String,
    },
    /// No `<link>` at all.
    #[error("the URDF has no links")]
    NoLinks,
    /// A file that is XML but not a robot description.
    #[error(
        "the file's root element is <{root}>, not <robot> (URDF) or <mujoco> (MJCF): not a robot description"
    )]
    NotARobot {
        /// The root element's name (cut to 80 characters).
        root: String,
    },
    /// A file that is not XML at all.
    #[error("not XML: {what}")]
    NotXml {
        /// What its first line is instead.
        what: String,
    },
    /// A joint names a link that does not exist.
    #[error("joint '{joint}': {role} link '{link}' does not exist")]
    MissingLink {
        /// The joint.
        joint: String,
        /// "parent" or "child".
        role: &'static str,
        /// The missing link name.
        link: String,
    },
    /// A link is the child of two joints.
    #[error("link '{link}' is the child of two joints, '{first}' and '{second}'")]
    TwoParents {
        /// The link.
        link: String,
        /// First joint.
        first: String,
        /// Second joint.
        second: String,
    },
    /// Every link has a parent: the joints form a loop.
    #[error("the URDF has no root link (every link is some joint's child): the joints form a loop")]
    NoRoot,
    /// More than one link has no parent.
    #[error("the URDF has several root links ({}); an arm needs exactly one", .0.join(", "))]
    ManyRoots(Vec<String>),
    /// A link cannot be reached from the root.
    #[error("link '{link}' is on a loop of joints and cannot be reached from the root")]
    Cycle {
        /// A link on the loop.
        link: String,
    },
    /// A joint kind the plant cannot simulate.
    #[error(
        "joint '{joint}' is {kind}; only revolute, continuous, prismatic and fixed joints are supported"
    )]
    UnsupportedJoint {
        /// The joint.
        joint: String,
        /// Its kind.
        kind: String,
    },
    /// A `<mimic>` that cannot be simulated.
    #[error("joint '{joint}' has <mimic>: {reason}")]
    Mimic {
        /// The joint.
        joint: String,
        /// What is wrong with it.
        reason: String,
    },
    /// An actuated joint with a zero axis.
    #[error(
        "joint '{joint}' has a zero-length axis (or an <axis> without xyz): a moving joint needs one"
    )]
    ZeroAxis {
        /// The joint.
        joint: String,
    },
    /// Lower limit above upper.
    #[error("joint '{joint}': limit lower {lower} is above upper {upper}")]
    BadLimits {
        /// The joint.
        joint: String,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
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
    /// The text is MJCF that the parser cannot read (an include not
    /// found, an unknown default class, malformed XML).
    #[error("not a valid MJCF: {0}")]
    MjcfParse(String),
    /// An MJCF `<include>` that is not read (outside the model's folder,
    /// not a regular file, not MJCF, over a cap): the include and the path
    /// are named, never what the file holds.
    #[error("MJCF {include} ({path}) is not included: {reason}")]
    MjcfInclude {
        /// The include tag as written (cut to 200 characters).
        include: String,
        /// The file it names, and where a symlink or `..` leads.
        path: String,
        /// Why it is not read.
        reason: String,
    },
    /// An MJCF element the testbed cannot simulate, named.
    #[error("MJCF {element}: {reason}")]
    MjcfRefused {
        /// The element, e.g. `<joint name='free'>` in `<body name='base'>`.
        element: String,
        /// Why it is refused and what to do.
        reason: String,
    },
    /// A setting out of range (a lock, say).
    #[error("{key} = {value} is invalid: it must be {need}")]
    InvalidConfig {
        /// The scenario key.
        key: String,
        /// The value.
        value: String,
        /// What it must be.
        need: String,
    },
    /// A document over [`MAX_URDF_BYTES`](crate::MAX_URDF_BYTES).
    #[error(
        "the robot file is {bytes} bytes, over the cap of {cap} bytes (a robot's URDF is tens of \
         kilobytes; meshes belong in their own files)"
    )]
    TooLarge {
        /// Its size.
        bytes: usize,
        /// The cap.
        cap: usize,
    },
    /// A tag with more than [`MAX_ATTRIBUTES`](crate::MAX_ATTRIBUTES) attributes.
    #[error(
        "line {line}: <{element}> has {count} attributes or more, over the cap of {cap} \
         (a URDF or MJCF element has a handful)"
    )]
    TooManyAttributes {
        /// The element's name (cut to 80 characters).
        element: String,
        /// Its line, from 1.
        line: usize,
        /// How many attributes were counted before stopping.
        count: usize,
        /// The cap.
        cap: usize,
    },
}
