//! `mpc`'s quadratic program (BASELINES §3): a constrained linear MPC on
//! the error dynamics that computed torque leaves, ë_i = u_i per joint,
//! with |e_i| ≤ k_c,i over the horizon from T_c on, solved by `clarabel`
//! every control step. [`crate::feedback::Feedback`] turns its first input
//! into a torque through the law's model, as `ctc` does. Optionally the
//! inputs are bounded (the torque box of `torque_box.rs`) and the rows are
//! tightened against a disturbance bound w on ë = u + d (tube MPC, [`Tube`]).

use clarabel::algebra::CscMatrix;

use crate::mpc_polish::Polish;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// The bound a constraint row gets before T_c: never reached, so the row
/// keeps its place in the QP (the solver is built once) without acting.
const OFF_BOUND: f64 = 1e3;

/// One step's errors and envelope, per joint.
pub(crate) struct MpcInput<'a> {
    /// Time, s.
    pub t: f64,
    /// e = q − q_d.
    pub e: &'a [f64],
    /// ė.
    pub ed: &'a [f64],
    /// k_c.
    pub kc: &'a [f64],
    /// k̇_c.
    pub kc_dot: &'a [f64],
    /// The bound |u_i| ≤ a_i of this step, if the QP has input rows.
    pub u_max: Option<&'a [f64]>,
}

/// How the QP is posed: its horizon N, step h, the time T_c from which
/// the envelope holds, whether it has input rows, and the disturbance
/// bound w it is tightened against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MpcShape {
    pub horizon: usize,
    pub h: f64,
    pub tc: f64,
    pub bounded: bool,
    pub disturbance: f64,
}

/// The QP of n joints: the error dynamics do not couple the joints, so it
/// is n independent QPs, each built once and re-solved with new bounds
/// every step.
#[derive(Debug)]
pub(crate) struct ErrorMpc {
    joints: Vec<JointQp>,
    shape: MpcShape,
    /// The inputs of the last step.
    u: Vec<f64>,
    /// How many QPs the solver has solved (the others were settled by the
    /// unconstrained optimum's check).
    solves: u64,
}

/// One joint's QP.
struct JointQp {
    solver: DefaultSolver<f64>,
    /// The constraint vector: the dynamics rows, then the envelope rows.
    b: Vec<f64>,
    /// ω = √K_p: ė = ω v, u = ω² w.
    omega: f64,
    /// The unconstrained optimum's gain: u = −(k_e e + k_v ė).
    lqr: [f64; 2],
    /// What the disturbance bound takes off each row.
    tube: Tube,
    /// Whether the QP has input rows.
    bounded: bool,
    /// The exact optimum from the solver's active rows.
    polish: Polish,
}

/// Constraint tightening against |d| ≤ w on ë = u + d, in the form of
/// Chisci, Rossiter & Zappa (Automatica 37(7), 2001), the tube of Mayne,
/// Seron & Raković (Automatica 41(2), 2005) with its centre started at the
/// measured state: the real error is the nominal prediction plus
/// ε_{j+1} = (A − BK) ε_j + δ_j, ε_0 = 0, under the ancillary feedback
/// u = v − K ε (K the LQR gain below), where one step's δ is within
/// (w h²/2, w h) per component whatever d does inside the step. So
/// |ε_e,j| ≤ α_j = Σ_{i<j} |row_e (A − BK)^i| δ̄ and |K ε_j| ≤ β_j =
/// Σ_{i<j} |K (A − BK)^i| δ̄, and the nominal rows become |e_j| ≤ k_j − α_j
/// and |v_j| ≤ a − β_j (each at least 0). With w = 0 both are 0: the
/// nominal MPC.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Tube {
    /// α_j, j = 0 … N.
    pub e: Vec<f64>,
    /// β_j, j = 0 … N − 1.
    pub u: Vec<f64>,
}

