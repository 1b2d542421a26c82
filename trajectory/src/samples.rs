//! A trajectory given as samples (a planner's output, a recorded motion):
//! a CSV of time and one column per joint, read and checked here (the file
//! itself is read by the scenario loader: this crate does no I/O), and
//! interpolated by a cubic spline with zero rate at both ends, so q̇_d and
//! q̈_d are its exact derivatives (q̈_d continuous) and the held ends join
//! without a jump in velocity.

use serde::{Deserialize, Serialize};

use crate::TrajectoryError;

/// Most rows a trajectory file may have (10⁶: 17 minutes at 1 kHz).
pub const MAX_ROWS: usize = 1_000_000;

/// Samples of one signal per column at times `t`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Samples {
    /// Where they came from, for messages.
    pub source: String,
    /// Column names after `t`.
    pub columns: Vec<String>,
    /// Times, s, strictly increasing.
    pub t: Vec<f64>,
    /// Per column, one value per time.
    pub values: Vec<Vec<f64>>,
    /// The header's row in its file, from 1, for messages (None: the
    /// samples were given inline or read back from a log).
    #[serde(skip)]
    pub header_row: Option<usize>,
}

/// Equal samples are equal wherever their header stood.
impl PartialEq for Samples {
    fn eq(&self, other: &Self) -> bool {
        (&self.source, &self.columns, &self.t, &self.values)
            == (&other.source, &other.columns, &other.t, &other.values)
    }
}

/// The closest two sample times may be, s: a microsecond. Times 1e-300
/// apart passed "increasing" and made the spline's slopes overflow on
/// every step.
pub const MIN_TIME_STEP_S: f64 = 1e-6;

/// The largest |t| taken, s (eleven days).
pub const MAX_TIME_S: f64 = 1e6;

/// The largest |value| taken (rad or m for a reference, the envelope's
/// width for an envelope): 1e3 is past any joint's travel, where 1e200
/// passed "finite" and then overflowed the controller's squares.
pub const MAX_VALUE: f64 = 1e3;

/// Why `v`, a time, is out of bounds after `last` (None: it is not).
fn time_out_of_bounds(v: f64, last: Option<f64>) -> Option<String> {
    if !(-MAX_TIME_S..=MAX_TIME_S).contains(&v) {
        return Some(format!(
            "time {v:e} is out of range: times must be from -1e6 to 1e6 s"
        ));
    }
    match last {
        Some(last) if v <= last => Some(format!(
            "time {v} does not come after the previous row's {last}: times must increase"
        )),
        Some(last) if v - last < MIN_TIME_STEP_S => Some(format!(
            "time {v:e} comes {:e} s after the previous row's {last:e}: times must be at least 1e-6 s apart",
            v - last
        )),
        _ => None,
    }
}

/// Why `v`, a value, is out of bounds (None: it is not).
fn value_out_of_bounds(v: f64) -> Option<String> {
    (!(-MAX_VALUE..=MAX_VALUE).contains(&v))
        .then(|| format!("{v:e} is out of range: values must be from -1000 to 1000"))
}

fn csv_error(
    source: &str,
    row: usize,
    column: usize,
    name: &str,
    reason: String,
) -> TrajectoryError {
    TrajectoryError::Csv {
        file: source.to_string(),
        row,
        column,
        name: name.to_string(),
        reason,
    }
}

impl Samples {
    /// Reads CSV `text` from `source`: a header `t,<name>,…`, then rows of
    /// numbers; `#` lines and blank lines are skipped. Rows and columns in
    /// errors count from 1, as a spreadsheet shows them.
    pub fn from_csv(text: &str, source: &str) -> Result<Self, TrajectoryError> {
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let Some((h_row, header)) = lines.next() else {
            return Err(csv_error(
                source,
                1,
                1,
                "t",
                "the file is empty: give a header `t,<joint>,…` and rows".into(),
            ));
        };
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
        if names[0] != "t" || names.len() < 2 {
            return Err(csv_error(
                source,
                h_row + 1,
                1,
                &names[0],
                "the header must be `t` then one column per joint".into(),
            ));
        }
        let mut out = Samples {
            source: source.to_string(),
            columns: names[1..].to_vec(),
            t: Vec::new(),
            values: vec![Vec::new(); names.len() - 1],
            header_row: Some(h_row + 1),
        };
        for (row, line) in lines {
            if out.t.len() >= MAX_ROWS {
                return Err(csv_error(
                    source,
                    row + 1,
                    1,
                    "t",
                    format!("more than {MAX_ROWS} rows"),
                ));
            }
            out.push_row(line, row + 1, &names)?;
        }
        if out.t.len() < 2 {
            return Err(csv_error(
                source,
                h_row + 2,
                1,
                "t",
                "at least two rows are needed".into(),
            ));
        }
        Ok(out)
    }

