//! A trained policy as a Rust controller law: an ONNX network (run by
//! `tract`, pure Rust) with the record of the environment it was trained
//! in, acting on the observation the Gymnasium environment builds.
//!
//! Where it sits in the data flow: the controller node `testbed-policy
//! FILE.onnx` (`policy/node/src/main.rs`, run by `testbed run
//! --controller-cmd` and `testbed compare --controller-cmd`) receives the
//! joint state and the reference sample over the bus like any controller
//! node, and hands them to [`PolicyLaw::step`]. Every `decimation` plant
//! periods that builds the observation with [`gym_env::observe`] (the
//! environment's own function), runs the network ([`Policy::act`]) and
//! turns its action into a torque with [`gym_env::action_torque`];
//! every period it adds that torque, held, ramped or low-pass filtered by
//! [`gym_env::ActionShaper`] as the record says, to the base law's, as the
//! environment does. No Python is in the loop.
//!
//! The policy's record is the ONNX model's `metadata_props` entry
//! [`ENV_KEY`] (`testbed.env`), a JSON object: the `env` dict of
//! `testbed.policy.LinearPolicy` (python/inprocess/testbed/policy.py,
//! `env_record`), which `testbed.onnx_export` writes.
//!
//! ```no_run
//! # fn main() -> Result<(), policy::PolicyError> {
//! let policy = policy::Policy::load("runs/policy.onnx".as_ref())?;
//! let obs = vec![0.0; policy.record().obs_dim];
//! let mut action = vec![0.0; policy.record().dof];
//! policy.act(&obs, &mut action)?;
//! # Ok(()) }
//! ```
//!
//! # Limitations
//! - The network takes one input, of shape `[1, obs_dim]` or `[obs_dim]`,
//!   in f32 or f64, and its first output must hold `dof` numbers; a
//!   recurrent policy (state between steps) is not supported.
//! - The base law is built from the run's `[controller]` table (checked
//!   against the policy's record), not from the policy's scenario file.

mod check;
mod law;
mod record;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use tract_onnx::prelude::*;

pub use check::{ESSENTIAL, check_run};
pub use law::PolicyLaw;
pub use record::EnvRecord;

/// The largest policy file read, bytes: a policy MLP is kilobytes, the
/// largest network a 1 kHz loop can run is a few megabytes.
pub const MAX_POLICY_BYTES: u64 = 256 << 20;

/// The `metadata_props` key holding the environment record (JSON).
pub const ENV_KEY: &str = "testbed.env";

/// Why a policy file was refused, or a step of it failed.
#[derive(Debug, thiserror::Error)]
pub enum PolicyError {
    /// The file could not be read.
    #[error("{path}: cannot read it: {source}")]
    Read {
        /// The policy file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not an ONNX model tract can load.
    #[error("{path}: not an ONNX model tract can run: {reason}")]
    NotOnnx {
        /// The policy file.
        path: PathBuf,
        /// tract's reason.
        reason: String,
    },
    /// The model has no environment record.
    #[error(
        "{path}: no metadata_props entry '{ENV_KEY}' (the environment the policy was trained in); \
         export it with testbed.onnx_export"
    )]
    NoMetadata {
        /// The policy file.
        path: PathBuf,
    },
    /// A field of the record is missing or wrong.
    #[error("{path}: {ENV_KEY}.{field}: {reason}")]
    Record {
        /// The policy file.
        path: PathBuf,
        /// The field at fault.
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The network's input or output does not fit the record's sizes.
    #[error("{path}: the network's {which} has shape {shape}; {ENV_KEY} needs {need}")]
    Shape {
        /// The policy file.
        path: PathBuf,
        /// `input` or `output`.
        which: &'static str,
        /// The shape found.
        shape: String,
        /// The shape needed.
        need: String,
    },
    /// The network's output is not real numbers.
    #[error(
        "{path}: the network's output is of type {found}, not float or double (an integer torque would be rounded)"
    )]
    OutputType {
        /// The policy file.
        path: PathBuf,
        /// The type found (tract's name: an ONNX int64 reads as TDim).
        found: String,
    },
    /// The network gave a value that is not finite.
    #[error("{path}: the network's output {index} is {value}, not a finite number")]
    NotFinite {
        /// The policy file.
        path: PathBuf,
        /// Which action component.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The network failed while running.
    #[error("{path}: the network failed: {reason}")]
    Run {
        /// The policy file.
        path: PathBuf,
        /// tract's reason.
        reason: String,
    },
    /// The run is not the one the policy was trained for.
    #[error("{0}")]
    Mismatch(String),
}

