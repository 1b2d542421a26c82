//! What a policy sees and what its action does, as free functions: the
//! environment ([`crate::ArmEnv`]) and the Rust policy node (`policy/`)
//! both call these, so that a policy acts on the same observation bits in
//! training and in a run, and its action becomes the same torque.

use wire::{JointState, ReferenceSample};

/// Writes the observation of `state` with the `reference` sample due at
/// its time, at plant period `k` of an episode of `steps`: e, ė, q, q̇,
/// q_d, q̇_d, k_c, k / steps (length [`crate::obs_dim`]). It reads the
/// measured q and q̇ (what a controller sees). With `scale_obs`, e is
/// divided by k_c and the velocities by `velocity_scale`.
pub fn observe(
    state: &JointState,
    reference: &ReferenceSample,
    k: u64,
    steps: u64,
    scale_obs: bool,
    velocity_scale: &[f64],
    obs: &mut [f64],
) {
    let (n, s, r) = (velocity_scale.len(), state, reference);
    for i in 0..n {
        let e = s.q_measured[i] - r.q_d[i];
        let ed = s.qd_measured[i] - r.qd_d[i];
        if scale_obs {
            let v = velocity_scale[i];
            obs[i] = e / r.kc[i];
            obs[n + i] = ed / v;
            obs[3 * n + i] = s.qd_measured[i] / v;
            obs[5 * n + i] = r.qd_d[i] / v;
        } else {
            obs[i] = e;
            obs[n + i] = ed;
            obs[3 * n + i] = s.qd_measured[i];
            obs[5 * n + i] = r.qd_d[i];
        }
        obs[2 * n + i] = s.q_measured[i];
        obs[4 * n + i] = r.q_d[i];
        obs[6 * n + i] = r.kc[i];
    }
    obs[7 * n] = k as f64 / steps as f64;
}

/// Writes the last clipped action after [`observe`]'s entries (the
/// observation of [`crate::obs_dim_with`] with `observe_action`).
pub fn observe_action(last: &[f64], obs: &mut [f64]) {
    let at = 7 * last.len() + 1;
    obs[at..at + last.len()].copy_from_slice(last);
}

/// The torque a decision's action adds (spread over its periods by an
/// [`crate::ActionShaper`]): clip(a_i, −1, 1) ·
/// `span` · `scale_i`, with `span` 1 when the action is the torque and the
/// residual scale when it is added to a base law's. Returns Σ clip(a_i)²,
/// the reward's effort term before its weight.
pub fn action_torque(action: &[f64], span: f64, scale: &[f64], tau: &mut [f64]) -> f64 {
    let mut effort = 0.0;
    for ((a, s), t) in action.iter().zip(scale).zip(tau.iter_mut()) {
        let a = a.clamp(-1.0, 1.0);
        *t = a * span * s;
        effort += a * a;
    }
    effort
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_action_is_clipped_and_scaled() {
        let mut tau = [0.0; 2];
        let effort = action_torque(&[2.0, -0.5], 0.2, &[50.0, 10.0], &mut tau);
        assert_eq!(tau, [1.0 * 0.2 * 50.0, -0.5 * 0.2 * 10.0]);
        assert_eq!(effort, 1.25);
    }

    #[test]
    fn the_observation_scales_errors_by_the_envelope() {
        let mut s = JointState::default();
        let mut r = ReferenceSample::default();
        s.q_measured[0] = 0.3;
        s.qd_measured[0] = 2.0;
        r.q_d[0] = 0.1;
        r.kc[0] = 0.5;
        let mut obs = [0.0; 8];
        observe(&s, &r, 5, 10, true, &[4.0], &mut obs);
        assert_eq!(obs, [(0.3 - 0.1) / 0.5, 0.5, 0.3, 0.5, 0.1, 0.0, 0.5, 0.5]);
    }
}
