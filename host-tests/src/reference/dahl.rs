//! Dahl friction under a superimposed vibration, solved exactly (seed 003 eqs 5-7, seed 000
//! eq 10; physics-notes §2).
//!
//! With f = F / F_c (F_c = mu W) and kappa = k_t / F_c, the Dahl law
//! dz/dt = v (1 - (k_t z / F_c) sgn v)^alpha is rate independent: along a stretch travelled in
//! one direction s, g = 1 - s f obeys dg/dxi = -kappa g^alpha, xi the distance travelled. Its
//! exact solution ([`relax`]) is g = g0 e^(-kappa xi) for alpha = 1 and
//! g = g0 (1 - (1 - alpha) kappa xi g0^(alpha - 1))^(1/(1 - alpha)) otherwise (clamped at
//! g = 0 for alpha < 1, as physics-notes §2 prescribes). The drive
//! v(theta) = v_s + v_a cos(theta), theta = omega t, is split at its turning points
//! (cos theta = -zeta) into monotone stretches; the distance travelled is a closed form, and
//! the time average of f on a stretch is a converged adaptive Gauss-Legendre integral.

use std::f64::consts::PI;

use super::RefError;
use super::numerics::{acos_stable, bisect, integrate, one_minus_cos, sin_minus_identity};

/// Vibration drive and Dahl parameters, in SI units.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Drive {
    /// Sliding velocity v_s in m/s.
    pub sliding_velocity: f64,
    /// Vibration velocity amplitude v_a in m/s (>= 0).
    pub vibration_velocity: f64,
    /// kappa / omega = k_t / (mu W 2 pi f) in s/m: converts omega * distance into kappa * distance.
    pub kappa_over_omega: f64,
    /// Dahl shape exponent alpha (> 0).
    pub alpha: f64,
}

/// Kinematic state at the start of a monotone stretch, theta_a.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StretchStart {
    /// v(theta_a) = v_s + v_a cos(theta_a) in m/s (exactly 0 at a turning point).
    pub velocity: f64,
    /// v_a cos(theta_a) in m/s.
    pub cos_part: f64,
    /// v_a sin(theta_a) in m/s.
    pub sin_part: f64,
}

impl StretchStart {
    /// omega times the distance travelled from theta_a to theta_a + h, in m/s (times rad):
    /// |v(theta_a) h + v_a cos(theta_a) (sin h - h) - v_a sin(theta_a) (1 - cos h)|, written
    /// without cancellation at small h.
    pub fn travel(&self, h: f64) -> f64 {
        (self.velocity * h + self.cos_part * sin_minus_identity(h)
            - self.sin_part * one_minus_cos(h))
        .abs()
    }
}

/// Exact Dahl relaxation of g = 1 - s f (in [0, 2]) after a normalised travel y = kappa xi >= 0.
pub(crate) fn relax(g0: f64, y: f64, alpha: f64) -> f64 {
    if g0 <= 0.0 {
        return 0.0;
    }
    let p = 1.0 - alpha;
    if p == 0.0 {
        return g0 * (-y).exp();
    }
    let argument = -p * y * g0.powf(-p);
    if argument <= -1.0 {
        return 0.0; // alpha < 1: g reached 0 in finite travel and stays there
    }
    g0 * (argument.ln_1p() / p).exp()
}

/// Result of one stretch: integral of f over the stretch (in rad) and f at its end.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StretchResult {
    /// Integral of f d(theta) over the stretch.
    pub integral: f64,
    /// f at the end of the stretch.
    pub end_value: f64,
}

/// Integrates f over a monotone stretch of `length` rad travelled in `direction` (+1 / -1),
/// starting from `f_start`. `total_travel` optionally gives the exact omega * distance of the
/// whole stretch (used for the turning-point to turning-point stretches).
pub(crate) fn stretch(
    drive: &Drive,
    start: StretchStart,
    direction: f64,
    f_start: f64,
    length: f64,
    total_travel: Option<f64>,
) -> Result<StretchResult, RefError> {
    let alpha = drive.alpha;
    let g0 = (1.0 - direction * f_start).clamp(0.0, 2.0);
    let y = |h: f64| drive.kappa_over_omega * start.travel(h);
    let y_end = drive.kappa_over_omega * total_travel.unwrap_or_else(|| start.travel(length));
    let end_value = direction * (1.0 - relax(g0, y_end, alpha));
    if g0 == 0.0 || length <= 0.0 {
        return Ok(StretchResult {
            integral: direction * length,
            end_value,
        });
    }
    // Where g vanishes (alpha < 1) or underflows (alpha = 1, y > 800), the integrand is 0.
    let y_zero = if alpha < 1.0 {
        g0.powf(1.0 - alpha) / (1.0 - alpha)
    } else if alpha == 1.0 {
        800.0
    } else {
        f64::INFINITY
    };
    let y_stop = y_end.min(y_zero);
    let upper = if y_end > y_zero {
        bisect(|h| y(h) - y_zero, 0.0, length)
    } else {
        length
    };
    // Graded mesh at y = 1, 4, 16, ...: resolves the boundary layer of width ~ (kappa x_a)^-1/2
    // after a turning point however stiff the contact is.
    let mut breaks = vec![0.0];
    let mut level = 1.0;
    while level < y_stop && breaks.len() < 64 {
        breaks.push(bisect(|h| y(h) - level, 0.0, upper));
        level *= 4.0;
    }
    breaks.push(upper);
    let mut integral_g = 0.0;
    for pair in breaks.windows(2) {
        integral_g += integrate(
            |h| relax(g0, y(h), alpha),
            pair[0],
            pair[1],
            1e-15 * (pair[1] - pair[0]).max(1e-300),
        )?;
    }
    Ok(StretchResult {
        integral: direction * (length - integral_g),
        end_value,
    })
}

