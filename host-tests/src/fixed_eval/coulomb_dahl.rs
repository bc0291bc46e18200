//! The fixed-point Coulomb, Dahl, exponential-Coulomb and actuator models
//! (`sonolube::model::{littmann, coulomb, coulomb_sampled, dahl*, exp_coulomb, actuator}`)
//! evaluated from SI inputs, with exactly the model names and input, output and variant keys of
//! the reference (`reference::eval_named`), so that the two can be compared key by key.
//!
//! Path of every evaluation: SI f64 inputs -> scene constants (f64, once per scene, as the
//! firmware does at scene load) -> the fixed-point hot path -> SI outputs. The hot path's
//! inputs are quantised on the way in, and [`eval_with_quantized_inputs`] reports the values it
//! actually used (so that a comparison can separate representation from algorithm):
//! - velocities v, V_s in m/s: Q8.24 below 127 m/s, else Q16.16;
//! - loads W, F_N in N: the finest of Q1.31, Q8.24, Q16.16, Q24.8 holding the largest force of
//!   the model (mu W or mu_s F_N), 2^-24 relative or better;
//! - vibration amplitudes: x_a (or v_a) as a Q1.31 fraction in [1/2, 1) of a power-of-two full
//!   scale (2^-31 relative); friction coefficients and f0 in Q8.24 / Q2.30; zeta in Q2.30
//!   (Q16.16 beyond 2, saturated beyond 32768, where mu_i = sgn zeta either way);
//! - actuator voltages in V and frequencies in kHz, Q16.16.
//!
//! Differences from the reference: `quadrature_points` N selects the fixed-point rule (even,
//! 4..=4096, default 64) of `dahl_steady` and `dahl_window` where the reference ignores it
//! (it is validated and ignored by `coulomb_avg_friction`, a closed form); quantities outside
//! the fixed formats (|v| >= 32768 m/s, loads >= 8e6 N, x_a >= 128 um, I >= 128 A, V >= 32768 V)
//! are errors where the reference returns a number.

use std::collections::BTreeMap;

use super::defined;
use super::keys::Keys;
use sonolube::fx::scaled::Scaled;
use sonolube::fx::{Q, Q1_31, Q2_30, Q8_24, Q16_16};
use sonolube::model::ModelError;
use sonolube::model::actuator::{ActuatorConstants, ActuatorParams};
use sonolube::model::coulomb::CoulombConstants;
use sonolube::model::coulomb_sampled::SampledSign;
use sonolube::model::dahl::DahlParams;
use sonolube::model::dahl_steady::DahlModel;
use sonolube::model::dahl_window::DahlWindow;
use sonolube::model::exp_coulomb::ExpCoulombConstants;
use sonolube::model::littmann::mu_i;

pub use super::Outputs;

pub use super::Inputs;

/// Outputs, and the inputs as the fixed-point path represented them.
pub type QuantizedEvaluation = (Outputs, Inputs);

/// The models this module evaluates.
pub const MODELS: &[&str] = &[
    "littmann_mu_i",
    "coulomb_avg_friction",
    "coulomb_sampled_avg_sign",
    "dahl_steady",
    "dahl_window",
    "exp_coulomb_law",
    "actuator",
];

/// Default quadrature nodes per period of the Dahl models (within 5e-4 of the converged
/// steady state for alpha = 1; use 128 for alpha < 1).
pub const DEFAULT_QUADRATURE_POINTS: u32 = 64;

