//! The figures of `testbed compare`: every law's error against ±k_c per
//! joint, and effort and violation time as bars.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use scenario::Plan;

use crate::compare::{Comparison, LawRow};
use analysis::plots::{COLORS, FAMILY, FONT, Line, Panel, PlotError, RED, category, err, save};

/// Writes `compare_errors` and `compare_bars` (PNG and SVG) into `dir`;
/// returns how many figures.
pub fn write_all(dir: &Path, c: &Comparison, plan: &Plan) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(|e| PlotError(format!("{}: {e}", dir.display())))?;
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    errors(dir, c, plan).map_err(PlotError)?;
    bars(dir, c).map_err(PlotError)?;
    Ok(2)
}

/// The first seed's e = q − q_d of every law, one panel per joint.
fn errors(dir: &Path, c: &Comparison, plan: &Plan) -> Result<(), String> {
    let curves: Vec<(&LawRow, &crate::compare::LawSeries)> = c
        .laws
        .iter()
        .filter_map(|row| Some((row, row.runs.first()?.series.as_ref()?)))
        .collect();
    let Some((_, first)) = curves.first() else {
        return Err("no law kept its curves".into());
    };
    let names = plan.robot.model.joint_names();
    let neg_kc: Vec<Vec<f64>> = first
        .kc
        .iter()
        .map(|k| k.iter().map(|x| -x).collect())
        .collect();
    let panels: Vec<Panel<'_>> = (0..names.len())
        .map(|i| {
            let mut lines: Vec<Line<'_>> = curves
                .iter()
                .enumerate()
                .map(|(k, (row, s))| Line {
                    label: row.law.law.to_string(),
                    y: &s.e[i],
                    color: COLORS[k % COLORS.len()],
                    dashed: false,
                })
                .collect();
            lines.push(Line {
                label: "± k_c".into(),
                y: &first.kc[i],
                color: RED,
                dashed: true,
            });
            lines.push(Line {
                label: String::new(),
                y: &neg_kc[i],
                color: RED,
                dashed: true,
            });
            Panel {
                title: format!("{}: tracking error e = q − q_d", names[i]),
                y_label: "e [rad]",
                lines,
            }
        })
        .collect();
    save(
        dir,
        "compare_errors",
        &format!("Tracking errors of every law with ± k_c ({})", c.scenario),
        &first.t,
        &panels,
        Some(plan.scenario.controller.tc),
    )
}

/// Effort after T_c and violation time per law (medians over seeds).
fn bars(dir: &Path, c: &Comparison) -> Result<(), String> {
    let png = dir.join("compare_bars.png");
    draw_bars(
        &BitMapBackend::new(&png, (1000, 700)).into_drawing_area(),
        c,
    )
    .map_err(|e| format!("{}: {e}", png.display()))?;
    let svg = dir.join("compare_bars.svg");
    draw_bars(&SVGBackend::new(&svg, (1000, 700)).into_drawing_area(), c)
        .map_err(|e| format!("{}: {e}", svg.display()))
}

fn draw_bars<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    c: &Comparison,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(err)?;
    let title = format!(
        "Effort and envelope violation per law ({}, median over {} seed(s))",
        c.scenario, c.seeds
    );
    let root = root.titled(&title, (FAMILY, 20)).map_err(err)?;
    let areas = root.split_evenly((2, 1));
    let panels = [
        ("effort ∫τ² dt after T_c [N² m² s]", "effort_after_tc"),
        (
            "violation time ∫1[|e| ≥ k_c] dt over the run [s]",
            "violation_s",
        ),
    ];
    for (area, (caption, key)) in areas.iter().zip(panels) {
        let values: Vec<f64> = c
            .laws
            .iter()
            .map(|r| r.median.get(key).unwrap_or(0.0))
            .collect();
        bar_panel(area, caption, c, &values)?;
    }
    root.present().map_err(err)
}

