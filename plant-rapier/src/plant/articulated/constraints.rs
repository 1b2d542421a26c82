//! Dry friction and hard stops as velocity impulses at the end of a substep,
//! solved by projected Gauss–Seidel like Rapier's joint constraints: a
//! friction impulse is bounded by the friction torque times the substep, a
//! stop's only pushes back, and a stop is enforced once it is passed.
//!
//! With URDF damping integrated exactly, a friction impulse stands for a
//! constant torque over the substep, so it moves each stiff mode of the
//! damping by what that torque would (φ1 of its velocity, φ2 of its
//! displacement; the rest as undamped): an undamped impulse on a stiffly
//! damped light joint would overshoot it by λh and creep a stuck arm. A
//! stop acts at once (M⁻¹ as before).

use super::Follow;
use super::exponential::{Modes, Weights};
use super::linalg::Cholesky;

/// Which way a stop pushes.
#[derive(Debug, Clone, Copy)]
enum Row {
    /// Dry friction on a coordinate: |impulse| ≤ bound.
    Friction { coord: usize, bound: f64 },
    /// A passed lower (push ≥ 0) or upper (push ≤ 0) stop.
    Stop { coord: usize, upper: bool },
}

/// The constraints of one arm, with scratch space.
#[derive(Debug, Clone)]
pub(super) struct Impulses {
    /// Per full coordinate.
    friction: Vec<f64>,
    limits: Vec<Option<(f64, f64)>>,
    rows: Vec<Row>,
    lambda: Vec<f64>,
    /// M⁻¹ e_j for each controlled joint j, filled when needed.
    inverse: Vec<f64>,
    /// A friction impulse's velocity change per unit on joint j: M⁻¹ e_j,
    /// or its damped response.
    friction_response: Vec<f64>,
    /// The velocity change from friction alone.
    friction_dv: Vec<f64>,
    /// The friction impulse per controlled joint.
    friction_impulse: Vec<f64>,
    /// The joints whose columns the friction rows and the stop rows read.
    friction_cols: Vec<usize>,
    stop_cols: Vec<usize>,
    n: usize,
}

/// PGS sweeps: rows couple only through M⁻¹; a few sweeps converge for arms.
const SWEEPS: usize = 8;

impl Impulses {
    pub(super) fn new(friction: Vec<f64>, limits: Vec<Option<(f64, f64)>>, n: usize) -> Self {
        let rows = friction.len() + limits.len();
        Self {
            friction,
            limits,
            rows: Vec::with_capacity(rows),
            lambda: Vec::with_capacity(rows),
            inverse: vec![0.0; n * n],
            friction_response: vec![0.0; n * n],
            friction_dv: vec![0.0; n],
            friction_impulse: vec![0.0; n],
            friction_cols: Vec::with_capacity(n),
            stop_cols: Vec::with_capacity(n),
            n,
        }
    }

    /// Whether anything may need an impulse after a substep that ends at q.
    pub(super) fn needed(&self, follow: &[Follow], q: &[f64]) -> bool {
        self.friction.iter().any(|f| *f > 0.0) || self.passed(follow, q).next().is_some()
    }

    /// The joints whose columns the friction rows and the stop rows read,
    /// each once.
    /// Into `friction_cols` and `stop_cols`.
    fn columns(&mut self, follow: &[Follow]) {
        self.friction_cols.clear();
        self.stop_cols.clear();
        for row in &self.rows {
            let (coord, list) = match *row {
                Row::Friction { coord, .. } => (coord, &mut self.friction_cols),
                Row::Stop { coord, .. } => (coord, &mut self.stop_cols),
            };
            let leader = follow[coord].leader;
            if !list.contains(&leader) {
                list.push(leader);
            }
        }
    }

    /// Whether a stop is passed at q.
    pub(super) fn stop_passed(&self, follow: &[Follow], q: &[f64]) -> bool {
        self.passed(follow, q).next().is_some()
    }

