//! URDF elements into the model's plain types: numbers checked for being
//! numbers, names resolved; no physics judged yet.

use std::collections::HashMap;

use super::{JointInfo, JointKind, LinkInfo, MimicSpec, Origin};
use crate::ModelError;

fn finite(field: String, v: f64) -> Result<f64, ModelError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ModelError::NotFinite { field, value: v })
    }
}

/// No robot is larger (m) or heavier (kg), nor turns like a body of more
/// (kg m²): beyond these a URDF is in the wrong units or broken, and the
/// arm's dynamics would overflow (a 1e308 kg link makes K2 infinite).
const MAX_OFFSET_M: f64 = 1e4;
const MAX_MASS_KG: f64 = 1e6;
const MAX_MOMENT: f64 = 1e8;

/// `v` if it is finite and at most `max` in size; else what is wrong.
fn bounded(field: String, v: f64, max: f64, unit: &str) -> Result<f64, ModelError> {
    let v = finite(field.clone(), v)?;
    if v.abs() > max {
        return Err(ModelError::InvalidConfig {
            key: field,
            value: format!("{v:e}"),
            need: format!("at most {max:e} {unit} in size: no robot's is larger (check the units)"),
        });
    }
    Ok(v)
}

fn origin(field: &str, o: &urdf_rs::Pose) -> Result<Origin, ModelError> {
    let mut out = Origin::default();
    for k in 0..3 {
        out.xyz[k] = bounded(format!("{field} origin xyz"), o.xyz.0[k], MAX_OFFSET_M, "m")?;
        out.rpy[k] = finite(format!("{field} origin rpy"), o.rpy.0[k])?;
    }
    Ok(out)
}

/// A link's mass properties as written; only a negative mass is refused
/// here (what a link of no mass lists is judged later).
pub(super) fn link_info(l: &urdf_rs::Link) -> Result<LinkInfo, ModelError> {
    let field = format!("link '{}'", l.name);
    let mass = bounded(
        format!("{field} mass"),
        l.inertial.mass.value,
        MAX_MASS_KG,
        "kg",
    )?;
    if mass < 0.0 {
        return Err(ModelError::BadInertia {
            link: l.name.clone(),
            reason: format!("mass {mass} is negative"),
        });
    }
    let i = &l.inertial.inertia;
    let inertia = [i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz];
    for v in inertia {
        bounded(format!("{field} inertia"), v, MAX_MOMENT, "kg m²")?;
    }
    let c = super::collision::collisions(l, |o| origin(&field, o).ok());
    Ok(LinkInfo {
        name: l.name.clone(),
        mass,
        inertial_origin: origin(&format!("{field} inertial"), &l.inertial.origin)?,
        inertia,
        collisions: c.shapes,
        skipped_collisions: c.meshes,
        bad_collisions: c.bad,
    })
}

fn kind_of(j: &urdf_rs::Joint) -> Result<JointKind, ModelError> {
    use urdf_rs::JointType as T;
    match j.joint_type {
        T::Revolute => Ok(JointKind::Revolute),
        T::Continuous => Ok(JointKind::Continuous),
        T::Prismatic => Ok(JointKind::Prismatic),
        T::Fixed => Ok(JointKind::Fixed),
        T::Floating | T::Planar | T::Spherical => Err(ModelError::UnsupportedJoint {
            joint: j.name.clone(),
            kind: format!("{:?}", j.joint_type).to_lowercase(),
        }),
    }
}

fn mimic(j: &urdf_rs::Joint, field: &str) -> Result<Option<MimicSpec>, ModelError> {
    let Some(m) = &j.mimic else {
        return Ok(None);
    };
    Ok(Some(MimicSpec {
        joint: m.joint.clone(),
        multiplier: finite(
            format!("{field} mimic multiplier"),
            m.multiplier.unwrap_or(1.0),
        )?,
        offset: finite(format!("{field} mimic offset"), m.offset.unwrap_or(0.0))?,
    }))
}