/// Evaluates the fixed-point version of `model` at `inputs` (SI) with `variant` choices.
/// `None` when `model` is not one of [`MODELS`]; otherwise the outputs (the reference's keys)
/// or an error message (unknown, missing or non-finite input, unknown variant, input outside
/// the domain or the fixed-point range).
pub fn eval_fixed_coulomb_dahl(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Option<Result<Outputs, String>> {
    eval_with_quantized_inputs(model, inputs, variant).map(|r| r.map(|(outputs, _)| outputs))
}

/// As [`eval_fixed_coulomb_dahl`], and the inputs as the fixed-point path represented them
/// (same keys, SI values after quantisation).
pub fn eval_with_quantized_inputs(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Option<Result<QuantizedEvaluation, String>> {
    let name = *MODELS.iter().find(|known| **known == model)?;
    let mut keys = Keys::new(name, inputs, variant);
    let result = match name {
        "littmann_mu_i" => littmann(&mut keys),
        "coulomb_avg_friction" => coulomb_average(&mut keys),
        "coulomb_sampled_avg_sign" => coulomb_sampled(&mut keys),
        "dahl_steady" => dahl_steady(&mut keys),
        "dahl_window" => dahl_window(&mut keys),
        "exp_coulomb_law" => exp_coulomb(&mut keys),
        _ => actuator(&mut keys),
    };
    Some(result.and_then(|outputs| keys.finish().map(|quantized| (outputs, quantized))))
}

impl Keys<'_> {
    fn err(&self) -> impl Fn(ModelError) -> String + '_ {
        move |e| format!("{}: {e}", self.model)
    }

    /// A velocity in m/s in the finest format that holds it. A velocity that is not zero but
    /// rounds to zero (below 2^-25 m/s, subnormal ones included) is an error: the fixed point
    /// would read it as "no sliding" while the reference uses its direction.
    fn speed(&mut self, key: &'static str) -> Result<Speed, String> {
        let v = self.get(key)?;
        let speed = if v.abs() < 127.0 {
            Speed::Fine(Q8_24::from_f64(v).map_err(|e| format!("{key}: {e}"))?)
        } else {
            Speed::Wide(Q16_16::from_f64(v).map_err(|e| format!("{key}: {e}"))?)
        };
        self.nonzero_kept(key, v, speed.to_f64(), "Q8.24, 6.0e-8 m/s")?;
        self.record(key, speed.to_f64());
        Ok(speed)
    }

    /// Error when a nonzero input `value` reached the fixed point as zero (`quantized`).
    fn nonzero_kept(
        &self,
        key: &str,
        value: f64,
        quantized: f64,
        resolution: &str,
    ) -> Result<(), String> {
        if value != 0.0 && quantized == 0.0 {
            return Err(format!(
                "{}: input {key} = {value:e} is not zero but below the fixed-point resolution \
                 ({resolution}): it would reach the fixed point as 0, while the reference uses it",
                self.model
            ));
        }
        Ok(())
    }

    /// A force in N in the finest format that holds `headroom` times it.
    fn load(&mut self, key: &'static str, headroom: f64) -> Result<Load, String> {
        let w = self.get(key)?;
        let top = w.abs() * headroom.max(1.0) * 1.001;
        let fail = |e| format!("{key}: {e}");
        let load = if top < 1.0 {
            Load::L31(Q1_31::from_f64(w).map_err(fail)?)
        } else if top < 127.0 {
            Load::L24(Q8_24::from_f64(w).map_err(fail)?)
        } else if top < 32767.0 {
            Load::L16(Q16_16::from_f64(w).map_err(fail)?)
        } else {
            Load::L8(Q::<8>::from_f64(w).map_err(fail)?)
        };
        self.nonzero_kept(key, w, load.to_f64(), "Q1.31, 4.7e-10 N")?;
        self.record(key, load.to_f64());
        Ok(load)
    }

    /// An amplitude >= 0 as a Q1.31 fraction of a power-of-two full scale (returned in SI).
    fn amplitude(&mut self, key: &'static str) -> Result<(f64, Q1_31), String> {
        let x = self.get(key)?;
        if x < 0.0 {
            return Err(format!("{}: input {key} must be >= 0", self.model));
        }
        if x == 0.0 {
            return Ok((1.0, Q1_31::ZERO));
        }
        let full = (x.log2().floor() + 1.0).exp2(); // x / full in [1/2, 1): exact
        let fraction = Q1_31::from_f64_saturating(x / full).value;
        self.record(key, fraction.to_f64() * full);
        Ok((full, fraction))
    }

    fn coefficient(&mut self, key: &'static str) -> Result<f64, String> {
        let mu = self.get(key)?;
        if let Ok(q) = Q8_24::from_f64(mu) {
            self.record(key, q.to_f64());
        }
        Ok(mu)
    }
}

/// A velocity in its fixed format.
#[derive(Clone, Copy)]
enum Speed {
    Fine(Q8_24),
    Wide(Q16_16),
}

/// A force in its fixed format.
#[derive(Clone, Copy)]
enum Load {
    L31(Q1_31),
    L24(Q8_24),
    L16(Q16_16),
    L8(Q<8>),
}

impl Speed {
    fn to_f64(self) -> f64 {
        match self {
            Self::Fine(v) => v.to_f64(),
            Self::Wide(v) => v.to_f64(),
        }
    }
}

impl Load {
    fn to_f64(self) -> f64 {
        match self {
            Self::L31(w) => w.to_f64(),
            Self::L24(w) => w.to_f64(),
            Self::L16(w) => w.to_f64(),
            Self::L8(w) => w.to_f64(),
        }
    }
}

/// Runs `$body` with `$w` and `$v` bound to the load and speed in their formats.
macro_rules! dispatch {
    ($load:expr, $speed:expr, |$w:ident, $v:ident| $body:expr) => {
        match ($load, $speed) {
            (Load::L31($w), Speed::Fine($v)) => $body,
            (Load::L31($w), Speed::Wide($v)) => $body,
            (Load::L24($w), Speed::Fine($v)) => $body,
            (Load::L24($w), Speed::Wide($v)) => $body,
            (Load::L16($w), Speed::Fine($v)) => $body,
            (Load::L16($w), Speed::Wide($v)) => $body,
            (Load::L8($w), Speed::Fine($v)) => $body,
            (Load::L8($w), Speed::Wide($v)) => $body,
        }
    };
}

