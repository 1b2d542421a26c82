//! The figures of `testbed compare`: every law's error against ±k_c per
//! joint, and effort and violation time as bars.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use scenario::Plan;

use crate::compare::types::{Comparison, LawRow, LawSeries, Stats};
use analysis::plots::{COLORS, FAMILY, FONT, Line, Panel, PlotError, RED, category, err, save};

/// Writes `compare_errors`, `compare_error_ratio` and `compare_bars` (PNG
/// and SVG) into `dir`; returns how many figures.
pub fn write_all(dir: &Path, c: &Comparison, plan: &Plan) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(PlotError::folder(dir))?;
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    errors(dir, c, plan)?;
    crate::compare::ratio_plot::write(dir, c, plan)?;
    bars(dir, c)?;
    Ok(3)
}

/// The first seed's e = q − q_d of every law, one panel per joint.
fn errors(dir: &Path, c: &Comparison, plan: &Plan) -> Result<(), PlotError> {
    let curves: Vec<(&LawRow, &LawSeries)> = c
        .laws
        .iter()
        .filter_map(|row| Some((row, row.runs.first()?.series.as_ref()?)))
        .collect();
    let Some((_, first)) = curves.first() else {
        return Err(PlotError::Empty("no law kept its curves"));
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
                    label: match row.runs.first().and_then(|r| r.failed.as_ref()) {
                        Some(_) => format!("{} (FAILED)", row.name),
                        None => row.name.clone(),
                    },
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
fn bars(dir: &Path, c: &Comparison) -> Result<(), PlotError> {
    let png = dir.join("compare_bars.png");
    draw_bars(
        &BitMapBackend::new(&png, (1000, 700)).into_drawing_area(),
        c,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join("compare_bars.svg");
    draw_bars(&SVGBackend::new(&svg, (1000, 700)).into_drawing_area(), c)
        .map_err(PlotError::in_file(&svg))
}

fn draw_bars<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    c: &Comparison,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let title = if c.seeds > 1 {
        format!(
            "Effort and violation per law ({}: median of {} seeds, whiskers: its 95 % interval)",
            c.scenario, c.seeds
        )
    } else {
        format!(
            "Effort and envelope violation per law ({}, one seed)",
            c.scenario
        )
    };
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
        let get = |s: &Stats| s.get(key).unwrap_or(f64::NAN);
        let bars: Vec<Bar> = c
            .laws
            .iter()
            .map(|r| Bar {
                median: get(&r.median),
                low: get(&r.ci95_low),
                high: get(&r.ci95_high),
                failed: r.runs.iter().filter(|x| x.failed.is_some()).count(),
                runs: r.runs.len(),
            })
            .collect();
        bar_panel(area, caption, c, &bars)?;
    }
    root.present().map_err(err)
}

/// One law's bar: the median, its interval, and how many runs failed.
struct Bar {
    median: f64,
    low: f64,
    high: f64,
    failed: usize,
    runs: usize,
}

fn bar_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    c: &Comparison,
    bars: &[Bar],
) -> Result<(), PlotError> {
    let top = bars
        .iter()
        .flat_map(|b| [b.median, if c.seeds > 1 { b.high } else { 0.0 }])
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
        .max(1e-9);
    let n = bars.len();
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 15))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), 0.0..top * 1.15)
        .map_err(err)?;
    let names: Vec<String> = c.laws.iter().map(|r| r.name.clone()).collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n)
        .x_label_formatter(&|x| category(&names, *x))
        .label_style((FAMILY, 12))
        .draw()
        .map_err(err)?;
    let grey = RGBColor(200, 200, 200);
    for (i, b) in bars.iter().enumerate() {
        let x = i as f64;
        // A failed median has no value: a grey bar saying so, never a
        // tall coloured one that reads as a measurement.
        let (v, color) = if b.median.is_finite() {
            (b.median, COLORS[i % COLORS.len()])
        } else {
            (top * 1.1, grey)
        };
        chart
            .draw_series([Rectangle::new(
                [(x - 0.35, 0.0), (x + 0.35, v)],
                color.filled(),
            )])
            .map_err(err)?;
        if c.seeds > 1 && b.low.is_finite() && b.high.is_finite() && b.median.is_finite() {
            let whisker = BLACK.stroke_width(2);
            chart
                .draw_series([
                    PathElement::new(vec![(x, b.low), (x, b.high)], whisker),
                    PathElement::new(vec![(x - 0.1, b.low), (x + 0.1, b.low)], whisker),
                    PathElement::new(vec![(x - 0.1, b.high), (x + 0.1, b.high)], whisker),
                ])
                .map_err(err)?;
        }
        if b.failed > 0 {
            let text = if b.median.is_finite() {
                format!("{}/{} failed", b.failed, b.runs)
            } else {
                format!("FAILED ({}/{})", b.failed, b.runs)
            };
            chart
                .draw_series([Text::new(
                    text,
                    (x - 0.3, v * 0.5),
                    (FAMILY, 13).into_font().color(&RED),
                )])
                .map_err(err)?;
        }
    }
    Ok(())
}

