//! An external controller's own diagnostics, summed up: for each declared
//! diagnostic, its last value and its largest magnitude over the run, per
//! entry (one for a scalar, one per joint for a per-joint one).

use serde::Serialize;
use wire::OwnLayout;

/// One declared diagnostic over the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OwnDiagnosticSummary {
    /// Its declared name.
    pub name: String,
    /// Its value at the last row.
    pub last: Vec<f64>,
    /// Its largest |value| over the rows (NaN once a value was NaN).
    pub max_abs: Vec<f64>,
}

/// Collects the values row by row.
#[derive(Debug)]
pub struct OwnStats {
    layout: OwnLayout,
    dof: usize,
    last: Vec<f64>,
    max_abs: Vec<f64>,
}

impl OwnStats {
    /// For `layout` on `dof` joints.
    pub fn new(layout: OwnLayout, dof: usize) -> Self {
        let len = layout.len(dof);
        Self {
            layout,
            dof,
            last: vec![f64::NAN; len],
            max_abs: vec![0.0; len],
        }
    }

    /// One row's values (the layout's length).
    pub fn add(&mut self, values: &[f64]) {
        for ((last, max), v) in self.last.iter_mut().zip(&mut self.max_abs).zip(values) {
            *last = *v;
            *max = if v.is_nan() || max.is_nan() {
                f64::NAN
            } else {
                max.max(v.abs())
            };
        }
    }

    /// The summary, a diagnostic each.
    pub fn finish(&self) -> Vec<OwnDiagnosticSummary> {
        self.layout
            .spans(self.dof)
            .into_iter()
            .map(|(name, r)| OwnDiagnosticSummary {
                name: name.to_string(),
                last: self.last[r.clone()].to_vec(),
                max_abs: self.max_abs[r].to_vec(),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn last_and_largest_per_entry() {
        let layout = OwnLayout::parse("integral:joints,windup:scalar", 2).unwrap();
        let mut s = OwnStats::new(layout, 2);
        s.add(&[1.0, -3.0, 0.5]);
        s.add(&[2.0, 1.0, f64::NAN]);
        let out = s.finish();
        assert_eq!(out[0].name, "integral");
        assert_eq!(out[0].last, [2.0, 1.0]);
        assert_eq!(out[0].max_abs, [2.0, 3.0]);
        assert!(out[1].last[0].is_nan() && out[1].max_abs[0].is_nan());
    }
}
