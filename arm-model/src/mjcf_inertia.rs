//! A body's mass properties from its geoms, by MuJoCo's rule (the compiler's
//! `inertiafromgeom`): each primitive a solid of uniform density (1000
//! kg/m³ unless the geom gives `density` or `mass`), summed by the
//! parallel-axis theorem. Meshes would need the mesh: refused by name.

use mjcf_rs::body::{Geom, GeomType};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

use super::inertia::{merge_mass, origin_of};
use super::{LinkInfo, Origin};
use crate::ModelError;

/// MuJoCo's default geom density, kg/m³ (water).
const DEFAULT_DENSITY: f64 = 1000.0;

/// A geom's volume and principal moments per unit density, in its frame
/// (z along a capsule's or cylinder's axis), from its half-sizes.
fn unit_solid(kind: GeomType, s: [f64; 3]) -> Option<(f64, [f64; 3])> {
    use std::f64::consts::PI;
    let [a, b, c] = s;
    Some(match kind {
        GeomType::Sphere => {
            let v = 4.0 / 3.0 * PI * a.powi(3);
            let i = 0.4 * v * a * a;
            (v, [i, i, i])
        }
        GeomType::Capsule => {
            // A cylinder of length h plus two hemispheres, each hemisphere
            // moved from its own centre of mass (83/320 m r² about it) to
            // the capsule's: MuJoCo's closed form.
            let (r, h) = (a, 2.0 * b);
            let vc = PI * r * r * h;
            let vs = 4.0 / 3.0 * PI * r.powi(3);
            let side = vc * (r * r / 4.0 + h * h / 12.0)
                + vs * (0.4 * r * r + h * h / 4.0 + 3.0 * h * r / 8.0);
            (vc + vs, [side, side, vc * r * r / 2.0 + vs * 0.4 * r * r])
        }
        GeomType::Cylinder => {
            let (r, h) = (a, 2.0 * b);
            let v = PI * r * r * h;
            let side = v * (3.0 * r * r + h * h) / 12.0;
            (v, [side, side, v * r * r / 2.0])
        }
        GeomType::Box => {
            let v = 8.0 * a * b * c;
            (
                v,
                [
                    v * (b * b + c * c) / 3.0,
                    v * (a * a + c * c) / 3.0,
                    v * (a * a + b * b) / 3.0,
                ],
            )
        }
        GeomType::Ellipsoid => {
            let v = 4.0 / 3.0 * PI * a * b * c;
            (
                v,
                [
                    v * (b * b + c * c) / 5.0,
                    v * (a * a + c * c) / 5.0,
                    v * (a * a + b * b) / 5.0,
                ],
            )
        }
        _ => return None,
    })
}

/// The geom's frame in its body and its half-sizes, `fromto` applied: the
/// segment's midpoint, z along it, its half-length as the length size.
pub(super) fn placed(g: &Geom) -> (Isometry3<f64>, [f64; 3]) {
    let Some(ft) = g.fromto else {
        let (q, t) = (g.pose.rotation, g.pose.translation);
        let rot = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z));
        return (
            Isometry3::from_parts(Vector3::new(t.x, t.y, t.z).into(), rot),
            g.size,
        );
    };
    let (from, to) = (
        Vector3::new(ft[0], ft[1], ft[2]),
        Vector3::new(ft[3], ft[4], ft[5]),
    );
    let d = to - from;
    let rot = UnitQuaternion::rotation_between(&Vector3::z(), &d).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    });
    let mut size = g.size;
    // A box or ellipsoid keeps its x and y half-sizes; the others' radius
    // stays in size[0].
    let along = if matches!(g.type_, GeomType::Box | GeomType::Ellipsoid) {
        2
    } else {
        1
    };
    size[along] = d.norm() / 2.0;
    let mid = Point3::from((from + to) / 2.0);
    (Isometry3::from_parts(mid.coords.into(), rot), size)
}

