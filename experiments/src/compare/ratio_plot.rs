//! `compare_error_ratio`: |e_i| / k_c,i after T_c, one small panel per law
//! on one shared scale, so that errors of 0.03 rad are visible (on the ±k_c
//! scale they are a flat line) and eleven laws do not overlap. The envelope
//! is the line at 1; a failed law's title says so.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use scenario::Plan;

use crate::compare::types::{Comparison, LawRow, LawSeries};
use analysis::plots::{COLORS, FAMILY, PlotError, RED, err};

/// Writes `compare_error_ratio.png` and `.svg` into `dir`.
pub fn write(dir: &Path, c: &Comparison, plan: &Plan) -> Result<(), PlotError> {
    let (w, h) = size(c.laws.len());
    let png = dir.join("compare_error_ratio.png");
    draw(
        &BitMapBackend::new(&png, (w, h)).into_drawing_area(),
        c,
        plan,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join("compare_error_ratio.svg");
    draw(&SVGBackend::new(&svg, (w, h)).into_drawing_area(), c, plan)
        .map_err(PlotError::in_file(&svg))
}

/// Columns and rows of the grid for `n` panels.
fn grid(n: usize) -> (usize, usize) {
    let cols = if n <= 4 { 2 } else { 3 }.min(n.max(1));
    (cols, n.div_ceil(cols).max(1))
}

fn size(n: usize) -> (u32, u32) {
    let (cols, rows) = grid(n);
    (420 * cols as u32, 260 * rows as u32 + 60)
}

/// Times from T_c on, and |e_i|/k_c,i per joint at those times.
type Ratios = (Vec<f64>, Vec<Vec<f64>>);

/// Every law's (t, |e_i|/k_c,i per joint) from T_c on (first seed).
fn ratios(s: &LawSeries, tc: f64) -> Ratios {
    let from = s.t.iter().position(|t| *t >= tc).unwrap_or(s.t.len());
    let t = s.t[from..].to_vec();
    let r =
        s.e.iter()
            .zip(&s.kc)
            .map(|(e, k)| {
                e[from..]
                    .iter()
                    .zip(&k[from..])
                    .map(|(e, k)| e.abs() / k)
                    .collect()
            })
            .collect();
    (t, r)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    c: &Comparison,
    plan: &Plan,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let tc = plan.scenario.controller.tc;
    let title = format!(
        "|e| / k_c after T_c = {tc} s, per joint, first seed ({}); the envelope is 1",
        c.scenario
    );
    let root = root.titled(&title, (FAMILY, 18)).map_err(err)?;
    let curves: Vec<(&LawRow, Ratios)> = c
        .laws
        .iter()
        .filter_map(|row| Some((row, ratios(row.runs.first()?.series.as_ref()?, tc))))
        .collect();
    let (t_lo, t_hi) = curves
        .iter()
        .filter_map(|(_, (t, _))| Some((*t.first()?, *t.last()?)))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, b| {
            (a.0.min(b.0), a.1.max(b.1))
        });
    // NaN-free: both come from finite times, or are the fold's ±∞.
    if t_lo >= t_hi {
        return Err(PlotError::Empty("no law's run reaches past T_c"));
    }
    // One scale for every panel: the largest finite ratio, clipped at 2
    // (a failed law past it is marked as failed), at least 1.1.
    let top = curves
        .iter()
        .flat_map(|(_, (_, r))| r.iter().flatten().copied())
        .filter(|x| x.is_finite())
        .fold(0.0, f64::max)
        .clamp(1.1, 2.0);
    let (cols, rows) = grid(curves.len());
    let areas = root.split_evenly((rows, cols));
    let joints = plan.robot.model.joint_names();
    for (k, (area, (row, (t, r)))) in areas.iter().zip(&curves).enumerate() {
        let failed = row.runs.first().and_then(|x| x.failed.as_ref()).is_some();
        let caption = if failed {
            format!("{} — FAILED", row.name)
        } else {
            row.name.clone()
        };
        let style = (FAMILY, 15)
            .into_font()
            .color(if failed { &RED } else { &BLACK });
        let mut chart = ChartBuilder::on(area)
            .caption(caption, style)
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(45)
            .build_cartesian_2d(t_lo..t_hi, 0.0..top)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .label_style((FAMILY, 11))
            .draw()
            .map_err(err)?;
        chart
            .draw_series(DashedLineSeries::new(
                [(t_lo, 1.0), (t_hi, 1.0)],
                6,
                4,
                RED.stroke_width(1),
            ))
            .map_err(err)?;
        for (i, y) in r.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let points = t.iter().zip(y).map(|(t, y)| (*t, y.min(top)));
            let series = chart
                .draw_series(LineSeries::new(thin(points), color.stroke_width(1)))
                .map_err(err)?;
            if k == 0 {
                let name = joints.get(i).cloned().unwrap_or_default();
                series.label(name).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
                });
            }
        }
        if k == 0 {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.3))
                .label_font((FAMILY, 11))
                .draw()
                .map_err(err)?;
        }
    }
    root.present().map_err(err)
}

/// At most 2000 points per curve: more only makes the SVG large.
fn thin(points: impl Iterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    let all: Vec<(f64, f64)> = points.collect();
    let step = all.len().div_ceil(2000).max(1);
    all.into_iter().step_by(step).collect()
}
