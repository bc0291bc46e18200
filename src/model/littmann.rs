//! The Littmann velocity-ratio law (seed 001 eq 1; seed 003 eqs 1-4; physics-notes §1) in
//! fixed point: the velocity ratio zeta = v / v_a and mu_i(zeta). The Coulomb model built on it
//! (scene constants, averaged friction, [`super::coulomb::CoulombModel`]) is in
//! [`super::coulomb`].
//!
//! With v_total = v + v_a cos(omega t) (seed 003 eq 3) and F_T = mu W sgn(v_total) (eq 4), the
//! period average is exactly F_avg = mu W mu_i(zeta), zeta = v / v_a, v_a = x_a omega (eq 2):
//! mu_i(zeta) = (2/pi) asin(zeta) for |zeta| <= 1, sgn(zeta) beyond (physics-notes §1: the
//! argument is positive for a fraction acos(-zeta)/pi of the period). `fx`'s `asin` already
//! uses the half-angle form asin(z) = pi/2 - 2 asin(sqrt((1 - z)/2)) for |z| > 1/2, which keeps
//! full precision where the slope of mu_i blows up at |zeta| -> 1.
//!
//! Formats: the velocity ratio comes out of [`velocity_ratio`] as a [`VelocityRatio`] (zero,
//! finite with 30 significant bits, or infinite without vibration); mu_i is Q2.30 in [-1, 1]
//! with an exact 1.0. The sampled average of seed 003's printed numbers is in
//! [`super::coulomb_sampled`].

use crate::fx::{Q, Q2_30};

use super::ModelError;
use super::scaled::{Scaled, fx_error};
use super::wide;

/// zeta = v / v_a, as the hot path carries it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum VelocityRatio {
    /// v = 0 with vibration on: zeta = 0 (the friction averages to zero).
    Zero,
    /// zeta = +-magnitude, |zeta| > 0 finite (30 significant bits; 1e-300 to 1e300).
    Finite {
        /// True when v < 0.
        negative: bool,
        /// |v| / v_a.
        magnitude: Scaled,
    },
    /// No vibration (v_a = 0) and v != 0: zeta = +-infinity, no velocity reversal.
    Infinite {
        /// True when v < 0.
        negative: bool,
    },
}

impl VelocityRatio {
    /// True when v < 0.
    pub fn is_negative(&self) -> bool {
        matches!(
            self,
            Self::Finite { negative: true, .. } | Self::Infinite { negative: true }
        )
    }

    /// |zeta| in Q2.30 when the velocity reverses (|zeta| < 1; values within half an ulp of 1
    /// round to exactly 1.0), `None` when it never does (|zeta| >= 1, or no vibration).
    pub fn reversing_magnitude(&self) -> Option<Q2_30> {
        match *self {
            Self::Zero => Some(Q2_30::ZERO),
            Self::Finite { magnitude, .. } if !wide::at_least_one(magnitude) => {
                Some(wide::to_q::<30>(magnitude).value) // < 1: never saturates
            }
            _ => None,
        }
    }

    /// The Littmann ratio mu_i(zeta), Q2.30 in [-1, 1] (seed 001 eq 1). Cost: a compare, and
    /// for |zeta| < 1 one `asin` and one multiply (see [`mu_i`]).
    pub fn mu_i(&self) -> Result<Q2_30, ModelError> {
        let magnitude = match self.reversing_magnitude() {
            Some(z) => littmann_magnitude(z)?,
            None => Q2_30::ONE,
        };
        Ok(if self.is_negative() {
            Q2_30::from_bits(-magnitude.to_bits())
        } else {
            magnitude
        })
    }

    /// The ratio as f64 (tool level only): +-`f64::MAX` stands for +-infinity, like the
    /// reference model.
    pub fn to_f64(&self) -> f64 {
        match *self {
            Self::Zero => 0.0,
            Self::Finite {
                negative,
                magnitude,
            } => {
                let m = magnitude.to_f64().min(f64::MAX);
                if negative { -m } else { m }
            }
            Self::Infinite { negative } => {
                if negative {
                    -f64::MAX
                } else {
                    f64::MAX
                }
            }
        }
    }
}

