//! The paper's five figures, the error as a fraction of its envelope after
//! T_c, and a timing figure, as PNG and SVG.
//!
//! Text is drawn with an embedded DejaVu Sans (see `assets/`), so figures do
//! not depend on the fonts of the machine.

use std::path::Path;

pub use crate::plot_error::PlotError;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use scenario::Plan;

use crate::analyse::Series;

/// The embedded font every figure draws its text with.
pub static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
/// The font family name the embedded font is registered under.
pub const FAMILY: &str = "sans-serif";
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

/// One curve.
pub struct Line<'a> {
    /// Legend text.
    pub label: String,
    /// One value per time sample.
    pub y: &'a [f64],
    /// Its colour.
    pub color: RGBColor,
    /// Dashed (a bound or a reference) rather than solid.
    pub dashed: bool,
}

/// One panel of a figure (one joint).
pub struct Panel<'a> {
    /// Title above the panel.
    pub title: String,
    /// The y axis's label.
    pub y_label: &'static str,
    /// Its curves.
    pub lines: Vec<Line<'a>>,
}

/// The name of the category at integer x (bar and box charts), else "".
pub fn category(names: &[String], x: f64) -> String {
    let i = x.round();
    if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
        names[i as usize].clone()
    } else {
        String::new()
    }
}

