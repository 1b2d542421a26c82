//! The figures of `testbed compare`: every law's error against ±k_c per
//! joint, and effort and violation time as bars. Laws whose curves
//! coincide are drawn as one curve under a shared label ("nac =
//! nac-no-critic = …"); the rest are split into small multiples of a few
//! laws each, so that no law hides under another. The trade-off figure is
//! in `plots/tradeoff_figure.rs`.

mod tradeoff_figure;

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use scenario::Plan;

pub use tradeoff_figure::write_tradeoff;

use crate::compare::types::{Comparison, LawSeries, Stats};
use analysis::plot_style::{
    CAPTION, COINCIDE, GRID, GRID_LIGHT, NEAR, TICK, TITLE, category, category_axis, coincident,
    fitted, halo_widths, near_note, near_pairs, shared_label, text_px,
};
use analysis::plots::{COLORS, FAMILY, Line, Panel, PlotError, RED, err, register_font, save_grid};

/// The most laws' curves in one panel of `compare_errors`.
const PER_PANEL: usize = 4;

/// Writes `compare_errors`, `compare_error_ratio` and `compare_bars` (PNG
/// and SVG) into `dir`; returns how many figures.
pub fn write_all(dir: &Path, c: &Comparison, plan: &Plan) -> Result<usize, PlotError> {
    std::fs::create_dir_all(dir).map_err(PlotError::folder(dir))?;
    register_font();
    errors(dir, c, plan)?;
    crate::compare::ratio_plot::write(dir, c, plan)?;
    bars(dir, c)?;
    Ok(3)
}

/// One law's first-seed curves, drawn as one with the laws that coincide.
struct Curve<'a> {
    /// Its row in the comparison (its colour, as in the bars).
    row: usize,
    series: &'a LawSeries,
    failed: bool,
}

/// Laws drawn as one curve: their rows' curves, the first drawn.
struct Group<'a> {
    members: Vec<&'a Curve<'a>>,
    label: String,
}

/// The first seed's curves of every law that kept them.
fn curves(c: &Comparison) -> Vec<Curve<'_>> {
    c.laws
        .iter()
        .enumerate()
        .filter_map(|(row, law)| {
            let run = law.runs.first()?;
            Some(Curve {
                row,
                series: run.series.as_ref()?,
                failed: run.failed.is_some(),
            })
        })
        .collect()
}

