//! The fixed-point motor-effect model (`sonolube::model::motor`) evaluated from SI inputs, with
//! the reference's model name and keys (`reference::motor`), so that the two compare key by key.
//!
//! Path: SI inputs -> `MotorScene::new` (f64, once, as at scene load) -> the fixed-point hot path
//! at full drive amplitude (Q1.31 `MAX`, 1 - 2^-31 of the A and B given) -> SI outputs. Inputs
//! are quantised on the way in: F_n to Q16.16 N (below 32768 N), v_b to Q8.24 m/s (below
//! 128 m/s), x to 2L / 2^32 (`HornShape::new`). Differences from the reference: B is limited to
//! lambda B / R_q <= 8 (`motor::MAX_DECAY`) and |F_t| to 32768 N (errors, never saturation).

use std::collections::BTreeMap;

use super::Outputs;
use super::keys::Keys;
use sonolube::fx::{Q1_31, Q8_24, Q16_16};
use sonolube::model::horn::{HornShape, UPhase};
use sonolube::model::motor::{MotorParams, MotorPoint, MotorScene};

/// The models this module evaluates.
pub const MODELS: &[&str] = &["motor_force"];

/// Evaluates `motor_force` in fixed point; `None` for any other model name.
pub fn eval_fixed_motor(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Option<Result<Outputs, String>> {
    let name = *MODELS.iter().find(|known| **known == model)?;
    let mut keys = Keys::new(name, inputs, variant);
    let result = motor(&mut keys);
    Some(result.and_then(|outputs| keys.finish().map(|_| outputs)))
}

fn motor(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let u_phase = keys.choose(
        "u_phase",
        &[
            ("quadrature", UPhase::Quadrature),
            ("inphase", UPhase::InPhase),
        ],
    )?;
    let err = |e: sonolube::model::ModelError| format!("motor_force: {e}");
    let params = MotorParams {
        friction_coefficient: keys.get("mu")?,
        longitudinal_amplitude: keys.get("A")?,
        vertical_amplitude: keys.get("B")?,
        horn_length: keys.get("L")?,
        frequency: keys.get("f")?,
        roughness_rq: keys.get("Rq")?,
        distribution_lambda: keys.get("lam")?,
    };
    let scene = MotorScene::new(&params, u_phase).map_err(err)?;
    let shape = HornShape::new(keys.get("x")?, params.horn_length).map_err(err)?;
    let load = keys.get("F_n")?;
    let normal_force = Q16_16::from_f64(load).map_err(|_| {
        format!("motor_force: F_n = {load} N does not fit Q16.16 (|F_n| < 32768 N)")
    })?;
    let velocity = keys.get("v_b")?;
    let block_velocity = Q8_24::from_f64(velocity)
        .map_err(|_| format!("motor_force: v_b = {velocity} m/s does not fit Q8.24 (< 128 m/s)"))?;
    let point = MotorPoint {
        shape,
        normal_force,
        block_velocity,
    };
    let out = scene.force(&point, Q1_31::MAX).map_err(err)?;
    let (decay, face_speed) = scene.groups(&shape, Q1_31::MAX);
    keys.record("F_n", normal_force.to_f64());
    keys.record("v_b", block_velocity.to_f64());
    Ok(Outputs::from([
        ("F_t", out.force.to_f64()),
        ("phi", out.drive_ratio.to_f64()),
        ("kappa", decay.to_f64()),
        ("v_face", face_speed.to_f64()),
    ]))
}
