//! What every figure shares so that a newcomer can read it: text sizes at
//! which "." and "," stay apart, a quiet grid, the T_c marker, a legend
//! beside the data (never over it), y ranges fitted to the data, ticks
//! where they mean something and few enough that their labels do not
//! touch, and curves that coincide drawn once under a shared label.
//!
//! The rules that can be checked without drawing ([`fitted`],
//! [`coincident`], [`category_axis`], [`log_ticks`], [`tick_count`],
//! [`wrap`], [`main_body`], [`clip_log_x`]) are plain functions with tests; the drawing helpers only
//! apply them.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::coord::combinators::LogCoord;
use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::plot_error::PlotError;

/// The font family name the embedded font is registered under.
pub const FAMILY: &str = "sans-serif";
/// A figure's title.
pub const TITLE: u32 = 20;
/// A panel's caption.
pub const CAPTION: u32 = 16;
/// Tick labels: at 11 px the embedded font draws "." and "," as the same
/// dot, so "10.0,5.0" read "10·0·5·0".
pub const TICK: u32 = 13;
/// Legend entries.
pub const LEGEND: u32 = 13;
/// The width of the legend column beside a row of panels.
pub const LEGEND_WIDTH: u32 = 250;
/// The grid's major lines: light enough that a data line never reads as
/// one, and the T_c marker stands out.
pub const GRID: RGBAColor = RGBAColor(0, 0, 0, 0.12);
/// The grid's minor lines.
pub const GRID_LIGHT: RGBAColor = RGBAColor(0, 0, 0, 0.04);
/// The T_c marker: dark and dashed, unlike any grid line.
pub const T_C: RGBColor = RGBColor(40, 40, 40);
/// Notes in a legend.
pub const NOTE: RGBColor = RGBColor(90, 90, 90);
/// Curves closer than this fraction of their panel's range are drawn as
/// one: at 260 px a panel shows a thousandth of its range as a quarter
/// pixel.
pub const COINCIDE: f64 = 1e-3;
/// Curves closer than this fraction (about two pixels, a line's width)
/// look like one; a note says how close they are.
pub const NEAR: f64 = 1e-2;
/// The share of the data's span added above and below a fitted range.
pub const MARGIN: f64 = 0.06;

/// How a legend entry is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mark {
    /// A line segment, dashed or solid, this many pixels wide.
    Line {
        /// Dashed (a bound, a reference, T_c).
        dashed: bool,
        /// Stroke width.
        width: u32,
    },
    /// A circle marker, filled or hollow.
    Circle {
        /// Filled.
        filled: bool,
    },
    /// A cross over a marker.
    Cross,
    /// A short dashed upright line: a time marker (T_c), which a
    /// level dashed sample would make look like a reference curve.
    Upright,
}

/// One entry of a legend.
#[derive(Debug, Clone, PartialEq)]
pub struct Key {
    /// Its text (wrapped to the legend's width).
    pub label: String,
    /// Its colour.
    pub color: RGBColor,
    /// How its sample is drawn.
    pub mark: Mark,
}

impl Key {
    /// A line's entry.
    pub fn line(label: impl Into<String>, color: RGBColor, dashed: bool, width: u32) -> Self {
        Key {
            label: label.into(),
            color,
            mark: Mark::Line { dashed, width },
        }
    }
}

/// `values`' finite minimum and maximum widened by `margin` of their span
/// (a flat line by `margin` of its size, or by 1e-6 at zero); None when
/// no value is finite.
pub fn fitted(values: impl IntoIterator<Item = f64>, margin: f64) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return None;
    }
    let pad = if hi > lo {
        (hi - lo) * margin
    } else {
        (lo.abs() * margin).max(1e-6)
    };
    Some((lo - pad, hi + pad))
}

/// The largest |a − b| over samples, NaN where both are NaN counting as
/// equal; None when the lengths differ or only one of a pair is NaN.
pub fn max_gap(a: &[f64], b: &[f64]) -> Option<f64> {
    if a.len() != b.len() {
        return None;
    }
    let mut gap: f64 = 0.0;
    for (x, y) in a.iter().zip(b) {
        match (x.is_nan(), y.is_nan()) {
            (true, true) => {}
            (false, false) => gap = gap.max((x - y).abs()),
            _ => return None,
        }
    }
    Some(gap)
}