fn bar_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    c: &Comparison,
    values: &[f64],
) -> Result<(), String> {
    let top = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
        .max(1e-9);
    let n = values.len();
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 15))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), 0.0..top * 1.1)
        .map_err(err)?;
    let names: Vec<String> = c.laws.iter().map(|r| r.law.law.to_string()).collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n)
        .x_label_formatter(&|x| category(&names, *x))
        .label_style((FAMILY, 12))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(values.iter().enumerate().map(|(i, v)| {
            let x = i as f64;
            let v = if v.is_finite() { *v } else { top * 1.1 };
            Rectangle::new(
                [(x - 0.35, 0.0), (x + 0.35, v)],
                COLORS[i % COLORS.len()].filled(),
            )
        }))
        .map_err(err)?;
    Ok(())
}

/// Writes `compare_tradeoff` (PNG and SVG): IAE after T_c against effort
/// after T_c, log-log, one polyline per law through its gain scales;
/// filled markers are the law's Pareto front, failed scales are left out
/// and counted in the legend.
pub fn write_tradeoff(
    dir: &Path,
    t: &crate::compare_tradeoff::Tradeoff,
    scenario: &str,
) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(|e| PlotError(format!("{}: {e}", dir.display())))?;
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    let png = dir.join("compare_tradeoff.png");
    draw_tradeoff(
        &BitMapBackend::new(&png, (1000, 750)).into_drawing_area(),
        t,
        scenario,
    )
    .map_err(|e| PlotError(format!("{}: {e}", png.display())))?;
    let svg = dir.join("compare_tradeoff.svg");
    draw_tradeoff(
        &SVGBackend::new(&svg, (1000, 750)).into_drawing_area(),
        t,
        scenario,
    )
    .map_err(|e| PlotError(format!("{}: {e}", svg.display())))?;
    Ok(1)
}

fn draw_tradeoff<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    t: &crate::compare_tradeoff::Tradeoff,
    scenario: &str,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(err)?;
    let ok: Vec<(f64, f64)> = t
        .points
        .iter()
        .filter_map(|p| p.effort.zip(p.iae))
        .filter(|(e, i)| *e > 0.0 && *i > 0.0)
        .collect();
    if ok.is_empty() {
        return Err("no law has a finite, positive IAE and effort at any scale".into());
    }
    let span = |v: Vec<f64>| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        (lo / 1.5)..(hi * 1.5)
    };
    let x = span(ok.iter().map(|p| p.0).collect());
    let y = span(ok.iter().map(|p| p.1).collect());
    let scales: Vec<String> = t.scales.iter().map(|s| format!("{s}")).collect();
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "Trade-off per law ({scenario}): gain scales {} (filled: Pareto front)",
                scales.join(", ")
            ),
            (FAMILY, 18),
        )
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x.log_scale(), y.log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("effort ∫τ² dt after T_c [N² m² s] (median over seeds)")
        .y_desc("IAE after T_c [rad s]")
        .label_style((FAMILY, 13))
        .draw()
        .map_err(err)?;
    let mut laws: Vec<controller::LawName> = t.points.iter().map(|p| p.law).collect();
    laws.dedup();
    for (k, law) in laws.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let mine: Vec<_> = t.points.iter().filter(|p| p.law == *law).collect();
        let line: Vec<(f64, f64)> = mine
            .iter()
            .filter_map(|p| p.effort.zip(p.iae))
            .filter(|(e, i)| *e > 0.0 && *i > 0.0)
            .collect();
        let failed = mine.iter().filter(|p| p.iae.is_none()).count();
        let label = if failed > 0 {
            format!("{law} ({failed} scale(s) failed)")
        } else {
            law.to_string()
        };
        chart
            .draw_series(LineSeries::new(line, color.stroke_width(2)))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        chart
            .draw_series(mine.iter().filter_map(|p| {
                let (e, i) = p.effort.zip(p.iae)?;
                let style = if p.on_front {
                    color.filled()
                } else {
                    color.stroke_width(2)
                };
                Some(Circle::new((e, i), 5, style))
            }))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 13))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)
}
