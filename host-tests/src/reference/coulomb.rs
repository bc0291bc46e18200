//! Coulomb friction under a superimposed longitudinal vibration: the Littmann velocity-ratio
//! law (seed 001 eq 1; seed 003 eqs 1-4; physics-notes §1), the fixed-step sampled average that
//! seed 003's printed Coulomb columns come from, and the exponential (Stribeck-like) Coulomb
//! law of seed 002 eq 10.

use std::f64::consts::PI;

use super::RefError;
use super::error::{finite, non_negative, positive};
use super::numerics::acos_stable;

/// Velocity ratio zeta = v / v_a (seed 001 eq 1, seed 003 "xi").
///
/// Without vibration (`v_a = 0`) zeta has no value (v / 0): `None`, which the model outputs
/// report as undefined, never as a finite stand-in; the friction is then the full Coulomb level
/// (no velocity reversal). A ratio beyond the f64 range (v_a tiny, not zero) is also `None`.
/// No motion at all (`v = v_a = 0`) leaves the friction force undetermined (static friction):
/// [`RefError::ModelValidity`].
pub fn velocity_ratio(
    sliding_velocity: f64,
    vibration_velocity: f64,
) -> Result<Option<f64>, RefError> {
    if vibration_velocity > 0.0 {
        let zeta = sliding_velocity / vibration_velocity;
        Ok(zeta.is_finite().then_some(zeta))
    } else if sliding_velocity != 0.0 {
        Ok(None)
    } else {
        Err(RefError::ModelValidity(
            "no relative motion (v = 0 and no vibration): friction is static and undetermined"
                .into(),
        ))
    }
}

/// Direction used to normalise friction ratios: sgn(v); `None` at v = 0, where the friction
/// without vibration is zero and a ratio to it (or a percent reduction of it) is undefined.
pub fn reference_direction(sliding_velocity: f64) -> Option<f64> {
    if sliding_velocity < 0.0 {
        Some(-1.0)
    } else if sliding_velocity > 0.0 {
        Some(1.0)
    } else {
        None
    }
}

/// The mu_i of a velocity ratio from [`velocity_ratio`]: sgn(v) without a finite ratio.
pub fn littmann_of(zeta: Option<f64>, sliding_velocity: f64) -> f64 {
    zeta.map_or(1.0_f64.copysign(sliding_velocity), littmann_ratio)
}

/// Littmann friction ratio mu_i(zeta) = (2/pi) asin(zeta) for |zeta| <= 1, sgn(zeta) beyond
/// (seed 001 eq 1). It is exactly the period average of sgn(zeta + cos(theta))
/// (physics-notes §1). For |zeta| > 0.5 the half-angle form
/// asin(z) = pi/2 - 2 asin(sqrt((1 - z)/2)) keeps full precision near |zeta| = 1.
///
/// Input: any finite zeta (dimensionless). Output in [-1, 1].
pub fn littmann_ratio(zeta: f64) -> f64 {
    let magnitude = zeta.abs();
    let value = if magnitude >= 1.0 {
        1.0
    } else if magnitude <= 0.5 {
        2.0 / PI * magnitude.asin()
    } else {
        1.0 - 4.0 / PI * (0.5 * (1.0 - magnitude)).sqrt().asin()
    };
    value.copysign(zeta)
}

/// Typed entry point of model `littmann_mu_i`: [`littmann_ratio`] of a finite zeta
/// (dimensionless, any sign); NaN or infinite zeta is a [`RefError::NonFiniteInput`].
pub fn littmann_mu_i(zeta: f64) -> Result<f64, RefError> {
    Ok(littmann_ratio(finite("zeta", zeta)?))
}

/// 1 - mu_i(|zeta|) = (2/pi) acos(min(|zeta|, 1)), computed without cancellation (small
/// reductions near |zeta| = 1 keep their relative precision). Output in [0, 1].
pub fn littmann_reduction(zeta: f64) -> f64 {
    2.0 / PI * acos_stable(zeta.abs().min(1.0))
}

/// Inputs of [`coulomb_avg_friction`] (seed 003 eqs 2-4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoulombAvgInput {
    /// Kinetic friction coefficient mu (>= 0, dimensionless).
    pub friction_coefficient: f64,
    /// Normal load W = m g in N (>= 0).
    pub normal_load: f64,
    /// Sliding (macroscopic) velocity v in m/s (any sign).
    pub sliding_velocity: f64,
    /// Vibration displacement amplitude x_a in m (>= 0).
    pub vibration_amplitude: f64,
    /// Vibration frequency f in Hz (> 0).
    pub frequency: f64,
}

/// Outputs of [`coulomb_avg_friction`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoulombAvgOutput {
    /// Vibration velocity amplitude v_a = 2 pi f x_a in m/s.
    pub vibration_velocity: f64,
    /// Velocity ratio zeta = v / v_a; `None` without vibration (undefined: v / 0).
    pub velocity_ratio: Option<f64>,
    /// Friction without vibration mu W sgn(v) in N (0 at v = 0).
    pub friction_without_vibration: f64,
    /// Period-averaged friction mu W mu_i(zeta) in N.
    pub average_friction: f64,
    /// 100 (1 - F_avg / F_novib) = 100 (1 - mu_i(|zeta|)) in %, in [0, 100]; `None` when
    /// F_novib = 0 (v = 0, mu = 0 or W = 0): a reduction of zero friction is undefined.
    pub reduction_pct: Option<f64>,
}

