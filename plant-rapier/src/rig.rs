//! The arm as the controller meets it: the Rapier [`Plant`] with the
//! scenario's effects around it. One [`Rig::step`] is one control period.

use crate::effects::{Actuator, Disturbance, Effects, Sensor, stream};
use crate::plant::Plant;
use crate::{PlantConfig, PlantError};
use arm_model::ArmModel;

/// Random streams, one per effect (see [`crate::effects`]).
const SENSOR_STREAM: u64 = 1;
const DISTURBANCE_STREAM: u64 = 2;
const ACTUATOR_STREAM: u64 = 3;

/// A payload waiting to be picked up, or carried.
struct Payload {
    link: usize,
    point: [f64; 3],
    mass: f64,
    /// First period that starts with it attached.
    attach_k: u64,
    attached: bool,
}

/// When a contact object is grasped and let go, in periods.
struct Grasp {
    /// First period that starts with it grasped.
    grasp_k: u64,
    /// First period that starts with it free again.
    release_k: Option<u64>,
    held: bool,
    released: bool,
}

/// The plant, its actuators, its sensors and its disturbance, stepped one
/// control period at a time. Everything random comes from `seed`, so the
/// same calls give the same numbers, bit for bit.
pub struct Rig {
    plant: Plant,
    period_ns: u64,
    dt: f64,
    /// Index of the current state (periods stepped so far).
    k: u64,
    actuator: Actuator,
    sensor: Sensor,
    disturbance: Disturbance,
    payload: Option<Payload>,
    grasps: Vec<Grasp>,
    /// Effects over the last period (and the sensors'), see [`Effects`].
    effects: u32,
    static_effects: u32,
}

impl std::fmt::Debug for Rig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Rig")
            .field("plant", &self.plant)
            .field("k", &self.k)
            .finish_non_exhaustive()
    }
}

impl Rig {
    /// Builds the rig for `model` with a control period of `period_ns`.
    pub fn new(
        model: &ArmModel,
        config: &PlantConfig,
        seed: u64,
        period_ns: u64,
    ) -> Result<Self, PlantError> {
        if period_ns == 0 {
            return Err(PlantError::InvalidConfig {
                key: "rate_hz".into(),
                value: "a period of 0 ns".into(),
                need: "a rate up to 1 GHz".into(),
            });
        }
        let plant = Plant::new(model, config)?;
        let n = plant.dof();
        let dt = period_ns as f64 / 1e9;
        let s = &config.sensor;
        let sensor = Sensor::new(
            s.q_noise_std.resolve("plant.sensor.q_noise_std", n)?,
            s.qd_noise_std.resolve("plant.sensor.qd_noise_std", n)?,
            s.q_resolution.resolve("plant.sensor.q_resolution", n)?,
            stream(seed, SENSOR_STREAM),
        );
        let disturbance =
            Disturbance::new(&config.disturbance, n, dt, stream(seed, DISTURBANCE_STREAM))?;
        let a = &config.actuation;
        let actuator = Actuator::new(
            n,
            a.delay_periods,
            a.drop_probability,
            stream(seed, ACTUATOR_STREAM),
        );
        let payload = match &config.payload {
            None => None,
            Some(p) => {
                let (link, frame) =
                    model
                        .locate_link(&p.link)
                        .ok_or_else(|| PlantError::InvalidConfig {
                            key: "plant.payload.link".into(),
                            value: format!("\"{}\"", p.link),
                            need: format!(
                                "one of the robot's links ({})",
                                model.link_names().join(", ")
                            ),
                        })?;
                let at = arm_model::iso(&frame)
                    * nalgebra::Point3::new(p.offset[0], p.offset[1], p.offset[2]);
                Some(Payload {
                    link,
                    point: [at.x, at.y, at.z],
                    mass: p.mass,
                    attach_k: periods(p.attach_at_s, period_ns),
                    attached: false,
                })
            }
        };
        // On for the whole run; the payload and lost commands are flagged
        // when they happen.
        let static_effects =
            config.configured_effects().0 & !(Effects::PAYLOAD | Effects::COMMAND_DROPPED);
        let mut rig = Self {
            plant,
            period_ns,
            dt,
            k: 0,
            actuator,
            sensor,
            disturbance,
            payload,
            grasps: config
                .contact
                .object
                .iter()
                .map(|o| Grasp {
                    grasp_k: periods(o.grasp_at_s, period_ns),
                    release_k: o.release_at_s.map(|s| periods(s, period_ns)),
                    held: false,
                    released: false,
                })
                .collect(),
            effects: static_effects,
            static_effects,
        };
        rig.attach_due_payload()?;
        if rig.payload_attached() {
            rig.effects |= Effects::PAYLOAD;
        }
        Ok(rig)
    }