impl Tube {
    /// The tightening for the physical gain u = −(k_e e + k_v ė), step h.
    pub(crate) fn new(lqr: [f64; 2], h: f64, horizon: usize, w: f64) -> Self {
        let [ke, kv] = lqr;
        let ak = [
            [1.0 - 0.5 * h * h * ke, h - 0.5 * h * h * kv],
            [-h * ke, 1.0 - h * kv],
        ];
        let delta = [0.5 * h * h * w, h * w];
        let mut p: [[f64; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];
        let mut tube = Self {
            e: vec![0.0; horizon + 1],
            u: vec![0.0; horizon],
        };
        for i in 0..horizon {
            let de = p[0][0].abs() * delta[0] + p[0][1].abs() * delta[1];
            let kp = [ke * p[0][0] + kv * p[1][0], ke * p[0][1] + kv * p[1][1]];
            let du = kp[0].abs() * delta[0] + kp[1].abs() * delta[1];
            tube.e[i + 1] = tube.e[i] + de;
            if i + 1 < horizon {
                tube.u[i + 1] = tube.u[i] + du;
            }
            p = [
                [
                    ak[0][0] * p[0][0] + ak[0][1] * p[1][0],
                    ak[0][0] * p[0][1] + ak[0][1] * p[1][1],
                ],
                [
                    ak[1][0] * p[0][0] + ak[1][1] * p[1][0],
                    ak[1][0] * p[0][1] + ak[1][1] * p[1][1],
                ],
            ];
        }
        tube
    }
}

impl std::fmt::Debug for JointQp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JointQp")
            .field("lqr", &self.lqr)
            .finish_non_exhaustive()
    }
}

/// One joint's weights. The stage cost is ½(K_p² e² + (K_d² − 2K_p) ė² +
/// u²) h: its continuous-time LQR has `ctc`'s poles, the roots of
/// s² + K_d s + K_p (with K_d² < 2K_p the ė weight is 0: complex poles no
/// LQR of this form gives). The QP is posed in the joint's own time scale
/// ω = √K_p (ė = ω v, u = ω² w, a step of θ = ω h), where that cost is
/// K_p² h / ω · ½(e² + q_v v² + w²) θ with q_v = 4ζ² − 2, ζ = K_d / 2ω:
/// every weight of order one, which keeps the interior-point solver's
/// linear systems well conditioned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Weights {
    omega: f64,
    q_v: f64,
}

impl Weights {
    /// The weights matching `ctc`'s gains K_p, K_d.
    pub(crate) fn matching(kp: f64, kd: f64) -> Self {
        Self {
            omega: kp.sqrt(),
            q_v: (kd * kd / kp - 2.0).max(0.0),
        }
    }
}

/// Why the QP could not be set up.
#[derive(Debug, thiserror::Error)]
pub(crate) enum MpcSetupError {
    /// The terminal cost's Riccati iteration did not converge.
    #[error("the terminal cost's Riccati equation did not converge")]
    Riccati,
    /// The dynamics rows could not be inverted to condense the QP.
    #[error("the QP's dynamics rows are singular")]
    Dynamics,
    /// clarabel refused the problem.
    #[error("the QP solver refused the problem: {0}")]
    Solver(#[from] clarabel::solver::SolverError),
    /// clarabel refused the settings (a setting out of its range: every
    /// step would otherwise solve with defaults the law was not tested with).
    #[error("the QP solver refused its settings: {0}")]
    Settings(#[from] clarabel::solver::DefaultSettingsBuilderError),
}

impl ErrorMpc {
    /// The QP for `weights.len()` joints posed as `shape` says.
    pub(crate) fn new(weights: &[Weights], shape: MpcShape) -> Result<Self, MpcSetupError> {
        let joints = weights
            .iter()
            .map(|w| JointQp::new(w, &shape))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            joints,
            shape,
            u: vec![0.0; weights.len()],
            solves: 0,
        })
    }

    /// This step's first input of each joint, and whether the envelope
    /// could not be held (a solve that failed: then that joint's u is the
    /// unconstrained optimum, clipped to the input bound; with u unbounded
    /// and w = 0 the QP is always feasible, e₁ alone can be put anywhere,
    /// but bounded inputs or a tightened envelope can make it infeasible).
    /// A joint whose unconstrained optimum keeps every predicted error and
    /// input inside its rows has no active constraint: that optimum is
    /// the QP's solution, and the solver is not called.
    pub(crate) fn solve(&mut self, x: &MpcInput<'_>) -> (&[f64], bool) {
        let mut breached = false;
        let horizon = self.shape.horizon;
        for i in 0..self.joints.len() {
            let bounds = self.bounds(x, i);
            let joint = &mut self.joints[i];
            let x0 = [x.e[i], x.ed[i]];
            let [ke, kv] = joint.lqr;
            let unconstrained = -(ke * x0[0] + kv * x0[1]);
            if joint.rollout_inside(x0, horizon, &bounds) {
                self.u[i] = unconstrained;
                continue;
            }
            self.solves += 1;
            match joint.solve(x0, horizon, &bounds) {
                Some(u) => self.u[i] = u,
                None => {
                    let a = joint.input_bound(&bounds, 0).unwrap_or(f64::INFINITY);
                    self.u[i] = unconstrained.clamp(-a, a);
                    breached = true;
                }
            }
        }
        (&self.u, breached)
    }

