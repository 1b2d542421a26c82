//! The figures of `testbed sweep report`: box plots per cell and, for a
//! two-axis grid, a heat map of the median per law.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use super::report::{CellReport, SweepReport, quantile};
use analysis::plots::{COLORS, FAMILY, FONT, PlotError, category, err};

/// The metrics drawn as box plots.
const BOXED: [(&str, &str); 2] = [
    ("iae", "IAE after T_c [rad s]"),
    ("max_abs_error", "max |e| after T_c [rad]"),
];

/// Draws `$draw` (a closure of the drawing area) into `$name`.png and .svg.
macro_rules! both {
    ($dir:expr, $name:expr, $size:expr, $draw:expr) => {{
        let png = $dir.join(format!("{}.png", $name));
        ($draw)(&BitMapBackend::new(&png, $size).into_drawing_area())
            .map_err(PlotError::in_file(&png))?;
        let svg = $dir.join(format!("{}.svg", $name));
        ($draw)(&SVGBackend::new(&svg, $size).into_drawing_area())
            .map_err(PlotError::in_file(&svg))?;
    }};
}

/// Writes `sweep_boxes` and, with two axes, `sweep_heatmap` (PNG and SVG).
pub fn write_all(dir: &Path, r: &SweepReport) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(PlotError::folder(dir))?;
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    let h = 320 * BOXED.len() as u32 + 80;
    both!(dir, "sweep_boxes", (1100, h), |a| boxes(a, r));
    if r.axes.len() == 2 {
        let laws = laws(r);
        let size = (560 * laws.len().max(1) as u32, 520);
        both!(dir, "sweep_heatmap", size, |a| heatmap(a, r, &laws));
        return Ok(2);
    }
    Ok(1)
}

fn label(c: &CellReport) -> String {
    let v: Vec<String> = c.cell.values().map(|v| v.to_string()).collect();
    if v.is_empty() {
        c.law.clone()
    } else {
        format!("{} {}", v.join(","), c.law)
    }
}

fn boxes<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &SweepReport,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!("Sweep {}: per cell across seeds", r.name),
            (FAMILY, 20),
        )
        .map_err(err)?;
    let areas = root.split_evenly((BOXED.len(), 1));
    for (area, (metric, caption)) in areas.iter().zip(BOXED) {
        let data: Vec<Vec<f64>> = r
            .cells
            .iter()
            .map(|c| {
                c.metrics
                    .iter()
                    .find(|m| m.metric == metric)
                    .map(|m| m.values.iter().copied().filter(|x| x.is_finite()).collect())
                    .unwrap_or_default()
            })
            .collect();
        box_panel(area, caption, r, &data)?;
    }
    root.present().map_err(err)
}

fn box_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    r: &SweepReport,
    data: &[Vec<f64>],
) -> Result<(), PlotError> {
    let all = data.iter().flatten().copied();
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let pad = ((hi - lo) * 0.08).max(1e-9);
    let n = data.len();
    let names: Vec<String> = r.cells.iter().map(label).collect();
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 15))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), (lo - pad)..(hi + pad))
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n.min(24))
        .x_label_formatter(&|x| category(&names, *x))
        .label_style((FAMILY, 11))
        .draw()
        .map_err(err)?;
    for (i, v) in data.iter().enumerate().filter(|(_, v)| !v.is_empty()) {
        let x = i as f64;
        let c = COLORS[i % COLORS.len()];
        let (q1, med, q3) = (quantile(v, 0.25), quantile(v, 0.5), quantile(v, 0.75));
        let (min, max) = (v[0], v[v.len() - 1]);
        let style = ShapeStyle::from(&c).stroke_width(2);
        chart
            .draw_series([
                PathElement::new(vec![(x, min), (x, q1)], style),
                PathElement::new(vec![(x, q3), (x, max)], style),
                PathElement::new(
                    vec![(x - 0.3, med), (x + 0.3, med)],
                    ShapeStyle::from(&BLACK).stroke_width(3),
                ),
            ])
            .map_err(err)?;
        chart
            .draw_series([Rectangle::new([(x - 0.3, q1), (x + 0.3, q3)], style)])
            .map_err(err)?;
    }
    Ok(())
}

