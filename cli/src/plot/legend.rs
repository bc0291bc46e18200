//! Legends and point markers.

use super::axis::{FONT_PX, line, rect, text_width};
use super::svg::{Attrs, PathData, Svg};

/// Vertical distance between legend entries, px.
pub(crate) const ENTRY_PX: f64 = 16.0;
/// Width of a legend swatch plus the gap before its text, px.
const SWATCH_PX: f64 = 26.0;

/// Point marker shapes, assigned to scatter groups in this order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Shape {
    Circle,
    Square,
    Triangle,
    Diamond,
}

impl Shape {
    /// The shape of the `i`-th group.
    pub(crate) fn nth(i: usize) -> Shape {
        [
            Shape::Circle,
            Shape::Square,
            Shape::Triangle,
            Shape::Diamond,
        ][i % 4]
    }
}

/// Writes a marker of `shape` centred on (x, y) with half-size `r` px, filled with `fill`;
/// `outline` adds a dark ring (used for Pareto-front points).
pub(crate) fn draw_shape(
    svg: &mut Svg,
    shape: Shape,
    x: f64,
    y: f64,
    r: f64,
    fill: &str,
    outline: bool,
) {
    let style = |attrs: Attrs| {
        let attrs = attrs.str("fill", fill);
        if outline {
            attrs.str("stroke", "#111").str("stroke-width", "1.5")
        } else {
            attrs.str("stroke", "#fff").str("stroke-width", "0.6")
        }
    };
    match shape {
        Shape::Circle => {
            let attrs = Attrs::default().num("cx", x).num("cy", y).num("r", r);
            svg.leaf("circle", style(attrs));
        }
        Shape::Square => {
            let s = r * 0.9;
            svg.leaf("rect", style(rect(x - s, y - s, x + s, y + s)));
        }
        Shape::Triangle | Shape::Diamond => {
            let mut d = PathData::default();
            let r = r * 1.2;
            if shape == Shape::Triangle {
                d.move_to(x, y - r);
                d.line_to(x + r * 0.95, y + r * 0.7);
                d.line_to(x - r * 0.95, y + r * 0.7);
            } else {
                d.move_to(x, y - r);
                d.line_to(x + r, y);
                d.line_to(x, y + r);
                d.line_to(x - r, y);
            }
            d.close();
            svg.leaf("path", style(Attrs::default().str("d", d.as_str())));
        }
    }
}

/// What a legend entry shows before its text.
#[derive(Debug, Clone)]
pub(crate) enum Swatch {
    /// A line segment of this colour, width (px) and dash pattern (`None` for solid).
    Line(String, f64, Option<&'static str>),
    /// A translucent filled box of this colour.
    Fill(String),
    /// A point marker (shape, colour, outline).
    Point(Shape, String, bool),
    /// A marker drawn on a line (the Pareto front): line colour, then the marker.
    LinePoint(String, Shape, String),
}

/// One legend line.
#[derive(Debug, Clone)]
pub(crate) struct Entry {
    /// Swatch before the text.
    pub swatch: Swatch,
    /// Text, unescaped.
    pub text: String,
}

/// Width a legend of `entries` needs, px (0 for none).
pub(crate) fn legend_width(entries: &[Entry]) -> f64 {
    entries
        .iter()
        .map(|e| SWATCH_PX + text_width(&e.text, FONT_PX))
        .fold(0.0, f64::max)
}

/// Writes the legend with its top-left corner at (x, y), one entry per line.
pub(crate) fn draw_legend(svg: &mut Svg, x: f64, y: f64, entries: &[Entry]) {
    for (i, entry) in entries.iter().enumerate() {
        let mid = y + ENTRY_PX * (i as f64 + 0.5);
        let (x0, x1) = (x, x + SWATCH_PX - 8.0);
        match &entry.swatch {
            Swatch::Line(color, width, dash) => {
                let mut attrs = line(x0, mid, x1, mid)
                    .str("stroke", color)
                    .num("stroke-width", width.min(4.0));
                if let Some(dash) = dash {
                    attrs = attrs.str("stroke-dasharray", dash);
                }
                svg.leaf("line", attrs);
            }
            Swatch::Fill(color) => {
                let attrs = rect(x0, mid - 5.0, x1, mid + 5.0)
                    .str("fill", color)
                    .str("fill-opacity", "0.25")
                    .str("stroke", color)
                    .str("stroke-opacity", "0.5");
                svg.leaf("rect", attrs);
            }
            Swatch::Point(shape, color, outline) => {
                draw_shape(svg, *shape, (x0 + x1) / 2.0, mid, 4.0, color, *outline);
            }
            Swatch::LinePoint(line_color, shape, color) => {
                let attrs = line(x0, mid, x1, mid)
                    .str("stroke", line_color)
                    .str("stroke-width", "1.5");
                svg.leaf("line", attrs);
                draw_shape(svg, *shape, (x0 + x1) / 2.0, mid, 4.0, color, true);
            }
        }
        let attrs = Attrs::default()
            .num("x", x + SWATCH_PX)
            .num("y", mid + FONT_PX * 0.35);
        svg.text(attrs, &entry.text);
    }
}
