//! The Dahl ODE integrated in time, in f64, with an adaptive step (physics-notes §2): the
//! reference for the plant's time-integrated contact (`sonolube_sim::plant::DahlState`).
//!
//! dz/dt = v (1 - (k_t z / F_c) sgn v)^alpha, F = k_t z, F_c = mu W, under the drive
//! v = v_s + v_a cos(theta), theta = theta_0 + omega t, with the inputs (W, v_s, x_a, omega) held
//! over each [`DahlOdeSegment`]. Written independently of the core's closed-form relaxation:
//! an explicit Dormand-Prince 5(4) pair with error control on z (and on the integral of F,
//! carried as a second component for the time average), the step cut at every turning point
//! (v = 0, where sgn v switches and the right-hand side has a kink) so that each piece is
//! smooth. For alpha != 1 the base is clamped at 0 (physics-notes §2: not Lipschitz at g = 0,
//! a negative base has no real power).
//!
//! Load changes: z (the elastic deflection) is continuous, so F = k_t z is; f = F / (mu W)
//! follows. For alpha != 1 a force above the new Coulomb level has no defined rate and is
//! clamped to it (the plant's convention, `sonolube_sim::plant::dahl_state`).

use std::f64::consts::{PI, TAU};

use super::RefError;
use super::error::{finite, non_negative, positive, within};

/// The contact: mu, k_t, alpha.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlOdeContact {
    /// Friction coefficient mu (> 0).
    pub friction_coefficient: f64,
    /// Tangential stiffness k_t, N/m (> 0).
    pub tangential_stiffness: f64,
    /// Shape exponent alpha in (0, 20].
    pub shape_exponent: f64,
}

/// Inputs held over one segment of time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlOdeSegment {
    /// Length of the segment, s (> 0).
    pub duration_s: f64,
    /// Normal load W, N (> 0).
    pub normal_load_n: f64,
    /// Sliding velocity v_s, m/s (any sign).
    pub sliding_velocity_m_per_s: f64,
    /// Vibration displacement amplitude x_a, m (>= 0).
    pub vibration_amplitude_m: f64,
    /// Vibration frequency, Hz (> 0).
    pub frequency_hz: f64,
}

/// The state carried from segment to segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlOdeState {
    /// Elastic deflection z, m (F = k_t z).
    pub deflection_m: f64,
    /// Vibration phase, rad (0 = the velocity crest).
    pub phase_rad: f64,
}

/// Result of one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlOdeAverage {
    /// Time average of F over the segment, N.
    pub mean_force_n: f64,
    /// F at the end of the segment, N.
    pub end_force_n: f64,
    /// Accepted steps.
    pub steps: u32,
}

/// Relative tolerance of the step control (on z in units of F_c / k_t, and on the integral of
/// F in units of F_c times the segment).
pub const TOLERANCE: f64 = 1e-10;

/// Largest number of steps per segment before the integration reports `NotConverged`.
const MAX_STEPS: u32 = 2_000_000;

// Dormand-Prince 5(4) tableau.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Fifth-order weights (the last row of A, FSAL) and the fourth-order ones.
const B5: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
const B4: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];

