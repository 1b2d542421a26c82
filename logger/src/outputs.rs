//! Where each sample the logger receives goes: the log always; the arm's
//! frames and figure, derived from the joint states; and the live view when
//! the run has one. One path, so the live view shows what the log keeps.

use std::collections::BTreeMap;

use arm_model::ArmModel;
use wire::{Command, JointState};

use crate::live::LiveView;
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
    next_transforms_ns: u64,
    next_scene_ns: u64,
    next_state_view_ns: u64,
    next_command_view_ns: u64,
    /// A derived message's CDR, reused.
    buf: Vec<u8>,
}

impl Outputs {
    /// Opens every channel of the run in `log` (so each exists even if its
    /// topic stays silent).
    pub(crate) fn open(
        mut log: LogWriter,
        model: &ArmModel,
        live: Option<Box<dyn LiveView>>,
    ) -> Result<Self, LogError> {
        for spec in channels() {
            log.add_channel_spec(&spec)?;
        }
        log.flush()?;
        Ok(Self {
            log,
            live,
            arm: ArmScene::new(model),
            dof: model.dof(),
            names: model.joint_names(),
            next_transforms_ns: 0,
            next_scene_ns: 0,
            next_state_view_ns: 0,
            next_command_view_ns: 0,
            buf: Vec::with_capacity(4096),
        })
    }

    /// One sample of any topic.
    pub(crate) fn take<M: LogMessage>(&mut self, msg: &M) -> Result<(), LogError> {
        let data = self.log.write(msg)?;
        if let Some(live) = self.live.as_mut() {
            live.offer(M::LOG_TOPIC, msg.header().t_ns, data);
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
            let n = (s.dof as usize).min(wire::MAX_DOF);
            self.buf.clear();
            crate::ros2::joint_state(
                &mut self.buf,
                t,
                self.names.get(..n).unwrap_or_default(),
                &s.q[..n],
                &s.qd[..n],
                &s.tau_applied[..n],
            );
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
        }
        Ok(())
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