/// zeta = v / v_a from the sliding velocity `v` (m/s in any format `Q<FV>`, any sign) and the
/// vibration velocity amplitude `v_a` (m/s, `None` = no vibration). Error `OutOfDomain` for
/// v = 0 without vibration: the friction is static and undetermined (seed 003 eq 4 needs
/// motion). Cost: two CLZ normalisations, a reciprocal and a product, no division.
pub fn velocity_ratio<const FV: u32>(
    v: Q<FV>,
    v_a: Option<Scaled>,
) -> Result<VelocityRatio, ModelError> {
    let negative = v.is_negative();
    let speed = wide::from_q(v.saturating_abs().value); // |MIN| clamps to MAX: 1 ulp
    Ok(match (speed, v_a) {
        (None, None) => {
            return Err(ModelError::OutOfDomain {
                input: "v",
                reason: "no relative motion (v = 0 and no vibration): static friction",
            });
        }
        (None, Some(_)) => VelocityRatio::Zero,
        (Some(_), None) => VelocityRatio::Infinite { negative },
        (Some(speed), Some(v_a)) => VelocityRatio::Finite {
            negative,
            magnitude: wide::mul(speed, wide::recip(v_a)),
        },
    })
}

/// (2/pi) asin(z) for z = |zeta| in [0, 1], Q2.30.
fn littmann_magnitude(z: Q2_30) -> Result<Q2_30, ModelError> {
    if z >= Q2_30::ONE {
        return Ok(Q2_30::ONE); // exact, rather than (pi/2)(2/pi) rounded
    }
    let angle = z.asin().map_err(fx_error("zeta"))?;
    angle
        .checked_mul(Q2_30::FRAC_2_PI)
        .map_err(fx_error("mu_i"))
}

