//! `compare_tradeoff`: IAE after T_c against a cost, log-log, one polyline
//! per law through its gain scales. Laws whose points coincide at every
//! scale (within a thousandth of each axis's range, in decades) are one
//! polyline under a shared label: on the paper's scenario six laws fall
//! on one line, and drawn apart five of them hide under the last.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::compare::tradeoff::{Tradeoff, TradeoffPoint};
use analysis::plot_style::{
    COINCIDE, GRID, GRID_LIGHT, Key, LEGEND_WIDTH, Mark, NEAR, NOTE, TICK, TITLE, clip_log_x,
    coincident, halo_widths, legend, log_axis, main_body, near_note, near_pairs, plain,
    shared_label, span, text_px, tick_count,
};
use analysis::plots::{COLORS, FAMILY, PlotError, err, register_font};

/// Writes `compare_tradeoff` (PNG and SVG): IAE after T_c against effort
/// beyond the gravity hold after T_c and against energy, log-log, one
/// polyline per law (or per laws that coincide) through its gain scales;
/// filled markers are the law's Pareto front, a cross over a marker a
/// point whose torques saturated, failed scales are left out and counted
/// in the legend.
pub fn write_tradeoff(dir: &Path, t: &Tradeoff, scenario: &str) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(PlotError::folder(dir))?;
    register_font();
    let size = (1000 + LEGEND_WIDTH, 700);
    let png = dir.join("compare_tradeoff.png");
    draw(
        &BitMapBackend::new(&png, size).into_drawing_area(),
        t,
        scenario,
    )
    .map_err(PlotError::in_file(&png))?;
    let svg = dir.join("compare_tradeoff.svg");
    draw(
        &SVGBackend::new(&svg, size).into_drawing_area(),
        t,
        scenario,
    )
    .map_err(PlotError::in_file(&svg))?;
    Ok(1)
}

/// Laws drawn as one polyline: the leader's points, the shared label, the
/// leader's colour (its place among the laws), its stroke width (wider
/// under a polyline drawn close over it).
struct Group<'a> {
    points: Vec<&'a TradeoffPoint>,
    label: String,
    color: RGBColor,
    width: u32,
}

/// log10 of a positive value, NaN for anything else (a failed scale).
fn decades(v: Option<f64>) -> f64 {
    v.filter(|v| *v > 0.0 && v.is_finite())
        .map_or(f64::NAN, f64::log10)
}

/// The laws in the order run, their points grouped where they coincide
/// on IAE, effort and energy at every scale, and notes for the groups
/// that only look alike.
fn groups(t: &Tradeoff) -> (Vec<Group<'_>>, Vec<String>) {
    let mut laws: Vec<controller::LawName> = t.points.iter().map(|p| p.law).collect();
    laws.dedup();
    let mine: Vec<Vec<&TradeoffPoint>> = laws
        .iter()
        .map(|law| t.points.iter().filter(|p| p.law == *law).collect())
        .collect();
    let axes: [fn(&TradeoffPoint) -> Option<f64>; 3] = [|p| p.iae, |p| p.effort, |p| p.energy];
    let coords: Vec<Vec<Vec<f64>>> = mine
        .iter()
        .map(|pts| {
            axes.iter()
                .map(|a| pts.iter().map(|p| decades(a(p))).collect())
                .collect()
        })
        .collect();
    let ranges: Vec<f64> = (0..axes.len())
        .map(|a| span(coords.iter().map(|c| c[a].as_slice())))
        .collect();
    let slices: Vec<Vec<&[f64]>> = coords
        .iter()
        .map(|c| c.iter().map(Vec::as_slice).collect())
        .collect();
    let members = coincident(&slices, &ranges, COINCIDE);
    let pairs = near_pairs(&slices, &ranges, &members, NEAR);
    let widths = halo_widths(members.len(), &pairs);
    let notes = pairs
        .iter()
        .map(|(a, b, gap)| {
            near_note(
                &laws[members[*b][0]].to_string(),
                &laws[members[*a][0]].to_string(),
                *gap,
            )
        })
        .collect();
    let groups = members
        .iter()
        .zip(widths)
        .map(|(members, width)| {
            let lead = members[0];
            let names: Vec<String> = members.iter().map(|m| laws[*m].to_string()).collect();
            let failed = mine[lead].iter().filter(|p| p.iae.is_none()).count();
            let mut label = shared_label(&names);
            if failed > 0 {
                label.push_str(&format!(" ({failed} scale(s) failed)"));
            }
            Group {
                points: mine[lead].clone(),
                label,
                color: COLORS[lead % COLORS.len()],
                width,
            }
        })
        .collect();
    (groups, notes)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    t: &Tradeoff,
    scenario: &str,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let scales: Vec<String> = t.scales.iter().map(|s| plain(*s)).collect();
    let title = format!(
        "Trade-off per law ({scenario}): K1, K2 times {}",
        scales.join(", ")
    );
    let root = root.titled(&title, (FAMILY, TITLE)).map_err(err)?;
    let (groups, near) = groups(t);
    let (w, _) = root.dim_in_pixel();
    let (plots, side) = root.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
    let (left, right) = plots.split_horizontally(plots.dim_in_pixel().0 / 2);
    let mut off = panel(
        &left,
        &groups,
        (|p: &TradeoffPoint| p.effort, |p: &TradeoffPoint| p.on_front),
        (
            "effort beyond gravity ∫(τ − G(q))² dt after T_c [N² m² s]",
            "effort",
        ),
    )?;
    off.extend(panel(
        &right,
        &groups,
        (
            |p: &TradeoffPoint| p.energy,
            |p: &TradeoffPoint| p.on_energy_front,
        ),
        ("energy ∫|τ q̇| dt after T_c [J]", "energy"),
    )?);
    let mut notes = notes(near);
    notes.extend(off);
    legend(&side, &keys(&groups), &notes)?;
    root.present().map_err(err)
}