/// Turning-point geometry of the drive for |zeta| < 1.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TurningPoints {
    /// theta_1 = acos(-zeta) in (0, pi): the forward stretch is (-theta_1, theta_1).
    pub theta_forward_half: f64,
    /// pi - theta_1 = acos(zeta): the backward stretch is (theta_1, 2 pi - theta_1).
    pub theta_backward_half: f64,
    /// sqrt(v_a^2 - v_s^2) = v_a sin(theta_1) in m/s.
    pub sin_part: f64,
    /// omega D_f = 2 v_a (sin theta_1 - theta_1 cos theta_1): forward travel per period.
    pub forward_travel: f64,
    /// omega D_b = 2 v_a (sin phi - phi cos phi), phi = pi - theta_1: backward travel per period.
    pub backward_travel: f64,
}

/// Turning points of v_s + v_a cos(theta), or `None` when the velocity never reverses
/// (|zeta| >= 1 or no vibration).
pub(crate) fn turning_points(drive: &Drive) -> Option<TurningPoints> {
    let (v, v_a) = (drive.sliding_velocity, drive.vibration_velocity);
    if v_a <= 0.0 || v.abs() >= v_a {
        return None;
    }
    let zeta = v / v_a;
    let theta_1 = acos_stable(-zeta);
    let phi = acos_stable(zeta);
    Some(TurningPoints {
        theta_forward_half: theta_1,
        theta_backward_half: phi,
        sin_part: ((v_a - v) * (v_a + v)).sqrt(),
        forward_travel: 2.0 * v_a * super::numerics::sin_minus_phi_cos(theta_1),
        backward_travel: 2.0 * v_a * super::numerics::sin_minus_phi_cos(phi),
    })
}

/// f at the start of the forward stretch in the periodic steady state (the one-dimensional
/// fixed point of physics-notes §2). For alpha = 1 in closed form, written with expm1 so that
/// the kappa x_a -> 0 limit (D_f - D_b) / (D_f + D_b) keeps its precision; otherwise by
/// bisection of P(f) - f, P being the monotone contraction "forward then backward".
pub(crate) fn steady_forward_start(drive: &Drive, turns: &TurningPoints) -> f64 {
    let y_f = drive.kappa_over_omega * turns.forward_travel;
    let y_b = drive.kappa_over_omega * turns.backward_travel;
    if drive.alpha == 1.0 {
        let one_minus_a = -(-y_f).exp_m1();
        let one_minus_b = -(-y_b).exp_m1();
        let one_minus_ab = -(-(y_f + y_b)).exp_m1();
        if one_minus_ab == 0.0 {
            // kappa x_a below 1e-308: the first-order limit is exact in f64.
            return (turns.forward_travel - turns.backward_travel)
                / (turns.forward_travel + turns.backward_travel);
        }
        return (((1.0 - one_minus_b) * one_minus_a - one_minus_b) / one_minus_ab).clamp(-1.0, 1.0);
    }
    let period_map = |f: f64| {
        let f_f = 1.0 - relax(1.0 - f, y_f, drive.alpha);
        relax(1.0 + f_f, y_b, drive.alpha) - 1.0
    };
    bisect(|f| period_map(f) - f, -1.0, 1.0)
}

/// Period average of f = F / (mu W) in the periodic steady state, in [-1, 1].
pub(crate) fn steady_average(drive: &Drive) -> Result<f64, RefError> {
    let Some(turns) = turning_points(drive) else {
        // No reversal: f relaxes to sgn(v) and stays there (physics-notes §2: ratio 1).
        return Ok(drive.sliding_velocity.signum());
    };
    let v = drive.sliding_velocity;
    let f_b = steady_forward_start(drive, &turns);
    let forward = stretch(
        drive,
        StretchStart {
            velocity: 0.0,
            cos_part: -v,
            sin_part: -turns.sin_part,
        },
        1.0,
        f_b,
        2.0 * turns.theta_forward_half,
        Some(turns.forward_travel),
    )?;
    let backward = stretch(
        drive,
        StretchStart {
            velocity: 0.0,
            cos_part: -v,
            sin_part: turns.sin_part,
        },
        -1.0,
        forward.end_value,
        2.0 * turns.theta_backward_half,
        Some(turns.backward_travel),
    )?;
    Ok(((forward.integral + backward.integral) / (2.0 * PI)).clamp(-1.0, 1.0))
}