/// Each joint's range of e over the laws that did not fail, and ±k_c:
/// what "within a thousandth of the range" is measured against (a failed
/// law's runaway curve would make every other law look alike).
fn ranges(curves: &[Curve<'_>], kc: &[Vec<f64>]) -> Vec<f64> {
    kc.iter()
        .enumerate()
        .map(|(j, k)| {
            let laws = curves.iter().filter(|c| !c.failed);
            let e = laws.filter_map(|c| c.series.e.get(j)).flatten().copied();
            let bound = k.iter().flat_map(|x| [*x, -x]);
            fitted(e.chain(bound), 0.0).map_or(0.0, |(lo, hi)| hi - lo)
        })
        .collect()
}

/// Groups the laws whose e coincide on every joint within [`COINCIDE`] of
/// the joint's range, in table order; a failed law is its own group.
fn groups<'a>(curves: &'a [Curve<'a>], ranges: &[f64], c: &Comparison) -> Vec<Group<'a>> {
    let ok: Vec<&Curve<'_>> = curves.iter().filter(|c| !c.failed).collect();
    let slices: Vec<Vec<&[f64]>> = ok
        .iter()
        .map(|c| c.series.e.iter().map(Vec::as_slice).collect())
        .collect();
    let mut groups: Vec<Group<'_>> = coincident(&slices, ranges, COINCIDE)
        .into_iter()
        .map(|members| {
            let members: Vec<&Curve<'_>> = members.into_iter().map(|i| ok[i]).collect();
            let names: Vec<&str> = members
                .iter()
                .map(|m| c.laws[m.row].name.as_str())
                .collect();
            Group {
                label: shared_label(&names),
                members,
            }
        })
        .collect();
    groups.extend(curves.iter().filter(|c| c.failed).map(|m| Group {
        label: format!("{} (FAILED)", c.laws[m.row].name),
        members: vec![m],
    }));
    groups.sort_by_key(|g| g.members.first().map_or(usize::MAX, |m| m.row));
    groups
}

/// `n` groups in rows of at most [`PER_PANEL`], as even as they go.
fn chunk_size(n: usize) -> usize {
    let rows = n.div_ceil(PER_PANEL).max(1);
    n.div_ceil(rows).max(1)
}

/// How a row of panels draws its groups: the notes for those that look
/// alike without coinciding (two curves a line's width apart read as
/// one), and stroke widths that leave the one drawn first as a rim
/// around the one over it.
fn near_look(groups: &[&Group<'_>], ranges: &[f64], c: &Comparison) -> (Vec<String>, Vec<u32>) {
    let leaders: Vec<Vec<&[f64]>> = groups
        .iter()
        .map(|g| match g.members.first() {
            Some(m) if !m.failed => m.series.e.iter().map(Vec::as_slice).collect(),
            _ => Vec::new(),
        })
        .collect();
    let each: Vec<Vec<usize>> = (0..groups.len()).map(|i| vec![i]).collect();
    let pairs = near_pairs(&leaders, ranges, &each, NEAR);
    let name = |i: usize| {
        let row = groups[i].members.first().map_or(0, |m| m.row);
        c.laws[row].name.clone()
    };
    let notes = pairs
        .iter()
        .map(|(a, b, gap)| near_note(&name(*b), &name(*a), *gap))
        .collect();
    (notes, halo_widths(groups.len(), &pairs))
}

/// The first seed's e = q − q_d of every law: a row of panels (one per
/// joint) per few laws, each with ±k_c and T_c.
fn errors(dir: &Path, c: &Comparison, plan: &Plan) -> Result<(), PlotError> {
    let curves = curves(c);
    // The longest run's times and envelope: a law that stopped early has
    // fewer samples, never a shorter time axis for the others.
    let Some(longest) = curves.iter().max_by_key(|c| c.series.t.len()) else {
        return Err(PlotError::Empty("no law kept its curves"));
    };
    let (t, kc) = (&longest.series.t, &longest.series.kc);
    let ranges = ranges(&curves, kc);
    let groups = groups(&curves, &ranges, c);
    let neg_kc: Vec<Vec<f64>> = kc.iter().map(|k| k.iter().map(|x| -x).collect()).collect();
    let names = plan.robot.model.joint_names();
    let rows: Vec<Vec<Panel<'_>>> = groups
        .chunks(chunk_size(groups.len()))
        .map(|chunk| {
            let chunk: Vec<&Group<'_>> = chunk.iter().collect();
            let look = near_look(&chunk, &ranges, c);
            (0..names.len())
                .map(|j| error_panel(&names[j], j, &chunk, (&kc[j], &neg_kc[j]), &look))
                .collect()
        })
        .collect();
    let title = format!(
        "Tracking error of every law with ± k_c, first seed ({}); laws within {} % of the range drawn as one",
        c.scenario,
        COINCIDE * 100.0
    );
    save_grid(
        dir,
        "compare_errors",
        &title,
        t,
        &rows,
        Some(plan.scenario.controller.tc),
    )
}

/// Joint `j`'s panel for a few laws.
fn error_panel<'a>(
    joint: &str,
    j: usize,
    groups: &[&'a Group<'a>],
    (kc, neg_kc): (&'a [f64], &'a [f64]),
    (notes, widths): &(Vec<String>, Vec<u32>),
) -> Panel<'a> {
    let mut lines = vec![
        Line::new("± k_c", kc, RED).dashed(),
        Line::new("", neg_kc, RED).dashed(),
    ];
    for (k, g) in groups.iter().enumerate() {
        let Some(first) = g.members.first() else {
            continue;
        };
        let Some(e) = first.series.e.get(j) else {
            continue;
        };
        let width = widths.get(k).copied().unwrap_or(2);
        let line = Line::new(g.label.clone(), e, COLORS[first.row % COLORS.len()]).width(width);
        lines.push(if first.failed { line.unfitted() } else { line });
    }
    let mut panel = Panel::new(format!("{joint}: e = q − q_d"), "e [rad]", lines);
    panel.notes = notes.clone();
    panel
}

/// The bars' figure width: wide enough that every law's name fits under
/// its bar on one line.
fn bars_width(names: &[String]) -> u32 {
    let widest = names.iter().map(|n| text_px(n, TICK)).max().unwrap_or(0);
    (names.len() as u32 * (widest + 12) + 120).max(1000)
}

/// Effort after T_c and violation time per law (medians over seeds).
fn bars(dir: &Path, c: &Comparison) -> Result<(), PlotError> {
    let names: Vec<String> = c.laws.iter().map(|r| r.name.clone()).collect();
    let size = (bars_width(&names), 700);
    let png = dir.join("compare_bars.png");
    draw_bars(&BitMapBackend::new(&png, size).into_drawing_area(), c)
        .map_err(PlotError::in_file(&png))?;
    let svg = dir.join("compare_bars.svg");
    draw_bars(&SVGBackend::new(&svg, size).into_drawing_area(), c).map_err(PlotError::in_file(&svg))
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
    let root = root.titled(&title, (FAMILY, TITLE)).map_err(err)?;
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
        .caption(caption, (FAMILY, CAPTION))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(category_axis(n), 0.0..top * 1.15)
        .map_err(err)?;
    let names: Vec<String> = c.laws.iter().map(|r| r.name.clone()).collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .bold_line_style(GRID)
        .light_line_style(GRID_LIGHT)
        .x_label_formatter(&|x| category(&names, *x))
        .label_style((FAMILY, TICK))
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
                    (FAMILY, TICK).into_font().color(&RED),
                )])
                .map_err(err)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn laws_split_into_panels_of_at_most_four_as_even_as_they_go() {
        assert_eq!(chunk_size(11), 4);
        assert_eq!(chunk_size(7), 4);
        assert_eq!(chunk_size(5), 3);
        assert_eq!(chunk_size(4), 4);
        assert_eq!(chunk_size(1), 1);
        assert_eq!(chunk_size(0), 1);
        for n in 1..30 {
            let k = chunk_size(n);
            assert!(
                k <= PER_PANEL && n.div_ceil(k) == n.div_ceil(PER_PANEL),
                "{n}"
            );
        }
    }

    #[test]
    fn the_bars_figure_widens_until_every_name_fits_under_its_bar() {
        let names: Vec<String> = ["nac", "nac-no-networks", "nac-no-critic"]
            .map(String::from)
            .into();
        assert_eq!(bars_width(&names), 1000);
        let many: Vec<String> = (0..20).map(|i| format!("nac-no-networks-{i}")).collect();
        let w = bars_width(&many);
        let slot = (w - 120) / 20;
        assert!(many.iter().all(|n| text_px(n, TICK) < slot), "{w}");
    }
}
