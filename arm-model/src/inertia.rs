//! Mass properties: what a physical inertia is, and how two rigidly joined
//! links add up.

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion, Vector3};

use super::{LinkInfo, Origin};
use crate::ModelError;

/// A link lighter than this fraction of the heaviest moving link is
/// negligible: real URDFs use 1e-9 kg for frames that are not bodies.
pub(super) const NEGLIGIBLE_MASS_RATIO: f64 = 1e-6;

/// A link lighter than this fraction of the heaviest moving link whose
/// inertia is malformed is a placeholder, taken as massless (said) rather
/// than refused.
pub(super) const PLACEHOLDER_MASS_RATIO: f64 = 1e-2;

/// The rigid transform of a URDF `<origin>`.
pub fn iso(o: &Origin) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(o.xyz[0], o.xyz[1], o.xyz[2]),
        UnitQuaternion::from_euler_angles(o.rpy[0], o.rpy[1], o.rpy[2]),
    )
}

pub(super) fn origin_of(t: &Isometry3<f64>) -> Origin {
    let (r, p, y) = t.rotation.euler_angles();
    let v = t.translation.vector;
    Origin {
        xyz: [v.x, v.y, v.z],
        rpy: [r, p, y],
    }
}

pub(super) fn tensor(i: &[f64; 6]) -> Matrix3<f64> {
    let [ixx, ixy, ixz, iyy, iyz, izz] = *i;
    Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz)
}

/// The tensor about the COM in link axes, and the COM, of a link.
fn link_inertia(l: &LinkInfo) -> (Matrix3<f64>, Vector3<f64>) {
    let t = iso(&l.inertial_origin);
    let r = t.rotation.to_rotation_matrix();
    (
        r.matrix() * tensor(&l.inertia) * r.matrix().transpose(),
        t.translation.vector,
    )
}

/// Adds `child`, placed at `t` in `parent`'s frame, to `parent`'s mass properties.
pub(super) fn merge_mass(parent: &mut LinkInfo, child: &LinkInfo, t: &Isometry3<f64>) {
    let m = parent.mass + child.mass;
    if child.mass == 0.0 || m == 0.0 {
        return;
    }
    let (ip, cp) = link_inertia(parent);
    let (ic, cc) = link_inertia(child);
    let r = t.rotation.to_rotation_matrix();
    let ic = r.matrix() * ic * r.matrix().transpose();
    let cc = t * Point3::from(cc);
    let c = (parent.mass * cp + child.mass * cc.coords) / m;
    // Parallel-axis theorem for each part about the combined COM.
    let shift =
        |mass: f64, d: Vector3<f64>| mass * (d.dot(&d) * Matrix3::identity() - d * d.transpose());
    let i = ip + shift(parent.mass, cp - c) + ic + shift(child.mass, cc.coords - c);
    parent.mass = m;
    parent.inertial_origin = Origin {
        xyz: [c.x, c.y, c.z],
        rpy: [0.0; 3],
    };
    parent.inertia = [
        i[(0, 0)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 1)],
        i[(1, 2)],
        i[(2, 2)],
    ];
}

/// How far published files break the triangle inequality (relative to the
/// largest moment) from rounding alone: a plain note. Beyond it no rigid
/// body has the tensor, and the note says so.
const TRIANGLE_SLACK: f64 = 0.25;

/// What a positive semi-definite tensor is.
#[derive(Debug, PartialEq)]
pub(super) enum Tensor {
    /// A rigid body's, or near enough (the note, if any, says how near).
    Fine(Option<String>),
    /// No rigid body's (the triangle inequality broken beyond rounding),
    /// yet it simulates: M stays positive semi-definite. The reason.
    Impossible(String),
}

/// Principal moments below this (kg m²) are zero to rounding.
const POINT_MASS_MOMENT: f64 = 1e-12;