/// A joint with its links resolved and its numbers checked.
pub(super) fn joint_info(
    j: &urdf_rs::Joint,
    index: &HashMap<String, usize>,
) -> Result<JointInfo, ModelError> {
    let kind = kind_of(j)?;
    let link = |name: &str, role: &'static str| {
        index
            .get(name)
            .copied()
            .ok_or_else(|| ModelError::MissingLink {
                joint: j.name.clone(),
                role,
                link: name.to_string(),
            })
    };
    let parent = link(&j.parent.link, "parent")?;
    let child = link(&j.child.link, "child")?;
    if parent == child {
        return Err(ModelError::Cycle {
            link: j.child.link.clone(),
        });
    }
    let field = format!("joint '{}'", j.name);
    let mut axis = [0.0; 3];
    for (k, a) in axis.iter_mut().enumerate() {
        *a = finite(format!("{field} axis"), j.axis.xyz.0[k])?;
    }
    let norm = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
    if kind.is_actuated() {
        if norm < 1e-9 {
            return Err(ModelError::ZeroAxis {
                joint: j.name.clone(),
            });
        }
        axis.iter_mut().for_each(|a| *a /= norm);
    }
    let limits = limits(j, kind, &field)?;
    let effort = finite(format!("{field} limit effort"), j.limit.effort)?;
    // −1 is SDF's (and Gazebo's) "no limit"; files converted from it keep it.
    let effort = if effort == UNLIMITED_EFFORT {
        0.0
    } else {
        effort
    };
    if effort < 0.0 {
        return Err(ModelError::InvalidConfig {
            key: format!("{field} limit effort"),
            value: effort.to_string(),
            need: "≥ 0 (0 or absent: no effort limit)".into(),
        });
    }
    let (damping, friction) = dynamics(j, &field)?;
    Ok(JointInfo {
        name: j.name.clone(),
        kind,
        parent,
        child,
        origin: origin(&field, &j.origin)?,
        axis,
        limits,
        effort: (kind.is_actuated() && effort > 0.0).then_some(effort),
        damping,
        friction,
        mimic: if kind.is_actuated() {
            mimic(j, &field)?
        } else {
            None
        },
        armature: 0.0,
    })
}

/// The effort SDF writes for "no limit" (read as none, and said).
pub(super) const UNLIMITED_EFFORT: f64 = -1.0;

/// Position limits of a revolute or prismatic joint.
fn limits(
    j: &urdf_rs::Joint,
    kind: JointKind,
    field: &str,
) -> Result<Option<(f64, f64)>, ModelError> {
    let lower = finite(format!("{field} limit lower"), j.limit.lower)?;
    let upper = finite(format!("{field} limit upper"), j.limit.upper)?;
    // A revolute joint without a usable <limit> (lower = upper, as urdf-rs
    // fills a missing one) turns freely rather than being locked. A sliding
    // one has no scale to choose a posture or an envelope from, and URDF
    // requires the limit: refused.
    if kind == JointKind::Prismatic && lower == upper {
        return Err(ModelError::InvalidConfig {
            key: format!("{field} <limit>"),
            value: format!("lower = upper = {lower}"),
            need: "lower < upper (URDF requires a <limit> on a prismatic joint)".into(),
        });
    }
    Ok(match kind {
        JointKind::Revolute | JointKind::Prismatic if lower < upper => Some((lower, upper)),
        JointKind::Revolute | JointKind::Prismatic if lower > upper => {
            return Err(ModelError::BadLimits {
                joint: j.name.clone(),
                lower,
                upper,
            });
        }
        _ => None,
    })
}

/// `<dynamics damping friction>`, both ≥ 0 (zero when absent).
fn dynamics(j: &urdf_rs::Joint, field: &str) -> Result<(f64, f64), ModelError> {
    let (damping, friction) = match &j.dynamics {
        Some(d) => (
            finite(format!("{field} dynamics damping"), d.damping)?,
            finite(format!("{field} dynamics friction"), d.friction)?,
        ),
        None => (0.0, 0.0),
    };
    for (what, v) in [("damping", damping), ("friction", friction)] {
        if v < 0.0 {
            return Err(ModelError::InvalidConfig {
                key: format!("{field} dynamics {what}"),
                value: v.to_string(),
                need: "≥ 0".into(),
            });
        }
    }
    Ok((damping, friction))
}