/// `<compiler inertiagrouprange>`: the geom groups whose geoms weigh
/// something when a body's inertia comes from its geoms (MuJoCo's default
/// 0 5; the last compiler element that gives it wins, as MuJoCo merges them).
pub(super) fn group_range(whole: &str) -> Result<[i32; 2], ModelError> {
    let Some(value) = super::mjcf_include::tags(whole, "compiler")
        .filter_map(|t| super::mjcf_include::attribute(t, "inertiagrouprange"))
        .last()
    else {
        return Ok([0, 5]);
    };
    let bad = || {
        ModelError::MjcfParse(format!(
            "<compiler inertiagrouprange=\"{value}\">: need two integers, the first not above the second"
        ))
    };
    let parts: Vec<i32> = (value.split_whitespace())
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match parts[..] {
        [a, b] if a <= b => Ok([a, b]),
        _ => Err(bad()),
    }
}

/// How far past equality (relative to the largest moment) a tensor may
/// break the triangle inequality and still be taken: rounding of its
/// principal moments, not a tensor MuJoCo would refuse.
const TRIANGLE_ROUNDING: f64 = 1e-9;

/// An `<inertial>`'s tensor as MuJoCo's compiler takes it (#60 item 9):
/// its principal moments satisfy the triangle inequality A + B ≥ C, as
/// every rigid body's do, or the model is refused; with `<compiler
/// balanceinertia="true">` such a tensor becomes its mean moment about
/// every axis, as MuJoCo makes it, and a note says so. A tensor with a
/// negative moment is left to the common check, which names it as such.
pub(super) fn balanced(
    body: &str,
    t: [f64; 6],
    balance: bool,
) -> Result<([f64; 6], Option<String>), ModelError> {
    let mut ev: Vec<f64> = (super::inertia::tensor(&t).symmetric_eigenvalues().iter())
        .copied()
        .collect();
    ev.sort_by(f64::total_cmp);
    let broken = ev[0] >= 0.0 && ev[2] - ev[0] - ev[1] > TRIANGLE_ROUNDING * ev[2];
    if !broken {
        return Ok((t, None));
    }
    let moments = format!(
        "principal moments {:.3e}, {:.3e}, {:.3e}",
        ev[0], ev[1], ev[2]
    );
    if !balance {
        return Err(ModelError::MjcfRefused {
            element: format!("<inertial> in <body name='{body}'>"),
            reason: format!(
                "{moments} break the triangle inequality (A + B ≥ C): no rigid body has them, and MuJoCo refuses them (correct the tensor, or set <compiler balanceinertia=\"true\"> to have them averaged, as MuJoCo does)"
            ),
        });
    }
    let mean = (ev[0] + ev[1] + ev[2]) / 3.0;
    let note = format!(
        "<inertial> in <body name='{body}'>: {moments} break the triangle inequality; balanceinertia sets each to their mean {mean:.3e}, as MuJoCo does"
    );
    Ok(([mean, 0.0, 0.0, mean, 0.0, mean], Some(note)))
}

/// The name MuJoCo messages would give a geom: its name or its index.
fn geom_label(g: &Geom, i: usize) -> String {
    match &g.name {
        Some(n) => format!("<geom name='{n}'>"),
        None => format!("<geom> #{i}"),
    }
}

