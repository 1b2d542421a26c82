//! Every law behind one step interface: the machine, `sim`, the node and
//! `compare` hold a [`Law`] and do not care which one it is.

use arm_model::ArmModel;

use crate::feedback::Feedback;
use crate::law_table::LawKind;
use crate::ppc::Ppc;
use crate::{Controller, ControllerError, ControllerInput, ControllerParams, Diagnostics};

/// One of the laws of BASELINES.md, ready to step.
#[derive(Debug)]
pub enum Law {
    /// `nac`, its ablations and `blf`: the paper's law with parts switched off.
    Nac(Box<Controller>),
    /// `pd`, `pd-gravity`, `ctc`.
    Feedback(Box<Feedback>),
    /// `ppc`.
    Ppc(Ppc),
}

impl Law {
    /// The law `params.law` for `dof` joints; `model` is the arm's, needed by
    /// the model-based laws only (and ignored by the others).
    pub fn new(
        params: &ControllerParams,
        dof: usize,
        model: Option<&ArmModel>,
    ) -> Result<Self, ControllerError> {
        params.validate()?;
        if dof == 0 {
            return Err(ControllerError::NoJoints);
        }
        Ok(match params.law.kind() {
            LawKind::Barrier(_) => Law::Nac(Box::new(Controller::new(params.clone(), dof)?)),
            LawKind::Feedback(kind) => {
                Law::Feedback(Box::new(Feedback::new(params, kind, dof, model)?))
            }
            LawKind::Ppc => Law::Ppc(Ppc::new(params, dof)?),
        })
    }

    /// One control step over `dt` seconds (SPEC §10 faults for every law).
    pub fn step(&mut self, dt: f64, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        match self {
            Law::Nac(c) => c.step(dt, input, out),
            Law::Feedback(f) => f.step(input, out),
            Law::Ppc(p) => p.step(input, out),
        }
    }
}
