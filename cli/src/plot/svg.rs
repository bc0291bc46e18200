//! Minimal SVG text writer: escaping, compact fixed-precision numbers, attribute lists and path
//! data. Everything is written in one pass into a `String`; nothing is hashed or reordered, so the
//! same calls give byte-identical output.

use std::fmt::Write as _;

use super::ticks::TickLabel;

/// Coordinates are clamped to +-this many pixels, so data far outside an axis range (drawn under a
/// clip path) cannot produce huge numbers.
const COORD_LIMIT_PX: f64 = 1.0e5;

/// Style sheet shared by both plot kinds (classes keep per-element attributes short).
const STYLE: &str = "text{font-family:DejaVu Sans,Helvetica,Arial,sans-serif;font-size:11px;fill:#222}\
.title{font-size:15px;font-weight:bold}.axis{font-size:12px}.small{font-size:10px}\
.grid{stroke:#e3e3e3;stroke-width:1}.minor{stroke:#f1f1f1}.tick{stroke:#444;stroke-width:1}\
.frame{fill:none;stroke:#555;stroke-width:1}\
.line{fill:none;stroke-linejoin:round;stroke-linecap:round}\
.halo{paint-order:stroke;stroke:#fff;stroke-width:3px;stroke-linejoin:round}";

/// Escapes `&`, `<`, `>` and `"` for SVG text content and attribute values. Tabs and line breaks
/// become spaces; other control characters (which XML 1.0 cannot carry) are dropped.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\t' | '\n' | '\r' => out.push(' '),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

/// `v` in tenths of a pixel, clamped to +-[`COORD_LIMIT_PX`]; NaN becomes 0.
pub(crate) fn tenths(v: f64) -> i64 {
    let v = v.clamp(-COORD_LIMIT_PX, COORD_LIMIT_PX);
    if v.is_nan() {
        0
    } else {
        (v * 10.0).round() as i64
    }
}

/// Appends a value given in tenths as a decimal without trailing zeros (`12`, `12.5`, `-0.1`).
fn push_tenths(out: &mut String, t: i64) {
    let sign = if t < 0 { "-" } else { "" };
    let (whole, frac) = (t.abs() / 10, t.abs() % 10);
    let _ = if frac == 0 {
        write!(out, "{sign}{whole}")
    } else {
        write!(out, "{sign}{whole}.{frac}")
    };
}

/// Appends `v` rounded to 0.1 (see [`tenths`]).
pub(crate) fn push_num(out: &mut String, v: f64) {
    push_tenths(out, tenths(v));
}

/// An attribute list, built in call order.
#[derive(Debug, Default)]
pub(crate) struct Attrs(String);

impl Attrs {
    /// Adds a numeric attribute rounded to 0.1.
    pub(crate) fn num(mut self, name: &str, v: f64) -> Self {
        let _ = write!(self.0, " {name}=\"");
        push_num(&mut self.0, v);
        self.0.push('"');
        self
    }

    /// Adds a text attribute, escaped.
    pub(crate) fn str(mut self, name: &str, v: &str) -> Self {
        let _ = write!(self.0, " {name}=\"{}\"", escape(v));
        self
    }
}

/// Path data (`d` attribute) with consecutive repeats at 0.1 px dropped.
#[derive(Debug, Default)]
pub(crate) struct PathData {
    d: String,
    last: Option<(i64, i64)>,
    in_line: bool,
}

impl PathData {
    /// Starts a new sub-path at (x, y).
    pub(crate) fn move_to(&mut self, x: f64, y: f64) {
        let p = (tenths(x), tenths(y));
        self.d.push('M');
        self.push_point(p);
        self.in_line = false;
    }

    /// Draws a straight line to (x, y); does nothing if that is the current point.
    pub(crate) fn line_to(&mut self, x: f64, y: f64) {
        let p = (tenths(x), tenths(y));
        if self.last == Some(p) {
            return;
        }
        self.d.push(if self.in_line { ' ' } else { 'L' });
        self.push_point(p);
        self.in_line = true;
    }

    /// Adds a zero-length segment so a lone point shows as a dot (with a round line cap).
    pub(crate) fn dot(&mut self) {
        self.d.push_str("h0");
        self.in_line = false;
    }

    /// Closes the current sub-path.
    pub(crate) fn close(&mut self) {
        self.d.push('Z');
        self.in_line = false;
    }

    /// True when nothing has been drawn.
    pub(crate) fn is_empty(&self) -> bool {
        self.d.is_empty()
    }

    /// The `d` attribute text.
    pub(crate) fn as_str(&self) -> &str {
        &self.d
    }