/// Writes `compare_tradeoff` (PNG and SVG): IAE after T_c against effort
/// beyond the gravity hold after T_c, log-log, one polyline per law through
/// its gain scales; filled markers are the law's Pareto front, a cross over
/// a marker a point whose torques saturated, failed scales are left out
/// and counted in the legend.
pub fn write_tradeoff(
    dir: &Path,
    t: &crate::compare::tradeoff::Tradeoff,
    scenario: &str,
) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(PlotError::folder(dir))?;
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    let png = dir.join("compare_tradeoff.png");
    draw_tradeoff(
        &BitMapBackend::new(&png, (1000, 750)).into_drawing_area(),
        t,
        scenario,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join("compare_tradeoff.svg");
    draw_tradeoff(
        &SVGBackend::new(&svg, (1000, 750)).into_drawing_area(),
        t,
        scenario,
    )
    .map_err(PlotError::in_file(&svg))?;
    Ok(1)
}

fn draw_tradeoff<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    t: &crate::compare::tradeoff::Tradeoff,
    scenario: &str,
) -> Result<(), PlotError> {
    use crate::compare::tradeoff::TradeoffPoint as P;
    root.fill(&WHITE).map_err(err)?;
    let scales: Vec<String> = t.scales.iter().map(|s| format!("{s}")).collect();
    let title = format!(
        "Trade-off per law ({scenario}): K1, K2 times {} (filled: the law's Pareto front; ×: saturated)",
        scales.join(", ")
    );
    let root = root.titled(&title, (FAMILY, 18)).map_err(err)?;
    let (left, right) = root.split_horizontally(root.dim_in_pixel().0 / 2);
    tradeoff_panel(
        &left,
        t,
        (|p: &P| p.effort, |p: &P| p.on_front),
        "effort beyond gravity ∫(τ − G(q))² dt after T_c [N² m² s]",
    )?;
    tradeoff_panel(
        &right,
        t,
        (|p: &P| p.energy, |p: &P| p.on_energy_front),
        "energy ∫|τ q̇| dt after T_c [J]",
    )?;
    root.present().map_err(err)
}

/// A point's cost and whether it is on the front for that cost.
type CostOf = (
    fn(&crate::compare::tradeoff::TradeoffPoint) -> Option<f64>,
    fn(&crate::compare::tradeoff::TradeoffPoint) -> bool,
);

/// IAE against one cost, log-log, one polyline per law in scale order.
fn tradeoff_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    t: &crate::compare::tradeoff::Tradeoff,
    (cost, on_front): CostOf,
    x_desc: &str,
) -> Result<(), PlotError> {
    let xy = |p: &crate::compare::tradeoff::TradeoffPoint| {
        cost(p).zip(p.iae).filter(|(e, i)| *e > 0.0 && *i > 0.0)
    };
    let ok: Vec<(f64, f64)> = t.points.iter().filter_map(xy).collect();
    if ok.is_empty() {
        return Err(PlotError::Empty(
            "no law has a finite, positive IAE and cost at any scale",
        ));
    }
    let span = |v: Vec<f64>| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        (lo / 1.5)..(hi * 1.5)
    };
    let x = span(ok.iter().map(|p| p.0).collect());
    let y = span(ok.iter().map(|p| p.1).collect());
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x.log_scale(), y.log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(format!("{x_desc} (median over seeds)"))
        .y_desc("IAE after T_c [rad s]")
        .label_style((FAMILY, 12))
        .draw()
        .map_err(err)?;
    let mut laws: Vec<controller::LawName> = t.points.iter().map(|p| p.law).collect();
    laws.dedup();
    for (k, law) in laws.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let mine: Vec<_> = t.points.iter().filter(|p| p.law == *law).collect();
        let line: Vec<(f64, f64)> = mine.iter().filter_map(|p| xy(p)).collect();
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
                let style = if on_front(p) {
                    color.filled()
                } else {
                    color.stroke_width(2)
                };
                Some(Circle::new(xy(p)?, 5, style))
            }))
            .map_err(err)?;
        // Saturated points: limited by the motors, not by the gains.
        chart
            .draw_series(
                mine.iter()
                    .filter(|p| p.saturated_s > 0.0)
                    .filter_map(|p| Some(Cross::new(xy(p)?, 9, BLACK.stroke_width(2)))),
            )
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 12))
        .draw()
        .map_err(err)?;
    Ok(())
}
