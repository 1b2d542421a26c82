//! The paper's five figures, the error as a fraction of its envelope after
//! T_c, and a timing figure, as PNG and SVG.
//!
//! Text is drawn with an embedded DejaVu Sans (see `assets/`), so figures do
//! not depend on the fonts of the machine. How a figure is made readable
//! (legend beside the data, fitted ranges, the T_c marker) is
//! [`crate::plot_style`].

use std::path::Path;

pub use crate::plot_error::PlotError;
pub use crate::plot_style::{FAMILY, category, err};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use scenario::Plan;

use crate::analyse::Series;
use crate::plot_style::{
    CAPTION, GRID, GRID_LIGHT, Key, LEGEND_WIDTH, MARGIN, TICK, TITLE, fitted, legend, plain,
    tc_key, tc_marker, text_px, tick_count,
};

/// The embedded font every figure draws its text with.
pub static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
/// More points than a figure can show only make SVGs large.
const MAX_POINTS: usize = 4000;
/// The palette, one colour per joint or law.
pub const COLORS: [RGBColor; 11] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(0, 0, 0),
    RGBColor(174, 199, 232),
];
/// The reference (q_d, q̇_d): black and dashed, drawn over the measured
/// curve, so where the two agree both stay visible.
pub const REFERENCE: RGBColor = RGBColor(0, 0, 0);
/// The height of one panel, px.
const PANEL_H: u32 = 260;

/// One curve.
pub struct Line<'a> {
    /// Legend text ("" for none: the second side of a ± bound).
    pub label: String,
    /// One value per time sample.
    pub y: &'a [f64],
    /// Its colour.
    pub color: RGBColor,
    /// Dashed (a bound or a reference) rather than solid.
    pub dashed: bool,
    /// Stroke width, px.
    pub width: u32,
    /// Whether the panel's y range is fitted to it: false for a reference
    /// that would flatten the data (the envelope's 1 beside a 1 % error)
    /// and for a failed law's runaway curve.
    pub fit: bool,
}

impl<'a> Line<'a> {
    /// A solid 2 px curve the range is fitted to.
    pub fn new(label: impl Into<String>, y: &'a [f64], color: RGBColor) -> Self {
        Line {
            label: label.into(),
            y,
            color,
            dashed: false,
            width: 2,
            fit: true,
        }
    }

    /// Dashed.
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }

    /// `w` px wide.
    pub fn width(mut self, w: u32) -> Self {
        self.width = w;
        self
    }

    /// Left out of the fitted range (drawn clipped to it, or noted when
    /// wholly off it).
    pub fn unfitted(mut self) -> Self {
        self.fit = false;
        self
    }
}

/// One panel of a figure (one joint).
pub struct Panel<'a> {
    /// Title above the panel.
    pub title: String,
    /// The y axis's label.
    pub y_label: &'static str,
    /// Its curves, drawn in this order (the last on top).
    pub lines: Vec<Line<'a>>,
    /// Show only t ≥ this (a window after a start-up transient whose
    /// peak would flatten the rest).
    pub from: Option<f64>,
    /// Keep 0 in the y range (a ratio or a norm, where 0 is the floor).
    pub from_zero: bool,
    /// Lines of text for the legend beside the panel.
    pub notes: Vec<String>,
}

impl<'a> Panel<'a> {
    /// A panel over the whole run, its range fitted to its lines.
    pub fn new(title: impl Into<String>, y_label: &'static str, lines: Vec<Line<'a>>) -> Self {
        Panel {
            title: title.into(),
            y_label,
            lines,
            from: None,
            from_zero: false,
            notes: Vec::new(),
        }
    }
}

fn decimate(t: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let stride = t.len().div_ceil(MAX_POINTS).max(1);
    t.iter()
        .zip(y)
        .step_by(stride)
        .filter(|(_, y)| y.is_finite())
        .map(|(t, y)| (*t, *y))
        .collect()
}

