//! One ETDRK4 step of an arm with URDF damping: positions as in RK4,
//! velocities in the damping's coordinates (`exponential.rs`: its stiff
//! modes and the rest), each decaying exactly; plain RK4 where the step's
//! damping is mild.

use super::exponential::{self, MILD_DAMPING, Modes};
use super::linalg::Cholesky;
use super::{Articulated, Drive, Stage};

/// ETDRK4's buffers: per joint, the start, the damping's shares, the
/// stages' velocities and (in the damping's coordinates, up to 2n long)
/// their velocities and forcings and the step's end.
#[derive(Debug, Clone)]
pub(super) struct Exponential {
    pub(super) modes: Modes,
    /// Whether the last step used the modes (not plain RK4 for mild damping).
    pub(super) modal: bool,
    q0: Vec<f64>,
    v0: Vec<f64>,
    qs: Vec<f64>,
    g: Vec<f64>,
    shares: Vec<f64>,
    v: [Vec<f64>; 3],
    y: [Vec<f64>; 4],
    f: [Vec<f64>; 4],
    end: [Vec<f64>; 2],
}

impl Exponential {
    pub(super) fn new(chol: &Cholesky, n: usize) -> Self {
        let v = || vec![0.0; n];
        let v2 = || vec![0.0; 2 * n];
        Self {
            modes: Modes::new(chol.clone(), n),
            modal: false,
            q0: v(),
            v0: v(),
            qs: v(),
            g: v(),
            shares: v(),
            v: std::array::from_fn(|_| v()),
            y: std::array::from_fn(|_| v2()),
            f: std::array::from_fn(|_| v2()),
            end: std::array::from_fn(|_| v2()),
        }
    }
}

impl Articulated {
    /// One ETDRK4 step of `h` (Cox & Matthews' scheme; see
    /// `exponential.rs`): positions as in RK4, velocities in the damping's
    /// modes at the start of the step, each decaying exactly. The step
    /// starts `s0` into the period; the drive has no states of its own
    /// (with them the arm takes RK4 steps).
    pub(super) fn etdrk4(&mut self, x: &mut Exponential, drive: &dyn Drive, s0: f64, h: f64) {
        let n = self.q.len();
        x.q0.copy_from_slice(&self.q);
        x.v0.copy_from_slice(&self.qd);
        if self.factor_mass(&x.q0, &x.v0).is_err() {
            // Blown up (see `acceleration`): report the non-finite state.
            self.blown_up();
            return;
        }
        let chol = &self.scratch.chol;
        let stiffest =
            exponential::damping_shares(chol, &self.reduced_damping, &mut x.qs, &mut x.shares);
        x.modal = h * stiffest > MILD_DAMPING;
        if !x.modal {
            self.rk4(drive, s0, h, true);
            return;
        }
        if !x.modes.update(chol, &self.reduced_damping, &x.shares, h) {
            // Blown up past a finite G: report the non-finite state.
            self.blown_up();
            return;
        }
        let len = x.modes.len();
        let at = Stage {
            s: s0,
            q: &x.q0,
            qd: &x.v0,
            x: &[],
        };
        self.accelerate_factored(drive, &at, &mut x.g, &mut []);
        x.modes.to_modes(&x.v0, &mut x.y[0]);
        forcing(x, 0);
        // Stages a, b, c: position, then the velocity in modes.
        for stage in 1..4 {
            for i in 0..n {
                let v = if stage == 1 {
                    x.v0[i]
                } else {
                    x.v[stage - 2][i]
                };
                x.qs[i] = x.q0[i] + if stage == 3 { h * v } else { 0.5 * h * v };
            }
            for m in 0..len {
                let w = x.modes.weight(m);
                x.y[stage][m] = match stage {
                    1 => w.e2 * x.y[0][m] + w.half * x.f[0][m],
                    2 => w.e2 * x.y[0][m] + w.half * x.f[1][m],
                    _ => w.e2 * x.y[1][m] + w.half * (2.0 * x.f[2][m] - x.f[0][m]),
                };
            }
            let (ys, vs) = (&x.y[stage], &mut x.v[stage - 1]);
            x.modes.to_joints(ys, vs);
            let (qs, vs) = (
                std::mem::take(&mut x.qs),
                std::mem::take(&mut x.v[stage - 1]),
            );
            let at = Stage {
                s: s0 + if stage == 3 { h } else { 0.5 * h },
                q: &qs,
                qd: &vs,
                x: &[],
            };
            self.acceleration(drive, &at, &mut x.g, &mut []);
            (x.qs, x.v[stage - 1]) = (qs, vs);
            forcing(x, stage);
        }
        // The step's end: velocity and displacement, per mode.
        let [mut y1, mut dy] = std::mem::take(&mut x.end);
        for m in 0..len {
            let (w, f) = (x.modes.weight(m), &x.f);
            y1[m] = w.e * x.y[0][m]
                + w.f1 * f[0][m]
                + 2.0 * w.f2 * (f[1][m] + f[2][m])
                + w.f3 * f[3][m];
            dy[m] = w.p0 * x.y[0][m] + w.p1 * f[0][m] + w.p2 * (f[1][m] + f[2][m]) + w.p3 * f[3][m];
        }
        x.modes.to_joints(&y1, &mut self.qd);
        x.modes.to_joints(&dy, &mut self.q);
        for (q, q0) in self.q.iter_mut().zip(&x.q0) {
            *q += q0;
        }
        x.end = [y1, dy];
    }
}

/// The modal forcing of stage `stage`: W⁻¹ q̈ + Λ y, i.e. everything but
/// the damping's linear part at M₀ (q̈ is in `x.g`).
fn forcing(x: &mut Exponential, stage: usize) {
    let f = &mut x.f[stage][..x.modes.len()];
    x.modes.to_modes(&x.g, f);
    for (m, f) in f.iter_mut().enumerate() {
        *f += x.modes.rate(m) * x.y[stage][m];
    }
}