/// An ONNX policy and the environment it was trained in.
#[derive(Debug, Clone)]
pub struct Policy {
    path: PathBuf,
    record: EnvRecord,
    plan: Arc<TypedRunnableModel>,
    input: DatumType,
    /// The input's shape: `[1, obs_dim]` or `[obs_dim]`.
    input_shape: Vec<usize>,
}

impl Policy {
    /// Loads the ONNX file at `path`.
    pub fn load(path: &Path) -> Result<Self, PolicyError> {
        // A regular file of at most MAX_POLICY_BYTES: a FIFO hung the run
        // (and left this node behind it), /dev/zero filled memory (#60 item 5).
        let bytes = wire::read_regular_file(path, Some(MAX_POLICY_BYTES)).map_err(|source| {
            PolicyError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Self::from_bytes(&bytes, path)
    }

    /// The policy in `bytes`; `path` names it in errors.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, PolicyError> {
        let not_onnx = |e: &dyn std::fmt::Display| PolicyError::NotOnnx {
            path: path.to_path_buf(),
            reason: format!("{e:#}"),
        };
        let onnx = tract_onnx::onnx();
        let proto = onnx
            .proto_model_for_read(&mut &bytes[..])
            .map_err(|e| not_onnx(&e))?;
        // A protobuf decoder takes almost any bytes (an empty file is an
        // empty message): a model without a graph is not a model.
        if proto.graph.is_none() {
            return Err(not_onnx(&"no graph in it"));
        }
        let text = proto
            .metadata_props
            .iter()
            .find(|p| p.key == ENV_KEY)
            .map(|p| p.value.clone())
            .ok_or_else(|| PolicyError::NoMetadata {
                path: path.to_path_buf(),
            })?;
        let record = EnvRecord::parse(&text, path)?;
        let model = onnx
            .model_for_proto_model(&proto)
            .map_err(|e| not_onnx(&e))?;
        let inputs = declared_input(&proto);
        let (plan, input, input_shape) = runnable(model, &inputs, &record, path)?;
        Ok(Self {
            path: path.to_path_buf(),
            record,
            plan,
            input,
            input_shape,
        })
    }

    /// The environment the policy was trained in.
    pub fn record(&self) -> &EnvRecord {
        &self.record
    }

    /// The file it was loaded from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The network's action for `obs` (length `obs_dim`) into `action`
    /// (length `dof`), unclipped: the caller clips as the environment does.
    pub fn act(&self, obs: &[f64], action: &mut [f64]) -> Result<(), PolicyError> {
        let run_err = |e: &dyn std::fmt::Display| PolicyError::Run {
            path: self.path.clone(),
            reason: format!("{e:#}"),
        };
        let input = if self.input == f32::datum_type() {
            let v: Vec<f32> = obs.iter().map(|&x| x as f32).collect();
            Tensor::from_shape(&self.input_shape, &v)
        } else {
            Tensor::from_shape(&self.input_shape, obs)
        }
        .map_err(|e| run_err(&e))?;
        let out = self
            .plan
            .run(tvec!(input.into_tvalue()))
            .map_err(|e| run_err(&e))?;
        let first = out.first().ok_or_else(|| run_err(&"no output"))?;
        let values: Vec<f64> = first
            .cast_to::<f64>()
            .map_err(|e| run_err(&e))?
            .to_plain_array_view::<f64>()
            .map_err(|e| run_err(&e))?
            .iter()
            .copied()
            .collect();
        if values.len() != action.len() {
            return Err(PolicyError::Shape {
                path: self.path.clone(),
                which: "output",
                shape: format!("{:?}", first.shape()),
                need: format!("{} numbers (dof)", action.len()),
            });
        }
        for (index, (a, v)) in action.iter_mut().zip(values).enumerate() {
            if !v.is_finite() {
                return Err(PolicyError::NotFinite {
                    path: self.path.clone(),
                    index,
                    value: v,
                });
            }
            *a = v;
        }
        Ok(())
    }
}

/// The network's one input as the file declares it: ONNX element type
/// (1: f32, 11: f64) and dims (None: symbolic or unknown).
fn declared_input(proto: &tract_onnx::pb::ModelProto) -> Vec<(i32, Option<Vec<Option<i64>>>)> {
    use tract_onnx::pb::tensor_shape_proto::dimension::Value as Dim;
    use tract_onnx::pb::type_proto::Value as Type;
    let Some(graph) = &proto.graph else {
        return Vec::new();
    };
    // Old files list the initializers among the inputs: those are weights.
    let weights: Vec<&str> = graph.initializer.iter().map(|t| t.name.as_str()).collect();
    graph
        .input
        .iter()
        .filter(|i| !weights.contains(&i.name.as_str()))
        .map(|i| match i.r#type.as_ref().and_then(|t| t.value.as_ref()) {
            Some(Type::TensorType(t)) => (
                t.elem_type,
                t.shape.as_ref().map(|s| {
                    s.dim
                        .iter()
                        .map(|d| match d.value {
                            Some(Dim::DimValue(v)) => Some(v),
                            _ => None,
                        })
                        .collect()
                }),
            ),
            _ => (0, None),
        })
        .collect()
}

