//! Contact through Rapier (`[plant.contact]`): the links' `<collision>`
//! primitives as massless colliders on their bodies, the obstacles as fixed
//! bodies, and what the contact solver did over a period read back from
//! Rapier's narrow phase.

use arm_model::ArmModel;
use rapier3d_f64::prelude::*;

use super::shapes::{pose, shape};
use crate::{ContactConfig, EngineError, PlantError};

/// Arm colliders are in group 1, obstacles in group 2, free objects in 3:
/// the arm meets obstacles and objects (it can push one); objects rest on
/// obstacles and on each other. A grasped object's collider joins the
/// arm's group, as part of its link.
const ARM: Group = Group::GROUP_1;
const OBSTACLES: Group = Group::GROUP_2;
const OBJECTS: Group = Group::GROUP_3;
/// How far from the grasping link's frame an object's surface may be when
/// the link grasps it, m: the longest link of a shipped arm is under
/// 0.5 m, so this takes anything a link can reach and nothing across the
/// workspace.
pub const MAX_GRASP_DISTANCE_M: f64 = 2.0;
/// What a free object meets.
const OBJECT_MEETS: Group = ARM.union(OBSTACLES).union(OBJECTS);

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
    /// Free objects in `objects`.
    pub n_objects: usize,
    /// Each free object's pose at the period's end, world frame: x, y, z,
    /// then the quaternion x, y, z, w.
    pub objects: [[f64; 7]; wire::MAX_OBJECTS],
}

/// The colliders of one arm and what they met.
pub(super) struct Contacts {
    reading: ContactReading,
    /// Impulse summed over the period's substeps so far, N s.
    impulse: f64,
    /// The arm's link bodies: a contact counts when one side rides on them.
    arm: Vec<RigidBodyHandle>,
    /// The objects a link grasps and releases.
    objects: Vec<Held>,
    /// The arm colliders' groups (they meet each other with `self_contact`).
    arm_groups: (Group, Group),
}

/// A free object and the link that grasps it.
struct Held {
    body: RigidBodyHandle,
    collider: ColliderHandle,
    link: RigidBodyHandle,
}

/// Adds the arm's colliders and the obstacles to `world`. A robot with no
/// primitive to collide is refused: contact could never happen.
pub(super) fn insert(
    world: &mut PhysicsWorld,
    model: &ArmModel,
    bodies_of_arm: &[RigidBodyHandle],
    config: &ContactConfig,
) -> Result<Contacts, PlantError> {
    super::contact_check::check_contact_shapes(model, config)?;
    let arm_filter = if config.self_contact {
        ARM | OBSTACLES | OBJECTS
    } else {
        OBSTACLES | OBJECTS
    };
    let material = |b: ColliderBuilder| {
        b.restitution(config.restitution)
            .restitution_combine_rule(CoefficientCombineRule::Max)
            .friction(config.friction)
            .friction_combine_rule(CoefficientCombineRule::Max)
    };
    for (link, &body) in model.links.iter().zip(bodies_of_arm) {
        for c in &link.collisions {
            // Massless: the URDF's <inertial> alone gives the dynamics.
            let b = material(shape(&c.geometry))
                .position(pose(&c.origin))
                .density(0.0);
            attach(world, b, body, (ARM, arm_filter));
        }
    }
    for (i, o) in config.obstacle.iter().enumerate() {
        let fixed = RigidBodyBuilder::fixed().pose(pose(&o.origin()));
        let fixed = world.bodies.insert(fixed.build());
        let b = material(shape(&o.geometry(i)?));
        attach(world, b, fixed, (OBSTACLES, ARM | OBJECTS));
    }
    let mut objects = Vec::with_capacity(config.object.len());
    for (i, o) in config.object.iter().enumerate() {
        let (link, _) = model
            .locate_link(&o.link)
            .ok_or_else(|| PlantError::InvalidConfig {
                key: format!("plant.contact.object[{i}].link"),
                value: format!("\"{}\"", o.link),
                need: format!(
                    "one of the robot's links ({})",
                    model.link_names().join(", ")
                ),
            })?;
        let free = RigidBodyBuilder::dynamic()
            .pose(pose(&o.origin()))
            .can_sleep(false);
        let body = world.bodies.insert(free.build());
        let b = material(shape(&o.geometry(i)?)).mass(o.mass);
        objects.push(Held {
            body,
            collider: attach(world, b, body, (OBJECTS, OBJECT_MEETS)),
            link: bodies_of_arm[link],
        });
    }
    Ok(Contacts {
        reading: ContactReading::default(),
        impulse: 0.0,
        arm: bodies_of_arm.to_vec(),
        objects,
        arm_groups: (ARM, arm_filter),
    })
}

/// Puts the collider `b` on `body` in the collision groups `(member, filter)`.
fn attach(
    world: &mut PhysicsWorld,
    b: ColliderBuilder,
    body: RigidBodyHandle,
    (member, filter): (Group, Group),
) -> ColliderHandle {
    let collider = b.collision_groups(groups((member, filter))).build();
    let PhysicsWorld {
        colliders, bodies, ..
    } = world;
    colliders.insert_with_parent(collider, body, bodies)
}

