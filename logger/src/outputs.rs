//! Where each sample the logger receives goes: the log always; the arm's
//! frames and figure, derived from the joint states; and the live view when
//! the run has one. One path, so the live view shows what the log keeps.

use std::collections::BTreeMap;

use arm_model::ArmModel;
use serde_json::Value;
use wire::JointState;

use crate::live::LiveView;
use crate::scene::{ArmScene, SCENE_TOPIC, TRANSFORMS_TOPIC};
use crate::{LogError, LogMessage, LogWriter, channels};

/// The arm's frames are written at 50 Hz of sim time: smooth to the eye,
/// 2 % of the messages at 1 kHz.
const TRANSFORMS_EVERY_NS: u64 = 20_000_000;
/// The figure is written again every second, so that a viewer that joins
/// late or seeks into the log finds it.
const SCENE_EVERY_NS: u64 = 1_000_000_000;

/// The logger's outputs.
pub(crate) struct Outputs {
    log: LogWriter,
    live: Option<Box<dyn LiveView>>,
    arm: ArmScene,
    dof: usize,
    next_transforms_ns: u64,
    next_scene_ns: u64,
    json: Vec<u8>,
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
            next_transforms_ns: 0,
            next_scene_ns: 0,
            json: Vec::with_capacity(4096),
        })
    }

    /// One sample of any topic.
    pub(crate) fn take<M: LogMessage>(&mut self, msg: &M) -> Result<(), LogError> {
        let json = self.log.write(msg)?;
        if let Some(live) = self.live.as_mut() {
            live.offer(M::LOG_TOPIC, msg.header().t_ns, json);
        }
        Ok(())
    }

    /// A joint state: the sample, then the arm's frames and figure when due.
    /// A state of another arm's size, or not finite (a run blowing up),
    /// moves no frame: its numbers are in the log all the same.
    pub(crate) fn take_state(&mut self, s: &JointState) -> Result<(), LogError> {
        self.take(s)?;
        let (t, wall) = (s.header.t_ns, s.header.wall_ns);
        let q = s.q.get(..self.dof).filter(|_| s.dof as usize == self.dof);
        if let Some(q) = q.filter(|q| q.iter().all(|x| x.is_finite()))
            && t >= self.next_transforms_ns
        {
            self.next_transforms_ns = t.saturating_add(TRANSFORMS_EVERY_NS);
            let v = self.arm.transforms(t, q);
            self.emit(TRANSFORMS_TOPIC, t, wall, &v)?;
        }
        if t >= self.next_scene_ns {
            self.next_scene_ns = t.saturating_add(SCENE_EVERY_NS);
            let v = self.arm.scene(t);
            self.emit(SCENE_TOPIC, t, wall, &v)?;
        }
        Ok(())
    }

    fn emit(&mut self, topic: &'static str, t: u64, wall: u64, v: &Value) -> Result<(), LogError> {
        self.json.clear();
        serde_json::to_writer(&mut self.json, v).map_err(|cause| LogError::Encode {
            path: self.log.path().display().to_string(),
            topic,
            cause,
        })?;
        self.log.write_json(topic, t, wall, &self.json)?;
        if let Some(live) = self.live.as_mut() {
            live.offer(topic, t, &self.json);
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
