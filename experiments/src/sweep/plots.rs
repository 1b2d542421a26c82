//! The figures of `testbed sweep report`: box plots per cell and, for a
//! two-axis grid, a heat map of the median per law.
//!
//! Cells are named as a reader says them, "k1=10, k2=5: nac" (the axis
//! key's last part, the value as written), not as the values' JSON; the
//! heat map's ticks sit at the centres of its cells.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontTransform;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::report::{CellReport, SweepReport, quantile};
use analysis::plot_style::{
    CAPTION, GRID, GRID_LIGHT, TICK, TITLE, category, category_axis, plain, text_px,
};
use analysis::plots::{COLORS, FAMILY, PlotError, err, register_font};

/// The metrics drawn as box plots.
const BOXED: [(&str, &str); 2] = [
    ("iae", "IAE after T_c [rad s]"),
    ("max_abs_error", "max |e| after T_c [rad]"),
];
/// The widest the box plots grow to keep their labels level; past it
/// the labels turn upright.
const MAX_WIDTH: u32 = 2000;
/// Left and right of the boxes' plotting area, px.
const BOX_FRAME: u32 = 100;

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
    register_font();
    let names = box_labels(r);
    let layout = box_layout(&names);
    let h = 340 * BOXED.len() as u32 + 60 + 2 * layout.label_area;
    both!(dir, "sweep_boxes", (layout.width, h), |a| boxes(
        a, r, &names, &layout
    ));
    if r.axes.len() == 2 {
        let laws = laws(r);
        let size = (560 * laws.len().max(1) as u32 + 130, 540);
        both!(dir, "sweep_heatmap", size, |a| heatmap(a, r, &laws));
        return Ok(2);
    }
    Ok(1)
}

/// Each axis key's last dotted part ("controller.k1" → "k1") when those
/// are distinct, else the keys whole.
fn short_keys(axes: &[String]) -> Vec<String> {
    let short: Vec<String> = axes
        .iter()
        .map(|a| a.rsplit('.').next().unwrap_or(a).to_string())
        .collect();
    let distinct = short
        .iter()
        .enumerate()
        .all(|(i, s)| !short[..i].contains(s));
    if distinct { short } else { axes.to_vec() }
}

/// An axis value as written: 10 (not 10.0), 0.5, rapier (not "rapier").
fn value_text(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::Number(n) => n.as_f64().map_or_else(|| n.to_string(), plain),
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// "k1=10, k2=5" for a cell, in the axes' order.
fn cell_text(c: &CellReport, axes: &[String], short: &[String]) -> String {
    let parts: Vec<String> = axes
        .iter()
        .zip(short)
        .filter_map(|(axis, name)| Some(format!("{name}={}", value_text(c.cell.get(axis)?))))
        .collect();
    parts.join(", ")
}

/// Each box's label: "k1=10, k2=5: nac", or the law alone without axes.
fn box_labels(r: &SweepReport) -> Vec<String> {
    let short = short_keys(&r.axes);
    r.cells
        .iter()
        .map(|c| match cell_text(c, &r.axes, &short) {
            cell if cell.is_empty() => c.law.clone(),
            cell => format!("{cell}: {}", c.law),
        })
        .collect()
}

/// How the box plots fit their labels.
#[derive(Debug, PartialEq)]
struct BoxLayout {
    /// Figure width, px.
    width: u32,
    /// Labels upright (too many to lie level side by side).
    upright: bool,
    /// The height of the label area under each panel, px.
    label_area: u32,
}

/// Level labels when the figure can grow (up to [`MAX_WIDTH`]) to give
/// each its width and a gap; else upright labels, a slot of 26 px each.
fn box_layout(names: &[String]) -> BoxLayout {
    let n = names.len().max(1) as u32;
    let widest = names.iter().map(|s| text_px(s, TICK)).max().unwrap_or(0);
    let level = n * (widest + 16) + BOX_FRAME;
    if level <= MAX_WIDTH {
        BoxLayout {
            width: level.max(1100),
            upright: false,
            label_area: 40,
        }
    } else {
        BoxLayout {
            width: (n * 26 + BOX_FRAME).max(1100),
            upright: true,
            label_area: widest + 20,
        }
    }
}

fn boxes<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &SweepReport,
    names: &[String],
    layout: &BoxLayout,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let title = format!(
        "Sweep {}: each cell across seeds (box: quartiles, bar: median, whiskers: range)",
        r.name
    );
    let root = root.titled(&title, (FAMILY, TITLE)).map_err(err)?;
    let areas = root.split_evenly((BOXED.len(), 1));
    let laws = laws(r);
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
        // One colour per law, so a law's boxes read as a series.
        let colors: Vec<RGBColor> = r
            .cells
            .iter()
            .map(|c| {
                let k = laws.iter().position(|l| *l == c.law).unwrap_or(0);
                COLORS[k % COLORS.len()]
            })
            .collect();
        box_panel(area, caption, names, layout, &data, &colors)?;
    }
    root.present().map_err(err)
}

