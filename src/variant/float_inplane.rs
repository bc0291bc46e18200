//! The in-plane models in float forms: the Littmann law, one exact Dahl update, the Coulomb
//! ratio and the Dahl periodic steady state (alpha = 1), generic over the float type and the
//! maths library ([`super::real`]).
//!
//! Same algorithms as the fixed point of [`crate::model`]: the Littmann closed form
//! (seed 001 eq 1), the exact update f' = s + (f - s) e^-y (physics-notes §2), and for the
//! steady state the closed-form fixed point of the period map and the gap integral over each
//! stretch with the fixed point's node rule (`dahl_quadrature`: n = N/2 nodes per stretch at
//! h_j = L m(j/n), m(x) = x^2 (1 + x) / 2, and the logarithmic mean over each interval, exact
//! for an exponential). Inputs and outputs are in the float type; constants are folded in
//! `f64` at scene load. Invalid inputs give the fixed point's errors, never a NaN.

use super::real::{Maths, Real, phi};
use crate::model::ModelError;

/// The Littmann law mu_i(zeta) = (2/pi) asin(zeta) for |zeta| < 1, sgn(zeta) beyond
/// (dimensionless in, [-1, 1] out).
pub fn littmann<T: Real, M: Maths<T>>(zeta: T) -> T {
    let magnitude = zeta.abs();
    let value = if magnitude >= T::ONE {
        T::ONE
    } else {
        T::FRAC_2_PI * M::asin(magnitude)
    };
    if zeta < T::ZERO { -value } else { value }
}

/// One exact Dahl update (alpha = 1): f' = s + (f - s) e^(-y), s = +1 for `forward` travel.
/// `f` = F / (mu W), `travel` = kappa |dx| >= 0 (dimensionless). Errors: `NonFinite` for a NaN
/// or infinite state, `OutOfDomain` for a negative or NaN travel.
pub fn dahl_update<T: Real, M: Maths<T>>(f: T, forward: bool, travel: T) -> Result<T, ModelError> {
    if !f.is_finite() {
        return Err(ModelError::NonFinite { input: "f" });
    }
    if !travel.is_non_negative() {
        return Err(ModelError::OutOfDomain {
            input: "kappa |dx|",
            reason: "travel must be >= 0",
        });
    }
    let s = if forward { T::ONE } else { -T::ONE };
    Ok(s + (f - s) * M::exp(-travel))
}

/// `NonFinite` for a NaN or infinite velocity or amplitude.
fn finite<T: Real>(v: T, amplitude: T) -> Result<(), ModelError> {
    if !v.is_finite() {
        return Err(ModelError::NonFinite { input: "v" });
    }
    if !amplitude.is_finite() {
        return Err(ModelError::NonFinite { input: "amplitude" });
    }
    Ok(())
}

/// zeta = |v| / (amplitude v_fs), or `None` when there is no vibration and the contact slides
/// (F'/F = 1). Errors: negative amplitude, v = 0 without vibration.
fn zeta<T: Real>(v: T, amplitude: T, full_scale_velocity: T) -> Result<Option<T>, ModelError> {
    if amplitude < T::ZERO {
        return Err(negative("amplitude"));
    }
    let speed = v.abs();
    if amplitude == T::ZERO {
        return if speed > T::ZERO {
            Ok(None)
        } else {
            Err(no_motion())
        };
    }
    Ok(Some(speed / (amplitude * full_scale_velocity)))
}

fn negative(input: &'static str) -> ModelError {
    ModelError::OutOfDomain {
        input,
        reason: "must be >= 0",
    }
}

fn no_motion() -> ModelError {
    ModelError::OutOfDomain {
        input: "v",
        reason: "no relative motion (v = 0 and no vibration): static friction",
    }
}

/// The Coulomb model's ratio F'/F = |mu_i(v / v_a)| with v_a = amplitude x full-scale
/// vibration velocity (seed 003 eqs 1-4), in a float form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloatCoulomb<T> {
    /// Full-scale vibration velocity 2 pi f x_a,max, m/s.
    full_scale_velocity: T,
}

