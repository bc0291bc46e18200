//! The CSV file of a run: one row per control step; friction forces are magnitudes.
//! One row per control step; friction forces are magnitudes.
//!
//! Columns and units: the `scene` module docs.

use sonolube::protocol::TargetRange;
use std::fmt::Write as _;

use sonolube::control::Reason;
use sonolube::protocol::Target;
use sonolube_sim::StepRecord;

/// The CSV text of a run: a header row, then one row per record (columns in the `scene`
/// module docs).
pub fn csv(records: &[StepRecord]) -> String {
    let mut text = String::from(
        "step,time_s,target,target_friction_n,estimated_friction_n,true_friction_n,quantity,\
         target_value,true_value,error_pct,drive_amplitude,vibration_amplitude,normal_load_n,\
         state,reason,at_limit,sensor_fault,injected_fault\n",
    );
    for r in records {
        let (quantity, target_value, true_value, error) = match r.judged {
            Some(j) => (
                j.quantity.name(),
                j.target,
                j.actual,
                100.0 * j.relative_error(),
            ),
            None => ("-", f32::NAN, f32::NAN, f32::NAN),
        };
        let fault = r
            .sensor_fault
            .map_or("-", |f| Reason::SensorFault(f).name());
        let _ = writeln!(
            text,
            "{},{:.6},{},{:.6},{:.6},{:.6},{quantity},{:.6},{:.6},{:.4},{:.6},{:.6},{:.4},{},{},{},{fault},{}",
            r.step,
            r.time_s,
            r.target.map_or(String::from("none"), |t| target_text(&t)),
            r.target_friction_n,
            r.estimated_friction_n,
            r.true_friction_n,
            target_value,
            true_value,
            error,
            r.drive_amplitude,
            r.vibration_amplitude,
            r.normal_load_n,
            r.state.name(),
            r.reason.name(),
            u8::from(r.at_limit),
            u8::from(r.injected_fault),
        );
    }
    text
}

/// `kind:value` with the protocol's decimals (`reduction:50.000`, `coef:0.380000`).
fn target_text(target: &Target) -> String {
    let decimals = u32::from(target.quantity().decimals);
    let scale = 10u64.pow(decimals);
    let value = target.scaled_value();
    // Only the net force is signed (`net-force:-5.000`).
    let sign = if value < 0 { "-" } else { "" };
    let magnitude = value.unsigned_abs();
    let fraction = magnitude % scale;
    format!(
        "{}:{sign}{}.{fraction:0width$}",
        target.kind(),
        magnitude / scale,
        width = decimals as usize
    )
}