    /// The samples with one column per joint of `joints`, in the arm's
    /// order, each found by its name in the header: a column is never
    /// taken for a joint by its place (`t,joint2,joint1` drove joint1 with
    /// joint2's motion). A name that is no joint of the arm, a name given
    /// twice and a joint with no column are refused, naming the file, the
    /// header's row and the column (or the joints missing).
    pub fn by_joint_names(&self, joints: &[String]) -> Result<Self, TrajectoryError> {
        let row = self.header_row.unwrap_or(1);
        let at = |c: usize, reason: String| {
            csv_error(&self.source, row, c + 2, &self.columns[c], reason)
        };
        let mut order: Vec<Option<usize>> = vec![None; joints.len()];
        for (c, name) in self.columns.iter().enumerate() {
            let Some(j) = joints.iter().position(|n| n == name) else {
                return Err(at(
                    c,
                    format!(
                        "no joint of the arm is named so: the header names each column by its joint ({})",
                        joints.join(", ")
                    ),
                ));
            };
            if let Some(first) = order[j] {
                return Err(at(
                    c,
                    format!("joint '{name}' has a column already (column {})", first + 2),
                ));
            }
            order[j] = Some(c);
        }
        let missing: Vec<&str> = joints
            .iter()
            .zip(&order)
            .filter(|(_, c)| c.is_none())
            .map(|(n, _)| n.as_str())
            .collect();
        if !missing.is_empty() {
            return Err(csv_error(
                &self.source,
                row,
                self.columns.len() + 2,
                missing[0],
                format!(
                    "no column for joint{} {}: the header needs `t` then one column per joint, by name",
                    if missing.len() == 1 { "" } else { "s" },
                    missing.join(", ")
                ),
            ));
        }
        let order: Vec<usize> = order.into_iter().flatten().collect();
        Ok(Self {
            source: self.source.clone(),
            columns: joints.to_vec(),
            t: self.t.clone(),
            values: order.iter().map(|&c| self.values[c].clone()).collect(),
            header_row: self.header_row,
        })
    }

    fn push_row(
        &mut self,
        line: &str,
        row: usize,
        names: &[String],
    ) -> Result<(), TrajectoryError> {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(csv_error(
                &self.source,
                row,
                cells.len().min(names.len()) + 1,
                names.get(cells.len()).map_or("", String::as_str),
                format!("{} cells, but the header has {}", cells.len(), names.len()),
            ));
        }
        for (c, (cell, name)) in cells.iter().zip(names).enumerate() {
            let v: f64 = cell.parse().map_err(|_| {
                csv_error(
                    &self.source,
                    row,
                    c + 1,
                    name,
                    format!("{cell:?} is not a number"),
                )
            })?;
            if !v.is_finite() {
                return Err(csv_error(
                    &self.source,
                    row,
                    c + 1,
                    name,
                    format!("{v} is not finite"),
                ));
            }
            if c == 0 {
                if let Some(why) = time_out_of_bounds(v, self.t.last().copied()) {
                    return Err(csv_error(&self.source, row, 1, name, why));
                }
                self.t.push(v);
            } else {
                if let Some(why) = value_out_of_bounds(v) {
                    return Err(csv_error(&self.source, row, c + 1, name, why));
                }
                self.values[c - 1].push(v);
            }
        }
        Ok(())
    }

    /// Checks samples given inline (not from a file): the shape a CSV
    /// would have had.
    pub(crate) fn validate(&self, field: &str) -> Result<(), TrajectoryError> {
        let invalid = |reason: String| TrajectoryError::Invalid {
            field: field.to_string(),
            reason,
        };
        if self.t.len() < 2 || self.values.is_empty() {
            return Err(invalid(
                "at least two times and one column are needed".into(),
            ));
        }
        if self.values.iter().any(|v| v.len() != self.t.len()) {
            return Err(invalid("every column needs one value per time".into()));
        }
        if !self.t.windows(2).all(|w| w[1] > w[0]) {
            return Err(invalid("times must increase".into()));
        }
        if self
            .t
            .iter()
            .chain(self.values.iter().flatten())
            .any(|v| !v.is_finite())
        {
            return Err(invalid("a value is not finite".into()));
        }
        for (k, v) in self.t.iter().enumerate() {
            let last = k.checked_sub(1).map(|j| self.t[j]);
            if let Some(why) = time_out_of_bounds(*v, last) {
                return Err(invalid(format!("time {k}: {why}")));
            }
        }
        if let Some(why) = self
            .values
            .iter()
            .flatten()
            .find_map(|v| value_out_of_bounds(*v))
        {
            return Err(invalid(why));
        }
        Ok(())
    }
}