fn laws(r: &SweepReport) -> Vec<String> {
    let mut laws: Vec<String> = Vec::new();
    for c in &r.cells {
        if !laws.contains(&c.law) {
            laws.push(c.law.clone());
        }
    }
    laws
}

/// Median IAE over the grid of the two axes, one panel per law.
fn heatmap<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &SweepReport,
    laws: &[String],
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &format!("Sweep {}: median IAE after T_c", r.name),
            (FAMILY, 20),
        )
        .map_err(err)?;
    let distinct = |axis: &str| {
        let mut v: Vec<String> = Vec::new();
        for c in &r.cells {
            let s = c.cell.get(axis).map(|x| x.to_string()).unwrap_or_default();
            if !v.contains(&s) {
                v.push(s);
            }
        }
        v
    };
    let (xs, ys) = (distinct(&r.axes[0]), distinct(&r.axes[1]));
    let medians: Vec<f64> = r
        .cells
        .iter()
        .filter_map(|c| {
            c.metrics
                .iter()
                .find(|m| m.metric == "iae")
                .map(|m| m.median)
        })
        .filter(|x| x.is_finite())
        .collect();
    let lo = medians.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = medians.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let width = root.dim_in_pixel().0 as i32;
    let (main, bar) = root.split_horizontally(width - 130);
    if lo.is_finite() && hi.is_finite() {
        colour_bar(&bar, lo, hi)?;
    }
    let areas = main.split_evenly((1, laws.len().max(1)));
    for (area, law) in areas.iter().zip(laws) {
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("{law}: x {}, y {}", r.axes[0], r.axes[1]),
                (FAMILY, 14),
            )
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(60)
            .build_cartesian_2d(0..xs.len(), 0..ys.len())
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_label_formatter(&|i| xs.get(*i).cloned().unwrap_or_default())
            .y_label_formatter(&|i| ys.get(*i).cloned().unwrap_or_default())
            .label_style((FAMILY, 11))
            .draw()
            .map_err(err)?;
        for c in r.cells.iter().filter(|c| &c.law == law) {
            let (Some(x), Some(y)) = (
                c.cell.get(&r.axes[0]).and_then(|v| {
                    let v = v.to_string();
                    xs.iter().position(|s| *s == v)
                }),
                c.cell.get(&r.axes[1]).and_then(|v| {
                    let v = v.to_string();
                    ys.iter().position(|s| *s == v)
                }),
            ) else {
                continue;
            };
            let m = c
                .metrics
                .iter()
                .find(|m| m.metric == "iae")
                .map_or(f64::NAN, |m| m.median);
            let color = if m.is_finite() {
                heat(if hi > lo { (m - lo) / (hi - lo) } else { 0.5 })
            } else {
                BLACK.to_rgba()
            };
            chart
                .draw_series([Rectangle::new([(x, y), (x + 1, y + 1)], color.filled())])
                .map_err(err)?;
            chart
                .draw_series([Text::new(
                    if m.is_finite() {
                        format!("{m:.3}")
                    } else {
                        "n/a".into()
                    },
                    (x, y + 1),
                    (FAMILY, 12),
                )])
                .map_err(err)?;
        }
    }
    root.present().map_err(err)
}

/// The heat map's colour for f in [0, 1] (blue: least, red: most).
fn heat(f: f64) -> RGBAColor {
    HSLColor(0.66 * (1.0 - f), 0.8, 0.5).to_rgba()
}

/// The heat map's colour scale: median IAE from `lo` to `hi`; black is a
/// cell without a value (every run failed).
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    lo: f64,
    hi: f64,
) -> Result<(), PlotError> {
    let top = if hi > lo { hi } else { lo + 1e-12 };
    let mut chart = ChartBuilder::on(area)
        .caption("IAE", (FAMILY, 13))
        .margin(12)
        .margin_top(40)
        .right_y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, lo..top)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_label_formatter(&|v| format!("{v:.3}"))
        .label_style((FAMILY, 11))
        .draw()
        .map_err(err)?;
    let steps = 64;
    let h = (top - lo) / steps as f64;
    chart
        .draw_series((0..steps).map(|k| {
            let y = lo + k as f64 * h;
            let f = (k as f64 + 0.5) / steps as f64;
            Rectangle::new([(0.0, y), (1.0, y + h)], heat(f).filled())
        }))
        .map_err(err)?;
    Ok(())
}