impl<T: Real> FloatCoulomb<T> {
    /// The model for a drive at `frequency_hz` with full-scale amplitude `amplitude_m`
    /// (f64, scene load). Errors as [`crate::model::coulomb::CoulombConstants::new`].
    pub fn new(frequency_hz: f64, amplitude_m: f64) -> Result<Self, ModelError> {
        let velocity = core::f64::consts::TAU * frequency_hz * amplitude_m;
        if !velocity.is_finite() {
            return Err(ModelError::NonFinite { input: "v_a" });
        }
        if velocity <= 0.0 {
            return Err(ModelError::OutOfDomain {
                input: "v_a",
                reason: "f and x_a must be > 0",
            });
        }
        Ok(Self {
            full_scale_velocity: T::of(velocity),
        })
    }

    /// F'/F in [0, 1] at sliding velocity `v` (m/s, any sign) and `amplitude` (fraction of full
    /// scale, [0, 1]). Errors: a NaN or infinite input, negative amplitude, v = 0 without
    /// vibration.
    pub fn ratio<M: Maths<T>>(&self, v: T, amplitude: T) -> Result<T, ModelError> {
        finite(v, amplitude)?;
        let Some(zeta) = zeta(v, amplitude, self.full_scale_velocity)? else {
            return Ok(T::ONE); // sliding without vibration: natural friction
        };
        Ok(littmann::<T, M>(zeta))
    }
}

/// The Dahl steady state (alpha = 1) with N nodes per period, in a float form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloatDahl<T> {
    /// Full-scale vibration velocity 2 pi f x_a,max, m/s.
    full_scale_velocity: T,
    /// k_t x_a,max / mu in N: kappa x_a = this * amplitude / W.
    stiffness_amplitude_per_load: T,
    /// Nodes per stretch, N / 2.
    nodes: u32,
}

impl<T: Real> FloatDahl<T> {
    /// The model (f64, scene load): friction coefficient `mu` in (0, 128), stiffness `k_t`
    /// N/m > 0, drive `frequency_hz` > 0, full-scale amplitude `amplitude_m` > 0, `points` N
    /// per period (even, 4..=4096). Errors `NonFinite` / `OutOfDomain` like
    /// [`crate::model::dahl::DahlConstants::new`]; only alpha = 1 is implemented here.
    pub fn new(
        mu: f64,
        k_t: f64,
        frequency_hz: f64,
        amplitude_m: f64,
        points: u32,
    ) -> Result<Self, ModelError> {
        for (input, value) in [
            ("mu", mu),
            ("k_t", k_t),
            ("f", frequency_hz),
            ("x_a", amplitude_m),
        ] {
            if !value.is_finite() {
                return Err(ModelError::NonFinite { input });
            }
            if value <= 0.0 {
                return Err(ModelError::OutOfDomain {
                    input,
                    reason: "must be > 0",
                });
            }
        }
        if mu >= 128.0 {
            return Err(ModelError::OutOfDomain {
                input: "mu",
                reason: "friction coefficient must be in [0, 128)",
            });
        }
        if !points.is_multiple_of(2) || !(4..=4096).contains(&points) {
            return Err(ModelError::OutOfDomain {
                input: "quadrature_points",
                reason: "must be even, 4..=4096",
            });
        }
        Ok(Self {
            full_scale_velocity: T::of(core::f64::consts::TAU * frequency_hz * amplitude_m),
            stiffness_amplitude_per_load: T::of(k_t * amplitude_m / mu),
            nodes: points / 2,
        })
    }

    /// Steady-state F_avg / (mu W sgn v), [0, 1], at load `load_n` (N, > 0), sliding velocity
    /// `v` (m/s) and `amplitude` (fraction of full scale, [0, 1]). Errors: a NaN or infinite
    /// input, W <= 0, negative amplitude, v = 0 without vibration.
    pub fn ratio<M: Maths<T>>(&self, load_n: T, v: T, amplitude: T) -> Result<T, ModelError> {
        finite(v, amplitude)?;
        if !load_n.is_finite() {
            return Err(ModelError::NonFinite { input: "W" });
        }
        if !load_n.is_positive() {
            return Err(ModelError::OutOfDomain {
                input: "W",
                reason: "must be > 0 (F_c = mu W)",
            });
        }
        let Some(zeta) = zeta(v, amplitude, self.full_scale_velocity)? else {
            return Ok(T::ONE); // sliding without vibration: natural friction
        };
        if zeta >= T::ONE {
            return Ok(T::ONE); // no reversal: f relaxes to sgn v
        }
        if zeta == T::ZERO {
            return Ok(T::ZERO); // odd symmetry
        }
        let kxa = self.stiffness_amplitude_per_load * amplitude / load_n;
        Ok(self.steady::<M>(zeta, kxa))
    }