/// The cubic spline through samples, with zero slope at both ends.
#[derive(Debug, Clone)]
pub(crate) struct Spline {
    t: Vec<f64>,
    y: Vec<Vec<f64>>,
    /// Second derivative at each knot, per column.
    m: Vec<Vec<f64>>,
}

impl Spline {
    pub(crate) fn new(s: &Samples) -> Self {
        let m = s.values.iter().map(|y| clamped_moments(&s.t, y)).collect();
        Self {
            t: s.t.clone(),
            y: s.values.clone(),
            m,
        }
    }

    pub(crate) fn columns(&self) -> usize {
        self.y.len()
    }

    /// Value, rate, acceleration of column `c` at `t` (held before the
    /// first time and after the last).
    pub(crate) fn eval(&self, c: usize, t: f64) -> [f64; 3] {
        let (ts, y, m) = (&self.t, &self.y[c], &self.m[c]);
        let n = ts.len();
        if t <= ts[0] {
            return [y[0], 0.0, 0.0];
        }
        if t >= ts[n - 1] {
            return [y[n - 1], 0.0, 0.0];
        }
        let i = ts.partition_point(|&x| x <= t) - 1;
        let h = ts[i + 1] - ts[i];
        let (a, b) = (ts[i + 1] - t, t - ts[i]);
        let (ci, cj) = (y[i] / h - m[i] * h / 6.0, y[i + 1] / h - m[i + 1] * h / 6.0);
        [
            m[i] * a * a * a / (6.0 * h) + m[i + 1] * b * b * b / (6.0 * h) + ci * a + cj * b,
            -m[i] * a * a / (2.0 * h) + m[i + 1] * b * b / (2.0 * h) - ci + cj,
            (m[i] * a + m[i + 1] * b) / h,
        ]
    }

    /// The smallest and largest value of column `c`, checked at the knots
    /// and ten points between each (a spline can overshoot its samples).
    pub(crate) fn range(&self, c: usize) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for w in self.t.windows(2) {
            for k in 0..=10 {
                let v = self.eval(c, w[0] + (w[1] - w[0]) * k as f64 / 10.0)[0];
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo, hi)
    }
}