/// The panel's y range: fitted to its fitted lines over its window.
fn y_range(panel: &Panel<'_>, from: usize) -> (f64, f64) {
    let values = panel
        .lines
        .iter()
        .filter(|l| l.fit)
        .flat_map(|l| l.y.get(from..).unwrap_or_default().iter().copied());
    let zero = panel.from_zero.then_some(0.0);
    fitted(values.chain(zero), MARGIN).unwrap_or((-1.0, 1.0))
}

/// Where a line lies against the range: None if some of it is inside,
/// else "above" or "below".
fn off_scale(pts: &[(f64, f64)], (lo, hi): (f64, f64)) -> Option<&'static str> {
    if pts.iter().any(|(_, y)| *y >= lo && *y <= hi) || pts.is_empty() {
        None
    } else if pts.iter().all(|(_, y)| *y > hi) {
        Some("above")
    } else {
        Some("below")
    }
}

/// Draws one panel; returns its legend entries and notes.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel<'_>,
    t: &[f64],
    vline: Option<f64>,
) -> Result<(Vec<Key>, Vec<String>), PlotError> {
    let from = panel.from.map_or(0, |f| t.partition_point(|x| *x < f));
    let t = &t[from.min(t.len())..];
    let t0 = t.first().copied().unwrap_or(0.0);
    let t_end = t.last().copied().unwrap_or(1.0).max(t0 + 1e-9);
    let (lo, hi) = y_range(panel, from);
    let (w, h) = area.dim_in_pixel();
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FAMILY, CAPTION))
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(68)
        .build_cartesian_2d(t0..t_end, lo..hi)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_desc(panel.y_label)
        .bold_line_style(GRID)
        .light_line_style(GRID_LIGHT)
        .x_labels(tick_count(w.saturating_sub(80), text_px("10.00", TICK)))
        .y_labels(tick_count(h.saturating_sub(70), 2 * TICK))
        .label_style((FAMILY, TICK))
        .draw()
        .map_err(err)?;
    let mut keys = Vec::new();
    let mut notes = panel.notes.clone();
    for l in &panel.lines {
        let pts = decimate(t, l.y.get(from..).unwrap_or_default());
        if let Some(side) = off_scale(&pts, (lo, hi)) {
            notes.push(format!("{}: {side} this scale, not drawn", l.label));
            continue;
        }
        let pts: Vec<(f64, f64)> = pts.into_iter().map(|(x, y)| (x, y.clamp(lo, hi))).collect();
        let style = ShapeStyle::from(&l.color).stroke_width(l.width);
        if l.dashed {
            chart
                .draw_series(DashedLineSeries::new(pts, 7, 5, style))
                .map_err(err)?;
        } else {
            chart
                .draw_series(LineSeries::new(pts, style))
                .map_err(err)?;
        }
        if !l.label.is_empty() {
            keys.push(Key::line(l.label.clone(), l.color, l.dashed, l.width));
        }
    }
    if let Some(x) = vline.filter(|x| *x > t0 && *x <= t_end) {
        tc_marker(&mut chart, x, (lo, hi))?;
        keys.push(tc_key(x));
    }
    Ok((keys, notes))
}

/// Draws rows of panels, each row with its legend in a column on its
/// right (left out when it repeats the row above's).
fn draw_grid<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    t: &[f64],
    rows: &[Vec<Panel<'_>>],
    vline: Option<f64>,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, (FAMILY, TITLE)).map_err(err)?;
    let width = root.dim_in_pixel().0;
    let mut last: Option<(Vec<Key>, Vec<String>)> = None;
    for (area, row) in root.split_evenly((rows.len().max(1), 1)).iter().zip(rows) {
        let (cells, side) = area.split_horizontally(width.saturating_sub(LEGEND_WIDTH));
        let mut row_legend: Option<(Vec<Key>, Vec<String>)> = None;
        for (cell, panel) in cells.split_evenly((1, row.len().max(1))).iter().zip(row) {
            let (keys, notes) = draw_panel(cell, panel, t, vline)?;
            let entry = row_legend.get_or_insert_with(|| (keys, Vec::new()));
            for note in notes {
                if !entry.1.contains(&note) {
                    entry.1.push(note);
                }
            }
        }
        if row_legend.is_some() && row_legend != last {
            if let Some((keys, notes)) = &row_legend {
                legend(&side, keys, notes)?;
            }
            last = row_legend;
        }
    }
    root.present().map_err(err)
}