/// The largest gap between curves `a` and `b` over every panel, as a
/// fraction of each panel's range; None when they cannot be compared.
pub fn relative_gap(a: &[&[f64]], b: &[&[f64]], ranges: &[f64]) -> Option<f64> {
    if a.len() != b.len() || a.len() != ranges.len() {
        return None;
    }
    let mut worst: f64 = 0.0;
    for ((a, b), range) in a.iter().zip(b).zip(ranges) {
        let gap = max_gap(a, b)?;
        worst = worst.max(if *range > 0.0 { gap / range } else { gap });
    }
    Some(worst)
}

/// Groups the curves that coincide: curve `i` is drawn in every panel
/// (`curves[i][panel]`), and two coincide when they are within `tol` of
/// each panel's range (`ranges[panel]`) everywhere. Each group lists its
/// members in order and is led by its first; a curve joins the first
/// group whose leader it coincides with.
pub fn coincident(curves: &[Vec<&[f64]>], ranges: &[f64], tol: f64) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, curve) in curves.iter().enumerate() {
        let home = groups
            .iter_mut()
            .find(|g| relative_gap(&curves[g[0]], curve, ranges).is_some_and(|gap| gap <= tol));
        match home {
            Some(g) => g.push(i),
            None => groups.push(vec![i]),
        }
    }
    groups
}

/// The finite span (max − min) of every curve in one panel.
pub fn span<'a>(curves: impl IntoIterator<Item = &'a [f64]>) -> f64 {
    let all = curves.into_iter().flatten().copied();
    fitted(all, 0.0).map_or(0.0, |(lo, hi)| hi - lo)
}

/// The label of curves drawn as one: "a = b = c".
pub fn shared_label<S: AsRef<str>>(names: &[S]) -> String {
    let names: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
    names.join(" = ")
}

/// Pairs of groups (by index into `groups`, the first before the
/// second) whose leaders lie within `tol` of the ranges without
/// coinciding: curves that look like one and need a note saying how close
/// they are, with the gap.
pub fn near_pairs(
    curves: &[Vec<&[f64]>],
    ranges: &[f64],
    groups: &[Vec<usize>],
    tol: f64,
) -> Vec<(usize, usize, f64)> {
    let mut pairs = Vec::new();
    for (a, ga) in groups.iter().enumerate() {
        for (b, gb) in groups.iter().enumerate().skip(a + 1) {
            let (Some(la), Some(lb)) = (ga.first(), gb.first()) else {
                continue;
            };
            if let Some(gap) = relative_gap(&curves[*la], &curves[*lb], ranges)
                && gap <= tol
            {
                pairs.push((a, b, gap));
            }
        }
    }
    pairs
}

/// Stroke widths for `n` curves drawn in order: 2 px, plus one for each
/// later curve it lies near (`pairs` from [`near_pairs`]), at most 6, so a
/// curve drawn under a close one shows as a rim around it.
pub fn halo_widths(n: usize, pairs: &[(usize, usize, f64)]) -> Vec<u32> {
    (0..n)
        .map(|i| {
            let later = pairs.iter().filter(|(a, b, _)| *a == i && *b > i).count();
            (2 + later as u32).min(6)
        })
        .collect()
}

/// The note for two curves that look like one: "pd ≈ nac (within 0.6 %
/// of the range)".
pub fn near_note(a: &str, b: &str, gap: f64) -> String {
    format!("{a} ≈ {b} (within {:.1} % of the range)", gap * 100.0)
}

/// An axis whose ticks are given rather than chosen by plotters: labels
/// (its bold points) where they mean something, grid lines (its light
/// points) where they help, and tick values formatted by [`plain`].
pub struct Ticked<R> {
    inner: R,
    bold: Vec<f64>,
    light: Vec<f64>,
}

