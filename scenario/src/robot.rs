//! The arm a scenario runs: its URDF, loaded with the scenario's locks.

use std::path::{Path, PathBuf};

use plant_rapier::{ArmModel, Locks};

use crate::ScenarioError;

/// The robot a scenario runs: its URDF text and where it came from.
#[derive(Debug, Clone)]
pub struct RobotSource {
    /// The URDF file, or None for the built-in two-link arm.
    pub path: Option<PathBuf>,
    /// The URDF text.
    pub urdf: String,
    /// The checked model.
    pub model: ArmModel,
}

impl RobotSource {
    /// A label for messages: the path, or "built-in two_link.urdf".
    pub fn label(&self) -> String {
        match &self.path {
            Some(p) => p.display().to_string(),
            None => "built-in two_link.urdf".into(),
        }
    }

    /// Loads and checks a URDF file with the joints in `locks` held.
    pub fn from_file(path: &Path, locks: &Locks) -> Result<Self, ScenarioError> {
        let file = path.display().to_string();
        let urdf = wire::read_text_file(path, wire::MAX_URDF_BYTES).map_err(|cause| {
            ScenarioError::Io {
                file: file.clone(),
                cause,
            }
        })?;
        // An MJCF file's includes inlined: the text is read again alone
        // (the plant node, a log's attachment), #47.
        let dir = path.parent().unwrap_or(Path::new("."));
        let urdf = ArmModel::self_contained(&urdf, dir).map_err(|cause| ScenarioError::Plant {
            file: file.clone(),
            cause: cause.into(),
        })?;
        let model =
            ArmModel::from_urdf_str_locked(&urdf, locks).map_err(|cause| ScenarioError::Plant {
                file,
                cause: cause.into(),
            })?;
        Ok(Self {
            path: Some(path.to_path_buf()),
            urdf,
            model,
        })
    }

    /// The same URDF with other joints locked.
    pub fn relocked(&self, locks: &Locks) -> Result<Self, ScenarioError> {
        let model = ArmModel::from_urdf_str_locked(&self.urdf, locks).map_err(|cause| {
            ScenarioError::Plant {
                file: self.label(),
                cause: cause.into(),
            }
        })?;
        Ok(Self {
            model,
            ..self.clone()
        })
    }

    /// A URDF given as text (e.g. a log's attachment); `label` names it in messages.
    pub fn from_text(urdf: &str, label: &str, locks: &Locks) -> Result<Self, ScenarioError> {
        let model =
            ArmModel::from_urdf_str_locked(urdf, locks).map_err(|cause| ScenarioError::Plant {
                file: label.to_string(),
                cause: cause.into(),
            })?;
        Ok(Self {
            path: Some(PathBuf::from(label)),
            urdf: urdf.to_string(),
            model,
        })
    }

    /// The paper's two-link arm.
    pub fn builtin() -> Self {
        let urdf = plant_rapier::TWO_LINK_URDF.to_string();
        match ArmModel::from_urdf_str(&urdf) {
            Ok(model) => Self {
                path: None,
                urdf,
                model,
            },
            // The embedded file is checked by this crate's tests.
            Err(e) => unreachable!("built-in two_link.urdf is invalid: {e}"),
        }
    }
}
