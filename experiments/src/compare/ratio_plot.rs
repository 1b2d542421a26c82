//! `compare_error_ratio`: |e_i| / k_c,i after T_c, one small panel per law
//! on one shared scale fitted to the errors, so that errors of 0.03 rad
//! are visible (on the ±k_c scale they are a flat line) and eleven laws do
//! not overlap. Laws whose ratios coincide share a panel and its title
//! ("nac = nac-no-critic = …"). The envelope is the line at 1, drawn when
//! the scale reaches it; a failed law's title says so.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use scenario::Plan;

use crate::compare::types::{Comparison, LawSeries};
use analysis::plot_style::{
    CAPTION, COINCIDE, GRID, GRID_LIGHT, Key, LEGEND_WIDTH, MARGIN, TICK, TITLE, caption,
    caption_height, coincident, legend, plain, shared_label, text_px, tick_count,
};
use analysis::plots::{COLORS, FAMILY, PlotError, RED, err};

/// Writes `compare_error_ratio.png` and `.svg` into `dir`.
pub fn write(dir: &Path, c: &Comparison, plan: &Plan) -> Result<(), PlotError> {
    let tc = plan.scenario.controller.tc;
    let laws = law_ratios(c, tc);
    let top = scale_top(&laws);
    let panels = panels(c, &laws, top);
    let (w, h) = size(panels.len());
    let (cols, _) = grid(panels.len());
    let title_w = (w - LEGEND_WIDTH) / cols as u32;
    let caption_lines = panels
        .iter()
        .map(|p| caption_height(&p.title, title_w))
        .max()
        .unwrap_or(1);
    let png = dir.join("compare_error_ratio.png");
    let figure = Figure {
        c,
        plan,
        laws: &laws,
        panels: &panels,
        top,
        caption_lines,
    };
    draw(
        &BitMapBackend::new(&png, (w, h)).into_drawing_area(),
        &figure,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join("compare_error_ratio.svg");
    draw(&SVGBackend::new(&svg, (w, h)).into_drawing_area(), &figure)
        .map_err(PlotError::in_file(&svg))
}

/// Columns and rows of the grid for `n` panels.
fn grid(n: usize) -> (usize, usize) {
    let cols = if n <= 4 { 2 } else { 3 }.min(n.max(1));
    (cols, n.div_ceil(cols).max(1))
}

fn size(n: usize) -> (u32, u32) {
    let (cols, rows) = grid(n);
    (420 * cols as u32 + LEGEND_WIDTH, 280 * rows as u32 + 60)
}

/// Times from T_c on, and |e_i|/k_c,i per joint at those times.
type Ratios = (Vec<f64>, Vec<Vec<f64>>);

/// One law's ratios (first seed) and whether its run failed.
struct LawRatios {
    row: usize,
    ratios: Ratios,
    failed: bool,
}

/// (t, |e_i|/k_c,i per joint) from T_c on.
fn ratios(s: &LawSeries, tc: f64) -> Ratios {
    let from = s.t.iter().position(|t| *t >= tc).unwrap_or(s.t.len());
    let t = s.t[from..].to_vec();
    let r =
        s.e.iter()
            .zip(&s.kc)
            .map(|(e, k)| {
                e.get(from..)
                    .unwrap_or_default()
                    .iter()
                    .zip(k.get(from..).unwrap_or_default())
                    .map(|(e, k)| e.abs() / k)
                    .collect()
            })
            .collect();
    (t, r)
}

/// Every law that kept its curves.
fn law_ratios(c: &Comparison, tc: f64) -> Vec<LawRatios> {
    c.laws
        .iter()
        .enumerate()
        .filter_map(|(row, law)| {
            let run = law.runs.first()?;
            Some(LawRatios {
                row,
                ratios: ratios(run.series.as_ref()?, tc),
                failed: run.failed.is_some(),
            })
        })
        .collect()
}

/// The one scale of every panel: the largest finite ratio of the laws
/// that did not fail, with a margin, at most 2 (a failed law past it is
/// clipped and marked as failed). Not at least 1: a fixed 0–1 flattens a
/// 1 % error into the axis.
fn scale_top(laws: &[LawRatios]) -> f64 {
    let peak = |failed: bool| {
        laws.iter()
            .filter(|l| l.failed == failed)
            .flat_map(|l| l.ratios.1.iter().flatten().copied())
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max)
    };
    let peak = if peak(false) > 0.0 {
        peak(false)
    } else {
        peak(true)
    };
    (peak * (1.0 + 2.0 * MARGIN)).clamp(1e-6, 2.0)
}

/// One panel: the laws whose ratios coincide (indices into the laws),
/// and its title.
struct PanelOf {
    members: Vec<usize>,
    title: String,
    failed: bool,
}

/// The laws grouped where their ratios coincide within [`COINCIDE`] of
/// the shared scale on every joint; a failed law alone, in table order.
fn panels(c: &Comparison, laws: &[LawRatios], top: f64) -> Vec<PanelOf> {
    let ok: Vec<usize> = (0..laws.len()).filter(|i| !laws[*i].failed).collect();
    let slices: Vec<Vec<&[f64]>> = ok
        .iter()
        .map(|i| laws[*i].ratios.1.iter().map(Vec::as_slice).collect())
        .collect();
    let joints = slices.first().map_or(0, Vec::len);
    let mut panels: Vec<PanelOf> = coincident(&slices, &vec![top; joints], COINCIDE)
        .into_iter()
        .map(|g| {
            let members: Vec<usize> = g.into_iter().map(|k| ok[k]).collect();
            let names: Vec<&str> = members
                .iter()
                .map(|m| c.laws[laws[*m].row].name.as_str())
                .collect();
            PanelOf {
                title: shared_label(&names),
                members,
                failed: false,
            }
        })
        .collect();
    panels.extend(
        (0..laws.len())
            .filter(|i| laws[*i].failed)
            .map(|i| PanelOf {
                members: vec![i],
                title: format!("{} — FAILED", c.laws[laws[i].row].name),
                failed: true,
            }),
    );
    panels.sort_by_key(|p| p.members.first().copied().unwrap_or(usize::MAX));
    panels
}