impl<R: Ranged<ValueType = f64>> Ranged for Ticked<R> {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}

impl<R: Ranged<ValueType = f64>> ValueFormatter<f64> for Ticked<R> {
    fn format(value: &f64) -> String {
        plain(*value)
    }
}

/// The x axis of `n` categories: the range −0.5 … n − 0.5, with a tick at
/// each category's centre (its index) and nowhere else, so a label names
/// the bar, box or cell above it.
pub fn category_axis(n: usize) -> Ticked<RangedCoordf64> {
    Ticked {
        inner: (-0.5..(n.max(1) as f64 - 0.5)).into(),
        bold: (0..n).map(|i| i as f64).collect(),
        light: Vec::new(),
    }
}

/// A log axis from `lo` to `hi` (both > 0) with at most `max` labelled
/// ticks ([`log_ticks`]).
pub fn log_axis(lo: f64, hi: f64, max: usize) -> Ticked<LogCoord<f64>> {
    let (bold, light) = log_ticks(lo, hi, max);
    Ticked {
        inner: (lo..hi).log_scale().into(),
        bold,
        light,
    }
}

/// The name of the category at `x` (a centre of [`category_axis`]), else "".
pub fn category(names: &[String], x: f64) -> String {
    let i = x.round();
    if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
        names[i as usize].clone()
    } else {
        String::new()
    }
}

/// About how many pixels `text` takes at `font` px (DejaVu Sans averages
/// a little under 0.6 em a character; the estimate errs wide).
pub fn text_px(text: &str, font: u32) -> u32 {
    (text.chars().count() as f64 * f64::from(font) * 0.6).ceil() as u32
}

/// How many labels of `label_px` fit along `axis_px` with a gap of half
/// a label between neighbours (at least 2: both ends).
pub fn tick_count(axis_px: u32, label_px: u32) -> usize {
    let slot = (f64::from(label_px) * 1.5).max(1.0);
    ((f64::from(axis_px) / slot).floor() as usize).max(2)
}

/// Ticks of a log axis from `lo` to `hi` (both > 0): the bold ones
/// labelled, at most `max`: every decade, thinned to every k-th when
/// there are too many, or 1, 2, 5 per decade when the range spans too
/// few decades to show more than one; and the light ones (the grid) at
/// every integer multiple of a decade.
pub fn log_ticks(lo: f64, hi: f64, max: usize) -> (Vec<f64>, Vec<f64>) {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let decades: Vec<f64> = (d0..=d1).map(|d| 10f64.powi(d)).filter(inside).collect();
    let light: Vec<f64> = (d0..=d1)
        .flat_map(|d| (1..10).map(move |m| f64::from(m) * 10f64.powi(d)))
        .filter(inside)
        .collect();
    let bold = if decades.len() >= 2 {
        let every = decades.len().div_ceil(max.max(2));
        decades.into_iter().step_by(every).collect()
    } else {
        let steps: Vec<f64> = (d0..=d1)
            .flat_map(|d| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(d)))
            .filter(inside)
            .collect();
        let every = steps.len().div_ceil(max.max(2)).max(1);
        steps.into_iter().step_by(every).collect()
    };
    (bold, light)
}

/// The main body of positive values on a log axis: split where two
/// neighbours (sorted) lie more than `gap` decades apart, the cluster
/// holding the median; None when no value is positive and finite. A
/// runaway point (a saturated gain scale at 10⁵ beside costs of 3) then
/// does not squash every other point into one column.
pub fn main_body(values: impl IntoIterator<Item = f64>, gap: f64) -> Option<(f64, f64)> {
    let mut logs: Vec<f64> = values
        .into_iter()
        .filter(|v| *v > 0.0 && v.is_finite())
        .map(f64::log10)
        .collect();
    logs.sort_by(f64::total_cmp);
    let mid = logs.len().checked_sub(1)? / 2;
    let mut lo = mid;
    while lo > 0 && logs[lo] - logs[lo - 1] <= gap {
        lo -= 1;
    }
    let mut hi = mid;
    while hi + 1 < logs.len() && logs[hi + 1] - logs[hi] <= gap {
        hi += 1;
    }
    Some((10f64.powf(logs[lo]), 10f64.powf(logs[hi])))
}