/// Second derivatives at the knots of the spline through (t, y) with zero
/// slope at both ends (a tridiagonal system, solved by elimination).
fn clamped_moments(t: &[f64], y: &[f64]) -> Vec<f64> {
    let n = t.len();
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let slope = |i: usize| (y[i + 1] - y[i]) / h[i];
    let (mut sub, mut diag, mut sup, mut rhs) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    diag[0] = 2.0 * h[0];
    sup[0] = h[0];
    rhs[0] = 6.0 * slope(0);
    for i in 1..n - 1 {
        sub[i] = h[i - 1];
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        sup[i] = h[i];
        rhs[i] = 6.0 * (slope(i) - slope(i - 1));
    }
    sub[n - 1] = h[n - 2];
    diag[n - 1] = 2.0 * h[n - 2];
    rhs[n - 1] = -6.0 * slope(n - 2);
    for i in 1..n {
        let w = sub[i] / diag[i - 1];
        diag[i] -= w * sup[i - 1];
        rhs[i] -= w * rhs[i - 1];
    }
    let mut m = vec![0.0; n];
    m[n - 1] = rhs[n - 1] / diag[n - 1];
    for i in (0..n - 1).rev() {
        m[i] = (rhs[i] - sup[i] * m[i + 1]) / diag[i];
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_csv_is_read_and_interpolated_smoothly() {
        let text = "# a move\nt, a, b\n0, 0, 1\n1, 0.5, 1\n2, 1, 0.5\n3, 1, 0.5\n";
        let s = Samples::from_csv(text, "move.csv").unwrap();
        assert_eq!(s.columns, ["a", "b"]);
        let sp = Spline::new(&s);
        // Through the samples, at rest at both ends, held outside.
        for (k, &t) in s.t.iter().enumerate() {
            assert!((sp.eval(0, t)[0] - s.values[0][k]).abs() < 1e-12);
        }
        assert!(sp.eval(0, 0.0)[1].abs() < 1e-12 && sp.eval(0, 3.0)[1].abs() < 1e-12);
        assert_eq!(sp.eval(1, 7.0), [0.5, 0.0, 0.0]);
        // The derivatives are the spline's own.
        for &t in &[0.3, 0.99, 1.01, 1.7, 2.5] {
            let h = 1e-6;
            let fd1 = (sp.eval(0, t + h)[0] - sp.eval(0, t - h)[0]) / (2.0 * h);
            let fd2 = (sp.eval(0, t + h)[1] - sp.eval(0, t - h)[1]) / (2.0 * h);
            assert!((sp.eval(0, t)[1] - fd1).abs() < 1e-6, "t = {t}");
            assert!((sp.eval(0, t)[2] - fd2).abs() < 1e-4, "t = {t}");
        }
    }

    /// Issue 48 item 11 (D11): columns were taken by their place, so
    /// `t,joint2,joint1` drove joint1 with joint2's motion and another
    /// arm's names ran unremarked. Each column is found by its name; an
    /// unknown name, a name twice and a joint with no column are refused
    /// naming the file, the header's row and the column.
    #[test]
    fn columns_are_the_joints_by_name() {
        let joints = ["joint1".to_string(), "joint2".to_string()];
        let read = |text: &str| Samples::from_csv(text, "f.csv").unwrap();
        let s = read(
            "t,joint2,joint1
0,2,1
1,20,10
",
        );
        let s = s.by_joint_names(&joints).unwrap();
        assert_eq!(s.columns, joints);
        assert_eq!(s.values, [vec![1.0, 10.0], vec![2.0, 20.0]]);
        let e = |text: &str| read(text).by_joint_names(&joints).unwrap_err().to_string();
        let other = e("# from the iiwa\nt,iiwa_joint_1,iiwa_joint_2\n0,0,0\n1,0,0\n");
        assert!(
            other.starts_with("f.csv: row 2, column 2 ('iiwa_joint_1'): no joint of the arm")
                && other.contains("(joint1, joint2)"),
            "{other}"
        );
        let twice = e("t,joint1,joint1\n0,0,0\n1,0,0\n");
        assert!(
            twice.starts_with(
                "f.csv: row 1, column 3 ('joint1'): joint 'joint1' has a column already (column 2)"
            ),
            "{twice}"
        );
        let missing = e("t,joint2\n0,0\n1,0\n");
        assert!(
            missing.starts_with("f.csv: row 1, column 3 ('joint1'): no column for joint joint1"),
            "{missing}"
        );
    }

    #[test]
    fn bad_files_name_row_and_column() {
        let e = |text: &str| Samples::from_csv(text, "f.csv").unwrap_err().to_string();
        assert_eq!(
            e("t,a\n0,0\n1,x\n"),
            "f.csv: row 3, column 2 ('a'): \"x\" is not a number"
        );
        assert_eq!(
            e("t,a\n0,0\n0,1\n"),
            "f.csv: row 3, column 1 ('t'): time 0 does not come after the previous row's 0: times must increase"
        );
        assert!(e("t,a\n0,0\n1,2,3\n").starts_with("f.csv: row 3, column 3"));
        assert!(e("time,a\n0,0\n").contains("the header must be `t`"));
        assert!(e("t,a\n0,NaN\n1,0\n").contains("row 2, column 2 ('a'): NaN is not finite"));
        assert!(e("t,a\n0,0\n").contains("at least two rows"));
    }

    /// Issue 48 item 10 (N12): times 1e-300 apart and values of 1e200 or
    /// 1e300 passed "finite and increasing" and then faulted on every
    /// step; they are refused by row, column and range, in a file and
    /// given inline, and the edges are taken.
    #[test]
    fn samples_beyond_physical_bounds_are_refused() {
        let e = |text: &str| Samples::from_csv(text, "f.csv").unwrap_err().to_string();
        let close = e("t,a\n0,0\n1e-300,1\n");
        assert!(
            close.contains("row 3, column 1 ('t')") && close.contains("at least 1e-6 s"),
            "{close}"
        );
        for v in ["1e200", "1e300", "-1001"] {
            let big = e(&format!("t,a\n0,0\n1,{v}\n"));
            assert!(
                big.contains("row 3, column 2 ('a')") && big.contains("from -1000 to 1000"),
                "{big}"
            );
        }
        let late = e("t,a\n0,0\n1e300,1\n");
        assert!(late.contains("from -1e6 to 1e6 s"), "{late}");
        Samples::from_csv("t,a\n0,-1000\n1e-6,1000\n", "f.csv").unwrap();
        let inline = |t: Vec<f64>, v: Vec<f64>| Samples {
            t,
            values: vec![v],
            ..Samples::from_csv("t,a\n0,0\n1,0\n", "f.csv").unwrap()
        };
        for bad in [
            inline(vec![0.0, 1e-300], vec![0.0, 1.0]),
            inline(vec![0.0, 1.0], vec![0.0, 1e300]),
        ] {
            let e = bad.validate("reference.samples").unwrap_err().to_string();
            assert!(e.contains("reference.samples"), "{e}");
        }
        inline(vec![0.0, 1e-6], vec![0.0, 1e3])
            .validate("reference.samples")
            .unwrap();
    }
}