/// What one drawing of the figure needs.
struct Figure<'a> {
    c: &'a Comparison,
    plan: &'a Plan,
    laws: &'a [LawRatios],
    panels: &'a [PanelOf],
    top: f64,
    /// Lines of the longest panel title.
    caption_lines: usize,
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    f: &Figure<'_>,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let tc = f.plan.scenario.controller.tc;
    let title = format!(
        "|e| / k_c after T_c = {} s per joint, first seed ({}); one scale for every law",
        plain(tc),
        f.c.scenario
    );
    let root = root.titled(&title, (FAMILY, TITLE)).map_err(err)?;
    let (t_lo, t_hi) = f
        .laws
        .iter()
        .filter_map(|l| Some((*l.ratios.0.first()?, *l.ratios.0.last()?)))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, b| {
            (a.0.min(b.0), a.1.max(b.1))
        });
    // NaN-free: both come from finite times, or are the fold's ±∞.
    if t_lo >= t_hi {
        return Err(PlotError::Empty("no law's run reaches past T_c"));
    }
    let (w, _) = root.dim_in_pixel();
    let (main, side) = root.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
    let (cols, rows) = grid(f.panels.len());
    for (area, p) in main.split_evenly((rows, cols)).iter().zip(f.panels) {
        law_panel(area, f, p, (t_lo, t_hi))?;
    }
    side_legend(&side, f)?;
    root.present().map_err(err)
}

/// The joints' colours, the envelope, and how to read the panels.
fn side_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    f: &Figure<'_>,
) -> Result<(), PlotError> {
    let joints = f.plan.robot.model.joint_names();
    let mut keys: Vec<Key> = joints
        .iter()
        .enumerate()
        .map(|(i, name)| Key::line(name.clone(), COLORS[i % COLORS.len()], false, 2))
        .collect();
    let mut notes = vec![format!(
        "Laws in one panel coincide within {} % of the scale.",
        COINCIDE * 100.0
    )];
    if f.top >= 1.0 {
        keys.push(Key::line("the envelope (1)", RED, true, 1));
    } else {
        notes.push(format!(
            "The envelope (1) is above this scale: the largest ratio is {} of it.",
            plain((f.top / (1.0 + 2.0 * MARGIN) * 1000.0).round() / 1000.0)
        ));
    }
    legend(area, &keys, &notes)
}

/// One panel: its laws' leader's ratio per joint.
fn law_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    f: &Figure<'_>,
    p: &PanelOf,
    (t_lo, t_hi): (f64, f64),
) -> Result<(), PlotError> {
    let Some(lead) = p.members.first().and_then(|m| f.laws.get(*m)) else {
        return Ok(());
    };
    let color = if p.failed { RED } else { BLACK };
    let font = (FAMILY, CAPTION).into_font().color(&color);
    // Every panel's caption as tall as the tallest, so the axes line up.
    let area = caption(area, &p.title, font, CAPTION, f.caption_lines)?;
    let (w, h) = area.dim_in_pixel();
    let top = f.top;
    let mut chart = ChartBuilder::on(&area)
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(t_lo..t_hi, 0.0..top)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_desc("|e| / k_c")
        .bold_line_style(GRID)
        .light_line_style(GRID_LIGHT)
        .x_labels(tick_count(w.saturating_sub(60), text_px("10.0", TICK)))
        .y_labels(tick_count(h.saturating_sub(40), 2 * TICK))
        .label_style((FAMILY, TICK))
        .draw()
        .map_err(err)?;
    if top >= 1.0 {
        chart
            .draw_series(DashedLineSeries::new(
                [(t_lo, 1.0), (t_hi, 1.0)],
                6,
                4,
                RED.stroke_width(1),
            ))
            .map_err(err)?;
    }
    let (t, r) = &lead.ratios;
    for (i, y) in r.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let points = t.iter().zip(y).map(|(t, y)| (*t, y.min(top)));
        chart
            .draw_series(LineSeries::new(thin(points), color.stroke_width(1)))
            .map_err(err)?;
    }
    Ok(())
}

/// At most 2000 points per curve: more only makes the SVG large.
fn thin(points: impl Iterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    let all: Vec<(f64, f64)> = points.collect();
    let step = all.len().div_ceil(2000).max(1);
    all.into_iter().step_by(step).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law(peak: f64, failed: bool) -> LawRatios {
        LawRatios {
            row: 0,
            ratios: (vec![2.0, 3.0], vec![vec![peak / 2.0, peak]]),
            failed,
        }
    }

    #[test]
    fn the_shared_scale_is_fitted_to_the_errors_not_to_the_envelope() {
        // 1 % of the envelope: a scale a little above 0.01, not 0–1.
        let top = scale_top(&[law(0.01, false), law(0.004, false)]);
        assert!(top > 0.01 && top < 0.0115, "{top}");
        // A failed law's runaway does not set the scale.
        let top = scale_top(&[law(0.2, false), law(1e9, true)]);
        assert!(top < 0.25, "{top}");
        // Only failed laws: theirs, at most 2.
        assert_eq!(scale_top(&[law(1e9, true)]), 2.0);
        assert!(scale_top(&[]) > 0.0);
    }
}