/// A polyline on log-log axes cut to `lo ≤ x ≤ hi`: the pieces inside,
/// each ending where it crosses an edge (interpolated in decades, as the
/// axes draw it), so a segment to an off-scale point leaves the panel
/// at its edge instead of being dropped or drawn over the axis.
pub fn clip_log_x(points: &[(f64, f64)], lo: f64, hi: f64) -> Vec<Vec<(f64, f64)>> {
    let inside = |x: f64| x >= lo && x <= hi;
    let cross = |(x0, y0): (f64, f64), (x1, y1): (f64, f64), edge: f64| {
        let f = (edge.log10() - x0.log10()) / (x1.log10() - x0.log10());
        (edge, 10f64.powf(y0.log10() + f * (y1.log10() - y0.log10())))
    };
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    for (k, p) in points.iter().enumerate() {
        let prev = k.checked_sub(1).map(|i| points[i]);
        match (prev, inside(p.0)) {
            (Some(q), true) if !inside(q.0) => {
                current.push(cross(q, *p, if q.0 > hi { hi } else { lo }));
                current.push(*p);
            }
            (_, true) => current.push(*p),
            (Some(q), false) if inside(q.0) => {
                current.push(cross(q, *p, if p.0 > hi { hi } else { lo }));
                pieces.push(std::mem::take(&mut current));
            }
            _ => {}
        }
    }
    if !current.is_empty() {
        pieces.push(current);
    }
    pieces
}

/// A tick value without the noise of a fixed format: 10 (not 10.0), 0.5,
/// 0.001, and 1e-5 or 2e6 at the extremes.
pub fn plain(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-4..1e5).contains(&a) {
        format!("{v:e}")
    } else {
        // Shortest decimal that reads back as v, rounded off float noise.
        let r = (v * 1e6).round() / 1e6;
        format!("{r}")
    }
}

/// `label` broken into lines of at most `width_px` at `font` px, at spaces
/// (a word longer than a line keeps its own line).
pub fn wrap(label: &str, width_px: u32, font: u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in label.split(' ').filter(|w| !w.is_empty()) {
        let candidate = if current.is_empty() {
            word.to_string()
        } else {
            format!("{current} {word}")
        };
        if text_px(&candidate, font) > width_px && !current.is_empty() {
            lines.push(std::mem::replace(&mut current, word.to_string()));
        } else {
            current = candidate;
        }
    }
    if !current.is_empty() || lines.is_empty() {
        lines.push(current);
    }
    lines
}

/// plotters' drawing error as a [`PlotError`].
pub fn err(e: impl std::fmt::Display) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// Draws `keys`, then `notes` in grey, top down in `area` (a column
/// beside the panels or a strip below them), each wrapped to its width.
pub fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[Key],
    notes: &[String],
) -> Result<(), PlotError> {
    const SAMPLE: i32 = 30;
    let (w, _) = area.dim_in_pixel();
    let line_h = (f64::from(LEGEND) * 1.35) as i32;
    let text_w = w.saturating_sub(SAMPLE as u32 + 16);
    let font = (FAMILY, LEGEND).into_font();
    let mut y = 12;
    for key in keys {
        let mid = (6, y + line_h / 2);
        sample(area, key, mid, SAMPLE)?;
        for line in wrap(&key.label, text_w, LEGEND) {
            area.draw(&Text::new(line, (SAMPLE + 12, y), font.clone()))
                .map_err(err)?;
            y += line_h;
        }
        y += 4;
    }
    y += 6;
    let note_font = font.color(&NOTE);
    for note in notes {
        for line in wrap(note, w.saturating_sub(12), LEGEND) {
            area.draw(&Text::new(line, (6, y), note_font.clone()))
                .map_err(err)?;
            y += line_h;
        }
        y += 4;
    }
    Ok(())
}

