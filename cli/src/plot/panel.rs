//! One panel of a time-series plot: its own y axis, lines, bands, markers and legend.

use super::axis::{PALETTE, Scale};
use super::legend::{Entry, Swatch};
use super::series::{Band, BandShape, Marker, Series};
use super::ticks::{Tick, linear_ticks, nice_linear_range, sane_range};

/// Colour of bands without their own.
pub(crate) const BAND_GREY: &str = "#7f7f7f";

/// One panel: its own y axis (`name (unit)`), lines, bands, markers and legend.
#[derive(Debug, Clone)]
pub struct Panel<'a> {
    pub(crate) name: String,
    pub(crate) unit: String,
    pub(crate) series: Vec<Series<'a>>,
    pub(crate) bands: Vec<Band<'a>>,
    pub(crate) markers: Vec<Marker>,
    pub(crate) y_range: Option<(f64, f64)>,
}

impl<'a> Panel<'a> {
    /// An empty panel whose y axis reads `name (unit)` (just `name` when `unit` is empty).
    pub fn new(name: &str, unit: &str) -> Self {
        Panel {
            name: name.to_string(),
            unit: unit.to_string(),
            series: Vec::new(),
            bands: Vec::new(),
            markers: Vec::new(),
            y_range: None,
        }
    }

    /// Adds a line (drawn in the order added, later on top).
    pub fn series(mut self, series: Series<'a>) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a shaded band (drawn under all lines).
    pub fn band(mut self, band: Band<'a>) -> Self {
        self.bands.push(band);
        self
    }

    /// Adds a vertical marker to this panel only (see
    /// [`TimeSeriesPlot::marker`](super::TimeSeriesPlot::marker) for one across all panels).
    pub fn marker(mut self, marker: Marker) -> Self {
        self.markers.push(marker);
        self
    }

    /// Fixes the y axis to `[lo, hi]` (panel unit; e.g. 0..1 for a drive amplitude); by default
    /// it spans the visible data and bands, widened to whole tick steps. Data outside are clipped.
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Axis title: `name (unit)`, or `name`.
    pub(crate) fn title(&self) -> String {
        if self.unit.is_empty() {
            self.name.clone()
        } else {
            format!("{} ({})", self.name, self.unit)
        }
    }

    /// Colour of series `i` (its own, else the palette's i-th).
    pub(crate) fn series_color(&self, i: usize) -> &str {
        self.series[i]
            .color
            .as_deref()
            .unwrap_or(PALETTE[i % PALETTE.len()])
    }

    /// The y domain and its ticks, given the x domain (data outside it do not count).
    pub(crate) fn y_axis(&self, x_dom: &Scale, target_ticks: usize) -> (f64, f64, Vec<Tick>) {
        let (lo, hi) = match self.y_range {
            Some((lo, hi)) => sane_range(lo, hi),
            None => {
                let mut ext = Extent::default();
                for s in &self.series {
                    for i in (0..s.len()).filter(|&i| x_dom.contains(s.x[i])) {
                        ext.add(s.y[i]);
                    }
                }
                for b in &self.bands {
                    if let BandShape::Horizontal(a, c) = b.shape {
                        ext.add(a);
                        ext.add(c);
                    }
                    for (_, lo, hi) in (0..b.len()).filter_map(|i| b.sample(i)) {
                        ext.add(lo);
                        ext.add(hi);
                    }
                }
                let (lo, hi) = ext.0.unwrap_or((0.0, 1.0));
                nice_linear_range(lo, hi, target_ticks)
            }
        };
        (lo, hi, linear_ticks(lo, hi, target_ticks))
    }

    /// Legend entries: labelled series, then labelled bands.
    pub(crate) fn legend(&self) -> Vec<Entry> {
        let lines = self.series.iter().enumerate().map(|(i, s)| Entry {
            swatch: Swatch::Line(
                self.series_color(i).to_string(),
                s.width_px,
                s.dashed.then_some("6 4"),
            ),
            text: s.label.clone(),
        });
        let bands = self.bands.iter().map(|b| Entry {
            swatch: Swatch::Fill(b.color.clone().unwrap_or(BAND_GREY.to_string())),
            text: b.label.clone(),
        });
        lines.chain(bands).filter(|e| !e.text.is_empty()).collect()
    }
}

/// Running min/max of the finite values seen.
#[derive(Debug, Default)]
pub(crate) struct Extent(pub(crate) Option<(f64, f64)>);

impl Extent {
    /// Widens the extent to `v` if finite.
    pub(crate) fn add(&mut self, v: f64) {
        if v.is_finite() {
            self.0 = Some(self.0.map_or((v, v), |(a, b)| (a.min(v), b.max(v))));
        }
    }
}