/// Registers the embedded font (registering twice is harmless; the bytes
/// are a valid font by construction).
pub fn register_font() {
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
}

/// Writes `name.png` and `name.svg`: one panel per row.
pub fn save(
    dir: &Path,
    name: &str,
    title: &str,
    t: &[f64],
    panels: Vec<Panel<'_>>,
    vline: Option<f64>,
) -> Result<(), PlotError> {
    let rows: Vec<Vec<Panel<'_>>> = panels.into_iter().map(|p| vec![p]).collect();
    save_grid(dir, name, title, t, &rows, vline)
}

/// Writes `name.png` and `name.svg`: rows of panels side by side, each
/// row's legend on its right.
pub fn save_grid(
    dir: &Path,
    name: &str,
    title: &str,
    t: &[f64],
    rows: &[Vec<Panel<'_>>],
    vline: Option<f64>,
) -> Result<(), PlotError> {
    let cols = rows.iter().map(Vec::len).max().unwrap_or(1).max(1) as u32;
    let panel_w = if cols == 1 { 820 } else { 520 };
    let size = (
        LEGEND_WIDTH + cols * panel_w,
        PANEL_H * rows.len().max(1) as u32 + 50,
    );
    let png = dir.join(format!("{name}.png"));
    draw_grid(
        &BitMapBackend::new(&png, size).into_drawing_area(),
        title,
        t,
        rows,
        vline,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join(format!("{name}.svg"));
    draw_grid(
        &SVGBackend::new(&svg, size).into_drawing_area(),
        title,
        t,
        rows,
        vline,
    )
    .map_err(PlotError::in_file(&svg))
}

fn bounds(a: &[f64], b: &[f64], sign: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(a, b)| a + sign * b).collect()
}

/// Writes every figure into `dir` (created if needed); returns how many.
pub fn write_all(dir: &Path, s: &Series, plan: &Plan) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(PlotError::folder(dir))?;
    register_font();
    let names = plan.robot.model.joint_names();
    let tc = plan.scenario.controller.tc;
    positions(dir, s, &names, tc)?;
    velocities(dir, s, &names)?;
    errors(dir, s, &names, tc)?;
    weights_and_torques(dir, s, &names, tc)?;
    let mut written = 5;
    if error_over_envelope(dir, s, &names, tc)? {
        written += 1;
    }
    // An in-process run has no cross-process timing to draw.
    if s.jitter_us.is_empty() && s.round_trip_us.is_empty() {
        return Ok(written);
    }
    timing_figure(dir, s)?;
    Ok(written + 1)
}

/// The colour of a constraint bound.
pub const RED: RGBColor = RGBColor(214, 39, 40);

/// A measured curve and its reference: the measured one wide underneath,
/// the reference dashed in black over it, so where they agree both show.
fn tracked<'a>(name: &str, measured: &'a [f64], reference: &'a [f64]) -> [Line<'a>; 2] {
    [
        Line::new(name, measured, COLORS[0]).width(3),
        Line::new(format!("{name}_d (reference)"), reference, REFERENCE).dashed(),
    ]
}

/// A ± bound: two red dashed lines under one legend entry.
fn envelope<'a>(label: &str, upper: &'a [f64], lower: &'a [f64]) -> [Line<'a>; 2] {
    [
        Line::new(label, upper, RED).dashed(),
        Line::new("", lower, RED).dashed(),
    ]
}