    /// How many joint QPs went to the solver so far (tests).
    #[cfg(test)]
    pub(crate) fn solves(&self) -> u64 {
        self.solves
    }

    /// The unconstrained optimum's gains per joint (tests and docs).
    #[cfg(test)]
    pub(crate) fn lqr(&self) -> Vec<[f64; 2]> {
        self.joints.iter().map(|j| j.lqr).collect()
    }

    /// Solves joint `i`'s QP with the solver, whether or not a constraint
    /// is active (tests).
    #[cfg(test)]
    pub(crate) fn solve_joint(&mut self, i: usize, x: &MpcInput<'_>) -> Option<f64> {
        let bounds = self.bounds(x, i);
        self.joints[i].solve([x.e[i], x.ed[i]], self.shape.horizon, &bounds)
    }

    /// Joint `i`'s tightening (tests).
    #[cfg(test)]
    pub(crate) fn tube(&self, i: usize) -> &Tube {
        &self.joints[i].tube
    }

    /// Joint `i`'s envelope and input bound over the horizon.
    fn bounds(&self, x: &MpcInput<'_>, i: usize) -> Bounds {
        Bounds {
            t: x.t,
            tc: self.shape.tc,
            h: self.shape.h,
            kc: x.kc[i],
            rate: x.kc_dot[i] / x.kc[i],
            u_max: x.u_max.and_then(|a| a.get(i).copied()),
        }
    }
}

/// The envelope over the horizon: k_j at predicted time t + jh ≥ T_c,
/// k_c extrapolated as an exponential (exact for the shipped envelopes'
/// decay, and positive whatever k̇_c is); no bound before T_c.
struct Bounds {
    t: f64,
    tc: f64,
    h: f64,
    kc: f64,
    /// k̇_c / k_c.
    rate: f64,
    /// The input bound a of this step, if any.
    u_max: Option<f64>,
}

impl Bounds {
    fn at(&self, j: usize) -> Option<f64> {
        let dt = j as f64 * self.h;
        (self.t + dt >= self.tc).then(|| (self.kc * (self.rate * dt).exp()).min(OFF_BOUND))
    }
}

impl JointQp {
    fn new(w: &Weights, shape: &MpcShape) -> Result<Self, MpcSetupError> {
        let (horizon, h) = (shape.horizon, shape.h);
        let theta = w.omega * h;
        let terminal = riccati(w.q_v, theta).ok_or(MpcSetupError::Riccati)?;
        let layout = Layout {
            horizon,
            bounded: shape.bounded,
        };
        let p = layout.cost(w.q_v, &terminal, theta);
        let q = vec![0.0; layout.vars()];
        let a = layout.constraints(theta);
        let b = layout.initial_bounds();
        let cones = [
            SupportedConeT::ZeroConeT(layout.equality_rows()),
            SupportedConeT::NonnegativeConeT(a.m - layout.equality_rows()),
        ];
        let solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings()?)?;
        let polish = Polish::new(&p, &a, layout.equality_rows()).ok_or(MpcSetupError::Dynamics)?;
        let [ke, kv] = lqr_gain(&terminal, theta);
        let lqr = [w.omega * w.omega * ke, w.omega * kv];
        Ok(Self {
            solver,
            b,
            omega: w.omega,
            lqr,
            tube: Tube::new(lqr, h, horizon, shape.disturbance),
            bounded: shape.bounded,
            polish,
        })
    }

    /// The envelope row at step j, tightened: k_j − α_j (at least 0), or
    /// None before T_c.
    fn envelope(&self, bounds: &Bounds, j: usize) -> Option<f64> {
        bounds.at(j).map(|k| (k - self.tube.e[j]).max(0.0))
    }

    /// The input row at step k, tightened: a − β_k (at least 0), or None
    /// without input rows.
    fn input_bound(&self, bounds: &Bounds, k: usize) -> Option<f64> {
        match self.bounded {
            true => bounds.u_max.map(|a| (a - self.tube.u[k]).max(0.0)),
            false => None,
        }
    }

    /// Whether x_{j+1} = (A − BK) x_j from `x0` keeps every predicted
    /// error and input inside its (tightened) row.
    fn rollout_inside(&self, x0: [f64; 2], horizon: usize, bounds: &Bounds) -> bool {
        let h = bounds.h;
        let [ke, kv] = self.lqr;
        let [mut e, mut ed] = x0;
        for j in 1..=horizon {
            let u = -(ke * e + kv * ed);
            if self.input_bound(bounds, j - 1).is_some_and(|a| u.abs() > a) {
                return false;
            }
            (e, ed) = (e + h * ed + 0.5 * h * h * u, ed + h * u);
            if self.envelope(bounds, j).is_some_and(|k| e.abs() > k) {
                return false;
            }
        }
        true
    }

    /// The solver's u₀, or None if it did not solve.
    fn solve(&mut self, x0: [f64; 2], horizon: usize, bounds: &Bounds) -> Option<f64> {
        let layout = Layout {
            horizon,
            bounded: self.bounded,
        };
        let (e_row, v_row) = (layout.equality_row(1, 0), layout.equality_row(1, 1));
        let v0 = x0[1] / self.omega;
        self.b[e_row] = x0[0] + self.omega * bounds.h * v0;
        self.b[v_row] = v0;
        for j in 1..=horizon {
            let (upper, lower) = layout.envelope_rows(j);
            let k = self.envelope(bounds, j).unwrap_or(OFF_BOUND);
            (self.b[upper], self.b[lower]) = (k, k);
        }
        let scale = self.omega * self.omega;
        for k in 0..horizon {
            if let Some((upper, lower)) = layout.input_rows(k) {
                // w = u / ω².
                let a = self.input_bound(bounds, k).map_or(OFF_BOUND, |a| a / scale);
                (self.b[upper], self.b[lower]) = (a, a);
            }
        }
        self.solver.update_b(&self.b).ok()?;
        self.solver.solve();
        let solution = &self.solver.solution;
        if !matches!(
            solution.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        ) {
            return None;
        }
        let w0 = match self.polish.inputs(&self.b, &solution.s, &solution.z) {
            Some(w) => w[0],
            None => solution.x[layout.input(0)],
        };
        Some(self.omega * self.omega * w0)
    }
}