fn box_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    names: &[String],
    layout: &BoxLayout,
    data: &[Vec<f64>],
    colors: &[RGBColor],
) -> Result<(), PlotError> {
    let all = data.iter().flatten().copied();
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let pad = ((hi - lo) * 0.08).max(1e-9);
    let n = data.len();
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, CAPTION))
        .margin(10)
        .x_label_area_size(layout.label_area)
        .y_label_area_size(70)
        .build_cartesian_2d(category_axis(n), (lo - pad)..(hi + pad))
        .map_err(err)?;
    let font = (FAMILY, TICK).into_font();
    let x_font = if layout.upright {
        font.clone().transform(FontTransform::Rotate90)
    } else {
        font.clone()
    };
    chart
        .configure_mesh()
        .disable_x_mesh()
        .bold_line_style(GRID)
        .light_line_style(GRID_LIGHT)
        .x_label_formatter(&|x| category(names, *x))
        .x_label_style(x_font)
        .y_label_style(font)
        .draw()
        .map_err(err)?;
    for (i, v) in data.iter().enumerate().filter(|(_, v)| !v.is_empty()) {
        let x = i as f64;
        let c = colors.get(i).copied().unwrap_or(COLORS[0]);
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

/// Each axis's values as written, in the order the sweep first has them.
fn distinct(r: &SweepReport, axis: &str) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for c in &r.cells {
        let s = c.cell.get(axis).map(value_text).unwrap_or_default();
        if !v.contains(&s) {
            v.push(s);
        }
    }
    v
}

/// A cell's median IAE (NaN: none).
fn median_iae(c: &CellReport) -> f64 {
    c.metrics
        .iter()
        .find(|m| m.metric == "iae")
        .map_or(f64::NAN, |m| m.median)
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
            &format!("Sweep {}: median IAE after T_c [rad s]", r.name),
            (FAMILY, TITLE),
        )
        .map_err(err)?;
    let medians: Vec<f64> = r
        .cells
        .iter()
        .map(median_iae)
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
        heat_panel(area, r, law, (lo, hi))?;
    }
    root.present().map_err(err)
}

/// One law's grid: a cell per pair of axis values, its median written in
/// its middle, the ticks at the cells' centres.
fn heat_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    r: &SweepReport,
    law: &str,
    (lo, hi): (f64, f64),
) -> Result<(), PlotError> {
    let (xs, ys) = (distinct(r, &r.axes[0]), distinct(r, &r.axes[1]));
    let short = short_keys(&r.axes);
    let mut chart = ChartBuilder::on(area)
        .caption(law, (FAMILY, CAPTION))
        .margin(12)
        .x_label_area_size(46)
        .y_label_area_size(70)
        .build_cartesian_2d(category_axis(xs.len()), category_axis(ys.len()))
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_label_formatter(&|x| category(&xs, *x))
        .y_label_formatter(&|y| category(&ys, *y))
        .x_desc(short[0].as_str())
        .y_desc(short[1].as_str())
        .label_style((FAMILY, TICK))
        .axis_desc_style((FAMILY, TICK))
        .draw()
        .map_err(err)?;
    for c in r.cells.iter().filter(|c| c.law == law) {
        let at = |axis: &str, values: &[String]| {
            let v = value_text(c.cell.get(axis)?);
            values.iter().position(|s| *s == v).map(|i| i as f64)
        };
        let (Some(x), Some(y)) = (at(&r.axes[0], &xs), at(&r.axes[1], &ys)) else {
            continue;
        };
        let m = median_iae(c);
        let color = if m.is_finite() {
            heat(if hi > lo { (m - lo) / (hi - lo) } else { 0.5 })
        } else {
            BLACK.to_rgba()
        };
        chart
            .draw_series([Rectangle::new(
                [(x - 0.5, y - 0.5), (x + 0.5, y + 0.5)],
                color.filled(),
            )])
            .map_err(err)?;
        let text = if m.is_finite() {
            format!("{m:.3}")
        } else {
            "n/a".into()
        };
        let font = (FAMILY, TICK + 1)
            .into_font()
            .color(&ink_on(color))
            .pos(Pos::new(HPos::Center, VPos::Center));
        chart
            .draw_series([Text::new(text, (x, y), font)])
            .map_err(err)?;
    }
    Ok(())
}