/// Fig. 1: q with q_d ± k_c.
fn positions(dir: &Path, s: &Series, names: &[String], tc: f64) -> Result<(), PlotError> {
    let n = names.len();
    let upper: Vec<Vec<f64>> = (0..n).map(|i| bounds(&s.q_d[i], &s.kc[i], 1.0)).collect();
    let lower: Vec<Vec<f64>> = (0..n).map(|i| bounds(&s.q_d[i], &s.kc[i], -1.0)).collect();
    let panels: Vec<Panel<'_>> = (0..n)
        .map(|i| {
            let mut lines: Vec<Line<'_>> = envelope("q_d ± k_c", &upper[i], &lower[i]).into();
            lines.extend(tracked("q", &s.q[i], &s.q_d[i]));
            Panel::new(format!("{}: position", names[i]), "q [rad]", lines)
        })
        .collect();
    save(
        dir,
        "fig1_positions",
        "Joint positions with q_d ± k_c",
        &s.t,
        panels,
        Some(tc),
    )
}

/// Fig. 2: q̇ and q̇_d.
fn velocities(dir: &Path, s: &Series, names: &[String]) -> Result<(), PlotError> {
    let panels: Vec<Panel<'_>> = (0..names.len())
        .map(|i| {
            let lines = tracked("q̇", &s.qd[i], &s.qd_d[i]).into();
            Panel::new(format!("{}: velocity", names[i]), "q̇ [rad/s]", lines)
        })
        .collect();
    save(
        dir,
        "fig2_velocities",
        "Joint velocities",
        &s.t,
        panels,
        None,
    )
}

/// Fig. 3: Z1 with ± k_c.
fn errors(dir: &Path, s: &Series, names: &[String], tc: f64) -> Result<(), PlotError> {
    let neg_kc: Vec<Vec<f64>> =
        s.kc.iter()
            .map(|k| k.iter().map(|x| -x).collect())
            .collect();
    let panels: Vec<Panel<'_>> = (0..names.len())
        .map(|i| {
            let mut lines: Vec<Line<'_>> = envelope("± k_c", &s.kc[i], &neg_kc[i]).into();
            lines.push(Line::new("Z1 = q − q_d", &s.z1[i], COLORS[0]));
            Panel::new(format!("{}: tracking error", names[i]), "Z1 [rad]", lines)
        })
        .collect();
    save(
        dir,
        "fig3_errors",
        "Tracking errors with ± k_c",
        &s.t,
        panels,
        Some(tc),
    )
}

/// |Z1|/k_c after T_c, per joint: how close the error comes to its
/// envelope, on a scale fitted to the error (a 1 % error on a fixed 0–1
/// scale is a flat line), the envelope's 1 drawn when the scale reaches
/// it and noted when not. None after T_c to draw: false.
fn error_over_envelope(
    dir: &Path,
    s: &Series,
    names: &[String],
    tc: f64,
) -> Result<bool, PlotError> {
    let from = s.t.partition_point(|t| *t < tc);
    if s.t.len().saturating_sub(from) < 2 {
        return Ok(false);
    }
    let t = &s.t[from..];
    let ratio: Vec<Vec<f64>> = (0..names.len())
        .map(|i| {
            (from..s.t.len())
                .map(|k| s.z1[i][k].abs() / s.kc[i][k])
                .collect()
        })
        .collect();
    let one = vec![1.0; t.len()];
    let panels: Vec<Panel<'_>> = (0..names.len())
        .map(|i| {
            let peak = ratio[i].iter().copied().filter(|x| x.is_finite());
            let peak = peak.fold(f64::NAN, f64::max);
            let lines = vec![
                Line::new("|Z1| / k_c", &ratio[i], COLORS[0]),
                Line::new("the envelope (1)", &one, RED).dashed().unfitted(),
            ];
            let mut panel = Panel::new(
                format!("{}: |Z1| / k_c after T_c", names[i]),
                "|Z1| / k_c",
                lines,
            );
            panel.from_zero = true;
            panel.notes.push(format!("peak {} of k_c", plain_3(peak)));
            panel
        })
        .collect();
    save(
        dir,
        "fig7_error_over_envelope",
        "Tracking error as a fraction of the envelope after T_c (scale fitted to the error)",
        t,
        panels,
        None,
    )?;
    Ok(true)
}