fn settings() -> Result<DefaultSettings<f64>, clarabel::solver::DefaultSettingsBuilderError> {
    // Presolve and dropped zeros are off so that `update_b` is allowed.
    // The QP is small and well scaled (see `Weights`): iterative
    // refinement would halve the solve rate and change nothing the law
    // uses. The gap tolerances stay at clarabel's defaults (1e-8), which
    // leave u₀ up to 6e-4 off where a row is active; `Polish` then makes
    // it exact from the active rows. Closing the gap to 1e-12 instead cost
    // about two more iterations and doubled the step time on the iiwa14
    // (docs/results.md, "MPC solve time").
    DefaultSettingsBuilder::default()
        .verbose(false)
        .presolve_enable(false)
        .input_sparse_dropzeros(false)
        .iterative_refinement_enable(false)
        .max_iter(50)
        .build()
}

/// Where each variable and row of one joint's QP lies. The variables are
/// x₁ … x_N (e_j, v_j interleaved) and w₀ … w_{N−1}; the rows are the 2N
/// dynamics equalities, then e_j ≤ k_j and −e_j ≤ k_j for j = 1 … N, then
/// (if bounded) w_k ≤ a_k and −w_k ≤ a_k for k = 0 … N − 1.
#[derive(Clone, Copy)]
struct Layout {
    horizon: usize,
    bounded: bool,
}

impl Layout {
    fn vars(self) -> usize {
        3 * self.horizon
    }
    fn state(self, j: usize, component: usize) -> usize {
        2 * (j - 1) + component
    }
    fn input(self, k: usize) -> usize {
        2 * self.horizon + k
    }
    fn equality_rows(self) -> usize {
        2 * self.horizon
    }
    fn equality_row(self, j: usize, component: usize) -> usize {
        2 * (j - 1) + component
    }
    fn envelope_rows(self, j: usize) -> (usize, usize) {
        let r = self.equality_rows() + 2 * (j - 1);
        (r, r + 1)
    }
    fn input_rows(self, k: usize) -> Option<(usize, usize)> {
        let r = self.equality_rows() + 2 * self.horizon + 2 * k;
        self.bounded.then_some((r, r + 1))
    }
    fn rows(self) -> usize {
        let inputs = if self.bounded { 2 * self.horizon } else { 0 };
        self.equality_rows() + 2 * self.horizon + inputs
    }

    /// b before the first step: dynamics rows 0 (the first two are set
    /// each step), the envelope rows off.
    fn initial_bounds(self) -> Vec<f64> {
        let mut b = vec![OFF_BOUND; self.rows()];
        b[..self.equality_rows()].fill(0.0);
        b
    }