/// Collision groups: `member` meets what `filter` names, both ways.
fn groups((member, filter): (Group, Group)) -> InteractionGroups {
    InteractionGroups::new(member, filter, InteractionTestMode::And)
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
            let (Some(c1), Some(c2)) =
                (colliders.get(pair.collider1), colliders.get(pair.collider2))
            else {
                continue;
            };
            let on_arm = |c: &Collider| c.parent().is_some_and(|p| self.arm.contains(&p));
            if !(on_arm(c1) || on_arm(c2)) {
                continue; // an object resting on an obstacle
            }
            self.impulse += pair.total_impulse_magnitude();
            for m in pair.manifolds() {
                // A point counts if it overlaps or the solver pushed on
                // it: Rapier measures distances before its solver moves
                // the bodies, so a resting contact sits just apart (dist
                // > 0) while it carries the whole load.
                for p in m
                    .points
                    .iter()
                    .filter(|p| p.dist <= 0.0 || p.data.impulse > 0.0)
                {
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

    /// Object `i` joins its link where it now is: its collider (and so its
    /// mass and inertia) rides on the link's body; its own body rests.
    /// An object farther than [`MAX_GRASP_DISTANCE_M`] from the link's
    /// frame is refused: a gripper holds what it touches, and a grasp from
    /// 900 m away once carried the object across the world.
    pub(super) fn grasp(&self, i: usize, world: &mut PhysicsWorld) -> Result<(), PlantError> {
        let (h, at, link) = self.where_held(i, world)?;
        let gap = world.colliders.get(h.collider).map_or(0.0, |c| {
            c.shape()
                .distance_to_point(&at, link.position().translation, true)
        });
        // NaN (a broken shape) is refused too.
        if gap.is_nan() || gap > MAX_GRASP_DISTANCE_M {
            return Err(PlantError::InvalidConfig {
                key: format!("plant.contact.object[{i}]"),
                value: format!("{gap:.3e} m from its link's frame when grasped"),
                need: format!(
                    "within {MAX_GRASP_DISTANCE_M} m of the grasping link's frame at grasp_at_s"
                ),
            });
        }
        let relative = link.position().inverse() * at;
        let PhysicsWorld {
            colliders, bodies, ..
        } = world;
        colliders.set_parent(h.collider, Some(h.link), bodies);
        if let Some(c) = colliders.get_mut(h.collider) {
            c.set_position_wrt_parent(relative);
            c.set_collision_groups(groups(self.arm_groups));
        }
        if let Some(b) = bodies.get_mut(h.body) {
            b.set_enabled(false);
        }
        Ok(())
    }

    /// Object `i` leaves its link as a free body, moving as the link's
    /// material at its place did.
    pub(super) fn release(&self, i: usize, world: &mut PhysicsWorld) -> Result<(), PlantError> {
        let (h, at, link) = self.where_held(i, world)?;
        let (v, w) = (link.velocity_at_point(at.translation), link.angvel());
        let PhysicsWorld {
            colliders, bodies, ..
        } = world;
        if let Some(b) = bodies.get_mut(h.body) {
            b.set_enabled(true);
            b.set_position(at, true);
            b.set_linvel(v, true);
            b.set_angvel(w, true);
        }
        colliders.set_parent(h.collider, Some(h.body), bodies);
        if let Some(c) = colliders.get_mut(h.collider) {
            c.set_position_wrt_parent(Pose::IDENTITY);
            c.set_collision_groups(groups((OBJECTS, OBJECT_MEETS)));
        }
        Ok(())
    }

    /// Where object `i`'s centre is, world frame.
    pub(super) fn object_position(&self, i: usize, colliders: &ColliderSet) -> Option<Vector> {
        let h = self.objects.get(i)?;
        Some(colliders.get(h.collider)?.position().translation)
    }

    /// Object `i`, where its collider is in the world, and its link's body
    /// (a copy: the caller changes the world next).
    fn where_held(
        &self,
        i: usize,
        world: &PhysicsWorld,
    ) -> Result<(&Held, Pose, RigidBody), PlantError> {
        let vanished = || EngineError::ObjectVanished { index: i };
        let h = self.objects.get(i).ok_or_else(vanished)?;
        let c = world.colliders.get(h.collider).ok_or_else(vanished)?;
        let link = world.bodies.get(h.link).ok_or_else(vanished)?;
        Ok((h, *c.position(), link.clone()))
    }

    /// Ends a period of length `dt`: the reading for it, with where each
    /// object is.
    pub(super) fn end(&mut self, dt: f64, colliders: &ColliderSet) -> ContactReading {
        self.reading.force = self.impulse / dt;
        self.reading.n_objects = self.objects.len().min(wire::MAX_OBJECTS);
        for (out, h) in self.reading.objects.iter_mut().zip(&self.objects) {
            if let Some(c) = colliders.get(h.collider) {
                let (t, r) = (c.position().translation, c.position().rotation);
                *out = [t.x, t.y, t.z, r.x, r.y, r.z, r.w];
            }
        }
        self.reading
    }
}
