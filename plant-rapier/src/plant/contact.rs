//! Contact through Rapier (`[plant.contact]`): the links' `<collision>`
//! primitives as massless colliders on their bodies, the obstacles as fixed
//! bodies, and what the contact solver did over a period read back from
//! Rapier's narrow phase.

use arm_model::{ArmModel, Geometry};
use rapier3d_f64::prelude::*;

use super::rapier::pose;
use crate::{ContactConfig, PlantError};

/// Arm colliders are in group 1, obstacles in group 2.
const ARM: Group = Group::GROUP_1;
const OBSTACLES: Group = Group::GROUP_2;

/// What contact did over the last period.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactReading {
    /// Mean contact force on the arm over the period (the solver's normal
    /// impulses summed over contacts and substeps, over the period), N.
    pub force: f64,
    /// Contact points at the period's last substep.
    pub points: u32,
    /// The deepest of them, world frame, m (0 with none).
    pub point: [f64; 3],
}

/// The colliders of one arm and what they met.
pub(super) struct Contacts {
    reading: ContactReading,
    /// Impulse summed over the period's substeps so far, N s.
    impulse: f64,
}

/// Adds the arm's colliders and the obstacles to `world`. A robot with no
/// primitive to collide is refused: contact could never happen.
pub(super) fn insert(
    world: &mut PhysicsWorld,
    model: &ArmModel,
    bodies: &[RigidBodyHandle],
    config: &ContactConfig,
) -> Result<Contacts, PlantError> {
    if model.links.iter().all(|l| l.collisions.is_empty()) {
        let skipped: Vec<&str> = model
            .links
            .iter()
            .flat_map(|l| l.skipped_collisions.iter().map(String::as_str))
            .take(3)
            .collect();
        return Err(PlantError::InvalidConfig {
            key: "plant.contact".into(),
            value: "set".into(),
            need: match skipped.is_empty() {
                true => "links with <collision> primitives (box, cylinder, sphere, capsule): this robot has none".into(),
                false => format!(
                    "links with <collision> primitives (box, cylinder, sphere, capsule): this robot has none usable ({}, …)",
                    skipped.join("; ")
                ),
            },
        });
    }
    let arm_filter = if config.self_contact {
        ARM | OBSTACLES
    } else {
        OBSTACLES
    };
    let material = |b: ColliderBuilder| {
        b.restitution(config.restitution)
            .restitution_combine_rule(CoefficientCombineRule::Max)
            .friction(config.friction)
            .friction_combine_rule(CoefficientCombineRule::Max)
    };
    for (link, &body) in model.links.iter().zip(bodies) {
        for c in &link.collisions {
            let collider = material(shape(&c.geometry))
                .position(pose(&c.origin))
                // Massless: the URDF's <inertial> alone gives the dynamics.
                .density(0.0)
                .collision_groups(InteractionGroups::new(
                    ARM,
                    arm_filter,
                    InteractionTestMode::And,
                ))
                .build();
            let PhysicsWorld {
                colliders, bodies, ..
            } = world;
            colliders.insert_with_parent(collider, body, bodies);
        }
    }
    for (i, o) in config.obstacle.iter().enumerate() {
        let fixed = world
            .bodies
            .insert(RigidBodyBuilder::fixed().pose(pose(&o.origin())).build());
        let collider = material(shape(&o.geometry(i)?))
            .collision_groups(InteractionGroups::new(
                OBSTACLES,
                ARM,
                InteractionTestMode::And,
            ))
            .build();
        let PhysicsWorld {
            colliders, bodies, ..
        } = world;
        colliders.insert_with_parent(collider, fixed, bodies);
    }
    Ok(Contacts {
        reading: ContactReading::default(),
        impulse: 0.0,
    })
}

/// A URDF primitive as a Rapier shape; cylinders and capsules along z.
fn shape(g: &Geometry) -> ColliderBuilder {
    match *g {
        Geometry::Box { size } => {
            ColliderBuilder::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0)
        }
        Geometry::Sphere { radius } => ColliderBuilder::ball(radius),
        Geometry::Capsule { radius, length } => ColliderBuilder::capsule_z(length / 2.0, radius),
        Geometry::Cylinder { radius, length } => {
            // Rapier's cylinder lies along y: a quarter turn about x puts it on z.
            let turn = Pose::from_parts(
                Vector::ZERO,
                Rotation::from_axis_angle(Vector::X, std::f64::consts::FRAC_PI_2),
            );
            ColliderBuilder::compound(vec![(turn, SharedShape::cylinder(length / 2.0, radius))])
        }
    }
}

impl Contacts {
    /// Starts a period.
    pub(super) fn begin(&mut self) {
        self.impulse = 0.0;
        self.reading = ContactReading::default();
    }

    /// Reads what the solver did at the substep just taken.
    pub(super) fn after_substep(&mut self, narrow_phase: &NarrowPhase, colliders: &ColliderSet) {
        let mut points = 0u32;
        let mut deepest = (f64::INFINITY, [0.0; 3]);
        for pair in narrow_phase.contact_pairs() {
            self.impulse += pair.total_impulse_magnitude();
            let Some(c1) = colliders.get(pair.collider1) else {
                continue;
            };
            for m in pair.manifolds() {
                // Points within the contact skin count; Rapier measures
                // them before its solver moves the bodies.
                for p in m.points.iter().filter(|p| p.dist <= 0.0) {
                    points += 1;
                    if p.dist < deepest.0 {
                        let w = c1.position() * p.local_p1;
                        deepest = (p.dist, [w.x, w.y, w.z]);
                    }
                }
            }
        }
        self.reading.points = points;
        self.reading.point = deepest.1;
    }

    /// Ends a period of length `dt`: the reading for it.
    pub(super) fn end(&mut self, dt: f64) -> ContactReading {
        self.reading.force = self.impulse / dt;
        self.reading
    }
}
