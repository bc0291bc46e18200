//! Stacked time-series panels sharing one x axis: the view of a closed-loop scene run.

use super::axis::{self, Scale, rect};
use super::draw::{Stats, draw_band, draw_markers, draw_series};
use super::legend::{draw_legend, legend_width};
use super::panel::{Extent, Panel};
use super::series::{BandShape, Marker};
use super::svg::{Attrs, Svg};
use super::ticks::{linear_ticks, sane_range};

/// Vertical space between panels, px.
const GAP_PX: f64 = 22.0;
/// Space under the last panel for tick labels and the x-axis title, px.
const BOTTOM_PX: f64 = 50.0;

/// Stacked panels sharing a linear x axis (usually time in s), rendered by
/// [`TimeSeriesPlot::to_svg`].
#[derive(Debug, Clone)]
pub struct TimeSeriesPlot<'a> {
    title: String,
    x_label: String,
    width_px: f64,
    panel_height_px: f64,
    x_range: Option<(f64, f64)>,
    panels: Vec<Panel<'a>>,
    markers: Vec<Marker>,
}

impl<'a> TimeSeriesPlot<'a> {
    /// An empty plot, 960 px wide with 200 px panels, titled `title` (empty for none).
    pub fn new(title: &str) -> Self {
        TimeSeriesPlot {
            title: title.to_string(),
            x_label: String::new(),
            width_px: 960.0,
            panel_height_px: 200.0,
            x_range: None,
            panels: Vec::new(),
            markers: Vec::new(),
        }
    }

    /// Title under the shared x axis, unit included (e.g. `time (s)`).
    pub fn x_label(mut self, label: &str) -> Self {
        self.x_label = label.to_string();
        self
    }

    /// Sets the total width (300..10 000 px) and the height of each panel's plot area
    /// (60..2 000 px); out-of-range values are clamped.
    pub fn size(mut self, width_px: f64, panel_height_px: f64) -> Self {
        let clamp = |v: f64, lo: f64, hi: f64| if v.is_nan() { lo } else { v.clamp(lo, hi) };
        self.width_px = clamp(width_px, 300.0, 1.0e4);
        self.panel_height_px = clamp(panel_height_px, 60.0, 2.0e3);
        self
    }

    /// Fixes the x axis to `[lo, hi]`; by default it spans all data, bands and markers exactly.
    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    /// Adds a panel below the existing ones.
    pub fn panel(mut self, panel: Panel<'a>) -> Self {
        self.panels.push(panel);
        self
    }

    /// Adds a vertical marker crossing every panel, labelled at the top of the first.
    pub fn marker(mut self, marker: Marker) -> Self {
        self.markers.push(marker);
        self
    }

    fn x_domain(&self) -> (f64, f64) {
        if let Some((lo, hi)) = self.x_range {
            return sane_range(lo, hi);
        }
        let mut ext = Extent::default();
        for p in &self.panels {
            for s in &p.series {
                s.x[..s.len()].iter().for_each(|&x| ext.add(x));
            }
            for b in &p.bands {
                match b.shape {
                    BandShape::Vertical(a, c) => [a, c].into_iter().for_each(|x| ext.add(x)),
                    BandShape::Between(x, ..) | BandShape::Around(x, ..) => {
                        x[..b.len()].iter().for_each(|&x| ext.add(x));
                    }
                    BandShape::Horizontal(..) => {}
                }
            }
            p.markers.iter().for_each(|m| ext.add(m.x));
        }
        self.markers.iter().for_each(|m| ext.add(m.x));
        let (lo, hi) = ext.0.unwrap_or((0.0, 1.0));
        sane_range(lo, hi)
    }

