//! What `sonolube eval` says at the extremes, besides the numbers: which outputs are undefined
//! (and why), which outputs fall outside the physical range of their quantity, and which inputs
//! lie outside the 20-60 kHz drive band the models are built for.
//!
//! Both evaluators (fixed point and reference) leave an undefined output out of their map (see
//! [`crate::reference::eval_named`]); the reason is the same whichever side computed it, so it is
//! stated once here, per model and key. Range and band checks read each side's numbers and the
//! user's inputs; they flag, they never change a number.

use std::collections::BTreeMap;

use sonolube::drive::Frequency;

use super::{Inputs, Outputs};

/// Outputs that can be undefined: (model, key, why).
pub const UNDEFINED: &[(&str, &str, &str)] = &[
    (
        "coulomb_avg_friction",
        "zeta",
        "no vibration (x_a = 0, so v_a = 0): zeta = v / v_a has no value; the velocity never \
         reverses, so F_avg = F_novib (reduction 0 %)",
    ),
    (
        "coulomb_avg_friction",
        "reduction_pct",
        "F_novib = mu W sgn(v) = 0 (v = 0, mu = 0 or W = 0): a percent reduction of zero friction \
         is undefined",
    ),
    (
        "coulomb_sampled_avg_sign",
        "reduction_pct",
        "v = 0: no sliding, so no friction without vibration to reduce; the percent reduction is \
         undefined (mean_sign is still the sampled average)",
    ),
    (
        "dahl_steady",
        "zeta",
        "no vibration (v_a = 0): zeta = v / v_a has no value; the velocity never reverses, so the \
         friction stays at the Coulomb level (ratio 1)",
    ),
    (
        "dahl_steady",
        "ratio",
        "v = 0: F_novib = 0, and the ratio F_avg / (mu W sgn v) to zero friction is undefined \
         (F_avg itself is given)",
    ),
    (
        "dahl_steady",
        "reduction_pct",
        "v = 0: F_novib = 0, and a percent reduction of zero friction is undefined",
    ),
    (
        "dahl_window",
        "reduction_pct",
        "v = 0: no friction without vibration, so its percent reduction is undefined (F_avg is \
         given)",
    ),
];

/// Models whose input `f` is the drive frequency of the stack.
const DRIVE_MODELS: &[&str] = &[
    "coulomb_avg_friction",
    "coulomb_sampled_avg_sign",
    "dahl_steady",
    "dahl_window",
    "cube_reduction",
    "horn_kinematics",
    "actuator",
    "motor_force",
];

/// Why `key` of `model` is undefined, if it can be.
pub fn undefined_reason(model: &str, key: &str) -> Option<&'static str> {
    UNDEFINED
        .iter()
        .find(|(m, k, _)| *m == model && *k == key)
        .map(|&(_, _, why)| why)
}

/// The keys of `model` that are undefined on a side whose outputs are `outputs`.
pub fn undefined_keys(model: &str, outputs: &Outputs) -> Vec<&'static str> {
    UNDEFINED
        .iter()
        .filter(|(m, k, _)| *m == model && !outputs.contains_key(k))
        .map(|&(_, key, _)| key)
        .collect()
}

/// The drive band, Hz (the stack's, seed 003 Table 1; the drive refuses anything else).
pub fn drive_band_hz() -> (f64, f64) {
    (
        Frequency::BAND_MIN.millihertz() as f64 / 1e3,
        Frequency::BAND_MAX.millihertz() as f64 / 1e3,
    )
}

/// Flags, keyed by the input or output they concern: an input `f` outside the drive band, and
/// outputs outside their physical range on either side (`fixed`, `reference`).
pub fn flags(
    model: &str,
    inputs: &Inputs,
    fixed: &Outputs,
    reference: &Outputs,
) -> BTreeMap<&'static str, String> {
    let mut flags = BTreeMap::new();
    if DRIVE_MODELS.contains(&model)
        && let Some(&f) = inputs.get("f")
    {
        let (low, high) = drive_band_hz();
        if !(low..=high).contains(&f) {
            flags.insert(
                "f",
                format!(
                    "f = {} Hz is outside the {:.0}-{:.0} kHz drive band these models are built \
                     for (the PMN-PT stack, seed 003 Table 1; the firmware's drive refuses it): \
                     the numbers are the formula's, not the stack's",
                    short_number(f),
                    low / 1e3,
                    high / 1e3
                ),
            );
        }
    }
    for (key, why) in out_of_range(model, inputs, fixed, reference) {
        flags.insert(key, why);
    }
    flags
}

/// One side's value of `key` outside `[low, high]`; the sides that show it.
/// `x` as a person reads it in a flag: as Rust writes it when that takes at most 12
/// characters (`39999.5`, `0.25`), else in scientific form with at most 4 decimals of
/// mantissa (`1e-300`, `1.2346e7`): never hundreds of digits (issue 26: `f=1e-300` was spelled
/// out to more than 300 digits).
pub fn short_number(x: f64) -> String {
    let plain = format!("{x}");
    if plain.len() <= 12 {
        return plain;
    }
    let scientific = format!("{x:.4e}");
    match scientific.split_once('e') {
        Some((mantissa, exponent)) if mantissa.contains('.') => {
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{mantissa}e{exponent}")
        }
        _ => scientific,
    }
}