/// Exact period average of Coulomb friction mu W sgn(v + v_a cos(2 pi f t)) (seed 003 eq 4,
/// closed form of physics-notes §1).
pub fn coulomb_avg_friction(input: &CoulombAvgInput) -> Result<CoulombAvgOutput, RefError> {
    let mu = non_negative("mu", input.friction_coefficient)?;
    let load = non_negative("W", input.normal_load)?;
    let v = finite("v", input.sliding_velocity)?;
    let x_a = non_negative("x_a", input.vibration_amplitude)?;
    let f = positive("f", input.frequency)?;
    let v_a = 2.0 * PI * f * x_a;
    let zeta = velocity_ratio(v, v_a)?;
    let level = mu * load;
    let natural = if v == 0.0 { 0.0 } else { level.copysign(v) };
    Ok(CoulombAvgOutput {
        vibration_velocity: v_a,
        velocity_ratio: zeta,
        friction_without_vibration: natural,
        average_friction: level * littmann_of(zeta, v),
        reduction_pct: (natural != 0.0).then(|| 100.0 * zeta.map_or(0.0, littmann_reduction)),
    })
}

/// Inputs of [`coulomb_sampled_avg_sign`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledSignInput {
    /// Sliding velocity v in m/s (any sign).
    pub sliding_velocity: f64,
    /// Vibration velocity amplitude v_a in m/s (>= 0).
    pub vibration_velocity: f64,
    /// Vibration frequency f in Hz (> 0).
    pub frequency: f64,
    /// Sampling step dt in s, 0 < dt <= 1 / (2 f) (two samples per period or more).
    pub time_step: f64,
    /// Averaging window Tw in s (> 0); N = round(Tw / dt) samples, 1 <= N <= 1e8.
    pub window: f64,
}

/// Outputs of [`coulomb_sampled_avg_sign`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledSignOutput {
    /// (1/N) sum_k sgn(v + v_a cos(2 pi f k dt)), k = 0..N-1, with sgn(0) = 0; in [-1, 1].
    pub mean_sign: f64,
    /// 100 (1 - sgn(v) mean_sign) in %; `None` at v = 0 (no friction without vibration).
    pub reduction_pct: Option<f64>,
}

/// Largest number of samples [`coulomb_sampled_avg_sign`] accepts.
pub const MAX_SAMPLES: f64 = 1e8;

/// Fixed-step sampled average of the Coulomb sign (physics-notes §1): the protocol whose
/// numbers seed 003 printed (0.1 us steps over a whole number of 40 kHz periods give 63.20 %
/// and 5.60 %, printed 63.21 % and 5.57 %). Samples at t_k = k dt (not accumulated), with the
/// phase reduced modulo one period before the cosine. It carries an O(1/N) error by design.
pub fn coulomb_sampled_avg_sign(input: &SampledSignInput) -> Result<SampledSignOutput, RefError> {
    let v = finite("v", input.sliding_velocity)?;
    let v_a = non_negative("v_a", input.vibration_velocity)?;
    let f = positive("f", input.frequency)?;
    let dt = positive("dt", input.time_step)?;
    let tw = positive("Tw", input.window)?;
    if f * dt > 0.5 {
        return Err(RefError::OutOfDomain {
            key: "dt",
            value: dt,
            rule: "fewer than 2 samples per vibration period (f dt > 1/2): the samples alias \
                   (at f dt = 1, 2, ... all fall at one phase); take dt <= 1 / (2 f)",
        });
    }
    let samples = (tw / dt).round();
    if !(1.0..=MAX_SAMPLES).contains(&samples) {
        return Err(RefError::OutOfDomain {
            key: "Tw",
            value: tw,
            rule: "Tw / dt must round to between 1 and 1e8 samples",
        });
    }
    let cycles_per_step = f * dt;
    let mut sum = 0i64;
    for k in 0..samples as u64 {
        let cycles = cycles_per_step * k as f64;
        let phase = 2.0 * PI * (cycles - cycles.floor());
        let total = v + v_a * phase.cos();
        sum += i64::from(total > 0.0) - i64::from(total < 0.0);
    }
    let mean_sign = sum as f64 / samples;
    Ok(SampledSignOutput {
        mean_sign,
        reduction_pct: reference_direction(v).map(|s| 100.0 * (1.0 - s * mean_sign)),
    })
}

/// Inputs of [`exp_coulomb_law`] (seed 002 eq 10, Table 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpCoulombInput {
    /// Static friction coefficient mu_s (>= 0).
    pub static_coefficient: f64,
    /// Dynamic friction coefficient mu_d (>= 0).
    pub dynamic_coefficient: f64,
    /// Exponential decay coefficient alpha_dc in s/m (>= 0).
    pub decay_coefficient: f64,
    /// Relative slip velocity V_s in m/s (any sign; only |V_s| enters).
    pub slip_velocity: f64,
    /// Normal force F_N in N (>= 0).
    pub normal_force: f64,
}

/// Exponential Coulomb law F_f = (mu_d + (mu_s - mu_d) exp(-alpha_dc |V_s|)) F_N in N
/// (seed 002 eq 10; the magnitude, the direction being -sgn(V_s)).
pub fn exp_coulomb_law(input: &ExpCoulombInput) -> Result<f64, RefError> {
    let mu_s = non_negative("mu_s", input.static_coefficient)?;
    let mu_d = non_negative("mu_d", input.dynamic_coefficient)?;
    let alpha = non_negative("alpha_dc", input.decay_coefficient)?;
    let slip = finite("Vs", input.slip_velocity)?;
    let normal = non_negative("F_N", input.normal_force)?;
    Ok((mu_d + (mu_s - mu_d) * (-alpha * slip.abs()).exp()) * normal)
}
