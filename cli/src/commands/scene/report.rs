//! The text a run prints: segment metrics, fault reactions, the criteria with their verdicts.

use std::fmt::Write as _;

use sonolube::protocol::SupervisorState;
use sonolube::scene::{Channel, Criterion, FaultKind, Scene};
use sonolube::station::Station;
use sonolube::variant::Selection;
use sonolube_sim::{
    DEFAULT_BAND, DEFAULT_STEADY_AFTER_S, Measured, Origin, RunSummary, StepRecord,
};

/// Where the segments' steady part starts, s after a change: the first `Settle` criterion's
/// time, else the judge's default (as `sonolube_sim::Judge` does).
pub(super) fn steady_after_s(scene: &Scene<'_>) -> f32 {
    scene
        .criteria
        .iter()
        .find_map(|c| match c {
            Criterion::Settle { within_s, .. } => Some(*within_s as f32),
            _ => None,
        })
        .unwrap_or(DEFAULT_STEADY_AFTER_S)
}

/// The band of the friction panel: the first `Settle` criterion's, else +-2 %.
pub(super) fn band_fraction(scene: &Scene<'_>) -> f64 {
    scene
        .criteria
        .iter()
        .find_map(|c| match c {
            Criterion::Settle { band_pct, .. } => Some(band_pct / 100.0),
            _ => None,
        })
        .unwrap_or(f64::from(DEFAULT_BAND))
}

pub(super) fn channel_name(channel: Channel) -> &'static str {
    match channel {
        Channel::Normal => "normal",
        Channel::Tangential => "tangential",
    }
}

pub(super) fn fault_text(kind: FaultKind) -> String {
    match kind {
        FaultKind::Disconnected { .. } => String::from("disconnected"),
        FaultKind::Stuck => String::from("stuck"),
        FaultKind::Spike { force_n } => format!("spike {} N", num(force_n)),
    }
}

/// The line naming the model the controller runs and why: the station's selection
/// ([`sonolube::variant::select`], as the firmware logs it at scene start), or the model it
/// was given.
pub fn model_line(station: &Station) -> String {
    match station.selection() {
        Some(selection) => format!("controller {selection}"),
        None => format!(
            "controller model {:?} (given, not selected)",
            station.model().kind()
        ),
    }
}

/// The model the controller runs, in a few words, for the `--all` lines: the selected
/// variant's name, or the scene's own model kind when nothing was measured or selected.
pub fn model_name(station: &Station) -> String {
    match station.selection() {
        Some(Selection {
            variant: Some(variant),
            ..
        }) => format!("model {}", variant.name),
        Some(_) => format!("own model {:?} (not measured)", station.model().kind()),
        None => format!("model {:?} (given)", station.model().kind()),
    }
}

pub(super) fn report(
    scene: &Scene<'_>,
    station: &Station,
    summary: &RunSummary,
    records: &[StepRecord],
) -> String {
    let mut text = String::new();
    let w = &mut text;
    let _ = writeln!(w, "scene {}: {}", scene.name, scene.description);
    let _ = writeln!(
        w,
        "  {} steps at {} Hz ({} s); scene's controller model {:?}, plant model {:?}",
        summary.steps,
        num(scene.control_rate_hz),
        num(scene.duration_s),
        scene.controller.kind,
        scene.plant.kind
    );
    let _ = writeln!(w, "  {}", model_line(station));
    let band = num(band_fraction(scene) * 100.0);
    let _ = writeln!(
        w,
        "  segments: settling into ±{band} %, overshoot in % of the step, RMS error from {} ms \
         after the change",
        num((f64::from(steady_after_s(scene)) * 1e6).round() / 1e3)
    );
    let _ = writeln!(
        w,
        "  {:<7} {:>9} {:>8} {:>10} {:>10} {:>10} {:>10} {:>9}",
        "segment",
        "from (s)",
        "quantity",
        "target",
        "settling",
        "overshoot",
        "RMS error",
        "at limit"
    );
    for segment in &summary.segments {
        let m = &segment.metrics;
        let origin = match segment.origin {
            Origin::Start => "start",
            Origin::Step => "step",
            Origin::Ramp => "ramp",
        };
        let overshoot = if segment.origin == Origin::Step && segment.same_quantity {
            format!("{:.2} %", m.overshoot_pct)
        } else if segment.origin == Origin::Step {
            // Measured in newtons of friction across the change of the target's kind.
            format!("{:.2} % (N)", m.overshoot_pct)
        } else {
            String::from("-")
        };
        let _ = writeln!(
            w,
            "  {origin:<7} {:>9.4} {:>8} {:>10.6} {:>10} {:>10} {:>10} {:>6.1} ms",
            m.start_s,
            segment.quantity.name(),
            m.target,
            m.settling_s
                .map_or(String::from("never"), |s| format!("{:.1} ms", s * 1e3)),
            overshoot,
            m.steady_rms_pct
                .map_or(String::from("-"), |p| format!("{p:.3} %")),
            m.at_limit_s * 1e3
        );
    }
    let _ = writeln!(
        w,
        "  time at the drive limit: {:.1} ms",
        summary.time_at_limit_s * 1e3
    );
    if summary.load_ramp.largest != Measured::Nothing {
        let _ = writeln!(
            w,
            "  while the normal load ramps: largest error {}, RMS {}",
            measured(summary.load_ramp.largest),
            measured(summary.load_ramp.rms)
        );
    }
    for (fault, reaction) in scene.faults.iter().zip(&summary.faults) {
        let reason = records
            .iter()
            .find(|r| r.step >= reaction.onset_step && r.state == SupervisorState::Fault)
            .map_or("none", |r| r.reason.name());
        let _ = writeln!(
            w,
            "  fault: {} {} at {} ms: {} (reason {reason})",
            channel_name(fault.channel),
            fault_text(fault.kind),
            num(fault.at_s * 1e3),
            reaction
                .periods
                .map_or(String::from("never in fault with zero drive"), |n| {
                    format!("fault with zero drive in {n} period(s)")
                })
        );
    }
    for v in &summary.verdicts {
        let _ = writeln!(
            w,
            "  {} {}: {}",
            pass(v.passed),
            criterion_text(&v.criterion),
            measured(v.measured)
        );
    }
    let _ = writeln!(w, "  verdict: {}", verdict(summary));
    text
}

