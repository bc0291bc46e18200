//! What a time-series panel holds: lines, shaded bands and vertical markers. Data are borrowed,
//! so plotting 100 000-point runs copies nothing.

/// Default line width, px.
const LINE_WIDTH_PX: f64 = 1.5;

/// One line of a panel: `y[i]` against `x[i]` (only the common length of the two is used;
/// NaN/inf points are skipped and break the line).
#[derive(Debug, Clone)]
pub struct Series<'a> {
    pub(crate) label: String,
    pub(crate) x: &'a [f64],
    pub(crate) y: &'a [f64],
    pub(crate) color: Option<String>,
    pub(crate) width_px: f64,
    pub(crate) dashed: bool,
}

impl<'a> Series<'a> {
    /// A solid line labelled `label` in the legend (an empty label leaves it out of the legend).
    /// `x` is in the plot's x unit (usually seconds), `y` in the panel's unit.
    pub fn line(label: &str, x: &'a [f64], y: &'a [f64]) -> Self {
        Series {
            label: label.to_string(),
            x,
            y,
            color: None,
            width_px: LINE_WIDTH_PX,
            dashed: false,
        }
    }

    /// Sets the colour (any SVG colour, such as `#d55e00`); by default the panel's n-th series
    /// takes the n-th palette colour.
    pub fn color(mut self, color: &str) -> Self {
        self.color = Some(color.to_string());
        self
    }

    /// Sets the line width in px (0.1..20; default 1.5; out-of-range values are clamped).
    pub fn width(mut self, px: f64) -> Self {
        self.width_px = if px.is_nan() {
            LINE_WIDTH_PX
        } else {
            px.clamp(0.1, 20.0)
        };
        self
    }

    /// Draws the line dashed.
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }

    /// Number of points drawn from (the common length of `x` and `y`).
    pub(crate) fn len(&self) -> usize {
        self.x.len().min(self.y.len())
    }
}

/// Where a band lies.
#[derive(Debug, Clone)]
pub(crate) enum BandShape<'a> {
    /// All x, between two y values.
    Horizontal(f64, f64),
    /// All y, between two x values.
    Vertical(f64, f64),
    /// Between `lo[i]` and `hi[i]` at `x[i]`.
    Between(&'a [f64], &'a [f64], &'a [f64]),
    /// Within `centre[i] +- fraction * |centre[i]|` at `x[i]`.
    Around(&'a [f64], &'a [f64], f64),
}

/// A translucent shaded region of a panel, drawn under the lines.
#[derive(Debug, Clone)]
pub struct Band<'a> {
    pub(crate) label: String,
    pub(crate) shape: BandShape<'a>,
    pub(crate) color: Option<String>,
}

impl<'a> Band<'a> {
    fn new(label: &str, shape: BandShape<'a>) -> Self {
        Band {
            label: label.to_string(),
            shape,
            color: None,
        }
    }

    /// The full width of the panel between `y_lo` and `y_hi` (panel unit, either order).
    pub fn horizontal(label: &str, y_lo: f64, y_hi: f64) -> Self {
        Band::new(label, BandShape::Horizontal(y_lo, y_hi))
    }

    /// The full height of the panel between `x_from` and `x_to` (x unit), e.g. a fault interval.
    pub fn vertical(label: &str, x_from: f64, x_to: f64) -> Self {
        Band::new(label, BandShape::Vertical(x_from, x_to))
    }

    /// Between the curves `lo` and `hi` sampled at `x` (common length used; points with a
    /// NaN/inf value break the band).
    pub fn between(label: &str, x: &'a [f64], lo: &'a [f64], hi: &'a [f64]) -> Self {
        Band::new(label, BandShape::Between(x, lo, hi))
    }

    /// Within `centre +- fraction * |centre|` around a curve sampled at `x`: `fraction` 0.02 is
    /// the +-2 % settling band around a target (fraction 0..1; its magnitude is used).
    pub fn around(label: &str, x: &'a [f64], centre: &'a [f64], fraction: f64) -> Self {
        Band::new(label, BandShape::Around(x, centre, fraction.abs()))
    }

    /// Sets the colour (any SVG colour; default grey); drawn at 18 % opacity.
    pub fn color(mut self, color: &str) -> Self {
        self.color = Some(color.to_string());
        self
    }

    /// Number of samples of a curve-following band (0 for horizontal and vertical ones).
    pub(crate) fn len(&self) -> usize {
        match self.shape {
            BandShape::Between(x, lo, hi) => x.len().min(lo.len()).min(hi.len()),
            BandShape::Around(x, c, _) => x.len().min(c.len()),
            _ => 0,
        }
    }

    /// `(x, lower, upper)` of sample `i` of a curve-following band, `None` when not finite.
    pub(crate) fn sample(&self, i: usize) -> Option<(f64, f64, f64)> {
        let (x, lo, hi) = match self.shape {
            BandShape::Between(x, lo, hi) => (x[i], lo[i].min(hi[i]), lo[i].max(hi[i])),
            BandShape::Around(x, c, f) => (x[i], c[i] - c[i].abs() * f, c[i] + c[i].abs() * f),
            _ => return None,
        };
        (x.is_finite() && lo.is_finite() && hi.is_finite()).then_some((x, lo, hi))
    }
}

/// A labelled vertical line at one x value (e.g. the time a fault is injected).
#[derive(Debug, Clone)]
pub struct Marker {
    pub(crate) label: String,
    pub(crate) x: f64,
    pub(crate) color: Option<String>,
}

impl Marker {
    /// A dashed vertical line at `x` (x unit), with `label` written beside its top.
    pub fn new(label: &str, x: f64) -> Self {
        Marker {
            label: label.to_string(),
            x,
            color: None,
        }
    }

    /// Sets the colour (any SVG colour; default dark red).
    pub fn color(mut self, color: &str) -> Self {
        self.color = Some(color.to_string());
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_samples_order_and_reject_non_finite() {
        let x = [0.0, 1.0, 2.0];
        let c = [1.0, -2.0, f64::NAN];
        let b = Band::around("", &x, &c, -0.1);
        assert_eq!(b.len(), 3);
        assert_eq!(b.sample(0), Some((0.0, 0.9, 1.1)));
        assert_eq!(b.sample(1), Some((1.0, -2.2, -1.8)));
        assert_eq!(b.sample(2), None);
        let hi = [0.0, 5.0];
        let b = Band::between("", &x, &c, &hi);
        assert_eq!((b.len(), b.sample(0)), (2, Some((0.0, 0.0, 1.0))));
        assert_eq!(Band::vertical("", 1.0, 2.0).sample(0), None);
        assert_eq!(
            Series::line("", &x, &hi).width(f64::NAN).width_px,
            LINE_WIDTH_PX
        );
    }
}