/// A physical inertia tensor is positive semi-definite (a point mass or a
/// thin rod has zero moments) and its principal moments obey the triangle
/// inequality. Only the first is required to simulate: a tensor that is
/// not positive semi-definite is refused; one that breaks the inequality
/// simulates, with a note (up to 25 % is rounding in published files;
/// beyond, it is [`Tensor::Impossible`]).
pub(super) fn check_inertia(link: &str, i: &[f64; 6]) -> Result<Tensor, ModelError> {
    let bad = |reason: String| {
        Err(ModelError::BadInertia {
            link: link.to_string(),
            reason,
        })
    };
    let mut ev: Vec<f64> = tensor(i).symmetric_eigenvalues().iter().copied().collect();
    ev.sort_by(f64::total_cmp);
    // Moments this small (a 1 g body 30 µm across) are rounding, not a
    // shape: such a link is a point mass, whatever the signs.
    if ev.iter().all(|e| e.abs() <= POINT_MASS_MOMENT) {
        let zero = ev.iter().any(|e| *e != 0.0);
        return Ok(Tensor::Fine(zero.then(|| {
            format!(
                "link '{link}': principal moments {:.3e}, {:.3e}, {:.3e} are zero to rounding: \
                 taken as a point mass",
                ev[0], ev[1], ev[2]
            )
        })));
    }
    let scale = ev[2].abs().max(f64::MIN_POSITIVE);
    if ev[0] < -1e-9 * scale {
        return bad(format!(
            "the inertia tensor is not positive semi-definite (principal moments {:.3e}, {:.3e}, {:.3e}): correct the tensor (its diagonal, and off-diagonal terms smaller than the moments they join)",
            ev[0], ev[1], ev[2]
        ));
    }
    let short = (ev[2] - ev[0] - ev[1]) / scale;
    if short > TRIANGLE_SLACK {
        return Ok(Tensor::Impossible(format!(
            "principal moments {:.3e}, {:.3e}, {:.3e} break the triangle inequality by {:.0} % of the largest (no rigid body has them; MuJoCo and Drake refuse such a tensor)",
            ev[0],
            ev[1],
            ev[2],
            100.0 * short
        )));
    }
    Ok(Tensor::Fine((short > 1e-6).then(|| {
        format!(
            "link '{link}': principal moments {:.3e}, {:.3e}, {:.3e} break the triangle inequality by {:.2} % of the largest; simulated as given",
            ev[0],
            ev[1],
            ev[2],
            100.0 * short
        )
    })))
}

/// How many times the arm's size a link's radius of gyration may be before
/// its tensor is no body of that link's: a link lies within the arm.
const GYRATION_PER_SIZE: f64 = 10.0;

/// The arm's size for [`implausible_gyration`], m: the offsets of the
/// joints that move something added up (no two points of what moves are
/// further apart), at least 1 m.
pub(super) fn arm_size(offsets: impl Iterator<Item = [f64; 3]>) -> f64 {
    offsets
        .map(|[x, y, z]| (x * x + y * y + z * z).sqrt())
        .sum::<f64>()
        .max(1.0)
}

/// A tensor whose radius of gyration √(I_max/m) is more than ten times the
/// arm's `size` is no body of that arm (a 1e-5 kg finger given the
/// identity tensor, 1 kg m², turns like a body 300 m across): the reason,
/// if so.
pub(super) fn implausible_gyration(mass: f64, i: &[f64; 6], size: f64) -> Option<String> {
    let largest = tensor(i).symmetric_eigenvalues().max();
    let radius = (largest / mass).sqrt();
    (mass > 0.0 && radius > GYRATION_PER_SIZE * size).then(|| {
        format!(
            "its largest principal moment {largest:.3e} kg m² on {mass:e} kg is a radius of gyration of {radius:.3e} m, over {GYRATION_PER_SIZE} times the arm's size of {size:.3} m (the offsets of its moving links' joints added up, at least 1 m): no part of this arm turns like that"
        )
    })
}