pub(super) fn verdict(summary: &RunSummary) -> &'static str {
    pass(summary.passed())
}

pub(super) fn pass(ok: bool) -> &'static str {
    if ok { "PASS" } else { "FAIL" }
}

pub(super) fn criterion_text(criterion: &Criterion) -> String {
    match *criterion {
        Criterion::Settle { band_pct, within_s } => {
            format!(
                "settle to ±{} % within {} ms",
                num(band_pct),
                num(within_s * 1e3)
            )
        }
        Criterion::Overshoot { max_pct } => format!("overshoot <= {} %", num(max_pct)),
        Criterion::SteadyRmsError {
            max_pct,
            from_s,
            to_s,
        } => format!(
            "RMS error <= {} % over {}-{} s",
            num(max_pct),
            num(from_s),
            num(to_s)
        ),
        Criterion::TrackingError {
            max_pct,
            from_s,
            to_s,
        } => format!(
            "|error| <= {} % over {}-{} s",
            num(max_pct),
            num(from_s),
            num(to_s)
        ),
        Criterion::FaultReaction { within_periods } => {
            format!("fault with zero drive within {within_periods} period(s)")
        }
    }
}

/// A criterion's name, measured value and limit in a few words, for the `--all` lines:
/// `settle 1.4 ms (max 3 ms)`.
pub fn short(criterion: &Criterion, value: Measured) -> String {
    let (name, limit) = match *criterion {
        Criterion::Settle { within_s, .. } => ("settle", format!("{} ms", num(within_s * 1e3))),
        Criterion::Overshoot { max_pct } => ("overshoot", format!("{} %", num(max_pct))),
        Criterion::SteadyRmsError { max_pct, .. } => ("RMS error", format!("{} %", num(max_pct))),
        Criterion::TrackingError { max_pct, .. } => ("|error|", format!("{} %", num(max_pct))),
        Criterion::FaultReaction { within_periods } => {
            ("fault reaction", format!("{within_periods}"))
        }
    };
    format!("{name} {} (max {limit})", measured(value))
}

pub(super) fn measured(value: Measured) -> String {
    match value {
        Measured::Seconds(s) => format!("{:.1} ms", s * 1e3),
        Measured::Percent(p) => format!("{p:.3} %"),
        Measured::Periods(n) => format!("{n} period(s)"),
        Measured::Never => String::from("never"),
        Measured::Undefined => String::from("undefined (no load or no natural friction)"),
        Measured::Nothing => String::from("nothing to measure"),
    }
}

/// `x` with up to six decimals, trailing zeros dropped (`3`, `0.025`, `-100`).
pub(super) fn num(x: f64) -> String {
    let text = format!("{x:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        String::from("0")
    } else {
        text.to_string()
    }
}
