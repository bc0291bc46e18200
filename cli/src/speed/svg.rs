//! `docs/speed.svg`: maximum error against instructions per evaluation (log-log), one panel per
//! level (each against its own exact model, so levels are not mixed on one front), points
//! grouped by numeric form and labelled by knob, the panel's Pareto front marked. Panels are the
//! plot module's scatter plots, nested in one SVG document.

use sonolube::variant::{CATALOGUE, Fidelity};

use super::errors::Errors;
use super::markdown::level_name;
use super::qemu::Counts;
use crate::plot::{ScatterPlot, pareto_front};

/// Panel size, px.
const PANEL: (f64, f64) = (620.0, 400.0);
/// Panels per row.
const COLUMNS: usize = 2;

const LEVELS: [Fidelity; 6] = [
    Fidelity::Littmann,
    Fidelity::DahlUpdate,
    Fidelity::Coulomb,
    Fidelity::DahlSteady,
    Fidelity::CubeElastic,
    Fidelity::CubeElasticPlastic,
];

/// One level's panel as a standalone SVG document.
fn panel(level: Fidelity, errors: &Errors, counts: &Counts) -> String {
    let mut plot = ScatterPlot::new(level_name(level))
        .log_x()
        .log_y()
        .size(PANEL.0, PANEL.1)
        .x_label("Cortex-M4 instructions per evaluation")
        .y_label("max |error| of F'/F");
    let mut xy = Vec::new();
    for v in CATALOGUE.iter().filter(|v| v.fidelity == level) {
        let x = counts.get(v.name).map_or(f64::NAN, |c| c.instructions);
        let y = errors.own(v.name).map_or(f64::NAN, |e| e.max);
        let label = if v.table > 0 {
            format!("T={}", v.table)
        } else if v.points > 0 {
            format!("N={}", v.points)
        } else {
            String::new()
        };
        plot = plot.point(&label, x, y, v.form_name());
        xy.push((x, y));
    }
    plot.pareto(&pareto_front(&xy)).to_svg()
}

/// The document: the panels in a grid of [`COLUMNS`].
pub fn render(errors: &Errors, counts: &Counts) -> String {
    let rows = LEVELS.len().div_ceil(COLUMNS);
    let (width, height) = (PANEL.0 * COLUMNS as f64, PANEL.1 * rows as f64);
    let mut doc = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" \
         width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\">\n\
         <!-- sonolube speed: error against instructions, one panel per level -->\n"
    );
    for (i, &level) in LEVELS.iter().enumerate() {
        let (x, y) = (
            (i % COLUMNS) as f64 * PANEL.0,
            (i / COLUMNS) as f64 * PANEL.1,
        );
        let inner = panel(level, errors, counts);
        // Drop the XML declaration and place the panel's own <svg> element.
        let body = inner
            .split_once('\n')
            .map_or(inner.as_str(), |(_, rest)| rest);
        doc.push_str(&body.replacen("<svg ", &format!("<svg x=\"{x}\" y=\"{y}\" "), 1));
    }
    doc.push_str("</svg>\n");
    doc
}
