//! Labelled scatter plot with optional log axes and a Pareto front: the speed-versus-accuracy
//! view (instructions per evaluation against error) of the trade table.

use super::axis::{self, PALETTE, Scale, rect, text_width};
use super::labels::{Area, place_labels};
use super::legend::{Entry, Shape, Swatch, draw_legend, draw_shape, legend_width};
use super::svg::{Attrs, PathData, Svg};
use super::ticks::{Tick, linear_ticks, log_range, log_ticks, nice_linear_range, sane_range};

/// Colour of the Pareto step line.
const FRONT_COLOR: &str = "#333333";
/// Font size of point labels, px.
const LABEL_FONT_PX: f64 = 10.0;

#[derive(Debug, Clone)]
struct Point {
    label: String,
    x: f64,
    y: f64,
    group: String,
}

/// A scatter plot, rendered by [`ScatterPlot::to_svg`]. Points are indexed in the order added.
#[derive(Debug, Clone)]
pub struct ScatterPlot {
    title: String,
    x_label: String,
    y_label: String,
    width_px: f64,
    height_px: f64,
    log_x: bool,
    log_y: bool,
    x_range: Option<(f64, f64)>,
    y_range: Option<(f64, f64)>,
    points: Vec<Point>,
    pareto: Vec<usize>,
}

/// Automatic ranges leave this fraction of the data span (in decades on a log axis) free at
/// each end before rounding outward, so no point sits on the frame.
const MARGIN: f64 = 0.04;

/// One axis: domain and ticks, from a fixed range or from the (usable) `values`.
fn axis_of(
    log: bool,
    fixed: Option<(f64, f64)>,
    values: &[f64],
    len_px: f64,
) -> (f64, f64, Vec<Tick>) {
    let (lo, hi) = values
        .iter()
        .fold((f64::NAN, f64::NAN), |(a, b), &v| (a.min(v), b.max(v)));
    let (lo, hi) = match (log, fixed) {
        (true, Some((a, b))) if a > 0.0 && b > 0.0 && a.is_finite() && b.is_finite() && a != b => {
            (a.min(b), a.max(b))
        }
        (true, Some((a, b))) => log_range(a, b),
        (true, None) => {
            let (l, h) = (lo.log10(), hi.log10());
            let m = MARGIN * (h - l);
            let lo = 10f64.powf(l - m).max(f64::MIN_POSITIVE);
            log_range(lo, 10f64.powf(h + m).min(f64::MAX))
        }
        (false, Some((a, b))) => sane_range(a, b),
        (false, None) => {
            let m = MARGIN * 2.0 * (hi / 2.0 - lo / 2.0);
            let (lo, hi) = ((lo - m).max(f64::MIN), (hi + m).min(f64::MAX));
            nice_linear_range(lo, hi, ((len_px / 90.0) as usize).max(2))
        }
    };
    let ticks = if log {
        log_ticks(lo, hi, ((len_px / 40.0) as usize).max(2))
    } else {
        linear_ticks(lo, hi, ((len_px / 90.0) as usize).max(2))
    };
    (lo, hi, ticks)
}

impl ScatterPlot {
    /// An empty 760 x 480 px plot titled `title` (empty for none), linear axes.
    pub fn new(title: &str) -> Self {
        ScatterPlot {
            title: title.to_string(),
            x_label: String::new(),
            y_label: String::new(),
            width_px: 760.0,
            height_px: 480.0,
            log_x: false,
            log_y: false,
            x_range: None,
            y_range: None,
            points: Vec::new(),
            pareto: Vec::new(),
        }
    }

    /// Title of the x axis, unit included.
    pub fn x_label(mut self, label: &str) -> Self {
        self.x_label = label.to_string();
        self
    }

    /// Title of the y axis, unit included.
    pub fn y_label(mut self, label: &str) -> Self {
        self.y_label = label.to_string();
        self
    }

    /// Sets the total size (300..10 000 px each way; out-of-range values are clamped).
    pub fn size(mut self, width_px: f64, height_px: f64) -> Self {
        let clamp = |v: f64| {
            if v.is_nan() {
                300.0
            } else {
                v.clamp(300.0, 1.0e4)
            }
        };
        (self.width_px, self.height_px) = (clamp(width_px), clamp(height_px));
        self
    }

    /// Makes the x axis logarithmic, with decade ticks labelled 10^n; points with x <= 0 are
    /// then skipped.
    pub fn log_x(mut self) -> Self {
        self.log_x = true;
        self
    }

    /// Makes the y axis logarithmic (see [`ScatterPlot::log_x`]).
    pub fn log_y(mut self) -> Self {
        self.log_y = true;
        self
    }

