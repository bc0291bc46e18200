//! Public Dahl models: periodic steady state, switch-on window (seed 003's printed Dahl
//! columns) and the constant-velocity transient of seed 000 eqs 10-11 (physics-notes §2).

use std::f64::consts::PI;

use super::RefError;
use super::coulomb::{reference_direction, velocity_ratio};
use super::dahl::{Drive, StretchStart, steady_average, stretch, turning_points};
use super::error::{finite, non_negative, positive, within};

/// Largest number of drive periods a [`dahl_window`] may span.
pub const MAX_WINDOW_PERIODS: f64 = 1e5;

/// Largest Dahl shape exponent alpha accepted.
pub const MAX_ALPHA: f64 = 20.0;

/// Inputs of [`dahl_steady`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlSteadyInput {
    /// Friction coefficient mu (> 0); F_c = mu W is the Coulomb level.
    pub friction_coefficient: f64,
    /// Normal load W in N (> 0).
    pub normal_load: f64,
    /// Tangential contact stiffness k_t in N/m (> 0; seed 003 uses 0.056 N/um = 5.6e4 N/m).
    pub tangential_stiffness: f64,
    /// Sliding velocity v in m/s (any sign).
    pub sliding_velocity: f64,
    /// Vibration velocity amplitude v_a in m/s (>= 0).
    pub vibration_velocity: f64,
    /// Vibration frequency f in Hz (> 0).
    pub frequency: f64,
    /// Dahl shape exponent alpha in (0, 20] (seed 003 uses 1).
    pub shape_exponent: f64,
}

/// Outputs of [`dahl_steady`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlSteadyOutput {
    /// zeta = v / v_a; `None` without vibration (undefined: v / 0).
    pub velocity_ratio: Option<f64>,
    /// Displacement amplitude x_a = v_a / (2 pi f) in m.
    pub vibration_amplitude: f64,
    /// kappa x_a = k_t x_a / (mu W), dimensionless: the model's stiffness parameter.
    pub stiffness_amplitude_product: f64,
    /// Friction without vibration mu W sgn(v) in N (0 at v = 0).
    pub friction_without_vibration: f64,
    /// Period-averaged friction in the periodic steady state, in N.
    pub average_friction: f64,
    /// F_avg / (mu W sgn v), dimensionless, in [-1, 1]; `None` at v = 0 (F_novib = 0).
    pub friction_ratio: Option<f64>,
    /// 100 (1 - ratio) in %; `None` at v = 0.
    pub reduction_pct: Option<f64>,
}

/// Validated common Dahl inputs: (Coulomb level mu W, drive).
fn dahl_drive(
    mu: f64,
    load: f64,
    stiffness: f64,
    v: f64,
    v_a: f64,
    frequency: f64,
    alpha: f64,
) -> Result<(f64, Drive), RefError> {
    let mu = positive("mu", mu)?;
    let load = positive("W", load)?;
    let stiffness = positive("k_t", stiffness)?;
    let v = finite("v", v)?;
    let v_a = non_negative("v_a", v_a)?;
    let frequency = positive("f", frequency)?;
    let alpha = within(
        "alpha",
        alpha,
        f64::MIN_POSITIVE,
        MAX_ALPHA,
        "must be in (0, 20]",
    )?;
    velocity_ratio(v, v_a)?; // rejects "no motion at all"
    let level = mu * load;
    let kappa_over_omega = stiffness / level / (2.0 * PI * frequency);
    if level <= 0.0 || !kappa_over_omega.is_finite() {
        return Err(RefError::ModelValidity(
            "k_t / (mu W 2 pi f) overflows: Coulomb level mu W too small for this stiffness".into(),
        ));
    }
    Ok((
        level,
        Drive {
            sliding_velocity: v,
            vibration_velocity: v_a,
            kappa_over_omega,
            alpha,
        },
    ))
}

