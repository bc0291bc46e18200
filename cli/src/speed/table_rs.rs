//! `src/variant/table.rs`: the measurements the firmware's selection reads, as Rust source.
//!
//! Costs of every catalogued variant, and the errors of the fixed-point model variants (the
//! only candidates) per scene and reference level, in `f32`. [`measurements`] builds the same
//! data in memory, so the choices reported in `docs/speed.md` are exactly the firmware's.

use std::fmt::Write as _;

use sonolube::variant::budget::StepCost;
use sonolube::variant::select::{Cost, Measurements, SceneError};
use sonolube::variant::{CATALOGUE, Form};

use super::errors::Errors;
use super::qemu::Counts;

/// The command that writes the file, for its header.
pub const COMMAND: &str = "scripts/speed-table";

fn costs(counts: &Counts) -> Vec<Cost> {
    CATALOGUE
        .iter()
        .filter_map(|v| {
            counts.get(v.name).map(|c| Cost {
                variant: v.name,
                instructions: c.instructions as f32,
            })
        })
        .collect()
}

/// The control step with each fixed-point model variant (`bench step NAME`).
fn steps(counts: &Counts) -> Vec<StepCost> {
    CATALOGUE
        .iter()
        .filter_map(|v| {
            let count = counts.get(&super::qemu::step_name(v.name))?;
            Some(StepCost {
                variant: v.name,
                mean: count.instructions as f32,
                longest: count.longest.unwrap_or(0).min(u64::from(u32::MAX)) as u32,
            })
        })
        .collect()
}

fn scene_errors(errors: &Errors) -> Vec<SceneError> {
    errors
        .scenes
        .iter()
        .filter(|e| e.variant.form == Form::Fixed)
        .map(|e| SceneError {
            scene: e.scene,
            variant: e.variant.name,
            reference: e.reference,
            max_error: round_up(e.stats.max) as f32,
            points: e.stats.points.min(u16::MAX as usize) as u16,
        })
        .collect()
}

/// The selection for `scene` as the host makes it when it loads the scene: the firmware's
/// ([`sonolube::variant::select`], from the committed table) for a scene whose measurement
/// inputs a built-in scene's errors were measured with ([`measured_twin`]),
/// and otherwise from the errors of the fixed-point candidates measured now against the
/// reference for this scene's contents ([`super::errors::scene_errors`], a few seconds at
/// most) with the committed instruction counts. Errors: the reference's (message).
pub fn select_on_host(
    scene: &sonolube::scene::Scene<'_>,
) -> Result<sonolube::variant::Selection, String> {
    use sonolube::variant::select::{measured_twin, select_from};
    if measured_twin(scene, &sonolube::variant::table::MEASURED).is_some() {
        return Ok(sonolube::variant::select(scene));
    }
    let errors: Vec<SceneError> = super::errors::scene_errors(scene, true)?
        .into_iter()
        .map(|(_, _, e)| SceneError {
            scene: e.scene,
            variant: e.variant.name,
            reference: e.reference,
            max_error: round_up(e.stats.max) as f32,
            points: e.stats.points.min(u16::MAX as usize) as u16,
        })
        .collect();
    let measured = Measurements {
        costs: sonolube::variant::table::MEASURED.costs,
        errors: Box::leak(errors.into_boxed_slice()),
        steps: sonolube::variant::table::MEASURED.steps,
    };
    Ok(select_from(scene, &measured))
}

/// The measurements of this run, as the selection sees them (leaked: a tool runs once).
pub fn measurements(errors: &Errors, counts: &Counts) -> Measurements {
    Measurements {
        costs: Box::leak(costs(counts).into_boxed_slice()),
        errors: Box::leak(scene_errors(errors).into_boxed_slice()),
        steps: Box::leak(steps(counts).into_boxed_slice()),
    }
}