/// ONNX's element type codes of f32 and f64.
const ONNX_FLOAT: i32 = 1;
const ONNX_DOUBLE: i32 = 11;

/// The optimised plan of `model` with its input fixed to the record's
/// observation, its output checked against the record's dof.
fn runnable(
    mut model: InferenceModel,
    inputs: &[(i32, Option<Vec<Option<i64>>>)],
    record: &EnvRecord,
    path: &Path,
) -> Result<(Arc<TypedRunnableModel>, DatumType, Vec<usize>), PolicyError> {
    let not_onnx = |e: &dyn std::fmt::Display| PolicyError::NotOnnx {
        path: path.to_path_buf(),
        reason: format!("{e:#}"),
    };
    let shape_err = |shape: String, need: String| PolicyError::Shape {
        path: path.to_path_buf(),
        which: "input",
        shape,
        need,
    };
    let [(elem, declared)] = inputs else {
        return Err(shape_err(
            format!("{} inputs", inputs.len()),
            format!("one input of {} numbers (obs_dim)", record.obs_dim),
        ));
    };
    let datum = match *elem {
        ONNX_FLOAT => f32::datum_type(),
        ONNX_DOUBLE => f64::datum_type(),
        other => {
            return Err(shape_err(
                format!("ONNX element type {other}"),
                "float (1) or double (11)".into(),
            ));
        }
    };
    let obs = record.obs_dim as i64;
    // [obs_dim] or [batch, obs_dim]: a batch of one.
    let shape = match declared.as_deref() {
        Some([d]) if d.is_none_or(|d| d == obs) => vec![record.obs_dim],
        Some([b, d]) if b.is_none_or(|b| b == 1) && d.is_none_or(|d| d == obs) => {
            vec![1, record.obs_dim]
        }
        None => vec![1, record.obs_dim],
        Some(other) => {
            let dims: Vec<String> = other
                .iter()
                .map(|d| d.map_or("?".to_string(), |d| d.to_string()))
                .collect();
            return Err(shape_err(
                format!("[{}]", dims.join(", ")),
                format!("[1, {}] or [{}] (obs_dim)", record.obs_dim, record.obs_dim),
            ));
        }
    };
    model
        .set_input_fact(0, InferenceFact::dt_shape(datum, &shape))
        .map_err(|e| not_onnx(&e))?;
    let typed = model.into_optimized().map_err(|e| not_onnx(&e))?;
    let out = typed.output_fact(0).map_err(|e| not_onnx(&e))?;
    let out_shape = out.shape.as_concrete().map(<[usize]>::to_vec);
    match out_shape {
        Some(s) if s.iter().product::<usize>() == record.dof => {}
        s => {
            return Err(PolicyError::Shape {
                path: path.to_path_buf(),
                which: "output",
                shape: format!("{s:?}"),
                need: format!("{} numbers (dof)", record.dof),
            });
        }
    }
    // An integer output would be a rounded torque (#60 item 10).
    if out.datum_type != f32::datum_type() && out.datum_type != f64::datum_type() {
        return Err(PolicyError::OutputType {
            path: path.to_path_buf(),
            found: format!("{:?}", out.datum_type),
        });
    }
    let plan = typed.into_runnable().map_err(|e| not_onnx(&e))?;
    Ok((plan, datum, shape))
}