/// Periodic steady state of the Dahl model under v + v_a cos(2 pi f t) (physics-notes §2: the
/// default reading; limits kappa x_a -> infinity: Coulomb/Littmann value, kappa x_a -> 0:
/// (D_f - D_b)/(D_f + D_b), |zeta| >= 1: ratio 1, zeta = 0: ratio 0).
pub fn dahl_steady(input: &DahlSteadyInput) -> Result<DahlSteadyOutput, RefError> {
    let (level, drive) = dahl_drive(
        input.friction_coefficient,
        input.normal_load,
        input.tangential_stiffness,
        input.sliding_velocity,
        input.vibration_velocity,
        input.frequency,
        input.shape_exponent,
    )?;
    let v = drive.sliding_velocity;
    let average = steady_average(&drive)?;
    let ratio = reference_direction(v).map(|s| average * s);
    Ok(DahlSteadyOutput {
        velocity_ratio: velocity_ratio(v, drive.vibration_velocity)?,
        vibration_amplitude: drive.vibration_velocity / (2.0 * PI * input.frequency),
        stiffness_amplitude_product: drive.kappa_over_omega * drive.vibration_velocity,
        friction_without_vibration: if v == 0.0 { 0.0 } else { level.copysign(v) },
        average_friction: level * average,
        friction_ratio: ratio,
        reduction_pct: ratio.map(|r| 100.0 * (1.0 - r)),
    })
}

/// Inputs of [`dahl_window`] (alpha = 1, as in seed 003).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlWindowInput {
    /// Friction coefficient mu (> 0).
    pub friction_coefficient: f64,
    /// Normal load W in N (> 0).
    pub normal_load: f64,
    /// Tangential contact stiffness k_t in N/m (> 0).
    pub tangential_stiffness: f64,
    /// Sliding velocity v in m/s (any sign).
    pub sliding_velocity: f64,
    /// Vibration velocity amplitude v_a in m/s (>= 0).
    pub vibration_velocity: f64,
    /// Vibration frequency f in Hz (> 0).
    pub frequency: f64,
    /// Averaging window Tw in s (> 0, at most 1e5 periods).
    pub window: f64,
    /// Initial F / (mu W) at t = 0, in [-1, 1] (seed 003 protocol: 1, steady sliding).
    pub initial_force_ratio: f64,
}

/// Outputs of [`dahl_window`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlWindowOutput {
    /// Time average of F over [0, Tw] in N.
    pub average_friction: f64,
    /// 100 (1 - F_avg / (mu W sgn v)) in %; `None` at v = 0 (no friction without vibration).
    pub reduction_pct: Option<f64>,
}

/// Dahl model with the vibration switched on at t = 0 from F = f0 mu W, averaged over
/// [0, Tw] (physics-notes §2: the protocol that reproduces seed 003's Dahl columns with
/// Tw = 1 ms and f0 = 1; a start-up transient, not the steady state).
pub fn dahl_window(input: &DahlWindowInput) -> Result<DahlWindowOutput, RefError> {
    let (level, drive) = dahl_drive(
        input.friction_coefficient,
        input.normal_load,
        input.tangential_stiffness,
        input.sliding_velocity,
        input.vibration_velocity,
        input.frequency,
        1.0,
    )?;
    let window = positive("Tw", input.window)?;
    let f0 = within(
        "f0",
        input.initial_force_ratio,
        -1.0,
        1.0,
        "must be in [-1, 1]",
    )?;
    let periods = window * input.frequency;
    if periods > MAX_WINDOW_PERIODS {
        return Err(RefError::OutOfDomain {
            key: "Tw",
            value: window,
            rule: "window must span at most 1e5 drive periods",
        });
    }
    let average = window_average(&drive, f0, 2.0 * PI * periods)?;
    Ok(DahlWindowOutput {
        average_friction: level * average,
        reduction_pct: reference_direction(drive.sliding_velocity)
            .map(|s| 100.0 * (1.0 - average * s)),
    })
}