    /// Renders the plot as a standalone SVG document. Never panics on any data: NaN/inf points
    /// are skipped (counted in the leading comment), empty panels get a 0..1 axis.
    pub fn to_svg(&self) -> String {
        let (x_lo, x_hi) = self.x_domain();
        let plot_h = self.panel_height_px;
        let y_target = ((plot_h / 45.0) as usize).clamp(2, 10);
        let unit_x = Scale {
            lo: x_lo,
            hi: x_hi,
            px_lo: 0.0,
            px_hi: 1.0,
            log: false,
        };
        let y_axes: Vec<_> = self
            .panels
            .iter()
            .map(|p| p.y_axis(&unit_x, y_target))
            .collect();
        let legends: Vec<_> = self.panels.iter().map(Panel::legend).collect();

        let tick_w = y_axes
            .iter()
            .map(|a| axis::max_label_width(&a.2))
            .fold(0.0, f64::max);
        let left = 38.0 + tick_w;
        let legend_w = legends.iter().map(|l| legend_width(l)).fold(0.0, f64::max);
        let right = if legend_w > 0.0 {
            legend_w + 30.0
        } else {
            20.0
        };
        let width = self.width_px.max(left + right + 120.0);
        let top = if self.title.is_empty() { 14.0 } else { 40.0 };
        let n = self.panels.len() as f64;
        let height = top + n * plot_h + (n - 1.0).max(0.0) * GAP_PX + BOTTOM_PX;
        let xs = Scale {
            px_lo: left,
            px_hi: width - right,
            ..unit_x
        };
        let x_ticks = linear_ticks(x_lo, x_hi, (((xs.px_hi - left) / 90.0) as usize).max(2));

        let mut svg = Svg::default();
        let mut stats = Stats::default();
        let title_at = Attrs::default()
            .num("x", (left + xs.px_hi) / 2.0)
            .num("y", 24.0);
        svg.text(
            title_at.str("class", "title").str("text-anchor", "middle"),
            &self.title,
        );
        for (i, (panel, (y_lo, y_hi, y_ticks))) in self.panels.iter().zip(&y_axes).enumerate() {
            let p_top = top + i as f64 * (plot_h + GAP_PX);
            let p_bottom = p_top + plot_h;
            let ys = Scale {
                lo: *y_lo,
                hi: *y_hi,
                px_lo: p_bottom,
                px_hi: p_top,
                log: false,
            };
            let last = i + 1 == self.panels.len();
            axis::draw_x_ticks(&mut svg, &xs, &x_ticks, p_top, p_bottom, last);
            axis::draw_y_ticks(&mut svg, &ys, y_ticks, left, xs.px_hi);
            axis::vertical_title(&mut svg, 16.0, (p_top + p_bottom) / 2.0, &panel.title());
            let clip_id = format!("clip{i}");
            svg.open("clipPath", Attrs::default().str("id", &clip_id));
            svg.leaf("rect", rect(left, p_top, xs.px_hi, p_bottom));
            svg.close("clipPath");
            svg.open(
                "g",
                Attrs::default().str("clip-path", &format!("url(#{clip_id})")),
            );
            for band in &panel.bands {
                stats.skipped += draw_band(&mut svg, band, &xs, &ys);
            }
            for (k, series) in panel.series.iter().enumerate() {
                draw_series(
                    &mut svg,
                    series,
                    panel.series_color(k),
                    &xs,
                    &ys,
                    &mut stats,
                );
            }
            svg.close("g");
            draw_markers(&mut svg, &panel.markers, &xs, p_top, p_bottom);
            svg.leaf(
                "rect",
                rect(left, p_top, xs.px_hi, p_bottom).str("class", "frame"),
            );
            draw_legend(&mut svg, xs.px_hi + 14.0, p_top, &legends[i]);
        }
        if !self.panels.is_empty() {
            draw_markers(&mut svg, &self.markers, &xs, top, height - BOTTOM_PX);
            let at = Attrs::default()
                .num("x", (left + xs.px_hi) / 2.0)
                .num("y", height - 10.0);
            svg.text(
                at.str("class", "axis").str("text-anchor", "middle"),
                &self.x_label,
            );
        }
        let series: usize = self.panels.iter().map(|p| p.series.len()).sum();
        let summary = format!(
            "sonolube time-series plot: {} panels, {series} series, {} points, {} drawn after \
             decimation, {} non-finite points skipped",
            self.panels.len(),
            stats.points,
            stats.drawn,
            stats.skipped
        );
        svg.into_document(width, height, &summary)
    }
}
