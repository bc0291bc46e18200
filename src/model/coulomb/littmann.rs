//! The Littmann velocity-ratio law (seed 001 eq 1; seed 003 eqs 1-4; physics-notes §1) in
//! fixed point: the velocity ratio zeta = v / v_a and mu_i(zeta). The Coulomb model built on it
//! (scene constants, averaged friction, [`super::coulomb::CoulombModel`]) is in
//! [`super::coulomb`].
//!
//! With v_total = v + v_a cos(omega t) (seed 003 eq 3) and F_T = mu W sgn(v_total) (eq 4), the
//! period average is exactly F_avg = mu W mu_i(zeta), zeta = v / v_a, v_a = x_a omega (eq 2):
//! mu_i(zeta) = (2/pi) asin(zeta) for |zeta| <= 1, sgn(zeta) beyond (physics-notes §1: the
//! argument is positive for a fraction acos(-zeta)/pi of the period). It is evaluated in one
//! pass by `fx`'s crate-internal `Q2_30::asin_frac_2_pi` (2/pi folded into the polynomial; the
//! half-angle form mu_i = 1 - (4/pi) asin(sqrt((1 - z)/2)) for |z| > 1/2, which keeps full
//! precision where the slope of mu_i blows up at |zeta| -> 1).
//!
//! Formats: the velocity ratio comes out of [`velocity_ratio`] as a [`VelocityRatio`] (zero,
//! finite with 30 significant bits, or infinite without vibration); mu_i is Q2.30 in [-1, 1]
//! with an exact 1.0. The sampled average of seed 003's printed numbers is in
//! [`super::coulomb_sampled`].

use crate::fx::{Q, Q2_30};