/// `x` rounded up to three significant digits (x >= 0; 0, infinity and NaN unchanged).
pub fn round_up(x: f64) -> f64 {
    if !x.is_finite() || x <= 0.0 {
        return x;
    }
    // 10^k by exact multiplications (powi's precision may differ between builds).
    let k = 2 - x.log10().floor() as i32;
    let power = (0..k.unsigned_abs()).fold(1.0f64, |p, _| p * 10.0);
    let scale = if k >= 0 { power } else { 1.0 / power };
    // Nearest first (so that a value already of three digits stays itself), then one up if
    // that is below x: never report less than measured.
    let nearest = (x * scale).round();
    if nearest / scale < x {
        (nearest + 1.0) / scale
    } else {
        nearest / scale
    }
}

/// An `f32` as a Rust expression that reads back to the same value.
fn literal(x: f32) -> String {
    if x.is_nan() {
        "f32::NAN".into()
    } else if x == f32::INFINITY {
        "f32::INFINITY".into()
    } else {
        let text = format!("{x:?}");
        if text.contains(['.', 'e']) {
            text
        } else {
            format!("{text}.0")
        }
    }
}

/// The source of `src/variant/table.rs`.
pub fn render(errors: &Errors, counts: &Counts) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "//! Measured costs and errors of the model variants, for `super::select`.\n//!\n\
         //! Generated by `{COMMAND}` (`sonolube speed`) from the QEMU benchmark build's\n\
         //! instruction counts (`docs/speed-qemu.txt`) and the errors against the f64\n\
         //! reference; do not edit. Method and the full table: `docs/speed.md`.\n\
         \n\
         use super::Fidelity;\n\
         use super::budget::StepCost;\n\
         use super::select::{{Cost, Measurements, SceneError}};\n\
         \n\
         /// The measurements [`super::select`] chooses from.\n\
         pub static MEASURED: Measurements = Measurements {{\n    costs: COSTS,\n    errors: ERRORS,\n    steps: STEPS,\n}};\n\
         \n\
         /// Instructions per evaluation on the Cortex-M4 (QEMU, `-icount shift=0`).\n\
         static COSTS: &[Cost] = &["
    );
    for c in costs(counts) {
        let _ = writeln!(
            s,
            "    Cost {{\n        variant: {:?},\n        instructions: {},\n    }},",
            c.variant,
            literal(c.instructions)
        );
    }
    let _ = writeln!(
        s,
        "];\n\n/// Maximum error of the fixed-point variants per scene and reference level, rounded up to\n\
         /// three significant digits.\n\
         static ERRORS: &[SceneError] = &["
    );
    for e in scene_errors(errors) {
        let _ = writeln!(
            s,
            "    SceneError {{\n        scene: {:?},\n        variant: {:?},\n        reference: Fidelity::{:?},\n        max_error: {},\n        points: {},\n    }},",
            e.scene,
            e.variant,
            e.reference,
            literal(e.max_error),
            e.points
        );
    }
    s.push_str(
        "];\n\n/// Whole control steps with each fixed-point model variant (QEMU, `-icount shift=0`).\n\
         static STEPS: &[StepCost] = &[\n",
    );
    for c in steps(counts) {
        let _ = writeln!(
            s,
            "    StepCost {{\n        variant: {:?},\n        mean: {},\n        longest: {},\n    }},",
            c.variant,
            literal(c.mean),
            c.longest
        );
    }
    s.push_str("];\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_round_up_to_three_digits() {
        assert_eq!(round_up(1.234e-4), 1.24e-4);
        assert_eq!(round_up(1.23e-4), 1.23e-4);
        assert_eq!(round_up(9.991), 10.0);
        assert_eq!(round_up(0.0), 0.0);
        assert_eq!(round_up(f64::INFINITY), f64::INFINITY);
        for x in [3.3e-9, 0.016_283, 7.0e-3, 1.0] {
            assert!(round_up(x) >= x && round_up(x) <= x * 1.01, "{x}");
        }
    }

    #[test]
    fn literals_read_back_exactly() {
        for x in [0.0f32, 1.0, 1488.575, 3.2e-9, 1e-30, 123456.0, f32::MAX] {
            let text = literal(x);
            assert_eq!(text.parse::<f32>().unwrap(), x, "{text}");
        }
        assert_eq!(literal(f32::INFINITY), "f32::INFINITY");
        assert_eq!(literal(2.0), "2.0");
    }
}