/// Integrates one segment from `state` (updated in place). Errors: inputs out of their domain,
/// `NotConverged` past the step budget.
pub fn integrate_segment(
    contact: &DahlOdeContact,
    state: &mut DahlOdeState,
    segment: &DahlOdeSegment,
) -> Result<DahlOdeAverage, RefError> {
    let mu = positive("mu", contact.friction_coefficient)?;
    let k_t = positive("k_t", contact.tangential_stiffness)?;
    let alpha = within(
        "alpha",
        contact.shape_exponent,
        f64::MIN_POSITIVE,
        20.0,
        "must be in (0, 20]",
    )?;
    let duration = positive("duration", segment.duration_s)?;
    let load = positive("W", segment.normal_load_n)?;
    let v_s = finite("v", segment.sliding_velocity_m_per_s)?;
    let x_a = non_negative("x_a", segment.vibration_amplitude_m)?;
    let omega = TAU * positive("f", segment.frequency_hz)?;
    finite("z", state.deflection_m)?;
    finite("theta", state.phase_rad)?;
    let level = mu * load;
    let v_a = omega * x_a;
    if alpha != 1.0 {
        let limit = level / k_t;
        state.deflection_m = state.deflection_m.clamp(-limit, limit);
    }
    let theta0 = state.phase_rad;
    let velocity = |t: f64| v_s + v_a * (theta0 + omega * t).cos();
    // dz/dt, and the force as the second component's rate.
    let rate = |t: f64, z: f64| -> [f64; 2] {
        let v = velocity(t);
        let s = if v > 0.0 {
            1.0
        } else if v < 0.0 {
            -1.0
        } else {
            0.0
        };
        let g = 1.0 - k_t * z / level * s;
        let shape = if alpha == 1.0 {
            g
        } else {
            g.max(0.0).powf(alpha)
        };
        [v * shape, k_t * z]
    };
    // Turning points within the segment: theta = +-theta_1 + 2 pi k, cos theta_1 = -zeta.
    let mut breaks: Vec<f64> = Vec::new();
    if v_a > v_s.abs() {
        let theta1 = (-v_s / v_a).acos();
        let end_theta = theta0 + omega * duration;
        for centre in [theta1, -theta1] {
            let mut k = ((theta0 - centre) / TAU).floor();
            loop {
                let theta = centre + TAU * k;
                if theta >= end_theta {
                    break;
                }
                if theta > theta0 {
                    breaks.push((theta - theta0) / omega);
                }
                k += 1.0;
            }
        }
    }
    breaks.push(duration);
    breaks.sort_by(f64::total_cmp);
    let z_scale = level / k_t;
    let q_scale = level * duration;
    let mut y = [state.deflection_m, 0.0];
    let mut t = 0.0;
    let mut h = (PI / omega / 64.0).min(duration);
    let mut steps = 0;
    for &stop in &breaks {
        while t < stop {
            let last = t + h >= stop;
            let step = if last { stop - t } else { h };
            // One Dormand-Prince step.
            let mut k = [[0.0f64; 2]; 7];
            for i in 0..7 {
                let mut yi = y;
                for (j, kj) in k.iter().enumerate().take(i) {
                    for c in 0..2 {
                        yi[c] += step * A[i][j] * kj[c];
                    }
                }
                k[i] = rate(t + C[i] * step, yi[0]);
            }
            let mut y5 = y;
            let mut err = [0.0f64; 2];
            for (i, ki) in k.iter().enumerate() {
                for c in 0..2 {
                    y5[c] += step * B5[i] * ki[c];
                    err[c] += step * (B5[i] - B4[i]) * ki[c];
                }
            }
            let e = (err[0] / z_scale).abs().max((err[1] / q_scale).abs()) / TOLERANCE;
            if !e.is_finite() {
                return Err(RefError::NotConverged("dahl_ode: non-finite step"));
            }
            if e <= 1.0 {
                y = y5;
                t = if last { stop } else { t + step };
                steps += 1;
                if steps > MAX_STEPS {
                    return Err(RefError::NotConverged("dahl_ode: step budget"));
                }
            }
            let grow = if e == 0.0 {
                5.0
            } else {
                (0.9 * e.powf(-0.2)).clamp(0.2, 5.0)
            };
            h = (step * grow).max(duration * 1e-14);
        }
    }
    state.deflection_m = y[0];
    state.phase_rad = (theta0 + omega * duration).rem_euclid(TAU);
    Ok(DahlOdeAverage {
        mean_force_n: y[1] / duration,
        end_force_n: k_t * y[0],
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without vibration the ODE has a closed form: f = 1 + (f0 - 1) e^(-kappa v t) forward.
    #[test]
    fn without_vibration_the_integration_is_the_closed_form() {
        let contact = DahlOdeContact {
            friction_coefficient: 0.24,
            tangential_stiffness: 4.48e4,
            shape_exponent: 1.0,
        };
        let level = 0.24 * 4.155;
        let mut state = DahlOdeState {
            deflection_m: -level / 4.48e4,
            phase_rad: 0.0,
        };
        let segment = DahlOdeSegment {
            duration_s: 1e-3,
            normal_load_n: 4.155,
            sliding_velocity_m_per_s: 0.038,
            vibration_amplitude_m: 0.0,
            frequency_hz: 40e3,
        };
        let out = integrate_segment(&contact, &mut state, &segment).unwrap();
        let y = 4.48e4 / level * 0.038 * 1e-3;
        let want_end = 1.0 - 2.0 * (-y).exp();
        let want_mean = 1.0 - 2.0 * (1.0 - (-y).exp()) / y;
        assert!((out.end_force_n / level - want_end).abs() < 1e-9);
        assert!((out.mean_force_n / level - want_mean).abs() < 1e-9);
    }

    /// Under vibration the integration settles on the periodic steady state of the reference's
    /// own steady-state model (turning-point fixed point and quadrature).
    #[test]
    fn the_integration_settles_on_the_steady_state() {
        for (k_t, alpha) in [(4.48e4, 1.0), (2e7, 1.0), (4.48e4, 0.5), (4.48e4, 2.0)] {
            let contact = DahlOdeContact {
                friction_coefficient: 0.24,
                tangential_stiffness: k_t,
                shape_exponent: alpha,
            };
            let mut state = DahlOdeState {
                deflection_m: 0.24 * 4.155 / k_t,
                phase_rad: 0.0,
            };
            let x_a = 0.3e-6;
            let segment = DahlOdeSegment {
                duration_s: 2.5e-5,
                normal_load_n: 4.155,
                sliding_velocity_m_per_s: 0.038,
                vibration_amplitude_m: x_a,
                frequency_hz: 40e3,
            };
            let mut mean = 0.0;
            for _ in 0..800 {
                mean = integrate_segment(&contact, &mut state, &segment)
                    .unwrap()
                    .mean_force_n;
            }
            let steady = super::super::dahl_models::dahl_steady(
                &super::super::dahl_models::DahlSteadyInput {
                    friction_coefficient: 0.24,
                    normal_load: 4.155,
                    tangential_stiffness: k_t,
                    sliding_velocity: 0.038,
                    vibration_velocity: TAU * 40e3 * x_a,
                    frequency: 40e3,
                    shape_exponent: alpha,
                },
            )
            .unwrap()
            .average_friction;
            assert!(
                (mean - steady).abs() < 1e-6 * 0.24 * 4.155,
                "k_t {k_t} alpha {alpha}: {mean} vs {steady}"
            );
        }
    }

    #[test]
    fn bad_inputs_are_refused() {
        let contact = DahlOdeContact {
            friction_coefficient: 0.24,
            tangential_stiffness: 4.48e4,
            shape_exponent: 1.0,
        };
        let mut state = DahlOdeState {
            deflection_m: 0.0,
            phase_rad: 0.0,
        };
        let good = DahlOdeSegment {
            duration_s: 2.5e-5,
            normal_load_n: 4.155,
            sliding_velocity_m_per_s: 0.038,
            vibration_amplitude_m: 1e-7,
            frequency_hz: 40e3,
        };
        for bad in [
            DahlOdeSegment {
                normal_load_n: 0.0,
                ..good
            },
            DahlOdeSegment {
                duration_s: f64::NAN,
                ..good
            },
            DahlOdeSegment {
                vibration_amplitude_m: -1.0,
                ..good
            },
        ] {
            assert!(integrate_segment(&contact, &mut state, &bad).is_err());
        }
        let soft = DahlOdeContact {
            shape_exponent: 0.0,
            ..contact
        };
        assert!(integrate_segment(&soft, &mut state, &good).is_err());
    }
}