fn value(x: Option<Scaled>) -> f64 {
    x.map_or(0.0, Scaled::to_f64)
}

fn littmann(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let zeta = keys.get("zeta")?;
    // Q2.30 wherever zeta rounds into it (|zeta| < 2 - 2^-31, the format the module states);
    // Q16.16 only beyond, where |zeta| >= 1 gives sgn either way and 2 is exact in Q16.16.
    // (A fixed cut at 1.999 sent 1.999 <= |zeta| < 2 through Q16.16, 4e-6 coarser than the
    // format the test's quantisation bound holds the conversion to: issue 24 item 7.)
    let result = match Q2_30::from_f64(zeta) {
        Ok(z) => {
            keys.record("zeta", z.to_f64());
            mu_i(z)
        }
        Err(_) => {
            let z = Q16_16::from_f64_saturating(zeta).value;
            keys.record("zeta", z.to_f64());
            mu_i(z)
        }
    };
    let mu = result.map_err(keys.err())?;
    Ok(Outputs::from([("mu_i", mu.to_f64())]))
}

fn coulomb_average(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    keys.quadrature_points(DEFAULT_QUADRATURE_POINTS)?; // a closed form: validated, not used
    let mu = keys.coefficient("mu")?;
    let frequency = keys.get("f")?;
    let (full_scale, amplitude) = keys.amplitude("x_a")?;
    let constants = CoulombConstants::new(mu, frequency, full_scale).map_err(keys.err())?;
    let (w, v) = (keys.load("W", mu)?, keys.speed("v")?);
    let a = dispatch!(w, v, |w, v| constants.average(w, v, amplitude).map(|a| {
        (
            a.vibration_velocity,
            a.velocity_ratio.to_f64(),
            a.friction_without_vibration.to_f64(),
            a.average_friction.to_f64(),
            a.reduction().to_f64(),
        )
    }))
    .map_err(keys.err())?;
    // A percent reduction of zero friction (v = 0, mu = 0 or W = 0) is undefined.
    let reduction = (a.2 != 0.0).then_some(100.0 * a.4);
    Ok(defined([
        ("v_a", Some(value(a.0))),
        ("zeta", a.1),
        ("F_novib", Some(a.2)),
        ("F_avg", Some(a.3)),
        ("reduction_pct", reduction),
    ]))
}

fn coulomb_sampled(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let (f, dt, tw) = (keys.get("f")?, keys.get("dt")?, keys.get("Tw")?);
    let protocol = SampledSign::new(f, dt, tw).map_err(keys.err())?;
    let v_a = keys.get("v_a")?;
    let vibration = if v_a == 0.0 {
        None
    } else {
        Some(sonolube::model::scaled_from_f64(v_a, "v_a").map_err(keys.err())?)
    };
    keys.record("v_a", value(vibration));
    let v = keys.speed("v")?;
    let mean = match v {
        Speed::Fine(v) => protocol.mean_sign(v, vibration),
        Speed::Wide(v) => protocol.mean_sign(v, vibration),
    }
    .map_err(keys.err())?
    .to_f64();
    // No sliding, no friction without vibration: its percent reduction is undefined.
    let direction = v.to_f64().signum();
    let reduction = (v.to_f64() != 0.0).then_some(100.0 * (1.0 - direction * mean));
    Ok(defined([
        ("mean_sign", Some(mean)),
        ("reduction_pct", reduction),
    ]))
}

/// Dahl scene parameters from the keys; returns them, the amplitude and the load.
fn dahl_scene(keys: &mut Keys<'_>, alpha: f64) -> Result<(DahlParams, Q1_31, Load, Speed), String> {
    let points = keys.quadrature_points(DEFAULT_QUADRATURE_POINTS)?;
    let mu = keys.coefficient("mu")?;
    let stiffness = keys.get("k_t")?;
    let frequency = keys.get("f")?;
    let (full_velocity, amplitude) = keys.amplitude("v_a")?;
    let params = DahlParams {
        friction_coefficient: mu,
        tangential_stiffness: stiffness,
        frequency_hz: frequency,
        full_scale_amplitude_m: full_velocity / (std::f64::consts::TAU * frequency),
        shape_exponent: alpha,
        quadrature_points: points,
    };
    Ok((params, amplitude, keys.load("W", mu)?, keys.speed("v")?))
}