/// A key's sample, starting at `(x, y)` (its vertical middle), `len` long.
fn sample<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    key: &Key,
    (x, y): (i32, i32),
    len: i32,
) -> Result<(), PlotError> {
    let mid = (x + len / 2, y);
    match key.mark {
        Mark::Line {
            dashed: false,
            width,
        } => area
            .draw(&PathElement::new(
                vec![(x, y), (x + len, y)],
                key.color.stroke_width(width),
            ))
            .map_err(err),
        Mark::Line {
            dashed: true,
            width,
        } => {
            for x0 in (x..x + len).step_by(10) {
                area.draw(&PathElement::new(
                    vec![(x0, y), ((x0 + 6).min(x + len), y)],
                    key.color.stroke_width(width),
                ))
                .map_err(err)?;
            }
            Ok(())
        }
        Mark::Circle { filled } => {
            let style = if filled {
                key.color.filled()
            } else {
                key.color.stroke_width(2)
            };
            area.draw(&Circle::new(mid, 5, style)).map_err(err)
        }
        Mark::Cross => area
            .draw(&Cross::new(mid, 7, key.color.stroke_width(2)))
            .map_err(err),
        Mark::Upright => {
            for y0 in [y - 9, y - 2, y + 5] {
                area.draw(&PathElement::new(
                    vec![(mid.0, y0), (mid.0, y0 + 4)],
                    key.color.stroke_width(2),
                ))
                .map_err(err)?;
            }
            Ok(())
        }
    }
}

/// The T_c marker on a time axis: a dark dashed vertical line from `lo`
/// to `hi` labelled "T_c" at its top, so it cannot be taken for a grid
/// line.
pub fn tc_marker<DB, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, Y>>,
    tc: f64,
    (lo, hi): (f64, f64),
) -> Result<(), PlotError>
where
    DB: DrawingBackend,
    Y: Ranged<ValueType = f64>,
{
    chart
        .draw_series(DashedLineSeries::new(
            [(tc, lo), (tc, hi)],
            7,
            5,
            T_C.stroke_width(2),
        ))
        .map_err(err)?;
    let font = (FAMILY, LEGEND)
        .into_font()
        .color(&T_C)
        .pos(Pos::new(HPos::Left, VPos::Top));
    chart
        .draw_series([EmptyElement::at((tc, hi)) + Text::new("T_c", (5, 3), font)])
        .map_err(err)?;
    Ok(())
}

/// The legend entry of [`tc_marker`].
pub fn tc_key(tc: f64) -> Key {
    Key {
        label: format!("T_c = {} s", plain(tc)),
        color: T_C,
        mark: Mark::Upright,
    }
}

/// How many lines [`caption`] breaks `text` into across `width` px.
pub fn caption_height(text: &str, width: u32) -> usize {
    wrap(text, width.saturating_sub(20), CAPTION).len()
}