/// plotters' drawing error as a [`PlotError`].
pub fn err(e: impl std::fmt::Display) -> PlotError {
    PlotError::Draw(e.to_string())
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

fn draw_panels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    t: &[f64],
    panels: &[Panel<'_>],
    vline: Option<f64>,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, (FAMILY, 22)).map_err(err)?;
    let areas = root.split_evenly((panels.len(), 1));
    let t0 = t.first().copied().unwrap_or(0.0);
    let t_end = t.last().copied().unwrap_or(1.0).max(t0 + 1e-9);
    for (area, panel) in areas.iter().zip(panels) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for l in &panel.lines {
            for y in l.y.iter().filter(|y| y.is_finite()) {
                lo = lo.min(*y);
                hi = hi.max(*y);
            }
        }
        if !lo.is_finite() {
            (lo, hi) = (-1.0, 1.0);
        }
        let pad = ((hi - lo) * 0.05).max(1e-6);
        let mut chart = ChartBuilder::on(area)
            .caption(&panel.title, (FAMILY, 16))
            .margin(8)
            .x_label_area_size(32)
            .y_label_area_size(60)
            .build_cartesian_2d(t0..t_end, (lo - pad)..(hi + pad))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .y_desc(panel.y_label)
            .label_style((FAMILY, 12))
            .draw()
            .map_err(err)?;
        for l in &panel.lines {
            let pts = decimate(t, l.y);
            let style = ShapeStyle::from(&l.color).stroke_width(2);
            let series = if l.dashed {
                chart
                    .draw_series(DashedLineSeries::new(pts, 6, 4, style))
                    .map_err(err)?
            } else {
                chart
                    .draw_series(LineSeries::new(pts, style))
                    .map_err(err)?
            };
            let c = l.color;
            if !l.label.is_empty() {
                series
                    .label(l.label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c));
            }
        }
        if let Some(x) = vline {
            chart
                .draw_series(LineSeries::new(
                    vec![(x, lo - pad), (x, hi + pad)],
                    ShapeStyle::from(&BLACK.mix(0.5)).stroke_width(1),
                ))
                .map_err(err)?
                .label(format!("T_c = {x} s"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.mix(0.5)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK.mix(0.3))
            .label_font((FAMILY, 12))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// Writes `name.png` and `name.svg`.
pub fn save(
    dir: &Path,
    name: &str,
    title: &str,
    t: &[f64],
    panels: &[Panel<'_>],
    vline: Option<f64>,
) -> Result<(), PlotError> {
    let h = 260 * panels.len() as u32 + 60;
    let png = dir.join(format!("{name}.png"));
    draw_panels(
        &BitMapBackend::new(&png, (1000, h)).into_drawing_area(),
        title,
        t,
        panels,
        vline,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join(format!("{name}.svg"));
    draw_panels(
        &SVGBackend::new(&svg, (1000, h)).into_drawing_area(),
        title,
        t,
        panels,
        vline,
    )
    .map_err(PlotError::in_file(&svg))
}

fn bounds(a: &[f64], b: &[f64], sign: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(a, b)| a + sign * b).collect()
}

/// Writes every figure into `dir` (created if needed); returns how many.
pub fn write_all(dir: &Path, s: &Series, plan: &Plan) -> Result<usize, PlotError> {
    write_figures(dir, s, plan)
}

fn write_figures(dir: &Path, s: &Series, plan: &Plan) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(PlotError::folder(dir))?;
    // Registering twice is harmless; the bytes are a valid font by construction.
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    let names = plan.robot.model.joint_names();
    let tc = plan.scenario.controller.tc;
    positions(dir, s, &names, tc)?;
    velocities(dir, s, &names, tc)?;
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

/// One line of a panel in the `i`-th colour.
fn line(label: String, y: &[f64], i: usize, dashed: bool) -> Line<'_> {
    Line {
        label,
        y,
        color: COLORS[i % COLORS.len()],
        dashed,
    }
}

/// The colour of a constraint bound.
pub const RED: RGBColor = RGBColor(214, 39, 40);

/// Fig. 1: q with q_d ± k_c.
fn positions(dir: &Path, s: &Series, names: &[String], tc: f64) -> Result<(), PlotError> {
    let n = names.len();
    let mut upper = Vec::new();
    let mut lower = Vec::new();
    for i in 0..n {
        upper.push(bounds(&s.q_d[i], &s.kc[i], 1.0));
        lower.push(bounds(&s.q_d[i], &s.kc[i], -1.0));
    }
    let positions: Vec<Panel<'_>> = (0..n)
        .map(|i| Panel {
            title: format!("{}: position", names[i]),
            y_label: "q [rad]",
            lines: vec![
                line("q".into(), &s.q[i], 0, false),
                line("q_d".into(), &s.q_d[i], 1, true),
                Line {
                    label: "q_d ± k_c".into(),
                    y: &upper[i],
                    color: RED,
                    dashed: true,
                },
                Line {
                    label: String::new(),
                    y: &lower[i],
                    color: RED,
                    dashed: true,
                },
            ],
        })
        .collect();
    save(
        dir,
        "fig1_positions",
        "Joint positions with q_d ± k_c",
        &s.t,
        &positions,
        Some(tc),
    )?;

    Ok(())
}

/// Fig. 2: q̇ and q̇_d.
fn velocities(dir: &Path, s: &Series, names: &[String], _tc: f64) -> Result<(), PlotError> {
    let n = names.len();
    let velocities: Vec<Panel<'_>> = (0..n)
        .map(|i| Panel {
            title: format!("{}: velocity", names[i]),
            y_label: "q̇ [rad/s]",
            lines: vec![
                line("q̇".into(), &s.qd[i], 0, false),
                line("q̇_d".into(), &s.qd_d[i], 1, true),
            ],
        })
        .collect();
    save(
        dir,
        "fig2_velocities",
        "Joint velocities",
        &s.t,
        &velocities,
        None,
    )?;
    Ok(())
}

/// Fig. 3: Z1 with ± k_c.
fn errors(dir: &Path, s: &Series, names: &[String], tc: f64) -> Result<(), PlotError> {
    let n = names.len();
    let neg_kc: Vec<Vec<f64>> =
        s.kc.iter()
            .map(|k| k.iter().map(|x| -x).collect())
            .collect();
    let errors: Vec<Panel<'_>> = (0..n)
        .map(|i| Panel {
            title: format!("{}: tracking error", names[i]),
            y_label: "Z1 [rad]",
            lines: vec![
                line("Z1 = q − q_d".into(), &s.z1[i], 0, false),
                Line {
                    label: "± k_c".into(),
                    y: &s.kc[i],
                    color: RED,
                    dashed: true,
                },
                Line {
                    label: String::new(),
                    y: &neg_kc[i],
                    color: RED,
                    dashed: true,
                },
            ],
        })
        .collect();
    save(
        dir,
        "fig3_errors",
        "Tracking errors with ± k_c",
        &s.t,
        &errors,
        Some(tc),
    )?;
    Ok(())
}

/// |Z1|/k_c after T_c, per joint, against the constraint's 1: how close
/// the error comes to its envelope, on a scale where a 0.03 rad error is
/// not a flat line beside a 0.5 rad bound. None before T_c to draw: false.
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
        .map(|i| Panel {
            title: format!("{}: |Z1| / k_c after T_c", names[i]),
            y_label: "|Z1| / k_c",
            lines: vec![
                line("|Z1| / k_c".into(), &ratio[i], 0, false),
                Line {
                    label: "constraint (1)".into(),
                    y: &one,
                    color: RED,
                    dashed: true,
                },
            ],
        })
        .collect();
    save(
        dir,
        "fig7_error_over_envelope",
        "Tracking error as a fraction of the envelope, after T_c",
        t,
        &panels,
        None,
    )?;
    Ok(true)
}

/// Figs. 4 and 5: the actor's weight norms and the torques.
fn weights_and_torques(
    dir: &Path,
    s: &Series,
    names: &[String],
    _tc: f64,
) -> Result<(), PlotError> {
    let n = names.len();
    let weights = vec![Panel {
        title: "actor weight norms".into(),
        y_label: "‖Ŵa‖",
        lines: (0..n)
            .map(|i| line(names[i].clone(), &s.wa[i], i, false))
            .collect(),
    }];
    save(
        dir,
        "fig4_actor_weights",
        "Norms of the actor weights per joint",
        &s.t,
        &weights,
        None,
    )?;

    let torques = vec![Panel {
        title: "torques".into(),
        y_label: "τ [N m]",
        lines: (0..n)
            .map(|i| line(names[i].clone(), &s.tau[i], i, false))
            .collect(),
    }];
    save(dir, "fig5_torques", "Input torques", &s.t, &torques, None)?;
    Ok(())
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
    let root = root.titled("Timing", (FAMILY, 22)).map_err(err)?;
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
        .caption(format!("{title} ({} samples)", sorted.len()), (FAMILY, 16))
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..hi, 0u64..top + top / 10 + 1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("µs")
        .y_desc("cycles")
        .label_style((FAMILY, 12))
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
