//! The SVG plot of a session's telemetry, drawn with [`crate::plot`] as `sonolube scene` draws
//! its runs: friction (target and estimate), forces, drive amplitude, and a marker at each
//! change of supervisor state.

use sonolube::protocol::{Target, TelemetryRecord};

use crate::plot::{Band, Marker, Panel, Series, TimeSeriesPlot};

/// State-change markers drawn at most (more would hide the data).
const MAX_STATE_MARKERS: usize = 12;

/// The SVG document of `records`, titled `title`. When `band_pct` is given, the coefficient
/// target is drawn with a ±`band_pct` % band (the acceptance tolerance).
pub fn telemetry_svg(title: &str, records: &[TelemetryRecord], band_pct: Option<f64>) -> String {
    let column =
        |f: &dyn Fn(&TelemetryRecord) -> f64| -> Vec<f64> { records.iter().map(f).collect() };
    let t = column(&|r| r.time_us as f64 * 1e-6);
    let mu = column(&|r| f64::from(r.reading.friction_coef_ppm) * 1e-6);
    // Targets of the other kinds have no value in this panel's unit: NaN breaks the line.
    let coef_target = column(&|r| match r.reading.target {
        Some(Target::Coef { coef_ppm }) => f64::from(coef_ppm) * 1e-6,
        _ => f64::NAN,
    });
    let force_target = column(&|r| match r.reading.target {
        Some(Target::Force { force_mn }) => f64::from(force_mn) * 1e-3,
        _ => f64::NAN,
    });
    // The net force (issue 27) is the horn's force on the block; the tangential cell reads
    // the block's drag on it, -F: drawn in the cell's sign so the two lines meet when held.
    let net_force_target = column(&|r| match r.reading.target {
        Some(Target::NetForce { force_mn }) => -f64::from(force_mn) * 1e-3,
        _ => f64::NAN,
    });
    let normal = column(&|r| f64::from(r.reading.normal_force_mn) * 1e-3);
    let tangential = column(&|r| f64::from(r.reading.tangential_force_mn) * 1e-3);
    let amplitude = column(&|r| f64::from(r.reading.drive_amplitude_ppm) * 1e-6);
    let reductions = records
        .iter()
        .filter(|r| matches!(r.reading.target, Some(Target::Reduction { .. })))
        .count();

    let band_label = band_pct.map(|pct| format!("target ±{pct} %"));
    let mut friction = Panel::new("friction coefficient", "");
    if let (Some(label), Some(pct)) = (&band_label, band_pct) {
        friction = friction.band(Band::around(label, &t, &coef_target, pct / 100.0));
    }
    friction = friction
        .series(Series::line("target", &t, &coef_target).dashed())
        .series(Series::line("estimate (mu)", &t, &mu));
    let mut forces = Panel::new("forces", "N")
        .series(Series::line("normal", &t, &normal))
        .series(Series::line("tangential", &t, &tangential));
    if force_target.iter().any(|v| v.is_finite()) {
        forces = forces.series(Series::line("force target", &t, &force_target).dashed());
    }
    if net_force_target.iter().any(|v| v.is_finite()) {
        forces = forces.series(
            Series::line("net-force target (cell sign, -F)", &t, &net_force_target).dashed(),
        );
    }
    let mut full_title = title.to_string();
    if reductions > 0 {
        full_title.push_str(&format!(
            " ({reductions} records with a reduction target, not drawn)"
        ));
    }
    let mut plot = TimeSeriesPlot::new(&full_title)
        .x_label("firmware time (s)")
        .panel(friction)
        .panel(
            Panel::new("drive amplitude", "fraction of full scale")
                .y_range(0.0, 1.0)
                .series(Series::line("amplitude", &t, &amplitude)),
        )
        .panel(forces);
    let changes = records
        .windows(2)
        .filter(|pair| pair[0].reading.state != pair[1].reading.state)
        .take(MAX_STATE_MARKERS);
    for pair in changes {
        let at = pair[1].time_us as f64 * 1e-6;
        plot = plot.marker(Marker::new(pair[1].reading.state.name(), at).color("#0072b2"));
    }
    plot.to_svg()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::protocol::LoopReading;
    use sonolube::protocol::SupervisorState;

    fn record(seq: u32, state: SupervisorState, target: Option<Target>) -> TelemetryRecord {
        TelemetryRecord {
            time_us: u64::from(seq) * 1000,
            seq,
            reading: LoopReading {
                state,
                target,
                friction_coef_ppm: 240_000 - 100 * seq,
                normal_force_mn: 40_000,
                tangential_force_mn: 9_600,
                drive_amplitude_ppm: 1000 * seq,
                drive_freq_chz: 4_000_000,
            },
            overruns: 0,
            lost_records: 0,
            lock: None,
            phase_mdeg: None,
            reach: sonolube::protocol::RunReach::UNKNOWN,
        }
    }

    #[test]
    fn panels_markers_and_legends() {
        let coef = Some(Target::Coef { coef_ppm: 150_000 });
        let mut records: Vec<_> = (0..50)
            .map(|i| record(i, SupervisorState::Idle, None))
            .collect();
        records.extend((50..200).map(|i| record(i, SupervisorState::Running, coef)));
        let svg = telemetry_svg("monitor test", &records, Some(3.0));
        assert!(
            svg.starts_with("<?xml") || svg.starts_with("<svg"),
            "{}",
            &svg[..80]
        );
        for text in [
            "monitor test",
            "friction coefficient",
            "drive amplitude (fraction of full scale)",
            "forces (N)",
            "estimate (mu)",
            "target ±3 %",
            "tangential",
            "running",
            "firmware time (s)",
        ] {
            assert!(svg.contains(text), "{text}");
        }
        assert!(!svg.contains("force target"));
    }

    #[test]
    fn empty_and_odd_data_still_plot() {
        assert!(telemetry_svg("", &[], None).contains("</svg>"));
        let force = Some(Target::Force { force_mn: 5_000 });
        let reduction = Some(Target::Reduction { reduction_mpct: 1 });
        let net = Some(Target::NetForce { force_mn: -3_000 });
        let records = [
            record(1, SupervisorState::Running, force),
            record(2, SupervisorState::Running, reduction),
            record(3, SupervisorState::Running, net),
        ];
        let svg = telemetry_svg("odd", &records, Some(3.0));
        assert!(svg.contains("force target"));
        assert!(svg.contains("net-force target (cell sign, -F)"));
        assert!(svg.contains("1 records with a reduction target"));
    }
}