    /// Stops passed at q: (coordinate, upper, limit).
    fn passed<'a>(
        &'a self,
        follow: &'a [Follow],
        q: &'a [f64],
    ) -> impl Iterator<Item = (usize, bool, f64)> + 'a {
        self.limits
            .iter()
            .zip(follow)
            .enumerate()
            .filter_map(|(k, (l, f))| {
                let (lo, hi) = (*l)?;
                let x = f.multiplier * q[f.leader] + f.offset;
                if x > hi {
                    Some((k, true, hi))
                } else if x < lo {
                    Some((k, false, lo))
                } else {
                    None
                }
            })
    }

    /// Applies the impulses to q̇ (and friction's share of the substep to q),
    /// then puts every passed stop's coordinate back at the stop. `m` is
    /// read only for a passed stop, or for friction when `damped` is None,
    /// and then holds the factored inertia at the end of the substep;
    /// `damped`, the URDF damping's modes over it, if the step used them.
    pub(super) fn apply(
        &mut self,
        follow: &[Follow],
        m: &Cholesky,
        damped: Option<&Modes>,
        q: &mut [f64],
        qd: &mut [f64],
        h: f64,
    ) {
        let n = self.n;
        self.rows.clear();
        for (coord, f) in self.friction.iter().enumerate() {
            if *f > 0.0 {
                self.rows.push(Row::Friction {
                    coord,
                    bound: f * h,
                });
            }
        }
        let stops: Vec<(usize, bool, f64)> = self.passed(follow, q).collect();
        for &(coord, upper, _) in &stops {
            self.rows.push(Row::Stop { coord, upper });
        }
        // M⁻¹'s columns for the stops, and for friction when no damping
        // acts; with damping, friction's response is the modes' (a stop's
        // impulse is instantaneous, friction's a torque over the substep).
        // Only the rows' own joints' columns are read.
        self.columns(follow);
        match damped {
            Some(modes) => modes.response_columns(
                |w: &Weights| w.phi1,
                &self.friction_cols,
                &mut self.friction_response,
            ),
            None => m.inverse_columns(&self.friction_cols, &mut self.friction_response),
        }
        m.inverse_columns(&self.stop_cols, &mut self.inverse);
        self.lambda.clear();
        self.lambda.resize(self.rows.len(), 0.0);
        self.friction_dv.iter_mut().for_each(|x| *x = 0.0);
        self.friction_impulse.iter_mut().for_each(|x| *x = 0.0);
        for _ in 0..SWEEPS {
            // A sweep that moves no multiplier leaves q̇ as it was, so every
            // later sweep would repeat it: the rest are skipped, exactly.
            let mut moved = false;
            for (r, row) in self.rows.iter().enumerate() {
                let (coord, cols) = match *row {
                    Row::Friction { coord, .. } => (coord, &self.friction_response),
                    Row::Stop { coord, .. } => (coord, &self.inverse),
                };
                let f = follow[coord];
                let col = &cols[f.leader * n..(f.leader + 1) * n];
                let w = f.multiplier * f.multiplier * col[f.leader];
                let rate = f.multiplier * qd[f.leader];
                let old = self.lambda[r];
                let free = old - rate / w;
                let new = match *row {
                    Row::Friction { bound, .. } => free.clamp(-bound, bound),
                    Row::Stop { upper: true, .. } => free.min(0.0),
                    Row::Stop { upper: false, .. } => free.max(0.0),
                };
                self.lambda[r] = new;
                if new == old {
                    continue;
                }
                moved = true;
                let push = f.multiplier * (new - old);
                let friction = matches!(row, Row::Friction { .. });
                if friction {
                    self.friction_impulse[f.leader] += push;
                }
                for i in 0..n {
                    qd[i] += col[i] * push;
                    if friction {
                        self.friction_dv[i] += col[i] * push;
                    }
                }
            }
            if !moved {
                break;
            }
        }
        // Friction acted over the substep as a constant torque: its effect
        // on q is half its velocity change times h undamped (exact), and
        // each damped mode's φ2 share of it otherwise.
        match damped {
            Some(modes) => {
                let mut dq = std::mem::take(&mut self.friction_dv);
                modes.response(|w: &Weights| w.phi2, &self.friction_impulse, &mut dq);
                for (q, dq) in q.iter_mut().zip(&dq) {
                    *q += h * dq;
                }
                self.friction_dv = dq;
            }
            None => {
                for (q, dv) in q.iter_mut().zip(&self.friction_dv) {
                    *q += 0.5 * h * dv;
                }
            }
        }
        for (coord, _, limit) in stops {
            let f = follow[coord];
            if f.multiplier != 0.0 {
                let x = f.multiplier * q[f.leader] + f.offset;
                q[f.leader] += (limit - x) / f.multiplier;
            }
        }
    }
}
