//! Where each sample the logger receives goes: the log always; the arm's
//! frames and figure, derived from the joint states; and the live view when
//! the run has one. One path, so the live view shows what the log keeps.

use std::collections::BTreeMap;

use arm_model::ArmModel;
use wire::{Command, ContactState, JointState, Logged};

use crate::obstacles::{CONTACT_MARKER_TOPIC, DrawnObstacle, DrawnShape, contact_marker};

use crate::live::LiveView;
use crate::ros2::ROBOT_DESCRIPTION_TOPIC;
use crate::scene::{ArmScene, SCENE_TOPIC, TRANSFORMS_TOPIC};
use crate::{JOINT_COMMANDS_TOPIC, JOINT_STATES_TOPIC, LogError, LogMessage, LogWriter, channels};

/// The arm's frames are written at 50 Hz of sim time: smooth to the eye,
/// 2 % of the messages at 1 kHz.
const TRANSFORMS_EVERY_NS: u64 = 20_000_000;
/// The standard views (`/joint_states`, `/joint_commands`) are written at
/// the frames' rate: they are for tools that draw the arm or plot a
/// glance (RViz, a robot_state_publisher); every sample, every field, is
/// in the testbed's own messages, and at 1 kHz the views would add half
/// the file's index and a sixth of its data.
const VIEWS_EVERY_NS: u64 = TRANSFORMS_EVERY_NS;
/// The figure is written again every second, so that a viewer that joins
/// late or seeks into the log finds it.
const SCENE_EVERY_NS: u64 = 1_000_000_000;

/// The logger's outputs.
pub(crate) struct Outputs {
    log: LogWriter,
    live: Option<Box<dyn LiveView>>,
    arm: ArmScene,
    dof: usize,
    names: Vec<String>,
    /// `/joint_states` names: the controlled joints, then the others.
    view_names: Vec<String>,
    /// The joints that are not controlled, as `/joint_states` lists them.
    others: Vec<OtherJoint>,
    /// Scratch for the view's position, velocity and effort.
    view: [Vec<f64>; 3],
    next_transforms_ns: u64,
    next_scene_ns: u64,
    next_state_view_ns: u64,
    next_command_view_ns: u64,
    next_contact_view_ns: u64,
    /// The free objects' shapes, drawn where the contact samples say.
    objects: Vec<DrawnShape>,
    /// A derived message's CDR, reused.
    buf: Vec<u8>,
    /// The model as a `std_msgs/msg/String` (`/robot_description`): in the
    /// log once (the writer's), offered live with the figure every second,
    /// so that a viewer that joins late finds it (the live server has no
    /// latching).
    description: Vec<u8>,
}

impl Outputs {
    /// Opens every channel of the run in `log` (so each exists even if its
    /// topic stays silent).
    pub(crate) fn open(
        mut log: LogWriter,
        (model, urdf): (&ArmModel, &str),
        (obstacles, objects): (&[DrawnObstacle], &[DrawnShape]),
        live: Option<Box<dyn LiveView>>,
    ) -> Result<Self, LogError> {
        for spec in channels() {
            log.add_channel_spec(&spec)?;
        }
        log.flush()?;
        let others = OtherJoint::of(model);
        let names = model.joint_names();
        let view_names = names
            .iter()
            .cloned()
            .chain(others.iter().map(|o| o.name.clone()))
            .collect();
        Ok(Self {
            log,
            live,
            arm: ArmScene::new(model).with_obstacles(obstacles),
            dof: model.dof(),
            names,
            view_names,
            others,
            view: Default::default(),
            next_transforms_ns: 0,
            next_scene_ns: 0,
            next_state_view_ns: 0,
            next_command_view_ns: 0,
            next_contact_view_ns: 0,
            objects: objects.to_vec(),
            buf: Vec::with_capacity(4096),
            description: {
                let mut d = Vec::with_capacity(urdf.len() + 16);
                crate::ros2::string_message(&mut d, urdf);
                d
            },
        })
    }