/// The Littmann law mu_i(zeta) (seed 001 eq 1, physics-notes §1) for a velocity ratio `zeta`
/// given in any format `Q<F>` (dimensionless, any sign: Q2.30 for |zeta| < 2 keeps 9.3e-10
/// resolution; wider formats saturate harmlessly, since |zeta| >= 1 gives sgn(zeta)).
///
/// Output: Q2.30 in [-1, 1], exact +-1 for |zeta| >= 1, odd in zeta. Error <= 2 ulp of Q2.30
/// (1.6 ulp = 1.5e-9 measured: asin's error times 2/pi, the product's rounding and that of the
/// 2/pi constant); relative error <= 1e-6 for |mu_i| >= 2e-3 (below, the absolute bound rules:
/// 1e-4 relative down to |mu_i| = 2e-5). Never fails for valid
/// formats (the `Result` carries fx errors that cannot occur after the |zeta| < 1 test).
/// Cost, measured on the Cortex-M4 (module docs of [`super::coulomb`]): 61 instructions for
/// |zeta| <= 1/2, 107 for 1/2 < |zeta| < 1 (the half-angle branch of `fx`'s `asin` and its
/// square root), 14 for |zeta| >= 1, call included.
pub fn mu_i<const F: u32>(zeta: Q<F>) -> Result<Q2_30, ModelError> {
    let magnitude = zeta.saturating_abs().value;
    let unit = match Q::<F>::from_int(1) {
        Ok(one) => magnitude >= one,
        Err(_) => false, // Q1.31 holds no 1.0: every value is below it
    };
    let value = if unit {
        Q2_30::ONE
    } else {
        // |zeta| < 1 converts exactly (F <= 30) or rounds to at most 1.0 (F = 31).
        littmann_magnitude(magnitude.convert::<30>().map_err(fx_error("zeta"))?)?
    };
    Ok(if zeta.is_negative() {
        Q2_30::from_bits(-value.to_bits())
    } else {
        value
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q1_31, Q8_24, Q16_16};
    use core::f64::consts::FRAC_2_PI;

    const ULP: f64 = 1.0 / (1u64 << 30) as f64;

    fn exact(z: f64) -> f64 {
        if z.abs() >= 1.0 {
            z.signum()
        } else {
            FRAC_2_PI * z.asin()
        }
    }

    #[test]
    fn exact_points_and_saturation() {
        assert_eq!(mu_i(Q2_30::ZERO), Ok(Q2_30::ZERO));
        assert_eq!(mu_i(Q2_30::ONE), Ok(Q2_30::ONE));
        assert_eq!(mu_i(Q2_30::from_f64(-1.5).unwrap()).unwrap().to_f64(), -1.0);
        assert_eq!(mu_i(Q16_16::MIN).unwrap().to_f64(), -1.0);
        assert_eq!(mu_i(Q16_16::MAX), Ok(Q2_30::ONE));
        assert_eq!(mu_i(Q1_31::MIN).unwrap().to_f64(), -1.0);
        let third = mu_i(Q2_30::from_f64(0.5).unwrap()).unwrap().to_f64();
        assert!((third - 1.0 / 3.0).abs() <= 2.0 * ULP);
    }

    /// Dense sweep of Q2.30 over [-1, 1] (every 511th input) against f64: <= 2 ulp, and
    /// <= 1e-6 relative above 2e-3; odd symmetry exact.
    #[test]
    fn dense_sweep_against_f64() {
        let mut worst_ulps: f64 = 0.0;
        let mut worst_rel: f64 = 0.0;
        for bits in (0..=(1i32 << 30)).step_by(511) {
            let z = Q2_30::from_bits(bits);
            let got = mu_i(z).unwrap();
            let want = exact(z.to_f64());
            let err = (got.to_f64() - want).abs();
            worst_ulps = worst_ulps.max(err / ULP);
            if want >= 2e-3 {
                worst_rel = worst_rel.max(err / want);
            }
            assert_eq!(
                mu_i(Q2_30::from_bits(-bits)).unwrap().to_bits(),
                -got.to_bits()
            );
        }
        assert!(worst_ulps <= 2.0, "mu_i error {worst_ulps} ulps");
        assert!(worst_rel <= 1e-6, "mu_i relative error {worst_rel:e}");
        // Q8.24 inputs (the format of a ratio computed from Q8.24 velocities) agree.
        let z = Q8_24::from_f64(0.556_368_960_468_521).unwrap();
        assert!((mu_i(z).unwrap().to_f64() - exact(z.to_f64())).abs() <= 2.0 * ULP);
    }

    #[test]
    fn velocity_ratio_cases() {
        let v_a = wide::from_f64(0.0683, "v_a").unwrap();
        let v = Q8_24::from_f64(-0.038).unwrap();
        let r = velocity_ratio(v, Some(v_a)).unwrap();
        assert!(r.is_negative());
        assert!((r.to_f64() - v.to_f64() / 0.0683).abs() < 1e-9);
        let z = r.reversing_magnitude().unwrap();
        assert!((z.to_f64() + v.to_f64() / 0.0683).abs() < 2e-9);
        let mu = r.mu_i().unwrap().to_f64();
        assert!((mu - exact(v.to_f64() / 0.0683)).abs() < 2.0 * ULP);
        assert_eq!(
            velocity_ratio(Q8_24::ZERO, Some(v_a)),
            Ok(VelocityRatio::Zero)
        );
        let none = velocity_ratio(v, None).unwrap();
        assert_eq!(none, VelocityRatio::Infinite { negative: true });
        assert_eq!(none.mu_i().unwrap().to_f64(), -1.0);
        assert_eq!(none.to_f64(), -f64::MAX);
        assert!(velocity_ratio(Q8_24::ZERO, None).is_err());
        let fast = velocity_ratio(Q8_24::from_f64(0.1).unwrap(), Some(v_a)).unwrap();
        assert_eq!(fast.reversing_magnitude(), None);
        assert_eq!(fast.mu_i(), Ok(Q2_30::ONE));
        // |v| = v_a exactly: zeta = 1, no reversal.
        let same = velocity_ratio(
            Q8_24::from_f64(0.5).unwrap(),
            wide::from_f64(0.5, "v_a").ok(),
        );
        assert_eq!(same.unwrap().mu_i(), Ok(Q2_30::ONE));
    }
}