    /// The steady state at 0 < zeta < 1 and kappa x_a = `kxa` > 0.
    fn steady<M: Maths<T>>(&self, zeta: T, kxa: T) -> T {
        let angle = M::asin(zeta);
        let sigma = M::sqrt((T::ONE - zeta) * (T::ONE + zeta));
        let two = T::of(2.0);
        let forward = Stretch {
            zeta,
            sigma,
            backward: false,
            length: T::PI + two * angle,
        };
        let backward = Stretch {
            zeta,
            sigma,
            backward: true,
            length: T::PI - two * angle,
        };
        let d_f = forward.travel::<M>(forward.length);
        let d_b = backward.travel::<M>(backward.length);
        let (y_f, y_b) = (kxa * d_f, kxa * d_b);
        // Fixed point f_b of the period map (physics-notes §2, `dahl_cycle`): with a = e^-y_f,
        // b = e^-y_b, f_b = (2b - 1 - ab) / (1 - ab); in the phi form where y_f + y_b <= 1,
        // so that the kappa x_a -> 0 limit (D_f - D_b) / (D_f + D_b) keeps its precision.
        let total = y_f + y_b;
        let b = M::exp(-y_b);
        let f_b = if total > T::ONE {
            let ab = M::exp(-total);
            (two * b - T::ONE - ab) / (T::ONE - ab)
        } else {
            let (w_f, w_b) = (d_f / (d_f + d_b), d_b / (d_f + d_b));
            (b * w_f * phi::<T, M>(y_f) - w_b * phi::<T, M>(y_b)) / phi::<T, M>(total)
        };
        let (g_f, end_f) = self.integrate::<M>(&forward, kxa, T::ONE - f_b);
        let f_a = T::ONE - end_f;
        let (g_b, _) = self.integrate::<M>(&backward, kxa, T::ONE + f_a);
        let average = T::FRAC_2_PI * angle - (g_f - g_b) * T::FRAC_1_TAU;
        if average < T::ZERO {
            T::ZERO
        } else if average > T::ONE {
            T::ONE
        } else {
            average
        }
    }

    /// Integral of the gap g = g0 e^(-kxa T(h)) over the stretch, and g at its end.
    fn integrate<M: Maths<T>>(&self, stretch: &Stretch<T>, kxa: T, g0: T) -> (T, T) {
        let n = T::of(f64::from(self.nodes));
        let mut h = T::ZERO;
        let mut lambda = T::ZERO;
        let mut gap = g0;
        let mut integral = T::ZERO;
        for j in 1..=self.nodes {
            let x = T::of(f64::from(j)) / n;
            let next_h = stretch.length * x * x * (T::ONE + x) * T::of(0.5);
            let next_lambda = kxa * stretch.travel::<M>(next_h);
            // Logarithmic mean over the interval: (h1 - h0) g0 phi(lambda1 - lambda0).
            let step = next_lambda - lambda;
            let step = if step < T::ZERO { T::ZERO } else { step };
            integral = integral + (next_h - h) * gap * phi::<T, M>(step);
            h = next_h;
            lambda = next_lambda;
            gap = g0 * M::exp(-lambda);
            if lambda > T::of(60.0) {
                // g < 1e-26: the rest of the stretch adds nothing, and g ends at 0.
                return (integral, T::ZERO);
            }
        }
        (integral, gap)
    }
}

/// One stretch of drive phase travelled in one direction, from a turning point.
#[derive(Debug, Clone, Copy)]
struct Stretch<T> {
    zeta: T,
    sigma: T,
    backward: bool,
    length: T,
}

