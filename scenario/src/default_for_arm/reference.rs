//! The default reference and envelope of each joint: a sinusoid about the
//! middle of its range, an envelope that fits it.

use plant_rapier::{ArmModel, JointKind};
use trajectory::{Signal, Sinusoid};

/// The widest envelope offset a joint may be given: 1 rad, or 0.3 of
/// its half range.
pub(super) fn kc_cap(model: &ArmModel) -> Vec<f64> {
    model
        .actuated
        .iter()
        .map(|&ji| {
            let half = model.joints[ji]
                .limits
                .map_or(f64::INFINITY, |(lo, hi)| 0.5 * (hi - lo));
            match model.joints[ji].kind {
                JointKind::Prismatic => (0.15 * half).min(PRISMATIC_KC_CAP_M),
                _ => (0.3 * half).min(1.0),
            }
        })
        .collect()
}

/// The largest reference amplitude of a prismatic joint, m: a mobile
/// base's ±1000 m rail is not swung over 300 m.
const PRISMATIC_AMPLITUDE_M: f64 = 0.25;
/// The default envelope of a prismatic joint at most, m.
const PRISMATIC_KC_M: f64 = 0.05;
/// The widest envelope a prismatic joint may be given, m.
const PRISMATIC_KC_CAP_M: f64 = 0.15;

/// A joint's reference amplitude and default envelope offset.
fn swing(kind: JointKind, half: f64) -> (f64, f64) {
    match kind {
        JointKind::Prismatic => (
            (0.3 * half).min(PRISMATIC_AMPLITUDE_M),
            (0.15 * half).min(PRISMATIC_KC_M),
        ),
        _ => ((0.3 * half).min(0.5), 0.25f64.min(0.3 * half)),
    }
}

/// The arm's start when the file names one (an MJCF keyframe `home`),
/// inside each joint's limits as the default start is.
pub(super) fn home_start(model: &ArmModel) -> Option<Vec<f64>> {
    let home = model.home.as_ref().filter(|h| h.len() == model.dof())?;
    Some(
        model
            .actuated
            .iter()
            .zip(home)
            .map(|(&ji, &q)| match model.joints[ji].limits {
                Some((lo, hi)) => {
                    let pad = 0.02 * (hi - lo);
                    q.clamp(lo + pad, hi - pad)
                }
                None => q,
            })
            .collect(),
    )
}

/// The reference offsets that put `start` where the default start would
/// be: 1.5 default envelopes from the reference's first sample, so that
/// an arm starting at its home pose still starts outside the envelope.
/// Each stays within 0.6 of the half range of the middle, as the posture
/// search's offsets do.
pub(super) fn offsets_for_start(
    model: &ArmModel,
    start: &[f64],
    amplitude: &[(String, f64)],
) -> Vec<f64> {
    model
        .actuated
        .iter()
        .enumerate()
        .map(|(i, &ji)| {
            let j = &model.joints[ji];
            let half = j.limits.map_or(f64::INFINITY, |(lo, hi)| 0.5 * (hi - lo));
            let (amp, kc) = swing(j.kind, half);
            let factor = amplitude
                .iter()
                .find(|(n, _)| *n == j.name)
                .map_or(1.0, |a| a.1);
            let first = if i % 2 == 0 { 0.0 } else { amp * factor };
            let centre = start[i] - first - 1.5 * kc;
            match j.limits {
                Some((lo, hi)) => {
                    let mid = 0.5 * (lo + hi);
                    centre.clamp(mid - 0.6 * half, mid + 0.6 * half)
                }
                None => centre,
            }
        })
        .collect()
}

/// Per joint: the reference about `offsets`, its amplitude times the
/// joint's factor in `amplitude` (by name; 1 if absent), the envelope
/// (offset `kc` when given), and the initial position.
pub(super) fn shape(
    model: &ArmModel,
    offsets: &[f64],
    amplitude: &[(String, f64)],
    kc: Option<&[f64]>,
) -> (Vec<Signal>, Vec<Signal>, Vec<f64>) {
    let (mut reference, mut envelope, mut q0) = (Vec::new(), Vec::new(), Vec::new());
    for (i, &ji) in model.actuated.iter().enumerate() {
        let j = &model.joints[ji];
        let half = j.limits.map_or(f64::INFINITY, |(lo, hi)| 0.5 * (hi - lo));
        let center = offsets[i];
        let (amp, kc_default) = swing(j.kind, half);
        let factor = amplitude
            .iter()
            .find(|(n, _)| *n == j.name)
            .map_or(1.0, |a| a.1);
        let amp = amp * factor;
        let kc = kc.map_or(kc_default, |k| k[i]);
        let omega = 0.8 + 0.2 * (i % 3) as f64;
        // Alternate sin and cos so the joints do not all start at rest.
        let (sin, cos) = if i % 2 == 0 { (amp, 0.0) } else { (0.0, amp) };
        let r = Sinusoid {
            offset: center,
            sin,
            cos,
            omega,
        };
        let e = Sinusoid {
            offset: kc,
            sin: 0.2 * kc,
            cos: 0.0,
            omega: 0.5,
        };
        // Start 1.5 envelopes away from the reference: outside the bound,
        // inside the joint limits.
        let mut q = r.eval(0.0)[0] + 1.5 * e.eval(0.0)[0];
        if let Some((lo, hi)) = j.limits {
            let pad = 0.02 * (hi - lo);
            q = q.clamp(lo + pad, hi - pad);
        }
        reference.push(r.into());
        envelope.push(e.into());
        q0.push(q);
    }
    (reference, envelope, q0)
}