/// Black or white, whichever reads on `bg`.
fn ink_on(bg: RGBAColor) -> RGBColor {
    let luma = 0.299 * f64::from(bg.0) + 0.587 * f64::from(bg.1) + 0.114 * f64::from(bg.2);
    if luma < 140.0 { WHITE } else { BLACK }
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
        .caption("IAE", (FAMILY, TICK))
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
        .label_style((FAMILY, TICK))
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

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn cell(values: serde_json::Value, law: &str) -> CellReport {
        CellReport {
            cell: values.as_object().cloned().unwrap_or_default(),
            law: law.into(),
            runs: 1,
            found: 1,
            not_ok: 0,
            success_rate: None,
            metrics: Vec::new(),
        }
    }

    fn report(axes: &[&str], cells: Vec<CellReport>) -> SweepReport {
        SweepReport {
            name: "t".into(),
            axes: axes.iter().map(|a| a.to_string()).collect(),
            total_runs: cells.len(),
            found_runs: cells.len(),
            unreadable_lines: 0,
            cells,
        }
    }

    #[test]
    fn box_labels_read_as_a_person_says_them() {
        let r = report(
            &["controller.k2", "controller.k1"],
            vec![
                cell(json!({"controller.k1": 10.0, "controller.k2": 5.0}), "nac"),
                cell(json!({"controller.k1": 0.5, "controller.k2": 15}), "pd"),
            ],
        );
        // In the axes' order, not the map's; 10 for 10.0.
        assert_eq!(box_labels(&r), ["k2=5, k1=10: nac", "k2=15, k1=0.5: pd"]);
        let r = report(&[], vec![cell(json!({}), "ppc")]);
        assert_eq!(box_labels(&r), ["ppc"]);
        let r = report(
            &["plant.engine"],
            vec![cell(json!({"plant.engine": "rapier"}), "pd")],
        );
        assert_eq!(box_labels(&r), ["engine=rapier: pd"]);
    }

    #[test]
    fn keys_stay_whole_when_their_last_parts_clash() {
        let axes = ["plant.sensor.q_noise_std", "controller.k1"].map(String::from);
        assert_eq!(short_keys(&axes), ["q_noise_std", "k1"]);
        let axes = ["plant.sensor.delay", "plant.actuator.delay"].map(String::from);
        assert_eq!(short_keys(&axes), axes);
    }

    #[test]
    fn box_labels_lie_level_while_they_fit_and_stand_up_past_that() {
        let few: Vec<String> = (0..12).map(|i| format!("k1=10, k2={i}: nac")).collect();
        let l = box_layout(&few);
        assert!(!l.upright);
        let widest = few.iter().map(|s| text_px(s, TICK)).max().unwrap_or(0);
        assert!((l.width - BOX_FRAME) / 12 > widest, "{l:?}");
        let many: Vec<String> = (0..81)
            .map(|i| format!("beta=5, a=0.5, psi={i}, k_a=0.05: nac"))
            .collect();
        let l = box_layout(&many);
        assert!(l.upright && l.width >= 81 * 26 && l.label_area > widest);
    }

    #[test]
    fn heat_map_text_contrasts_with_its_cell() {
        assert_eq!(ink_on(heat(0.0)), WHITE);
        assert_eq!(ink_on(RGBAColor(250, 250, 100, 1.0)), BLACK);
    }
}