    /// Fixes the x axis to `[lo, hi]` (e.g. 10..1e6); points outside are left out and counted.
    /// By default the axis spans the data (whole decades on a log axis, whole steps otherwise).
    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    /// Fixes the y axis to `[lo, hi]` (see [`ScatterPlot::x_range`]).
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Adds a point at (`x`, `y`) with `label` written beside it (empty for none). Points of one
    /// `group` share a colour and shape, assigned in order of first appearance, and the group
    /// name appears in the legend (an empty group is left out of the legend).
    pub fn point(mut self, label: &str, x: f64, y: f64, group: &str) -> Self {
        self.points.push(Point {
            label: label.to_string(),
            x,
            y,
            group: group.to_string(),
        });
        self
    }

    /// Marks the points with these indices (order of [`ScatterPlot::point`] calls; unknown or
    /// skipped ones are ignored) as the Pareto front: outlined, and joined by a step line in
    /// order of x. Replaces any earlier set. [`pareto_front`](super::pareto_front) computes the
    /// set for minimising both.
    pub fn pareto(mut self, indices: &[usize]) -> Self {
        self.pareto = indices.to_vec();
        self
    }

    /// Renders the plot as a standalone SVG document. Never panics on any data: NaN/inf points,
    /// and points <= 0 on a log axis, are skipped and counted in the leading comment.
    pub fn to_svg(&self) -> String {
        let usable = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
        let candidates: Vec<usize> = (0..self.points.len())
            .filter(|&i| {
                usable(self.points[i].x, self.log_x) && usable(self.points[i].y, self.log_y)
            })
            .collect();
        let xs_data: Vec<f64> = candidates.iter().map(|&i| self.points[i].x).collect();
        let ys_data: Vec<f64> = candidates.iter().map(|&i| self.points[i].y).collect();
        let (x_lo, x_hi, x_ticks) =
            axis_of(self.log_x, self.x_range, &xs_data, self.width_px - 200.0);
        let (y_lo, y_hi, y_ticks) =
            axis_of(self.log_y, self.y_range, &ys_data, self.height_px - 100.0);

        let mut groups: Vec<&str> = Vec::new();
        for p in &self.points {
            if !groups.contains(&p.group.as_str()) {
                groups.push(&p.group);
            }
        }
        let style = |g: usize| (Shape::nth(g), PALETTE[g % PALETTE.len()]);
        let mut legend: Vec<Entry> = groups
            .iter()
            .enumerate()
            .filter(|(_, g)| !g.is_empty())
            .map(|(g, name)| Entry {
                swatch: Swatch::Point(style(g).0, style(g).1.to_string(), false),
                text: name.to_string(),
            })
            .collect();

        let left = 38.0 + axis::max_label_width(&y_ticks);
        let top = if self.title.is_empty() { 14.0 } else { 40.0 };
        let (width, height) = (self.width_px, self.height_px);
        let mut xs = Scale {
            lo: x_lo,
            hi: x_hi,
            px_lo: left,
            px_hi: 0.0,
            log: self.log_x,
        };
        let mut ys = Scale {
            lo: y_lo,
            hi: y_hi,
            px_lo: height - 52.0,
            px_hi: top,
            log: self.log_y,
        };
        let visible: Vec<usize> = candidates
            .into_iter()
            .filter(|&i| xs.contains(self.points[i].x) && ys.contains(self.points[i].y))
            .collect();
        let mut front: Vec<usize> = self
            .pareto
            .iter()
            .copied()
            .filter(|i| visible.contains(i))
            .collect();
        front.sort_by(|&a, &b| {
            let (p, q) = (&self.points[a], &self.points[b]);
            p.x.total_cmp(&q.x)
                .then(p.y.total_cmp(&q.y))
                .then(a.cmp(&b))
        });
        front.dedup();
        if !front.is_empty() {
            let swatch = Swatch::LinePoint(
                FRONT_COLOR.to_string(),
                Shape::Circle,
                "#ffffff".to_string(),
            );
            legend.push(Entry {
                swatch,
                text: "Pareto front".to_string(),
            });
        }
        let legend_w = legend_width(&legend);
        let right = if legend_w > 0.0 {
            legend_w + 30.0
        } else {
            20.0
        };
        xs.px_hi = (width - right).max(left + 100.0);
        ys.px_hi = ys.px_hi.min(ys.px_lo - 100.0);

        let mut svg = Svg::default();
        let mid_x = (left + xs.px_hi) / 2.0;
        let at = Attrs::default()
            .num("x", mid_x)
            .num("y", 24.0)
            .str("class", "title");
        svg.text(at.str("text-anchor", "middle"), &self.title);
        axis::draw_x_ticks(&mut svg, &xs, &x_ticks, ys.px_hi, ys.px_lo, true);
        axis::draw_y_ticks(&mut svg, &ys, &y_ticks, left, xs.px_hi);
        axis::vertical_title(&mut svg, 16.0, (ys.px_lo + ys.px_hi) / 2.0, &self.y_label);
        let at = Attrs::default()
            .num("x", mid_x)
            .num("y", height - 12.0)
            .str("class", "axis");
        svg.text(at.str("text-anchor", "middle"), &self.x_label);

        let pixel = |i: usize| (xs.map(self.points[i].x), ys.map(self.points[i].y));
        let front_px: Vec<(f64, f64)> = front.iter().map(|&i| pixel(i)).collect();
        let segments = draw_front(&mut svg, &front_px);
        let group_of = |i: usize| {
            groups
                .iter()
                .position(|g| *g == self.points[i].group)
                .unwrap_or(0)
        };
        let on_front = |i: &usize| front.contains(i);
        for &i in visible.iter().filter(|i| !on_front(i)).chain(front.iter()) {
            let (shape, color) = style(group_of(i));
            let (x, y) = pixel(i);
            let r = if on_front(&i) { 5.0 } else { 4.0 };
            draw_shape(&mut svg, shape, x, y, r, color, on_front(&i));
        }
        let labelled: Vec<usize> = visible
            .iter()
            .copied()
            .filter(|&i| !self.points[i].label.is_empty())
            .collect();
        let at_px: Vec<(f64, f64)> = labelled.iter().map(|&i| pixel(i)).collect();
        let widths: Vec<f64> = labelled
            .iter()
            .map(|&i| text_width(&self.points[i].label, LABEL_FONT_PX))
            .collect();
        let bounds = Area {
            x0: left,
            y0: ys.px_hi,
            x1: xs.px_hi,
            y1: ys.px_lo,
        };
        for (&i, place) in labelled.iter().zip(place_labels(
            &at_px,
            &widths,
            LABEL_FONT_PX,
            bounds,
            &segments,
        )) {
            let attrs = Attrs::default()
                .num("x", place.x)
                .num("y", place.y)
                .str("text-anchor", place.anchor);
            svg.text(attrs.str("class", "small halo"), &self.points[i].label);
        }
        svg.leaf(
            "rect",
            rect(left, ys.px_hi, xs.px_hi, ys.px_lo).str("class", "frame"),
        );
        draw_legend(&mut svg, xs.px_hi + 14.0, ys.px_hi, &legend);

        let summary = format!(
            "sonolube scatter plot: {} points, {} drawn, {} Pareto, {} skipped (non-finite, or <= 0 on a \
             log axis), {} outside a fixed range",
            self.points.len(),
            visible.len(),
            front.len(),
            self.points.len() - xs_data.len(),
            xs_data.len() - visible.len()
        );
        svg.into_document(width, height, &summary)
    }
}