/// Time average of f over theta in [0, theta_end], starting from f0 at theta = 0, stretch by
/// stretch: within each period the breakpoints are 0, theta_1 and 2 pi - theta_1.
fn window_average(drive: &Drive, f0: f64, theta_end: f64) -> Result<f64, RefError> {
    let (v, v_a) = (drive.sliding_velocity, drive.vibration_velocity);
    let period_start = StretchStart {
        velocity: v + v_a,
        cos_part: v_a,
        sin_part: 0.0,
    };
    // (offset within the period, start state, direction, exact travel of a full stretch)
    let pieces: Vec<(f64, StretchStart, f64, Option<f64>)> = match turning_points(drive) {
        None => vec![(0.0, period_start, v.signum(), None)],
        Some(turns) => {
            let theta_1 = turns.theta_forward_half;
            vec![
                (0.0, period_start, 1.0, None),
                (
                    theta_1,
                    StretchStart {
                        velocity: 0.0,
                        cos_part: -v,
                        sin_part: turns.sin_part,
                    },
                    -1.0,
                    Some(turns.backward_travel),
                ),
                (
                    2.0 * PI - theta_1,
                    StretchStart {
                        velocity: 0.0,
                        cos_part: -v,
                        sin_part: -turns.sin_part,
                    },
                    1.0,
                    None,
                ),
            ]
        }
    };
    let mut f = f0;
    let mut integral = 0.0;
    let mut period = 0.0_f64;
    'periods: loop {
        let base = 2.0 * PI * period;
        for (index, &(offset, start, direction, full_travel)) in pieces.iter().enumerate() {
            let begin = base + offset;
            if begin >= theta_end {
                break 'periods;
            }
            let next_offset = pieces.get(index + 1).map_or(2.0 * PI, |piece| piece.0);
            let end = base + next_offset;
            let (length, travel) = if end > theta_end {
                (theta_end - begin, None)
            } else {
                (next_offset - offset, full_travel)
            };
            let piece = stretch(drive, start, direction, f, length, travel)?;
            integral += piece.integral;
            f = piece.end_value;
        }
        period += 1.0;
    }
    Ok((integral / theta_end).clamp(-1.0, 1.0))
}

/// Inputs of [`dahl_delta_transient`] (seed 000 eqs 10-11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeltaTransientInput {
    /// Static friction F_t0 in N (> 0).
    pub static_friction: f64,
    /// Tangential contact stiffness K_t in N/m (> 0).
    pub tangential_stiffness: f64,
    /// Relative sliding velocity v_rel in m/s (any sign; seed 000 uses 5 mm/s).
    pub relative_velocity: f64,
    /// Time since the start t in s (>= 0).
    pub time: f64,
    /// Microscopic deformation delta at t = 0, in m.
    pub initial_deformation: f64,
}

/// Outputs of [`dahl_delta_transient`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeltaTransientOutput {
    /// delta(t) in m.
    pub deformation: f64,
    /// Steady deformation F_t0 / K_t in m (magnitude; the signed limit is sgn(v_rel) times it).
    pub steady_deformation: f64,
}

/// Exact solution of seed 000 eq 10 at constant v_rel:
/// delta(t) = s delta_ss + (delta0 - s delta_ss) exp(-K_t |v_rel| t / F_t0), delta_ss = F_t0/K_t.
pub fn dahl_delta_transient(input: &DeltaTransientInput) -> Result<DeltaTransientOutput, RefError> {
    let force = positive("F_t0", input.static_friction)?;
    let stiffness = positive("K_t", input.tangential_stiffness)?;
    let v_rel = finite("v_rel", input.relative_velocity)?;
    let time = non_negative("t", input.time)?;
    let delta0 = finite("delta0", input.initial_deformation)?;
    let steady = force / stiffness;
    if v_rel == 0.0 {
        return Ok(DeltaTransientOutput {
            deformation: delta0,
            steady_deformation: steady,
        });
    }
    let target = steady.copysign(v_rel);
    let decay = if time == 0.0 {
        1.0
    } else {
        (-(stiffness / force) * v_rel.abs() * time).exp()
    };
    Ok(DeltaTransientOutput {
        deformation: target + (delta0 - target) * decay,
        steady_deformation: steady,
    })
}