fn sides_outside(
    key: &str,
    low: f64,
    high: f64,
    fixed: &Outputs,
    reference: &Outputs,
) -> Option<(&'static str, f64)> {
    let out = |o: &Outputs| o.get(key).copied().filter(|x| !(low..=high).contains(x));
    match (out(fixed), out(reference)) {
        (Some(x), Some(_)) => Some(("both sides", x)),
        (Some(x), None) => Some(("the fixed point", x)),
        (None, Some(x)) => Some(("the reference", x)),
        (None, None) => None,
    }
}

fn out_of_range(
    model: &str,
    inputs: &Inputs,
    fixed: &Outputs,
    reference: &Outputs,
) -> Vec<(&'static str, String)> {
    let mut found = Vec::new();
    let percent = |found: &mut Vec<(&'static str, String)>, why: &str| {
        if let Some((sides, x)) = sides_outside("reduction_pct", 0.0, 100.0, fixed, reference) {
            found.push((
                "reduction_pct",
                format!(
                    "{sides}: reduction {} % is outside [0, 100] %: {why}",
                    short_number(x)
                ),
            ));
        }
    };
    match model {
        "coulomb_avg_friction" => percent(
            &mut found,
            "the period average of Coulomb friction cannot exceed it nor reverse it",
        ),
        "coulomb_sampled_avg_sign" => {
            let periods = inputs.get("Tw").zip(inputs.get("f")).map(|(t, f)| t * f);
            let why = match periods {
                Some(p) if p < 1.0 => format!(
                    "the window Tw covers {p:.3} of a vibration period, so the samples are not a \
                     period average; take Tw >= 1 / f"
                ),
                _ => "the samples do not represent a period average (window or step not \
                      commensurate with the period)"
                    .to_string(),
            };
            percent(&mut found, &why);
        }
        "dahl_steady" => {
            if let Some((sides, x)) = sides_outside("ratio", -1e-9, 1.0 + 1e-9, fixed, reference) {
                found.push((
                    "ratio",
                    format!(
                        "{sides}: ratio {} is outside [0, 1]: a Dahl steady state neither \
                         exceeds nor reverses the Coulomb level (physics-notes §2)",
                        short_number(x)
                    ),
                ));
            }
            percent(&mut found, "follows from the ratio");
        }
        "cube_reduction" => {
            let u = reference
                .get("u_over_delta")
                .or(fixed.get("u_over_delta"))
                .copied()
                .unwrap_or(0.0);
            if let Some((sides, x)) = sides_outside("ratio", 0.0, f64::INFINITY, fixed, reference) {
                found.push((
                    "ratio",
                    format!(
                        "{sides}: F'/F = {} < 0 (a reduction above 100 %): the average friction \
                         would push the slider forward, which friction cannot do. The u term \
                         dominates: u/delta = {u:.3e}, the longitudinal amplitude is {:.3e} times \
                         the static tangential deflection delta, so the contact would slip within \
                         each cycle, and the linear spring of seed 000 eq 15 (F' = K_t' (delta + \
                         u)) no longer holds. Away from the node the model is outside its \
                         validity (physics-notes §4)",
                        short_number(x),
                        u.abs()
                    ),
                ));
            } else if u.abs() > 1.0 {
                found.push((
                    "u_over_delta",
                    format!(
                        "|u/delta| = {:.3e} > 1: the longitudinal amplitude exceeds the static \
                         tangential deflection delta, so the contact would slip within each \
                         cycle and the linear spring of seed 000 eq 15 no longer holds; ratio and \
                         reduction_pct are outside the model's validity (physics-notes §4)",
                        u.abs()
                    ),
                ));
            }
        }
        _ => {}
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_flags_are_short() {
        assert_eq!(short_number(1e-300), "1e-300");
        assert_eq!(short_number(-2.2e-14), "-2.2e-14");
        assert_eq!(short_number(39_999.5), "39999.5");
        assert_eq!(short_number(1.0 / 3.0), "3.3333e-1");
        assert_eq!(short_number(1e300), "1e300");
    }

    #[test]
    fn every_undefinable_output_has_one_reason() {
        for (i, (model, key, why)) in UNDEFINED.iter().enumerate() {
            assert!(!why.is_empty());
            assert!(
                UNDEFINED[..i]
                    .iter()
                    .all(|(m, k, _)| (m, k) != (model, key)),
                "{model}.{key} twice"
            );
            assert_eq!(undefined_reason(model, key), Some(*why));
        }
        assert_eq!(undefined_reason("coulomb_avg_friction", "F_avg"), None);
    }

    #[test]
    fn drive_band_is_the_stack_band() {
        assert_eq!(drive_band_hz(), (20e3, 60e3));
        let inputs = Inputs::from([("f".to_string(), 19_999.0)]);
        let none = Outputs::new();
        assert!(flags("coulomb_avg_friction", &inputs, &none, &none).contains_key("f"));
        assert!(flags("littmann_mu_i", &inputs, &none, &none).is_empty());
        let inputs = Inputs::from([("f".to_string(), 60e3)]);
        assert!(flags("actuator", &inputs, &none, &none).is_empty());
    }
}