/// Draws the Pareto staircase through `points` (px, sorted by x): across at each point's error,
/// then down to the next. Returns thin boxes around its segments, for label placement to avoid.
fn draw_front(svg: &mut Svg, points: &[(f64, f64)]) -> Vec<Area> {
    let mut d = PathData::default();
    let mut segments = Vec::new();
    for (k, &(x, y)) in points.iter().enumerate() {
        if k == 0 {
            d.move_to(x, y);
            continue;
        }
        let (prev_x, prev_y) = points[k - 1];
        d.line_to(x, prev_y);
        d.line_to(x, y);
        segments.push(Area {
            x0: prev_x,
            y0: prev_y - 1.5,
            x1: x,
            y1: prev_y + 1.5,
        });
        segments.push(Area {
            x0: x - 1.5,
            y0: prev_y.min(y),
            x1: x + 1.5,
            y1: prev_y.max(y),
        });
    }
    if !d.is_empty() {
        let attrs = Attrs::default().str("d", d.as_str()).str("class", "line");
        svg.leaf(
            "path",
            attrs.str("stroke", FRONT_COLOR).str("stroke-width", "1.5"),
        );
    }
    segments
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_skip_non_positive_and_fixed_ranges_count_outside() {
        let svg = ScatterPlot::new("t")
            .log_x()
            .log_y()
            .x_range(10.0, 1e6)
            .point("a", 100.0, 1e-3, "g")
            .point("b", -5.0, 1e-3, "g")
            .point("c", 1e8, 1e-3, "g")
            .point("d", 100.0, 0.0, "g")
            .to_svg();
        assert!(
            svg.contains("4 points, 1 drawn, 0 Pareto, 2 skipped"),
            "{}",
            &svg[..300]
        );
        assert!(svg.contains("1 outside a fixed range"));
    }
}