    /// One logged message, and the views it is drawn in.
    pub(crate) fn take_logged(&mut self, m: &Logged) -> Result<(), LogError> {
        match m {
            Logged::JointState(s) => self.take_state(s),
            Logged::Command(c) => self.take_command(c),
            Logged::ContactState(c) => self.take_contact(c),
            Logged::ReferenceSample(m) => self.take(m),
            Logged::ControllerDiagnostics(m) => self.take(m),
            Logged::Timing(m) => self.take(m),
            Logged::OwnDiagnostics(m) => self.take(m),
        }
    }

    /// One sample of any topic.
    fn take<M: LogMessage>(&mut self, msg: &M) -> Result<(), LogError> {
        let data = self.log.write(msg)?;
        if let Some(live) = self.live.as_mut() {
            live.offer(M::LOG_TOPIC, msg.header().t_ns, data);
        }
        Ok(())
    }

    /// What contact did: the sample, then, while the arm touches
    /// something or free objects are about, the contact point and the
    /// objects on `/arm/contact` at most every 20 ms of sim time (each
    /// marker lasting two of those, so it goes when the contact does).
    pub(crate) fn take_contact(&mut self, c: &ContactState) -> Result<(), LogError> {
        self.take(c)?;
        let (t, wall) = (c.header.t_ns, c.header.wall_ns);
        let shown = (c.points > 0 && c.force.is_finite()) || !self.objects.is_empty();
        if shown && t >= self.next_contact_view_ns {
            self.next_contact_view_ns = t.saturating_add(VIEWS_EVERY_NS);
            self.buf.clear();
            contact_marker(&mut self.buf, t, c, &self.objects, 2 * VIEWS_EVERY_NS);
            self.emit(CONTACT_MARKER_TOPIC, t, wall)?;
        }
        Ok(())
    }

    /// A joint state: the sample, then its standard view
    /// (`/joint_states`), the arm's frames and figure when due. A state of
    /// another arm's size, or not finite (a run blowing up), moves no
    /// frame: its numbers are in the log all the same.
    pub(crate) fn take_state(&mut self, s: &JointState) -> Result<(), LogError> {
        self.take(s)?;
        let (t, wall) = (s.header.t_ns, s.header.wall_ns);
        if t >= self.next_state_view_ns {
            self.next_state_view_ns = t.saturating_add(VIEWS_EVERY_NS);
            self.state_view(s);
            self.emit(JOINT_STATES_TOPIC, t, wall)?;
        }
        let q = s.q.get(..self.dof).filter(|_| s.dof as usize == self.dof);
        if let Some(q) = q.filter(|q| q.iter().all(|x| x.is_finite()))
            && t >= self.next_transforms_ns
        {
            self.next_transforms_ns = t.saturating_add(TRANSFORMS_EVERY_NS);
            self.buf.clear();
            self.arm.transforms(&mut self.buf, t, q);
            self.emit(TRANSFORMS_TOPIC, t, wall)?;
        }
        if t >= self.next_scene_ns {
            self.next_scene_ns = t.saturating_add(SCENE_EVERY_NS);
            self.buf.clear();
            self.arm.scene(&mut self.buf, t);
            self.emit(SCENE_TOPIC, t, wall)?;
            if let Some(live) = self.live.as_mut() {
                live.offer(ROBOT_DESCRIPTION_TOPIC, t, &self.description);
            }
        }
        Ok(())
    }

    /// `/joint_states` of `s` into `buf`: the controlled joints, then
    /// (for a state of this arm's size) the mimic joints where their
    /// leaders are and the locked joints at their fixed positions, as a
    /// robot_state_publisher needs every non-fixed joint of the URDF.
    fn state_view(&mut self, s: &JointState) {
        let n = (s.dof as usize).min(wire::MAX_DOF);
        let [pos, vel, eff] = &mut self.view;
        for v in [&mut *pos, &mut *vel, &mut *eff] {
            v.clear();
        }
        pos.extend_from_slice(&s.q[..n]);
        vel.extend_from_slice(&s.qd[..n]);
        eff.extend_from_slice(&s.tau_applied[..n]);
        let names = if n == self.dof {
            for o in &self.others {
                let (p, v) = o.state(&s.q[..n], &s.qd[..n]);
                pos.push(p);
                vel.push(v);
                eff.push(0.0);
            }
            &self.view_names[..]
        } else {
            self.names.get(..n).unwrap_or_default()
        };
        self.buf.clear();
        crate::ros2::joint_state(&mut self.buf, s.header.t_ns, names, pos, vel, eff);
    }