/// Three significant digits.
fn plain_3(v: f64) -> String {
    if !v.is_finite() {
        return "n/a".into();
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{v:.digits$}")
}

/// Figs. 4 and 5: the actor's weight norms and the torques; the torques
/// also after T_c alone, on a scale fitted to that window (the start-up
/// peak is many times the torque that tracks).
fn weights_and_torques(dir: &Path, s: &Series, names: &[String], tc: f64) -> Result<(), PlotError> {
    let mut weights = Panel::new("actor weight norms", "‖Ŵa‖", joint_lines(names, &s.wa));
    weights.from_zero = true;
    save(
        dir,
        "fig4_actor_weights",
        "Norms of the actor weights per joint",
        &s.t,
        vec![weights],
        None,
    )?;
    let mut torques = vec![Panel::new(
        "torques over the run",
        "τ [N m]",
        joint_lines(names, &s.tau),
    )];
    if s.t.iter().filter(|t| **t >= tc).count() >= 2 && s.t.first().is_some_and(|t| *t < tc) {
        let mut after = Panel::new(
            format!(
                "torques after T_c = {} s (scale fitted to this window)",
                plain(tc)
            ),
            "τ [N m]",
            joint_lines(names, &s.tau),
        );
        after.from = Some(tc);
        torques.push(after);
    }
    save(
        dir,
        "fig5_torques",
        "Input torques",
        &s.t,
        torques,
        Some(tc),
    )
}

/// One line per joint, in the joints' colours.
fn joint_lines<'a>(names: &[String], y: &'a [Vec<f64>]) -> Vec<Line<'a>> {
    names
        .iter()
        .zip(y)
        .enumerate()
        .map(|(i, (name, y))| Line::new(name.clone(), y, COLORS[i % COLORS.len()]))
        .collect()
}

/// Histograms of period jitter and round trip.
fn timing_figure(dir: &Path, s: &Series) -> Result<(), PlotError> {
    let png = dir.join("fig6_timing.png");
    draw_timing(
        &BitMapBackend::new(&png, (1000, 640)).into_drawing_area(),
        s,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join("fig6_timing.svg");
    draw_timing(&SVGBackend::new(&svg, (1000, 640)).into_drawing_area(), s)
        .map_err(PlotError::in_file(&svg))
}

fn draw_timing<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    s: &Series,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled("Timing", (FAMILY, TITLE)).map_err(err)?;
    let areas = root.split_evenly((2, 1));
    for (area, (title, data)) in areas.iter().zip([
        ("period jitter |actual − nominal period| [µs]", &s.jitter_us),
        ("round trip state → command [µs]", &s.round_trip_us),
    ]) {
        histogram(area, title, data)?;
    }
    root.present().map_err(err)
}

fn histogram<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    data: &[f64],
) -> Result<(), PlotError> {
    const BINS: usize = 60;
    let mut sorted: Vec<f64> = data.iter().copied().filter(|x| x.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    // Up to the 99th percentile (the last bin holds the rest): the far
    // tail would squash everything else into one bar.
    let hi = sorted
        .get(((sorted.len() as f64) * 0.99) as usize)
        .or(sorted.last())
        .copied()
        .unwrap_or(1.0)
        .max(1e-3);
    let width = hi / BINS as f64;
    let mut counts = [0u64; BINS];
    for x in &sorted {
        counts[((x / width) as usize).min(BINS - 1)] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(1).max(1);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{title} ({} samples)", sorted.len()),
            (FAMILY, CAPTION),
        )
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..hi, 0u64..top + top / 10 + 1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("µs")
        .y_desc("cycles")
        .bold_line_style(GRID)
        .light_line_style(GRID_LIGHT)
        .label_style((FAMILY, TICK))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(counts.iter().enumerate().map(|(i, c)| {
            let x0 = i as f64 * width;
            Rectangle::new([(x0, 0), (x0 + width, *c)], COLORS[0].filled())
        }))
        .map_err(err)?;
    Ok(())
}