/// Writes `text` centred at the top of `area`, wrapped to its width, in
/// at least `lines` lines' height, and returns the area below: a caption
/// too long for one line (a shared label of four laws) wraps instead of
/// running off the panel, and panels whose captions differ in length
/// keep their axes level.
pub fn caption<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    font: TextStyle<'_>,
    size: u32,
    lines: usize,
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    let (w, _) = area.dim_in_pixel();
    let wrapped = wrap(text, w.saturating_sub(20), size);
    let line_h = (f64::from(size) * 1.3) as i32;
    let height = line_h * wrapped.len().max(lines) as i32 + 6;
    let (top, rest) = area.split_vertically(height);
    let font = font.pos(Pos::new(HPos::Center, VPos::Top));
    for (k, line) in wrapped.into_iter().enumerate() {
        top.draw(&Text::new(
            line,
            (w as i32 / 2, 4 + line_h * k as i32),
            font.clone(),
        ))
        .map_err(err)?;
    }
    Ok(rest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::coord::ranged1d::BoldPoints;

    #[test]
    fn a_fitted_range_holds_the_data_with_a_small_margin() {
        // A 1 % error on a ratio: fitted, not 0–1.
        let (lo, hi) = fitted([0.004, 0.01, 0.007, f64::NAN], 0.05).unwrap();
        assert!(lo < 0.004 && lo > 0.0036, "{lo}");
        assert!(hi > 0.01 && hi < 0.0104, "{hi}");
        // A flat line still gets a range; nothing finite gets none.
        let (lo, hi) = fitted([2.0, 2.0], 0.05).unwrap();
        assert!(lo < 2.0 && hi > 2.0);
        assert_eq!(fitted([f64::NAN, f64::INFINITY], 0.05), None);
        let (lo, hi) = fitted([0.0], 0.05).unwrap();
        assert!(lo < 0.0 && hi > 0.0);
    }

    #[test]
    fn curves_within_a_thousandth_of_the_range_merge_and_others_do_not() {
        let nac = [0.5, 0.1, 0.0, 0.0];
        let twin = [0.5, 0.1004, 0.0, 0.0]; // 0.4e-3 of the range 1.0
        let pd = [0.5, 0.105, 0.0, 0.0]; // 5e-3: looks alike, is not
        let ctc = [0.5, -0.5, 0.0, 0.0];
        let curves = vec![
            vec![&nac[..]],
            vec![&pd[..]],
            vec![&twin[..]],
            vec![&ctc[..]],
        ];
        let range = span(curves.iter().map(|c| c[0]));
        assert_eq!(range, 1.0);
        let groups = coincident(&curves, &[range], COINCIDE);
        assert_eq!(groups, vec![vec![0, 2], vec![1], vec![3]]);
        let gap = relative_gap(&curves[0], &curves[1], &[range]).unwrap();
        assert!(gap > COINCIDE && gap < NEAR, "{gap}");
        assert_eq!(
            shared_label(&["nac", "nac-no-critic"]),
            "nac = nac-no-critic"
        );
    }

    #[test]
    fn curves_that_look_alike_are_paired_and_drawn_under_a_rim() {
        let nac = [0.0, 1.0];
        let pd = [0.0, 1.004];
        let blf = [0.0, 1.008];
        let far = [0.0, 0.5];
        let curves = vec![
            vec![&nac[..]],
            vec![&pd[..]],
            vec![&blf[..]],
            vec![&far[..]],
        ];
        let groups = coincident(&curves, &[1.0], COINCIDE);
        assert_eq!(groups.len(), 4);
        let pairs = near_pairs(&curves, &[1.0], &groups, NEAR);
        let found: Vec<(usize, usize)> = pairs.iter().map(|(a, b, _)| (*a, *b)).collect();
        assert_eq!(found, vec![(0, 1), (0, 2), (1, 2)]);
        // nac under pd and blf: the widest; blf last: plain.
        assert_eq!(halo_widths(4, &pairs), vec![4, 3, 2, 2]);
        assert!(near_note("pd", "nac", pairs[0].2).starts_with("pd ≈ nac (within 0.4 %"));
    }

    #[test]
    fn curves_must_coincide_in_every_panel_and_nan_only_matches_nan() {
        let a = [0.0, 1.0];
        let b = [0.0, 0.2];
        let nan = [f64::NAN, 1.0];
        // Same in panel 0, apart in panel 1: two groups.
        let curves = vec![vec![&a[..], &a[..]], vec![&a[..], &b[..]]];
        assert_eq!(coincident(&curves, &[1.0, 1.0], COINCIDE).len(), 2);
        assert_eq!(max_gap(&nan, &nan), Some(0.0));
        assert_eq!(max_gap(&nan, &a), None);
        assert_eq!(max_gap(&a, &a[..1]), None);
    }

    #[test]
    fn category_ticks_sit_at_cell_centres_only() {
        for n in 1..30 {
            let axis = category_axis(n);
            let ticks = axis.key_points(BoldPoints(100));
            assert_eq!(ticks, (0..n).map(|i| i as f64).collect::<Vec<_>>());
            let r = axis.range();
            // Each centre is half a cell from the edges around it.
            assert_eq!((r.start, r.end), (-0.5, n as f64 - 0.5));
        }
        let names = vec!["a".to_string(), "b".to_string()];
        assert_eq!(category(&names, 1.0), "b");
        assert_eq!(category(&names, 0.5), "");
        assert_eq!(category(&names, 2.0), "");
    }

    #[test]
    fn log_ticks_are_few_enough_and_inside_the_range() {
        let (bold, light) = log_ticks(3e-4, 2.5, 4);
        assert!(bold.len() <= 4 && bold.len() >= 2, "{bold:?}");
        assert!(bold.iter().all(|v| (3e-4..=2.5).contains(v)));
        assert!(light.len() > bold.len());
        // Within one decade: 1-2-5 steps, so there is more than one label.
        let (bold, _) = log_ticks(110.0, 320.0, 5);
        assert_eq!(bold, vec![200.0]);
        let (bold, _) = log_ticks(90.0, 600.0, 5);
        assert_eq!(bold, vec![100.0, 200.0, 500.0]);
        assert_eq!(log_ticks(0.0, 1.0, 5), (Vec::new(), Vec::new()));
    }

    #[test]
    fn tick_labels_leave_room_between_them() {
        // 700 px for labels of 60 px: 7 with half a label between each.
        assert_eq!(tick_count(700, 60), 7);
        assert!(tick_count(10, 60) >= 2);
        assert_eq!(plain(10.0), "10");
        assert_eq!(plain(0.5), "0.5");
        assert_eq!(plain(0.1 + 0.2), "0.3");
        assert_eq!(plain(1e-5), "1e-5");
        assert_eq!(plain(-2.0), "-2");
    }

    #[test]
    fn a_runaway_point_is_left_out_of_the_main_body() {
        // The paper's trade-off: costs of 2–80 and a saturated 5e5.
        let costs = [2.5, 2.9, 3.1, 4.1, 16.5, 76.5, 5.5e5, 5.5e5];
        let (lo, hi) = main_body(costs, 1.0).unwrap();
        assert!((lo - 2.5).abs() < 1e-12, "{lo}");
        assert!((hi - 76.5).abs() < 1e-9, "{hi}");
        // No gap: everything; nothing positive: None.
        let (lo, hi) = main_body([1.0, 5.0, 40.0], 1.0).unwrap();
        assert!((lo - 1.0).abs() < 1e-12 && (hi - 40.0).abs() < 1e-9);
        assert_eq!(main_body([0.0, -1.0, f64::NAN], 1.0), None);
    }

    #[test]
    fn a_polyline_to_an_off_scale_point_stops_at_the_edge() {
        // 1 → 100 in x, 1 → 100 in y: at the edge x = 10, y = 10.
        let pieces = clip_log_x(&[(0.5, 1.0), (1.0, 1.0), (100.0, 100.0)], 0.8, 10.0);
        assert_eq!(pieces.len(), 1);
        let piece = &pieces[0];
        assert_eq!(piece.len(), 3);
        assert!((piece[0].0 - 0.8).abs() < 1e-12 && (piece[0].1 - 1.0).abs() < 1e-12);
        assert!((piece[2].0 - 10.0).abs() < 1e-9 && (piece[2].1 - 10.0).abs() < 1e-9);
        // Out and back in: two pieces; wholly outside: none.
        let pieces = clip_log_x(&[(1.0, 1.0), (1e3, 1.0), (2.0, 1.0)], 0.5, 10.0);
        assert_eq!(pieces.len(), 2);
        assert!(clip_log_x(&[(1e3, 1.0), (1e4, 2.0)], 0.5, 10.0).is_empty());
    }

    #[test]
    fn long_labels_wrap_at_spaces_to_the_width() {
        let label = "nac = nac-no-critic = nac-no-networks";
        let lines = wrap(label, 170, 13);
        assert!(lines.len() >= 2, "{lines:?}");
        assert!(
            lines
                .iter()
                .all(|l| text_px(l, 13) <= 170 || !l.contains(' '))
        );
        assert_eq!(lines.join(" "), label);
        assert_eq!(wrap("", 100, 13), vec![String::new()]);
    }
}