use super::ModelError;
use super::fx_error;
use crate::fx::Scaled;
use crate::fx::wide;

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

    /// The Littmann ratio mu_i(zeta), Q2.30 in [-1, 1] (seed 001 eq 1), with the error
    /// bounds of [`mu_i`]. Cost: a compare, and for |zeta| < 1 the closed form of [`mu_i`].
    pub fn mu_i(&self) -> Result<Q2_30, ModelError> {
        let magnitude = match self.reversing_magnitude() {
            Some(z) => z.asin_frac_2_pi().map_err(fx_error("zeta"))?,
            None => Q2_30::ONE,
        };
        Ok(if self.is_negative() {
            Q2_30::from_bits(-magnitude.to_bits())
        } else {
            magnitude
        })
    }

    /// The ratio as f64 (tool level only); `None` where zeta has no value: without vibration
    /// (v / 0), or beyond the f64 range. Never a finite stand-in such as `f64::MAX`.
    pub fn to_f64(&self) -> Option<f64> {
        match *self {
            Self::Zero => Some(0.0),
            Self::Finite {
                negative,
                magnitude,
            } => {
                let m = magnitude.to_f64();
                m.is_finite().then_some(if negative { -m } else { m })
            }
            Self::Infinite { .. } => None,
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

/// The Littmann law mu_i(zeta) (seed 001 eq 1, physics-notes §1) for a velocity ratio `zeta`
/// given in any format `Q<F>` (dimensionless, any sign: Q2.30 for |zeta| < 2 keeps 9.3e-10
/// resolution; wider formats saturate harmlessly, since |zeta| >= 1 gives sgn(zeta)).
///
/// Output: Q2.30 in [-1, 1], exact +-1 for |zeta| >= 1, exact 0 at 0, odd and nondecreasing
/// in zeta (checked over every Q2.30 input). Error <= 1 ulp of Q2.30 (9.3e-10; 0.62 ulp
/// measured for |zeta| <= 1/2, 0.88 above, over every Q2.30 input; 1.6 before: one rounding
/// of (2/pi) asin evaluated with the gain folded into its polynomial, see `fx::asin`); relative
/// error <= 1e-6 for |mu_i| >= 2e-3 (below, the absolute bound rules: 1e-4 relative down to
/// |mu_i| = 2e-5). Never fails for valid formats (the `Result` carries fx errors that cannot
/// occur after the |zeta| < 1 test).
///
/// Cost, measured in the QEMU bench build (`cargo build --release -p sonolube-qemu --target
/// thumbv7em-none-eabihf --features bench`, then `SONOLUBE_ICOUNT_SHIFT=0 scripts/qemu-run`
/// on the ELF), zeta over [-1, 1): 45 instructions per call with the bench harness that
/// subtracts its own loop (call and return included), 48 with the first harness (commit
/// e22f5ba: 10-25 more of `black_box` traffic; 124 there before this form). With that first
/// harness, per branch: about 40 for |zeta| <= 1/2, 60 for 1/2 < |zeta| < 1 (the square
/// root's three hardware divisions take 2-12 cycles each on the Cortex-M4) and 18 for
/// |zeta| >= 1.
///
/// ```
/// use sonolube::fx::Q2_30;
/// use sonolube::model::littmann::mu_i;
///
/// // (2/pi) asin(1/2) = 1/3; beyond |zeta| = 1 the velocity never reverses: 1.
/// let third = mu_i(Q2_30::from_ratio(1, 2)?)?;
/// assert!((third.to_f64() - 1.0 / 3.0).abs() < 2e-9);
/// assert_eq!(mu_i(Q2_30::from_ratio(3, 2)?)?, Q2_30::ONE);
/// assert_eq!(mu_i(Q2_30::from_ratio(-3, 2)?)?.to_f64(), -1.0);
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
pub fn mu_i<const F: u32>(zeta: Q<F>) -> Result<Q2_30, ModelError> {
    // |zeta| in units of 2^-F (2^31 for Q1.31's -1.0 included): |zeta| >= 1 <=> a >> F != 0.
    let a = zeta.to_bits().unsigned_abs();
    let value = if a >> F != 0 {
        Q2_30::ONE
    } else {
        // |zeta| < 1 (a < 2^31) converts exactly (F <= 30) or rounds to at most 1.0 (F = 31).
        Q::<F>::from_bits(a as i32)
            .convert::<30>()
            .and_then(Q2_30::asin_frac_2_pi)
            .map_err(fx_error("zeta"))?
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
        assert!((third - 1.0 / 3.0).abs() <= ULP);
    }

    /// Dense sweep of Q2.30 over [-1, 1] (every 511th input, and every input within 2^16 ulps
    /// of 0, 1/2 and 1) against f64: <= 1 ulp, and <= 1e-6 relative above 2e-3; odd symmetry
    /// exact, monotone.
    #[test]
    fn dense_sweep_against_f64() {
        let mut worst_ulps: f64 = 0.0;
        let mut worst_rel: f64 = 0.0;
        let near = |c: i32| (c - (1 << 16)..=c + (1 << 16)).filter(|b| (0..=1 << 30).contains(b));
        let mut previous = Q2_30::ZERO;
        for (k, bits) in (0..=(1i32 << 30))
            .step_by(511)
            .chain(near(0))
            .chain(near(1 << 29))
            .chain(near(1 << 30))
            .enumerate()
        {
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
            // monotone along the coarse sweep (its first 2^21 + 1 points)
            if k <= (1 << 30) / 511 {
                assert!(got >= previous, "not monotone at {z:?}");
                previous = got;
            }
        }
        eprintln!("mu_i: max error {worst_ulps} ulp, relative {worst_rel:e} above 2e-3");
        assert!(worst_ulps <= 1.0, "mu_i error {worst_ulps} ulps");
        assert!(worst_rel <= 1e-6, "mu_i relative error {worst_rel:e}");
        // Q8.24 and Q1.31 inputs (a ratio computed from Q8.24 velocities; the finest format,
        // rounded to Q2.30 first: half an input ulp times the slope, 0.37 ulp at 1/2; its
        // largest values round to 1.0) agree.
        let z = Q8_24::from_f64(0.556_368_960_468_521).unwrap();
        assert!((mu_i(z).unwrap().to_f64() - exact(z.to_f64())).abs() <= ULP);
        for bits in [1, 3, 1 << 30, (1 << 30) + 1] {
            let z = Q1_31::from_bits(bits);
            assert!((mu_i(z).unwrap().to_f64() - exact(z.to_f64())).abs() <= 1.5 * ULP);
        }
        assert_eq!(mu_i(Q1_31::MAX), Ok(Q2_30::ONE));
    }

    #[test]
    fn velocity_ratio_cases() {
        let v_a = crate::model::scaled_from_f64(0.0683, "v_a").unwrap();
        let v = Q8_24::from_f64(-0.038).unwrap();
        let r = velocity_ratio(v, Some(v_a)).unwrap();
        assert!(r.is_negative());
        assert!((r.to_f64().unwrap() - v.to_f64() / 0.0683).abs() < 1e-9);
        let z = r.reversing_magnitude().unwrap();
        assert!((z.to_f64() + v.to_f64() / 0.0683).abs() < 2e-9);
        let mu = r.mu_i().unwrap().to_f64();
        assert!((mu - exact(v.to_f64() / 0.0683)).abs() < ULP);
        assert_eq!(
            velocity_ratio(Q8_24::ZERO, Some(v_a)),
            Ok(VelocityRatio::Zero)
        );
        let none = velocity_ratio(v, None).unwrap();
        assert_eq!(none, VelocityRatio::Infinite { negative: true });
        assert_eq!(none.mu_i().unwrap().to_f64(), -1.0);
        assert_eq!(none.to_f64(), None);
        assert!(velocity_ratio(Q8_24::ZERO, None).is_err());
        let fast = velocity_ratio(Q8_24::from_f64(0.1).unwrap(), Some(v_a)).unwrap();
        assert_eq!(fast.reversing_magnitude(), None);
        assert_eq!(fast.mu_i(), Ok(Q2_30::ONE));
        // |v| = v_a exactly: zeta = 1, no reversal.
        let same = velocity_ratio(
            Q8_24::from_f64(0.5).unwrap(),
            crate::model::scaled_from_f64(0.5, "v_a").ok(),
        );
        assert_eq!(same.unwrap().mu_i(), Ok(Q2_30::ONE));
    }
}
