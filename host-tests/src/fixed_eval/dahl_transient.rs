//! `dahl_delta_transient` (seed 000 eqs 10-11) through the fixed-point Dahl update.
//!
//! With f = K_t delta / F_t0, eq 10 at constant v_rel is the Dahl law with alpha = 1, so the
//! firmware's exact update `model::dahl::update` gives delta(t) in one step:
//! f(t) = s + (f0 - s) e^(-K_t |v_rel| t / F_t0). K_t and delta are never formed in fixed point
//! (physics-notes §5): the dimensionless f0 and K_t |v_rel| t / F_t0 are formed here in f64 at
//! the tool level, the update runs in Q2.30 / Q8.24, and delta = f F_t0 / K_t is formed in f64.

use std::collections::BTreeMap;

use sonolube::fx::{Q2_30, Q8_24};
use sonolube::model::dahl::update;

use super::Outputs;
use super::keys::Keys;

/// Evaluates `dahl_delta_transient` in fixed point; outputs `delta` and `delta_ss` (m).
pub fn eval(
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Result<Outputs, String> {
    let mut keys = Keys::new("dahl_delta_transient", inputs, variant);
    let (force, stiffness, v_rel, time, delta0) = (
        keys.get("F_t0")?,
        keys.get("K_t")?,
        keys.get("v_rel")?,
        keys.get("t")?,
        keys.get("delta0")?,
    );
    keys.finish()?;
    if force <= 0.0 || stiffness <= 0.0 {
        return Err("dahl_delta_transient: F_t0 and K_t must be > 0".into());
    }
    if time < 0.0 {
        return Err("dahl_delta_transient: t must be >= 0".into());
    }
    let steady = force / stiffness;
    let f0 = Q2_30::from_f64(delta0 / steady)
        .map_err(|_| "dahl_delta_transient: |delta0| must be below 2 F_t0 / K_t".to_string())?;
    let f = if v_rel == 0.0 {
        f0
    } else {
        // e^-128 is below the Q2.30 resolution: the saturated exponent gives the exact limit.
        let travel = Q8_24::from_f64_saturating(stiffness / force * v_rel.abs() * time).value;
        update(f0, v_rel > 0.0, travel).map_err(|e| format!("dahl_delta_transient: {e}"))?
    };
    Ok(BTreeMap::from([
        ("delta", f.to_f64() * steady),
        ("delta_ss", steady),
    ]))
}