impl<T: Real> Stretch<T> {
    /// Travel in units of x_a after a phase `h` from the stretch start:
    /// sigma (1 - cos h) +- zeta (h - sin h), with 1 - cos h = 2 sin^2(h/2) and h - sin h by
    /// its series below h = 1/2 (both cancel in the direct form).
    fn travel<M: Maths<T>>(&self, h: T) -> T {
        let half = M::sin(h * T::of(0.5));
        let rise = T::of(2.0) * half * half;
        let excess = if h < T::of(0.5) {
            // h^3/6 - h^5/120 + h^7/5040 - h^9/362880, Horner in h^2.
            let h2 = h * h;
            let mut sum = T::of(-1.0 / 362_880.0);
            for c in [1.0 / 5040.0, -1.0 / 120.0, 1.0 / 6.0] {
                sum = T::of(c) + h2 * sum;
            }
            sum * h2 * h
        } else {
            h - M::sin(h)
        };
        let lateral = self.zeta * excess;
        let value = if self.backward {
            self.sigma * rise - lateral
        } else {
            self.sigma * rise + lateral
        };
        if value < T::ZERO { T::ZERO } else { value }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variant::real::{Libm, Micromath};
    use core::f64::consts::{FRAC_2_PI, PI};

    #[test]
    fn littmann_and_update_match_the_closed_forms() {
        for z in [-1.5, -1.0, -0.7, -0.2, 0.0, 0.3, 0.5, 0.999, 1.0, 3.0] {
            let want = if f64::abs(z) >= 1.0 {
                f64::signum(z)
            } else {
                FRAC_2_PI * f64::asin(z)
            };
            assert!((littmann::<f64, Libm>(z) - want).abs() < 1e-15, "{z}");
            assert!((f64::from(littmann::<f32, Libm>(z as f32)) - want).abs() < 3e-7);
            assert!((f64::from(littmann::<f32, Micromath>(z as f32)) - want).abs() < 1e-2);
        }
        let got = dahl_update::<f64, Libm>(-0.5, true, 0.3).unwrap();
        assert!((got - (1.0 - 1.5 * f64::exp(-0.3))).abs() < 1e-15);
        let got = dahl_update::<f64, Libm>(0.5, false, 2.0).unwrap();
        assert!((got - (-1.0 + 1.5 * f64::exp(-2.0))).abs() < 1e-15);
        assert!(dahl_update::<f32, Libm>(0.0, true, -1e-3).is_err());
        assert!(dahl_update::<f32, Libm>(0.0, true, f32::NAN).is_err());
        assert!(dahl_update::<f32, Libm>(f32::NAN, true, 0.1).is_err());
    }

    #[test]
    fn coulomb_ratio_limits_and_errors() {
        let m = FloatCoulomb::<f64>::new(40e3, 0.4756e-6).unwrap();
        let v_full = 2.0 * PI * 40e3 * 0.4756e-6;
        let r = m.ratio::<Libm>(-0.038, 0.5).unwrap();
        assert!((r - FRAC_2_PI * (0.038 / (0.5 * v_full)).asin()).abs() < 1e-14);
        assert_eq!(m.ratio::<Libm>(0.038, 0.0), Ok(1.0));
        assert_eq!(m.ratio::<Libm>(0.0, 0.5), Ok(0.0));
        assert!(m.ratio::<Libm>(0.0, 0.0).is_err());
        assert!(m.ratio::<Libm>(0.01, -0.1).is_err());
        assert!(m.ratio::<Libm>(f64::NAN, 0.5).is_err());
        assert!(m.ratio::<Libm>(0.01, f64::INFINITY).is_err());
        assert!(FloatCoulomb::<f32>::new(0.0, 1e-6).is_err());
        assert!(FloatCoulomb::<f32>::new(40e3, f64::NAN).is_err());
    }

    /// Dense independent integration of the same steady state (bisection on the period map,
    /// trapezoid with 2e5 points per stretch): the N-node rule converges to it, and the limits
    /// hold exactly.
    fn dense(zeta: f64, kxa: f64) -> f64 {
        let sigma = (1.0 - zeta * zeta).sqrt();
        let theta = PI / 2.0 + zeta.asin();
        let phi_len = PI - theta;
        let travel = |h: f64, s: f64| sigma * (1.0 - h.cos()) + s * zeta * (h - h.sin());
        let (d_f, d_b) = (travel(2.0 * theta, 1.0), travel(2.0 * phi_len, -1.0));
        let map = |f: f64| {
            let f_a = 1.0 - (1.0 - f) * (-kxa * d_f).exp();
            (1.0 + f_a) * (-kxa * d_b).exp() - 1.0
        };
        let (mut lo, mut hi) = (-1.0f64, 1.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if map(mid) > mid { lo = mid } else { hi = mid }
        }
        let f_b = 0.5 * (lo + hi);
        let f_a = 1.0 - (1.0 - f_b) * (-kxa * d_f).exp();
        let integral = |g0: f64, length: f64, s: f64| {
            let m = 200_000;
            let dh = length / m as f64;
            (0..=m)
                .map(|i| {
                    let w = if i == 0 || i == m { 0.5 } else { 1.0 };
                    w * g0 * (-kxa * travel(i as f64 * dh, s)).exp()
                })
                .sum::<f64>()
                * dh
        };
        let g_f = integral(1.0 - f_b, 2.0 * theta, 1.0);
        let g_b = integral(1.0 + f_a, 2.0 * phi_len, -1.0);
        FRAC_2_PI * zeta.asin() - (g_f - g_b) / (2.0 * PI)
    }

    #[test]
    fn dahl_steady_converges_to_a_dense_integration() {
        // omega = 1 rad/s, x_a,max = 1 m, mu = 1: kappa x_a = k_t a / W.
        let model = |points| FloatDahl::<f64>::new(1.0, 1.0, 0.5 / PI, 1.0, points).unwrap();
        let (m16, m64) = (model(16), model(64));
        for zeta in [0.1, 0.556, 0.95] {
            for kxa in [1e-3, 0.3, 3.0, 30.0, 1e4] {
                // v = zeta a v_full with a = 1/2, W = 1/(2 kxa) gives kappa x_a = kxa.
                let (a, w) = (0.5, 0.5 / kxa);
                let want = dense(zeta, kxa);
                let got64 = m64.ratio::<Libm>(w, zeta * a, a).unwrap();
                let got16 = m16.ratio::<Libm>(w, zeta * a, a).unwrap();
                assert!(
                    (got64 - want).abs() < 1e-3,
                    "{zeta} {kxa}: {got64} vs {want}"
                );
                // N = 16 (8 nodes per stretch) is within 6.5e-3; the rule converges as 1/N^2.
                assert!(
                    (got16 - want).abs() < 1e-2,
                    "{zeta} {kxa}: {got16} vs {want}"
                );
                let got32 = f64::from(
                    FloatDahl::<f32>::new(1.0, 1.0, 0.5 / PI, 1.0, 64)
                        .unwrap()
                        .ratio::<Libm>(w as f32, (zeta * a) as f32, a as f32)
                        .unwrap(),
                );
                assert!((got32 - got64).abs() < 1e-5, "{zeta} {kxa}: f32 {got32}");
            }
        }
        // Stiff limit: Coulomb; soft limit: (D_f - D_b) / (D_f + D_b); no reversal: 1.
        let zeta = 0.5f64;
        let stiff = m64.ratio::<Libm>(1e-12, zeta * 0.5, 0.5).unwrap();
        assert!((stiff - FRAC_2_PI * zeta.asin()).abs() < 1e-9);
        let sigma = (1.0 - zeta * zeta).sqrt();
        let (theta, phi) = (PI / 2.0 + zeta.asin(), PI / 2.0 - zeta.asin());
        let (d_f, d_b) = (sigma + zeta * theta, sigma - zeta * phi);
        let soft = m64.ratio::<Libm>(1e12, zeta * 0.5, 0.5).unwrap();
        assert!((soft - (d_f - d_b) / (d_f + d_b)).abs() < 1e-9, "{soft}");
        assert_eq!(m64.ratio::<Libm>(1.0, 0.6, 0.5), Ok(1.0));
        assert_eq!(m64.ratio::<Libm>(1.0, 0.0, 0.5), Ok(0.0));
        assert!(m64.ratio::<Libm>(0.0, 0.1, 0.5).is_err());
        assert!(m64.ratio::<Libm>(1.0, 0.0, 0.0).is_err());
        assert!(m64.ratio::<Libm>(1.0, f64::NAN, 0.5).is_err());
        assert!(m64.ratio::<Libm>(f64::INFINITY, 0.1, 0.5).is_err());
        assert!(m64.ratio::<Libm>(1.0, 0.1, f64::NAN).is_err());
        assert!(FloatDahl::<f32>::new(0.2, 1e4, 40e3, 1e-6, 63).is_err());
        assert!(FloatDahl::<f32>::new(0.0, 1e4, 40e3, 1e-6, 64).is_err());
    }
}
