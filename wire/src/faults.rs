//! Why a controller published zero torque: the codes `Command::fault`
//! and `ControllerDiagnostics::fault` carry (0: none).

/// Why a step published zero torque instead of the law's output (SPEC §10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// A state or reference value was NaN or infinite.
    NonFiniteInput,
    /// An input slice did not have one entry per joint.
    WrongLength,
    /// The envelope k_c was zero or negative.
    EnvelopeNotPositive,
    /// The law produced a NaN or infinite value.
    NonFiniteOutput,
    /// The process shell had no reference sample to give (real time, before
    /// the trajectory's first sample arrived).
    NoReference,
}

impl Fault {
    /// Every fault.
    pub const ALL: [Fault; 5] = [
        Fault::NonFiniteInput,
        Fault::WrongLength,
        Fault::EnvelopeNotPositive,
        Fault::NonFiniteOutput,
        Fault::NoReference,
    ];

    /// The name other languages' bindings give it (`NON_FINITE_INPUT`).
    pub fn constant_name(self) -> &'static str {
        match self {
            Fault::NonFiniteInput => "NON_FINITE_INPUT",
            Fault::WrongLength => "WRONG_LENGTH",
            Fault::EnvelopeNotPositive => "ENVELOPE_NOT_POSITIVE",
            Fault::NonFiniteOutput => "NON_FINITE_OUTPUT",
            Fault::NoReference => "NO_REFERENCE",
        }
    }

    /// A stable numeric code for the wire and logs (0 means no fault).
    pub fn code(self) -> u32 {
        match self {
            Fault::NonFiniteInput => 1,
            Fault::WrongLength => 2,
            Fault::EnvelopeNotPositive => 3,
            Fault::NonFiniteOutput => 4,
            Fault::NoReference => 5,
        }
    }
}