    /// The Rapier plant inside.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// Number of actuated joints.
    pub fn dof(&self) -> usize {
        self.plant.dof()
    }

    /// Puts the arm at `q`, `qd`.
    pub fn set_state(&mut self, q: &[f64], qd: &[f64]) -> Result<(), PlantError> {
        self.plant.set_state(q, qd)
    }

    /// The true joint state.
    pub fn true_state_into(&self, q: &mut [f64], qd: &mut [f64]) {
        self.plant.state_into(q, qd);
    }

    /// What the sensors report for the current state. Call it once per
    /// state: each call draws new noise.
    pub fn measure_into(&mut self, q: &mut [f64], qd: &mut [f64]) {
        self.plant.state_into(q, qd);
        self.sensor.read(q, qd);
    }

    /// Steps one control period. `command` is the torque that reached the
    /// actuators this period, or None when none did (the last one is held).
    pub fn step(&mut self, command: Option<&[f64]>) -> Result<(), PlantError> {
        if let Some(c) = command
            && c.len() != self.dof()
        {
            return Err(PlantError::WrongLength {
                field: "command",
                expected: self.dof(),
                got: c.len(),
            });
        }
        let t = self.k as f64 * self.period_ns as f64 / 1e9;
        let held = self.hold_due_objects()?;
        let passage = self.actuator.pass(command);
        let d = self.disturbance.advance(t);
        self.plant.set_external_torque(d)?;
        self.plant.step(self.actuator.output(), self.dt)?;
        self.k += 1;
        let mut e = self.static_effects;
        if self.payload.as_ref().is_some_and(|p| p.attached) {
            e |= Effects::PAYLOAD;
        }
        if self.plant.saturated() {
            e |= Effects::SATURATED;
        }
        if self
            .plant
            .contact()
            .is_some_and(|c| c.force > 0.0 || c.points > 0)
        {
            e |= Effects::CONTACT;
        }
        if passage.dropped {
            e |= Effects::COMMAND_DROPPED;
        }
        if passage.held {
            e |= Effects::COMMAND_HELD;
        }
        if held {
            e |= Effects::PAYLOAD;
        }
        self.effects = e;
        self.attach_due_payload()
    }

    /// Grasps and lets go the contact objects due as period k starts (not
    /// before: the arm is put at its initial state after the rig is made);
    /// whether any is held.
    fn hold_due_objects(&mut self) -> Result<bool, PlantError> {
        for (i, g) in self.grasps.iter_mut().enumerate() {
            if !g.held && !g.released && self.k >= g.grasp_k {
                self.plant.hold_object(i, true)?;
                g.held = true;
            }
            if g.held && g.release_k.is_some_and(|r| self.k >= r) {
                self.plant.hold_object(i, false)?;
                (g.held, g.released) = (false, true);
            }
        }
        Ok(self.grasps.iter().any(|g| g.held))
    }

    /// Picks the payload up when the next period starts at or after its time.
    fn attach_due_payload(&mut self) -> Result<(), PlantError> {
        if let Some(p) = self.payload.as_mut()
            && !p.attached
            && self.k >= p.attach_k
        {
            self.plant.attach_point_mass(p.link, p.point, p.mass)?;
            p.attached = true;
        }
        Ok(())
    }

    /// The motor torque applied over the last period (after delay, loss and
    /// saturation).
    pub fn applied_torque(&self) -> &[f64] {
        self.plant.applied_torque()
    }

    /// The disturbance d applied over the last period.
    pub fn disturbance(&self) -> &[f64] {
        self.plant.external_torque()
    }

    /// The effects that acted over the last period and on the sensors.
    pub fn effects(&self) -> Effects {
        Effects(self.effects)
    }

    /// Whether the payload is attached now.
    pub fn payload_attached(&self) -> bool {
        self.payload.as_ref().is_some_and(|p| p.attached)
    }
}

/// The first period that starts at or after `s` seconds.
fn periods(s: f64, period_ns: u64) -> u64 {
    (s * 1e9 / period_ns as f64).ceil() as u64
}