    fn push_point(&mut self, p: (i64, i64)) {
        push_tenths(&mut self.d, p.0);
        self.d.push(' ');
        push_tenths(&mut self.d, p.1);
        self.last = Some(p);
    }
}

/// An SVG body under construction (everything inside the root element).
#[derive(Debug, Default)]
pub(crate) struct Svg {
    out: String,
}

impl Svg {
    /// Opens `<tag attrs>`.
    pub(crate) fn open(&mut self, tag: &str, attrs: Attrs) {
        let _ = writeln!(self.out, "<{tag}{}>", attrs.0);
    }

    /// Closes `</tag>`.
    pub(crate) fn close(&mut self, tag: &str) {
        let _ = writeln!(self.out, "</{tag}>");
    }

    /// Writes an empty element `<tag attrs/>`.
    pub(crate) fn leaf(&mut self, tag: &str, attrs: Attrs) {
        let _ = writeln!(self.out, "<{tag}{}/>", attrs.0);
    }

    /// Writes `<text attrs>content</text>`, escaping `content`.
    pub(crate) fn text(&mut self, attrs: Attrs, content: &str) {
        let _ = writeln!(self.out, "<text{}>{}</text>", attrs.0, escape(content));
    }

    /// Writes a tick label: plain text, or `10` with a raised, smaller exponent.
    pub(crate) fn tick_label(&mut self, attrs: Attrs, label: &TickLabel) {
        match label {
            TickLabel::Text(text) => self.text(attrs, text),
            TickLabel::Pow10(exp) => {
                let _ = writeln!(
                    self.out,
                    "<text{}>10<tspan dy=\"-5\" font-size=\"8\">{exp}</tspan></text>",
                    attrs.0
                );
            }
        }
    }

    /// Wraps the body in a complete document of `width` x `height` px. `summary` becomes an XML
    /// comment at the top (any `--` in it is broken up, as comments cannot contain it).
    pub(crate) fn into_document(self, width: f64, height: f64, summary: &str) -> String {
        let mut doc = String::with_capacity(self.out.len() + 1024);
        let mut size = String::new();
        push_num(&mut size, width);
        size.push(' ');
        push_num(&mut size, height);
        let (w, h) = size.split_once(' ').unwrap_or(("0", "0"));
        let _ = writeln!(doc, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
        let _ = writeln!(
            doc,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">"
        );
        let _ = writeln!(doc, "<!-- {} -->", comment_safe(summary));
        let _ = writeln!(doc, "<style>{STYLE}</style>");
        let _ = writeln!(doc, "<rect width=\"{w}\" height=\"{h}\" fill=\"#fff\"/>");
        doc.push_str(&self.out);
        doc.push_str("</svg>\n");
        doc
    }
}

/// `text` with `--` sequences broken up and markup characters escaped, safe inside a comment.
fn comment_safe(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in escape(text).chars() {
        if c == '-' && out.ends_with('-') {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup_characters() {
        assert_eq!(
            escape(r#"a & b < c > d "e" 'f'"#),
            "a &amp; b &lt; c &gt; d &quot;e&quot; 'f'"
        );
        assert_eq!(escape("µ ±2 %\tx\u{7}y"), "µ ±2 % xy");
    }

    #[test]
    fn numbers_are_compact_and_rounded() {
        let cases = [
            (0.0, "0"),
            (-0.0, "0"),
            (-0.04, "0"),
            (12.0, "12"),
            (12.34, "12.3"),
            (12.36, "12.4"),
            (-3.25, "-3.3"),
            (-0.1, "-0.1"),
            (f64::NAN, "0"),
            (f64::INFINITY, "100000"),
            (-1e300, "-100000"),
        ];
        for (v, want) in cases {
            let mut s = String::new();
            push_num(&mut s, v);
            assert_eq!(s, want, "{v}");
        }
    }

    #[test]
    fn path_drops_repeats_and_uses_implicit_lineto() {
        let mut p = PathData::default();
        p.move_to(1.0, 2.0);
        p.line_to(1.01, 2.0);
        p.line_to(3.0, 4.5);
        p.line_to(5.0, 6.0);
        p.move_to(7.0, 8.0);
        p.dot();
        p.line_to(9.0, 9.0);
        assert_eq!(p.as_str(), "M1 2L3 4.5 5 6M7 8h0L9 9");
    }

    #[test]
    fn comments_cannot_be_terminated_early() {
        assert_eq!(comment_safe("a--b-->c"), "a- -b- -&gt;c");
    }
}