    /// A command: the sample and, when due, its standard view
    /// (`/joint_commands`).
    pub(crate) fn take_command(&mut self, c: &Command) -> Result<(), LogError> {
        self.take(c)?;
        let t = c.header.t_ns;
        if t < self.next_command_view_ns {
            return Ok(());
        }
        self.next_command_view_ns = t.saturating_add(VIEWS_EVERY_NS);
        let n = (c.dof as usize).min(wire::MAX_DOF);
        self.buf.clear();
        crate::ros2::joint_state(
            &mut self.buf,
            t,
            self.names.get(..n).unwrap_or_default(),
            &[],
            &[],
            &c.tau[..n],
        );
        self.emit(JOINT_COMMANDS_TOPIC, t, c.header.wall_ns)
    }

    /// Writes the derived message in `buf` and offers it live.
    fn emit(&mut self, topic: &'static str, t: u64, wall: u64) -> Result<(), LogError> {
        self.log.write_raw(topic, t, wall, &self.buf)?;
        if let Some(live) = self.live.as_mut() {
            live.offer(topic, t, &self.buf);
        }
        Ok(())
    }

    /// Closes the chunk if it is due.
    pub(crate) fn flush_if_due(&mut self) -> Result<(), LogError> {
        self.log.flush_if_due()
    }

    /// Stops the live view and finishes the log with `stats` and the live
    /// view's own counts.
    pub(crate) fn finish(self, mut stats: BTreeMap<String, String>) -> Result<(), LogError> {
        if let Some(live) = self.live {
            stats.extend(live.finish());
        }
        self.log.finish(stats)
    }
}

/// A joint of the URDF that is not controlled: where `/joint_states` puts it.
#[derive(Debug, Clone)]
struct OtherJoint {
    name: String,
    /// Mimic: (leader's column, multiplier, offset); locked: None.
    mimic: Option<(usize, f64, f64)>,
    /// A locked joint's position.
    position: f64,
}

impl OtherJoint {
    fn of(model: &ArmModel) -> Vec<Self> {
        let mimics = model.mimic.iter().map(|m| Self {
            name: model.joints[m.joint].name.clone(),
            mimic: Some((m.leader, m.multiplier, m.offset)),
            position: 0.0,
        });
        let locked = model.locked.iter().map(|l| Self {
            name: l.name.clone(),
            mimic: None,
            position: l.position,
        });
        mimics.chain(locked).collect()
    }

    /// Position and velocity given the controlled joints' `q`, `qd`.
    fn state(&self, q: &[f64], qd: &[f64]) -> (f64, f64) {
        match self.mimic {
            Some((leader, k, offset)) => (
                k * q.get(leader).copied().unwrap_or(f64::NAN) + offset,
                k * qd.get(leader).copied().unwrap_or(f64::NAN),
            ),
            None => (self.position, 0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// #39 row 14: `/joint_states` lists the joints that are not
    /// controlled too: a mimic finger where its leader is, a locked joint
    /// at its fixed position.
    #[test]
    fn mimic_and_locked_joints_are_in_the_state_view() {
        let urdf = include_str!("../../robots/panda.urdf");
        let mut locks = arm_model::Locks::new();
        locks.insert("panda_joint7".into(), 0.5);
        let model = ArmModel::from_urdf_str_locked(urdf, &locks).unwrap();
        let others = OtherJoint::of(&model);
        let names: Vec<&str> = others.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["panda_finger_joint2", "panda_joint7"]);
        let (n, finger) = (
            model.dof(),
            model
                .joint_names()
                .iter()
                .position(|j| j == "panda_finger_joint1")
                .unwrap(),
        );
        let mut q = vec![0.0; n];
        q[finger] = 0.02;
        let qd = vec![0.1; n];
        assert_eq!(others[0].state(&q, &qd), (0.02, 0.1));
        assert_eq!(others[1].state(&q, &qd), (0.5, 0.0));
    }
}
