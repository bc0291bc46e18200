//! Shared drawing pieces: data-to-pixel scales, tick marks with grid lines and labels, text-width
//! estimates and the default colours.

use super::svg::{Attrs, Svg};
use super::ticks::{Tick, TickLabel};

/// Default series colours (Okabe-Ito, readable by colour-blind viewers and in greyscale print).
pub(crate) const PALETTE: [&str; 8] = [
    "#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9", "#000000", "#8c8c8c",
];

/// Font size of tick labels and legends, px.
pub(crate) const FONT_PX: f64 = 11.0;
/// Length of a tick mark outside the frame, px.
const TICK_PX: f64 = 4.0;

/// Estimated rendered width of `text` at `font_px` (sans-serif fonts average about 0.6 em per
/// character; an over-estimate only costs some margin).
pub(crate) fn text_width(text: &str, font_px: f64) -> f64 {
    text.chars().count() as f64 * font_px * 0.6
}

/// Estimated width of a tick label at [`FONT_PX`] (exponents are drawn at 8 px).
pub(crate) fn label_width(label: &TickLabel) -> f64 {
    match label {
        TickLabel::Text(text) => text_width(text, FONT_PX),
        TickLabel::Pow10(exp) => text_width("10", FONT_PX) + text_width(&exp.to_string(), 8.0),
    }
}

/// Widest label among `ticks`, px (0 when none is labelled).
pub(crate) fn max_label_width(ticks: &[Tick]) -> f64 {
    ticks
        .iter()
        .filter_map(|t| t.label.as_ref())
        .map(label_width)
        .fold(0.0, f64::max)
}

/// Maps data values on `[lo, hi]` (log10 of them when `log`) linearly to pixels `[px_lo, px_hi]`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scale {
    /// Data value at `px_lo`.
    pub lo: f64,
    /// Data value at `px_hi`.
    pub hi: f64,
    /// Pixel position of `lo`.
    pub px_lo: f64,
    /// Pixel position of `hi` (smaller than `px_lo` for a y axis, which grows upwards).
    pub px_hi: f64,
    /// Logarithmic when true (`lo` and `hi` then positive).
    pub log: bool,
}

impl Scale {
    /// Pixel position of `v` (values outside `[lo, hi]` extrapolate; the mid-point when the
    /// range is empty).
    pub(crate) fn map(&self, v: f64) -> f64 {
        let (a, b, x) = if self.log {
            (self.lo.log10(), self.hi.log10(), v.log10())
        } else {
            (self.lo, self.hi, v)
        };
        let span = b - a;
        if !(span.is_finite() && span != 0.0) {
            return (self.px_lo + self.px_hi) / 2.0;
        }
        self.px_lo + (x - a) / span * (self.px_hi - self.px_lo)
    }

    /// True when `v` lies in `[lo, hi]` (with a relative slack of 1e-9 of the span).
    pub(crate) fn contains(&self, v: f64) -> bool {
        let slack = (self.hi - self.lo).abs() * 1e-9;
        v >= self.lo.min(self.hi) - slack && v <= self.lo.max(self.hi) + slack
    }
}

/// Vertical grid lines from `top` to `bottom` at each tick of the horizontal `scale`; with
/// `labels`, also tick marks and labels below `bottom`, skipping a label that would overlap the
/// previous one.
pub(crate) fn draw_x_ticks(
    svg: &mut Svg,
    scale: &Scale,
    ticks: &[Tick],
    top: f64,
    bottom: f64,
    labels: bool,
) {
    let mut last_right = f64::NEG_INFINITY;
    for tick in ticks.iter().filter(|t| scale.contains(t.value)) {
        let x = scale.map(tick.value);
        let class = if tick.label.is_some() {
            "grid"
        } else {
            "grid minor"
        };
        svg.leaf("line", line(x, top, x, bottom).str("class", class));
        let Some(label) = tick.label.as_ref().filter(|_| labels) else {
            continue;
        };
        svg.leaf(
            "line",
            line(x, bottom, x, bottom + TICK_PX).str("class", "tick"),
        );
        let half = label_width(label) / 2.0;
        if x - half < last_right + 4.0 {
            continue;
        }
        last_right = x + half;
        let attrs = Attrs::default()
            .num("x", x)
            .num("y", bottom + TICK_PX + FONT_PX + 2.0)
            .str("text-anchor", "middle");
        svg.tick_label(attrs, label);
    }
}

/// Horizontal grid lines from `left` to `right` at each tick of the vertical `scale`, with tick
/// marks and right-aligned labels left of `left`.
pub(crate) fn draw_y_ticks(svg: &mut Svg, scale: &Scale, ticks: &[Tick], left: f64, right: f64) {
    for tick in ticks.iter().filter(|t| scale.contains(t.value)) {
        let y = scale.map(tick.value);
        let class = if tick.label.is_some() {
            "grid"
        } else {
            "grid minor"
        };
        svg.leaf("line", line(left, y, right, y).str("class", class));
        if let Some(label) = &tick.label {
            svg.leaf(
                "line",
                line(left - TICK_PX, y, left, y).str("class", "tick"),
            );
            let attrs = Attrs::default()
                .num("x", left - TICK_PX - 3.0)
                .num("y", y + FONT_PX * 0.35)
                .str("text-anchor", "end");
            svg.tick_label(attrs, label);
        }
    }
}

/// Attributes of a line from (x1, y1) to (x2, y2).
pub(crate) fn line(x1: f64, y1: f64, x2: f64, y2: f64) -> Attrs {
    Attrs::default()
        .num("x1", x1)
        .num("y1", y1)
        .num("x2", x2)
        .num("y2", y2)
}

/// Attributes of a rectangle spanning the two corners, in either order.
pub(crate) fn rect(x1: f64, y1: f64, x2: f64, y2: f64) -> Attrs {
    Attrs::default()
        .num("x", x1.min(x2))
        .num("y", y1.min(y2))
        .num("width", (x2 - x1).abs())
        .num("height", (y2 - y1).abs())
}

/// Writes an axis title rotated to read upwards, centred on (x, y).
pub(crate) fn vertical_title(svg: &mut Svg, x: f64, y: f64, text: &str) {
    let mut rotate = String::from("rotate(-90 ");
    super::svg::push_num(&mut rotate, x);
    rotate.push(' ');
    super::svg::push_num(&mut rotate, y);
    rotate.push(')');
    let attrs = Attrs::default()
        .num("x", x)
        .num("y", y)
        .str("class", "axis")
        .str("text-anchor", "middle")
        .str("transform", &rotate);
    svg.text(attrs, text);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_and_log_scales_map_ends_and_middle() {
        let s = Scale {
            lo: 0.0,
            hi: 10.0,
            px_lo: 100.0,
            px_hi: 300.0,
            log: false,
        };
        assert_eq!((s.map(0.0), s.map(5.0), s.map(10.0)), (100.0, 200.0, 300.0));
        let s = Scale {
            lo: 10.0,
            hi: 1e6,
            px_lo: 400.0,
            px_hi: 0.0,
            log: true,
        };
        assert!((s.map(1e3) - 240.0).abs() < 1e-9);
        assert!(s.contains(1e6) && !s.contains(2e6));
        let flat = Scale {
            lo: 2.0,
            hi: 2.0,
            px_lo: 0.0,
            px_hi: 50.0,
            log: false,
        };
        assert_eq!(flat.map(7.0), 25.0);
    }
}