    /// P (upper triangle): ½(e² + q_v v²) θ per stage before the last,
    /// ½ x_Nᵀ P_T x_N at the end, ½ w² θ.
    fn cost(self, q_v: f64, pt: &[f64; 3], theta: f64) -> CscMatrix<f64> {
        let mut t = Triplets::default();
        for j in 1..self.horizon {
            t.push(self.state(j, 0), self.state(j, 0), theta);
            t.push(self.state(j, 1), self.state(j, 1), q_v * theta);
        }
        let (e, v) = (self.state(self.horizon, 0), self.state(self.horizon, 1));
        t.push(e, e, pt[0]);
        t.push(e, v, pt[1]);
        t.push(v, v, pt[2]);
        for k in 0..self.horizon {
            t.push(self.input(k), self.input(k), theta);
        }
        t.into_csc(self.vars(), self.vars())
    }

    /// A: x_j − A x_{j−1} − B w_{j−1} = 0 (x₀ moves to b), with
    /// A = [[1, θ], [0, 1]], B = [θ²/2, θ]; then the envelope rows.
    fn constraints(self, theta: f64) -> CscMatrix<f64> {
        let mut t = Triplets::default();
        for j in 1..=self.horizon {
            let (re, rv) = (self.equality_row(j, 0), self.equality_row(j, 1));
            t.push(re, self.state(j, 0), 1.0);
            t.push(rv, self.state(j, 1), 1.0);
            if j > 1 {
                t.push(re, self.state(j - 1, 0), -1.0);
                t.push(re, self.state(j - 1, 1), -theta);
                t.push(rv, self.state(j - 1, 1), -1.0);
            }
            t.push(re, self.input(j - 1), -0.5 * theta * theta);
            t.push(rv, self.input(j - 1), -theta);
            let (upper, lower) = self.envelope_rows(j);
            t.push(upper, self.state(j, 0), 1.0);
            t.push(lower, self.state(j, 0), -1.0);
            if let Some((upper, lower)) = self.input_rows(j - 1) {
                t.push(upper, self.input(j - 1), 1.0);
                t.push(lower, self.input(j - 1), -1.0);
            }
        }
        t.into_csc(self.rows(), self.vars())
    }
}

#[derive(Default)]
struct Triplets {
    rows: Vec<usize>,
    cols: Vec<usize>,
    values: Vec<f64>,
}

impl Triplets {
    fn push(&mut self, row: usize, col: usize, value: f64) {
        self.rows.push(row);
        self.cols.push(col);
        self.values.push(value);
    }
    fn into_csc(self, m: usize, n: usize) -> CscMatrix<f64> {
        CscMatrix::new_from_triplets(m, n, self.rows, self.cols, self.values)
    }
}

/// The discrete Riccati equation's solution [p11, p12, p22] for the
/// double integrator of step θ (A = [[1, θ], [0, 1]], B = [θ²/2, θ]) with
/// stage weights Q = diag(1, q_v) θ, R = θ: the terminal cost that makes
/// the finite horizon's unconstrained optimum the infinite horizon's.
/// None if the iteration does not settle.
fn riccati(q_v: f64, theta: f64) -> Option<[f64; 3]> {
    let (b1, b2) = (0.5 * theta * theta, theta);
    let mut p = [theta, 0.0, q_v * theta];
    for _ in 0..200_000 {
        let [p11, p12, p22] = p;
        // AᵀPA, PB, AᵀPB.
        let apa = [
            p11,
            p11 * theta + p12,
            p11 * theta * theta + 2.0 * p12 * theta + p22,
        ];
        let pb = [p11 * b1 + p12 * b2, p12 * b1 + p22 * b2];
        let apb = [pb[0], theta * pb[0] + pb[1]];
        let s = theta + b1 * pb[0] + b2 * pb[1];
        let next = [
            theta + apa[0] - apb[0] * apb[0] / s,
            apa[1] - apb[0] * apb[1] / s,
            q_v * theta + apa[2] - apb[1] * apb[1] / s,
        ];
        let change = (0..3).map(|k| (next[k] - p[k]).abs()).fold(0.0, f64::max);
        let scale = next.iter().map(|x| x.abs()).fold(0.0, f64::max);
        p = next;
        if !p.iter().all(|x| x.is_finite()) {
            return None;
        }
        if change <= 1e-13 * scale {
            return Some(p);
        }
    }
    None
}

/// K = (R + BᵀPB)⁻¹ BᵀPA in the scaled variables: w = −K [e, v].
fn lqr_gain(p: &[f64; 3], theta: f64) -> [f64; 2] {
    let (b1, b2) = (0.5 * theta * theta, theta);
    let [p11, p12, p22] = *p;
    let pb = [p11 * b1 + p12 * b2, p12 * b1 + p22 * b2];
    let s = theta + b1 * pb[0] + b2 * pb[1];
    [pb[0] / s, (theta * pb[0] + pb[1]) / s]
}

#[cfg(test)]
#[path = "mpc_tests.rs"]
mod tests;
