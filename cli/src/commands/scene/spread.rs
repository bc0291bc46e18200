//! The SVG of a sweep's distributions: the quantile curve (value against the share of runs at
//! or below it) of the settling time and of the steady RMS error of every scene that has those
//! criteria, with each scene's limit as a dashed line.

use super::robust::Done;
use crate::plot::{Panel, Series, TimeSeriesPlot};

/// One curve: label, x (percent of runs), y (sorted values), limit.
struct Curve {
    label: String,
    x: Vec<f64>,
    y: Vec<f64>,
    limit_x: Vec<f64>,
    limit_y: Vec<f64>,
}

fn curves(sweeps: &[(String, Done)], criterion: &str) -> Vec<Curve> {
    sweeps
        .iter()
        .filter_map(|(name, done)| {
            let stats = done.stats.iter().find(|s| s.name == criterion)?;
            if stats.values.is_empty() {
                return None;
            }
            let n = stats.values.len() as f64;
            Some(Curve {
                label: format!("{name} ({}/{} pass)", stats.passed, stats.runs),
                x: (1..=stats.values.len())
                    .map(|i| 100.0 * i as f64 / n)
                    .collect(),
                y: stats.values.clone(),
                limit_x: vec![0.0, 100.0],
                limit_y: vec![stats.limit, stats.limit],
            })
        })
        .collect()
}

/// The SVG document of `sweeps` (scene name, finished sweep).
pub fn svg(sweeps: &[(String, Done)]) -> String {
    let settle = curves(sweeps, "settle");
    let rms = curves(sweeps, "RMS error");
    let runs: usize = sweeps.iter().map(|(_, d)| d.results.len()).sum();
    let mut plot = TimeSeriesPlot::new(&format!(
        "distributions over {runs} runs: settling time and steady RMS error (dashed: limits)"
    ))
    .x_label("runs at or below the value (%)")
    .x_range(0.0, 100.0);
    let mut settle_panel = Panel::new("settling time", "ms");
    for curve in &settle {
        settle_panel = settle_panel
            .series(Series::line(&curve.label, &curve.x, &curve.y))
            .series(
                Series::line(
                    &format!("{} limit", curve.label.split(' ').next().unwrap_or("")),
                    &curve.limit_x,
                    &curve.limit_y,
                )
                .dashed(),
            );
    }
    let mut rms_panel = Panel::new("steady RMS error", "%");
    for curve in &rms {
        rms_panel = rms_panel
            .series(Series::line(&curve.label, &curve.x, &curve.y))
            .series(
                Series::line(
                    &format!("{} limit", curve.label.split(' ').next().unwrap_or("")),
                    &curve.limit_x,
                    &curve.limit_y,
                )
                .dashed(),
            );
    }
    plot = plot.panel(settle_panel).panel(rms_panel);
    plot.to_svg()
}
