//! Drawing the contents of a time-series panel: decimated lines, bands and markers.

use super::axis::{FONT_PX, Scale, line, rect, text_width};
use super::decimate::{decimate_min_max, finite_runs};
use super::panel::BAND_GREY;
use super::series::{Band, BandShape, Marker, Series};
use super::svg::{Attrs, PathData, Svg};

/// Colour of markers without their own.
const MARKER_RED: &str = "#b2182b";

/// Point counts reported in the SVG's leading comment.
#[derive(Debug, Default)]
pub(crate) struct Stats {
    pub(crate) points: usize,
    pub(crate) drawn: usize,
    pub(crate) skipped: usize,
}

/// Draws `series` as one path (sub-paths broken at non-finite points), decimated per pixel column.
pub(crate) fn draw_series(
    svg: &mut Svg,
    series: &Series,
    color: &str,
    xs: &Scale,
    ys: &Scale,
    stats: &mut Stats,
) {
    let n = series.len();
    let (x, y) = (&series.x[..n], &series.y[..n]);
    let (runs, skipped) = finite_runs(x, y, false);
    stats.points += n;
    stats.skipped += skipped;
    let mut d = PathData::default();
    let mut px = Vec::new();
    for run in runs {
        let (x, y) = (&x[run.clone()], &y[run]);
        px.clear();
        px.extend(x.iter().map(|&v| xs.map(v)));
        let keep = decimate_min_max(&px, y);
        stats.drawn += keep.len();
        for (j, &k) in keep.iter().enumerate() {
            if j == 0 {
                d.move_to(px[k], ys.map(y[k]));
            } else {
                d.line_to(px[k], ys.map(y[k]));
            }
        }
        if keep.len() == 1 {
            d.dot();
        }
    }
    if d.is_empty() {
        return;
    }
    let mut attrs = Attrs::default()
        .str("d", d.as_str())
        .str("class", "line")
        .str("stroke", color)
        .num("stroke-width", series.width_px);
    if series.dashed {
        attrs = attrs.str("stroke-dasharray", "6 4");
    }
    svg.leaf("path", attrs);
}

/// Draws a band; returns how many of its samples were skipped as non-finite. Curve-following
/// bands keep, per pixel column, the lowest lower and the highest upper edge.
pub(crate) fn draw_band(svg: &mut Svg, band: &Band, xs: &Scale, ys: &Scale) -> usize {
    let color = band.color.as_deref().unwrap_or(BAND_GREY);
    let fill = |attrs: Attrs| attrs.str("fill", color).str("fill-opacity", "0.18");
    let finite = |a: f64, b: f64| a.is_finite() && b.is_finite();
    match band.shape {
        BandShape::Horizontal(a, b) if finite(a, b) => {
            svg.leaf("rect", fill(rect(xs.px_lo, ys.map(a), xs.px_hi, ys.map(b))));
            0
        }
        BandShape::Vertical(a, b) if finite(a, b) => {
            svg.leaf("rect", fill(rect(xs.map(a), ys.px_lo, xs.map(b), ys.px_hi)));
            0
        }
        BandShape::Horizontal(..) | BandShape::Vertical(..) => 1,
        BandShape::Between(..) | BandShape::Around(..) => {
            let mut d = PathData::default();
            // Per column: first px, last px, lowest lower edge, highest upper edge.
            let mut columns: Vec<(f64, f64, f64, f64)> = Vec::new();
            let mut skipped = 0;
            for i in 0..band.len() {
                let Some((x, lo, hi)) = band.sample(i) else {
                    skipped += 1;
                    close_band(&mut d, &mut columns, ys);
                    continue;
                };
                let px = xs.map(x);
                match columns.last_mut() {
                    Some(c) if c.0.floor() == px.floor() => {
                        *c = (c.0, px, c.2.min(lo), c.3.max(hi));
                    }
                    _ => columns.push((px, px, lo, hi)),
                }
            }
            close_band(&mut d, &mut columns, ys);
            if !d.is_empty() {
                svg.leaf("path", fill(Attrs::default().str("d", d.as_str())));
            }
            skipped
        }
    }
}

/// Appends the outline of one unbroken stretch of a band (upper edge forward, lower edge back).
fn close_band(d: &mut PathData, columns: &mut Vec<(f64, f64, f64, f64)>, ys: &Scale) {
    let Some(first) = columns.first() else {
        return;
    };
    d.move_to(first.0, ys.map(first.3));
    for c in columns.iter() {
        d.line_to(c.0, ys.map(c.3));
        d.line_to(c.1.max(c.0 + 0.5), ys.map(c.3));
    }
    for c in columns.iter().rev() {
        d.line_to(c.1.max(c.0 + 0.5), ys.map(c.2));
        d.line_to(c.0, ys.map(c.2));
    }
    d.close();
    columns.clear();
}

/// Dashed vertical lines from `top` to `bottom`, labels near `top`; labels that would collide
/// move down a row (up to three rows), and flip left of the line near the right edge.
pub(crate) fn draw_markers(svg: &mut Svg, markers: &[Marker], xs: &Scale, top: f64, bottom: f64) {
    let mut order: Vec<&Marker> = markers
        .iter()
        .filter(|m| m.x.is_finite() && xs.contains(m.x))
        .collect();
    order.sort_by(|a, b| a.x.total_cmp(&b.x));
    let mut row_ends = [f64::NEG_INFINITY; 3];
    for marker in order {
        let color = marker.color.as_deref().unwrap_or(MARKER_RED);
        let x = xs.map(marker.x);
        let attrs = line(x, top, x, bottom)
            .str("stroke", color)
            .str("stroke-width", "1.2")
            .str("stroke-dasharray", "5 3");
        svg.leaf("line", attrs);
        if marker.label.is_empty() {
            continue;
        }
        let w = text_width(&marker.label, FONT_PX - 1.0);
        let (tx, anchor, x0, x1) = if x + 4.0 + w <= xs.px_hi {
            (x + 4.0, "start", x, x + 4.0 + w)
        } else {
            (x - 4.0, "end", x - 4.0 - w, x)
        };
        let row = (0..row_ends.len())
            .find(|&r| row_ends[r] + 6.0 < x0)
            .unwrap_or(0);
        row_ends[row] = x1;
        let attrs = Attrs::default()
            .num("x", tx)
            .num("y", top + 12.0 + 12.0 * row as f64)
            .str("text-anchor", anchor)
            .str("class", "small halo")
            .str("style", &format!("fill:{color}"));
        svg.text(attrs, &marker.label);
    }
}
