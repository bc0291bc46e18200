//! The SVG plot of a run: friction (target, estimated, true, with the settling band), drive
//! amplitude (command and vibration envelope), normal load; markers at the injected faults and
//! where the supervisor latched a fault.

use sonolube::protocol::SupervisorState;
use sonolube::scene::Scene;
use sonolube_sim::{RunSummary, StepRecord};

use super::report::{band_fraction, channel_name, fault_text, num, verdict};
use crate::plot::{Band, Marker, Panel, Series, TimeSeriesPlot};

/// The SVG document of `records` of `scene`.
pub(super) fn svg(scene: &Scene<'_>, summary: &RunSummary, records: &[StepRecord]) -> String {
    let column = |f: fn(&StepRecord) -> f32| -> Vec<f64> {
        records.iter().map(|r| f64::from(f(r))).collect()
    };
    let t = column(|r| r.time_s);
    let target = column(|r| r.target_friction_n);
    let estimated = column(|r| r.estimated_friction_n);
    let truth = column(|r| r.true_friction_n);
    let drive = column(|r| r.drive_amplitude);
    let envelope = column(|r| r.vibration_amplitude);
    let load = column(|r| r.normal_load_n);
    let band = band_fraction(scene);
    let band_label = format!("target ±{} %", num(band * 100.0));
    let mut plot = TimeSeriesPlot::new(&format!("scene {}: {}", scene.name, verdict(summary)))
        .x_label("time (s)")
        .panel(
            Panel::new("friction", "N")
                .band(Band::around(&band_label, &t, &target, band))
                .series(Series::line("target", &t, &target).dashed())
                .series(Series::line("estimated", &t, &estimated))
                .series(Series::line("true", &t, &truth)),
        )
        .panel(
            Panel::new("drive amplitude", "fraction of full scale")
                .y_range(0.0, 1.0)
                .series(Series::line("command", &t, &drive))
                .series(Series::line("vibration", &t, &envelope)),
        )
        .panel(Panel::new("normal load", "N").series(Series::line("load", &t, &load)));
    for fault in scene.faults {
        let label = format!("{} {}", channel_name(fault.channel), fault_text(fault.kind));
        plot = plot.marker(Marker::new(&label, fault.at_s));
    }
    let latched = records
        .iter()
        .find(|r| r.state == SupervisorState::Fault)
        .filter(|r| {
            scene
                .faults
                .iter()
                .all(|f| (f.at_s - f64::from(r.time_s)).abs() > 1e-9)
        });
    if let Some(r) = latched {
        let label = format!("fault: {}", r.reason.name());
        plot = plot.marker(Marker::new(&label, f64::from(r.time_s)).color("#0072b2"));
    }
    plot.to_svg()
}