fn dahl_steady(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let alpha = keys.get_or("alpha", 1.0)?;
    let (params, amplitude, w, v) = dahl_scene(keys, alpha)?;
    let model = DahlModel::new(&params).map_err(keys.err())?;
    let s = dispatch!(w, v, |w, v| model.steady(w, v, amplitude).map(|s| {
        (
            s.drive,
            s.ratio.to_f64(),
            s.friction_without_vibration.to_f64(),
            s.average_friction.to_f64(),
        )
    }))
    .map_err(keys.err())?;
    // F_avg / (mu W sgn v) and its percent reduction are undefined without sliding.
    let ratio = (v.to_f64() != 0.0).then_some(s.1);
    Ok(defined([
        ("zeta", s.0.velocity_ratio.to_f64()),
        ("x_a", Some(value(s.0.vibration_amplitude))),
        ("kxa", Some(value(s.0.stiffness_amplitude))),
        ("F_novib", Some(s.2)),
        ("F_avg", Some(s.3)),
        ("ratio", ratio),
        ("reduction_pct", ratio.map(|r| 100.0 * (1.0 - r))),
    ]))
}

fn dahl_window(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let (params, amplitude, w, v) = dahl_scene(keys, 1.0)?;
    let window = keys.get("Tw")?;
    let f0_si = keys.get("f0")?;
    if !(-1.0..=1.0).contains(&f0_si) {
        return Err(format!("{}: input f0 must be in [-1, 1]", keys.model));
    }
    let f0 = Q2_30::from_f64(f0_si).map_err(|e| format!("f0: {e}"))?;
    keys.record("f0", f0.to_f64());
    let protocol = DahlWindow::new(&params, window).map_err(keys.err())?;
    let out = dispatch!(w, v, |w, v| protocol
        .average(w, v, amplitude, f0)
        .map(|o| (o.average_friction.to_f64(), o.reduction().to_f64())))
    .map_err(keys.err())?;
    Ok(defined([
        ("F_avg", Some(out.0)),
        (
            "reduction_pct",
            (v.to_f64() != 0.0).then_some(100.0 * out.1),
        ),
    ]))
}

fn exp_coulomb(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let mu_s = keys.coefficient("mu_s")?;
    let mu_d = keys.coefficient("mu_d")?;
    let decay = keys.get("alpha_dc")?;
    if decay < 0.0 {
        return Err(format!("{}: input alpha_dc must be >= 0", keys.model));
    }
    let constants = ExpCoulombConstants::new(mu_s, mu_d, decay).map_err(keys.err())?;
    let (v, w) = (keys.speed("Vs")?, keys.load("F_N", mu_s.max(mu_d))?);
    let force =
        dispatch!(w, v, |w, v| constants.friction(v, w).map(|f| f.to_f64())).map_err(keys.err())?;
    Ok(Outputs::from([("F_f", force)]))
}

fn actuator(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let params = ActuatorParams {
        discs: keys.get("n")?,
        d33_m_per_v: keys.get("d33")?,
        capacitance_f: keys.get("C")?,
        stack_stiffness: keys.get("K_stack")?,
        bolt_stiffness: keys.get("K_bolt")?,
        max_voltage_v: keys.get("V_max")?,
        max_current_a: keys.get("I_max")?,
    };
    let constants = ActuatorConstants::new(&params).map_err(keys.err())?;
    let fixed = |key: &'static str, x: f64| {
        Q16_16::from_f64(x).map_err(|e| format!("actuator: {key} outside Q16.16: {e}"))
    };
    let voltage = fixed("V", keys.get("V")?)?;
    let frequency_hz = keys.get("f")?;
    let frequency = fixed("f", frequency_hz / 1e3)?;
    keys.record("V", voltage.to_f64());
    keys.record("f", frequency.to_f64() * 1e3);
    keys.record(
        "V_max",
        Q16_16::from_f64(params.max_voltage_v).map_or(0.0, Q::to_f64),
    );
    keys.record(
        "I_max",
        Q8_24::from_f64(params.max_current_a).map_or(0.0, Q::to_f64),
    );
    let err = keys.err();
    let stroke = constants.stroke_um(voltage).map_err(&err)?;
    Ok(Outputs::from([
        ("x_a", stroke.to_f64() * 1e-6),
        (
            "v_a",
            constants
                .vibration_velocity(stroke, frequency)
                .map_err(&err)?
                .to_f64(),
        ),
        (
            "I",
            constants
                .current(voltage, frequency)
                .map_err(&err)?
                .to_f64(),
        ),
        (
            "within_limits",
            if constants.within_limits(voltage, frequency).map_err(&err)? {
                1.0
            } else {
                0.0
            },
        ),
        (
            "V_limit",
            constants.voltage_limit(frequency).map_err(&err)?.to_f64(),
        ),
    ]))
}