/// One entry per polyline, then what the markers mean.
fn keys(groups: &[Group<'_>]) -> Vec<Key> {
    let grey = NOTE;
    let mut keys: Vec<Key> = groups
        .iter()
        .map(|g| Key::line(g.label.clone(), g.color, false, 3))
        .collect();
    keys.push(Key {
        label: "on the law's Pareto front".into(),
        color: grey,
        mark: Mark::Circle { filled: true },
    });
    keys.push(Key {
        label: "not on it".into(),
        color: grey,
        mark: Mark::Circle { filled: false },
    });
    keys.push(Key {
        label: "torques saturated".into(),
        color: RGBColor(0, 0, 0),
        mark: Mark::Cross,
    });
    keys
}

/// How to read the figure, then which polylines only look alike.
fn notes(near: Vec<String>) -> Vec<String> {
    let mut notes = vec![
        "Each point is the median over seeds at one gain scale.".into(),
        format!(
            "Laws under one label coincide within {} % of each axis's range (in decades).",
            COINCIDE * 100.0
        ),
    ];
    notes.extend(near);
    notes
}

/// A point's cost and whether it is on the front for that cost.
type CostOf = (
    fn(&TradeoffPoint) -> Option<f64>,
    fn(&TradeoffPoint) -> bool,
);

/// A positive range around `v`'s main body ([`main_body`]: a runaway
/// cost a few decades out would squash every other point into one
/// column), with a margin of a factor 1.5 each side.
fn axis_span(v: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    main_body(v, OUTLIER_GAP).map(|(lo, hi)| (lo / 1.5, hi * 1.5))
}

/// A positive range around every value of `v` (IAE: every point stays
/// on the y scale, so only the x scale needs notes), margin as above.
fn full_span(v: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = v.fold((f64::INFINITY, 0.0_f64), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    (lo.is_finite() && hi > 0.0).then_some((lo / 1.5, hi * 1.5))
}

/// Costs more than this many decades beyond the rest are off the scale.
const OUTLIER_GAP: f64 = 1.0;

/// The notes for the points whose cost lies off the x scale, one per
/// gain scale (the laws that run away usually do so together): "Off the
/// effort scale (right) at K × 4: nac = pd, smc (effort 5.5e5,
/// saturated)."
fn off_scale_notes(
    groups: &[Group<'_>],
    xy: impl Fn(&TradeoffPoint) -> Option<(f64, f64)>,
    (lo, hi): (f64, f64),
    what: &str,
) -> Vec<String> {
    let off: Vec<(&str, &TradeoffPoint, f64)> = groups
        .iter()
        .flat_map(|g| g.points.iter().map(move |p| (g.label.as_str(), *p)))
        .filter_map(|(label, p)| {
            let x = xy(p)?.0;
            (x < lo || x > hi).then_some((label, p, x))
        })
        .collect();
    let mut scales: Vec<f64> = off.iter().map(|(_, p, _)| p.scale).collect();
    scales.sort_by(f64::total_cmp);
    scales.dedup();
    scales
        .iter()
        .map(|scale| {
            let here: Vec<&(&str, &TradeoffPoint, f64)> =
                off.iter().filter(|(_, p, _)| p.scale == *scale).collect();
            let labels: Vec<&str> = here.iter().map(|(l, _, _)| *l).collect();
            let side = if here.iter().all(|(_, _, x)| *x > hi) {
                "right"
            } else {
                "left"
            };
            let (min, max) = here
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |(a, b), (_, _, x)| {
                    (a.min(*x), b.max(*x))
                });
            let value = if sig2(min) == sig2(max) {
                sig2(min)
            } else {
                format!("{}–{}", sig2(min), sig2(max))
            };
            let saturated = if here.iter().all(|(_, p, _)| p.saturated_s > 0.0) {
                ", saturated"
            } else {
                ""
            };
            format!(
                "Off the {what} scale ({side}) at K × {}: {} ({what} {value}{saturated}).",
                plain(*scale),
                labels.join(", ")
            )
        })
        .collect()
}

/// Two significant digits, in scientific notation when large.
fn sig2(v: f64) -> String {
    if v.abs() >= 1e4 {
        format!("{v:.1e}")
    } else {
        plain(format!("{v:.2}").parse().unwrap_or(v))
    }
}

/// IAE against one cost, log-log, one polyline per group in scale order;
/// returns notes for the points off its x scale.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    groups: &[Group<'_>],
    (cost, on_front): CostOf,
    (x_desc, what): (&str, &str),
) -> Result<Vec<String>, PlotError> {
    let xy = |p: &TradeoffPoint| cost(p).zip(p.iae).filter(|(e, i)| *e > 0.0 && *i > 0.0);
    let ok: Vec<(f64, f64)> = groups
        .iter()
        .flat_map(|g| g.points.iter().filter_map(|p| xy(p)))
        .collect();
    let (Some(x), Some(y)) = (
        axis_span(ok.iter().map(|p| p.0)),
        full_span(ok.iter().map(|p| p.1)),
    ) else {
        return Err(PlotError::Empty(
            "no law has a finite, positive IAE and cost at any scale",
        ));
    };
    let (w, h) = area.dim_in_pixel();
    let x_ticks = tick_count(w.saturating_sub(100), text_px("0.0001", TICK));
    let y_ticks = tick_count(h.saturating_sub(90), 2 * TICK);
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(log_axis(x.0, x.1, x_ticks), log_axis(y.0, y.1, y_ticks))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc("IAE after T_c [rad s]")
        .bold_line_style(GRID)
        .light_line_style(GRID_LIGHT)
        .x_label_formatter(&|v| plain(*v))
        .y_label_formatter(&|v| plain(*v))
        .label_style((FAMILY, TICK))
        .draw()
        .map_err(err)?;
    let shown = |p: &TradeoffPoint| xy(p).is_some_and(|(c, _)| c >= x.0 && c <= x.1);
    for g in groups {
        let color = g.color;
        let line: Vec<(f64, f64)> = g.points.iter().filter_map(|p| xy(p)).collect();
        for piece in clip_log_x(&line, x.0, x.1) {
            chart
                .draw_series(LineSeries::new(piece, color.stroke_width(g.width)))
                .map_err(err)?;
        }
        chart
            .draw_series(g.points.iter().filter(|p| shown(p)).filter_map(|p| {
                let style = if on_front(p) {
                    color.filled()
                } else {
                    color.stroke_width(2)
                };
                Some(Circle::new(xy(p)?, 3 + g.width, style))
            }))
            .map_err(err)?;
        // Saturated points: limited by the motors, not by the gains.
        chart
            .draw_series(
                g.points
                    .iter()
                    .filter(|p| shown(p))
                    .filter(|p| p.saturated_s > 0.0)
                    .filter_map(|p| Some(Cross::new(xy(p)?, 9, BLACK.stroke_width(2)))),
            )
            .map_err(err)?;
    }
    Ok(off_scale_notes(groups, xy, x, what))
}
