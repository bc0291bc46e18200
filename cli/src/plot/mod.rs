//! Dependency-free SVG plots for the host tool: stacked time-series panels for closed-loop scene
//! runs, and a labelled (log-log) scatter with a Pareto front for the speed-versus-accuracy table.
//!
//! # Time series
//! ```text
//! let svg = TimeSeriesPlot::new("scene 3: load step")
//!     .x_label("time (s)")
//!     .panel(
//!         Panel::new("friction", "N")
//!             .band(Band::around("target ±2 %", &t, &target_n, 0.02))
//!             .series(Series::line("target", &t, &target_n).dashed())
//!             .series(Series::line("estimated", &t, &estimated_n))
//!             .series(Series::line("true", &t, &true_n)),
//!     )
//!     .panel(Panel::new("drive amplitude", "fraction").y_range(0.0, 1.0)
//!         .series(Series::line("amplitude", &t, &amplitude)))
//!     .panel(Panel::new("normal load", "N").series(Series::line("load", &t, &load_n)))
//!     .marker(Marker::new("fault", 1.2))
//!     .to_svg();
//! std::fs::write("scene3.svg", svg)?;
//! ```
//! Each panel has its own y axis (`name (unit)`, autoscaled to whole 1-2-5 steps unless
//! [`Panel::y_range`] is given) and its own legend, right of the panel; the x axis is shared and
//! spans the data exactly unless [`TimeSeriesPlot::x_range`] is given. Series are borrowed
//! slices; up to ~1e5 points per series are fine, as each is decimated to at most four points per
//! pixel column (first, min, max, last: see [`decimate_min_max`]) so spikes stay visible.
//!
//! # Scatter
//! ```text
//! let mut plot = ScatterPlot::new("speed vs accuracy").log_x().log_y()
//!     .x_range(10.0, 1e6).y_range(1e-12, 1.0)
//!     .x_label("instructions per evaluation").y_label("max abs error");
//! for row in &rows {
//!     plot = plot.point(&row.name, row.instructions, row.error, &row.method);
//! }
//! let xy: Vec<(f64, f64)> = rows.iter().map(|r| (r.instructions, r.error)).collect();
//! let svg = plot.pareto(&pareto_front(&xy)).to_svg();
//! ```
//!
//! # Guarantees
//! - Deterministic: the same input gives a byte-identical SVG (no hashing; coordinates are
//!   written with at most one decimal, 0.1 px).
//! - No panic on any data: NaN/inf points (and points <= 0 on a log axis) are skipped and
//!   counted in a comment at the top of the file; empty plots, empty series and constant series
//!   get a usable axis.
//! - All text is escaped; the output is a standalone SVG 1.1 document (UTF-8) that browsers and
//!   `rsvg-convert` render.

mod axis;
mod decimate;
mod draw;
mod labels;
mod legend;
mod panel;
mod pareto;
mod scatter;
mod series;
mod svg;
#[cfg(test)]
mod tests;
mod ticks;
mod timeseries;
#[cfg(test)]
mod wellformed;

pub use decimate::decimate_min_max;
pub use panel::Panel;
pub use pareto::pareto_front;
pub use scatter::ScatterPlot;
pub use series::{Band, Marker, Series};
pub use svg::escape;
pub use ticks::{
    Tick, TickLabel, format_linear_tick, linear_ticks, log_range, log_ticks, nice_linear_range,
    nice_step,
};
pub use timeseries::TimeSeriesPlot;
