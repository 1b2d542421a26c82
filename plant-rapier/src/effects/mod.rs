//! What a real arm adds between the controller and the rigid-body dynamics:
//! the actuator path (delay, lost commands), the sensors (noise,
//! quantisation), the disturbance d(t), and the flags that say which of
//! them acted. Each random effect draws from its own seeded stream, so
//! turning one effect on does not change another's numbers.

mod actuator;
mod disturbance;
mod sensor;

pub(crate) use actuator::Actuator;
pub(crate) use disturbance::Disturbance;
pub(crate) use sensor::Sensor;
/// The effect bits are part of the wire contract.
pub use wire::Effects;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// One random stream per effect, all from the scenario's seed.
pub(crate) fn stream(seed: u64, effect: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(effect);
    rng
}
