//! Fixed-point models evaluated from SI inputs (host side): SI inputs -> scene constants (f64)
//! -> the firmware's fixed-point hot path -> outputs converted back to SI, under the same model
//! names and keys as [`crate::reference::eval_named`].
pub mod contact_cube;
pub mod coulomb_dahl;
pub mod dahl_transient;
pub mod extremes;
mod keys;
pub mod motor;

use std::collections::BTreeMap;

/// Output map: key -> value in SI units (percent for `*_pct`). An output that is undefined at
/// the given inputs is absent, exactly as in [`crate::reference::eval_named`].
pub type Outputs = BTreeMap<&'static str, f64>;

/// The outputs that are defined (`Some`), keyed.
pub(crate) fn defined<const N: usize>(pairs: [(&'static str, Option<f64>); N]) -> Outputs {
    pairs
        .into_iter()
        .filter_map(|(key, value)| value.map(|value| (key, value)))
        .collect()
}

/// Input map: key -> value in SI units.
pub type Inputs = BTreeMap<String, f64>;

/// Every model the fixed-point path evaluates (the same list as the reference's).
pub fn models() -> Vec<&'static str> {
    let mut all: Vec<&'static str> = coulomb_dahl::MODELS.to_vec();
    all.push("dahl_delta_transient");
    all.extend_from_slice(contact_cube::MODELS);
    all.extend_from_slice(motor::MODELS);
    all
}

/// Evaluates the fixed-point version of `model`; an error names an unknown model, a bad input
/// or variant, or a state outside the model's validity or fixed-point range.
pub fn eval_fixed_named(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Result<Outputs, String> {
    if model == "dahl_delta_transient" {
        return dahl_transient::eval(inputs, variant);
    }
    coulomb_dahl::eval_fixed_coulomb_dahl(model, inputs, variant)
        .or_else(|| contact_cube::eval_fixed_contact_cube(model, inputs, variant))
        .or_else(|| motor::eval_fixed_motor(model, inputs, variant))
        .unwrap_or_else(|| Err(format!("unknown model `{model}`")))
}