/// The mass properties of body `body` (in the body's frame) from its geoms.
pub(super) fn from_geoms(body: &str, geoms: &[Geom]) -> Result<LinkInfo, ModelError> {
    let mut sum = LinkInfo {
        name: body.to_string(),
        mass: 0.0,
        inertial_origin: Origin::default(),
        inertia: [0.0; 6],
        collisions: Vec::new(),
        skipped_collisions: Vec::new(),
        bad_collisions: Vec::new(),
    };
    for (i, g) in geoms.iter().enumerate() {
        let weighs = g.mass.is_some_and(|m| m > 0.0) || g.density.is_none_or(|d| d > 0.0);
        if !weighs || matches!(g.type_, GeomType::Plane | GeomType::Hfield) {
            continue;
        }
        let (pose, size) = placed(g);
        let Some((volume, moments)) = unit_solid(g.type_, size) else {
            return Err(ModelError::MjcfRefused {
                element: format!("{} in <body name='{body}'>", geom_label(g, i)),
                reason: format!(
                    "the body has no <inertial>, so MuJoCo would take its mass from this {} geom's volume, which the testbed does not compute; give the body an <inertial> (MuJoCo's compiled body_mass/body_inertia)",
                    format!("{:?}", g.type_).to_lowercase()
                ),
            });
        };
        let density = match g.mass {
            Some(m) if volume > 0.0 => m / volume,
            _ => g.density.unwrap_or(DEFAULT_DENSITY),
        };
        let part = LinkInfo {
            mass: density * volume,
            inertial_origin: origin_of(&pose),
            inertia: [
                density * moments[0],
                0.0,
                0.0,
                density * moments[1],
                0.0,
                density * moments[2],
            ],
            ..sum.clone()
        };
        merge_mass(&mut sum, &part, &Isometry3::identity());
    }
    Ok(sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geom(kind: GeomType, size: [f64; 3]) -> Geom {
        Geom {
            type_: kind,
            size,
            ..Geom::default()
        }
    }

    #[test]
    fn a_sphere_weighs_its_volume_of_water() {
        let l = from_geoms("b", &[geom(GeomType::Sphere, [0.1, 0.0, 0.0])]).unwrap();
        let m = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 1e-3;
        assert!((l.mass - m).abs() < 1e-12 * m);
        assert!((l.inertia[0] - 0.4 * m * 0.01).abs() < 1e-12);
    }

    #[test]
    fn a_capsule_lies_between_its_cylinder_and_its_bounding_cylinder() {
        let cap = from_geoms("b", &[geom(GeomType::Capsule, [0.05, 0.2, 0.0])]).unwrap();
        let cyl = from_geoms("b", &[geom(GeomType::Cylinder, [0.05, 0.2, 0.0])]).unwrap();
        let long = from_geoms("b", &[geom(GeomType::Cylinder, [0.05, 0.25, 0.0])]).unwrap();
        assert!(cyl.mass < cap.mass && cap.mass < long.mass);
        assert!(cyl.inertia[0] < cap.inertia[0] && cap.inertia[0] < long.inertia[0]);
    }

    #[test]
    fn a_given_mass_sets_the_density() {
        let mut g = geom(GeomType::Box, [0.1, 0.2, 0.3]);
        g.mass = Some(2.0);
        let l = from_geoms("b", &[g]).unwrap();
        assert!((l.mass - 2.0).abs() < 1e-12);
        assert!((l.inertia[0] - 2.0 * (0.04 + 0.09) / 3.0).abs() < 1e-12);
    }

    #[test]
    fn the_inertia_group_range_is_the_last_compilers_and_checked() {
        assert_eq!(group_range("<mujoco/>").unwrap(), [0, 5]);
        let two = r#"<compiler inertiagrouprange="1 2"/><!-- <compiler inertiagrouprange="0 0"/> --><compiler angle="radian" inertiagrouprange=" 4 5 "/>"#;
        assert_eq!(group_range(two).unwrap(), [4, 5]);
        for bad in ["5 4", "1", "a b", "1 2 3"] {
            let e = group_range(&format!(r#"<compiler inertiagrouprange="{bad}"/>"#)).unwrap_err();
            assert!(e.to_string().contains("inertiagrouprange"), "{e}");
        }
    }

    #[test]
    fn a_mesh_without_inertial_is_refused_by_name() {
        let mut g = geom(GeomType::Mesh, [0.0; 3]);
        g.name = Some("shell".into());
        let e = from_geoms("link3", &[g]).unwrap_err().to_string();
        assert!(e.contains("shell") && e.contains("link3"), "{e}");
    }
}
