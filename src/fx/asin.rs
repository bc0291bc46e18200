//! Arcsine for the Littmann velocity-ratio law `mu_i = (2/pi) asin(zeta)` (physics-notes §1).
//!
//! Method: one odd polynomial serves both halves. With `P(t)` a degree-6 weighted minimax fit of
//! `(asin(sqrt t) - sqrt t) / t^1.5` on `t` in [0, 1/4]:
//! - `|z| <= 1/2`: `asin z = z + z t P(t)` with `t = z^2`. The correction `z t P` is below
//!   half an ulp for |z| < 1.4e-3, so small arguments come back exactly (`asin z = z` to
//!   rounding): the relative error stays below 1e-6 all the way down to one ulp.
//! - `|z| > 1/2`: `asin z = pi/2 - 2 asin w` with `w = sqrt t`, `t = (1 - |z|)/2` (exact in
//!   fixed point), which keeps full precision where the slope of asin blows up at |z| -> 1.
//!
//! The coefficients came from a Remez exchange (weight `2 t^1.5`, the absolute-error weight of
//! both branches) run offline in double precision (max weighted error 1.0e-11, degree 6) and
//! rounded to Q.33; the dense sweeps below vouch for them.

use super::error::FxError;
use super::q::Q2_30;
use super::raw::{mul_hi, mul_hi_round};
use super::sqrt::sqrt_q32_approx;

/// Q.33 coefficients of `P(t)`, lowest degree first (about 1/6, 3/40, 5/112, 35/1152, ...).
const P_COEFFS: [i32; 7] = [
    1431655863, 644237365, 383700699, 257869098, 215762266, 52273409, 311041967,
];
/// pi/2 in Q.33, exactly rounded (the f64 constant carries 53 bits).
const FRAC_PI_2_Q33: u64 = (core::f64::consts::FRAC_PI_2 * 8589934592.0 + 0.5) as u64;

/// `t P(t)` in Q.33 for `t` in Q.32, `t` in [0, 1/4]: six multiply-high-and-add steps (`SMMLA`;
/// their truncation costs < 0.03 ulp of the result) and one rounded multiply.
#[inline(always)]
const fn t_times_poly(t: i32) -> i32 {
    let mut p = P_COEFFS[6];
    p = P_COEFFS[5] + mul_hi(t, p);
    p = P_COEFFS[4] + mul_hi(t, p);
    p = P_COEFFS[3] + mul_hi(t, p);
    p = P_COEFFS[2] + mul_hi(t, p);
    p = P_COEFFS[1] + mul_hi(t, p);
    p = P_COEFFS[0] + mul_hi(t, p);
    mul_hi_round(t, p) // Q.33, t P(t) < 0.048
}

impl Q2_30 {
    /// `asin(self)` in radians, Q2.30 (range [-pi/2, pi/2]), for `self` in [-1, 1].
    ///
    /// Error <= 1 ulp (9.3e-10 absolute; 0.86 ulp measured over all inputs); relative error
    /// <= 1e-6 for every nonzero input (3.3e-7 measured), and `asin z = z` exactly for
    /// |z| < 1.4e-3. Odd: `asin(-z) = -asin(z)`. Error: `Domain` for |z| > 1 (the caller handles
    /// |zeta| >= 1, physics-notes §1). Cost: about 55 instructions for |z| <= 1/2 and 105 for
    /// |z| > 1/2 (square root included), plus the call.
    #[inline]
    pub const fn asin(self) -> Result<Self, FxError> {
        const ONE: u32 = 1 << 30;
        let z = self.to_bits();
        let a = z.unsigned_abs(); // |z| in Q.30
        if a > ONE {
            return Err(FxError::Domain);
        }
        let small = a <= ONE / 2;
        let t = if small {
            let a32 = a << 2; // |z| in Q.32, <= 2^31
            ((a32 as u64 * a32 as u64) >> 32) as u32 // z^2 in Q.32, <= 2^30
        } else {
            (ONE - a) << 1 // (1 - |z|)/2 in Q.32, exact, < 2^30
        };
        let tp = t_times_poly(t as i32) as u64; // t P(t) in Q.33
        let magnitude = if small {
            // z + z t P: Q.30 x Q.33 >> 33, rounded
            a + ((a as u64 * tp + (1 << 32)) >> 33) as u32
        } else {
            // w = sqrt(t) in Q.33, as the Q0.32 root of 4t < 1, within about one unit.
            let w = sqrt_q32_approx(t << 2) as u64;
            // 2 asin(w) = 2w + 2w tP in Q.33; 2 w tP = w tp / 2^32 there.
            let two_asin_w = 2 * w + ((w * tp + (1 << 31)) >> 32);
            // The estimate of w is low by half a unit on average (within [-1.02, +0.02] where
            // the polynomial error peaks): the extra -1 centres the error of 2w to +-1.04
            // units, +-0.13 ulp of the result.
            ((FRAC_PI_2_Q33 - two_asin_w - 1 + 4) >> 3) as u32
        };
        // magnitude <= pi/2 2^30 < 2^31
        let bits = if z < 0 {
            -(magnitude as i32)
        } else {
            magnitude as i32
        };
        Ok(Self::from_bits(bits))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const ULP: f64 = 1.0 / (1u64 << 30) as f64;

    fn err_ulps(bits: i32) -> f64 {
        let z = Q2_30::from_bits(bits);
        let got = z.asin().unwrap().to_f64();
        (got - z.to_f64().asin()) / ULP
    }

    #[test]
    fn constants_agree() {
        assert_eq!((FRAC_PI_2_Q33 + 4) >> 3, Q2_30::FRAC_PI_2.to_bits() as u64);
        assert_eq!(FRAC_PI_2_Q33, 13493037705);
    }

    #[test]
    fn exact_points_and_domain() {
        assert_eq!(Q2_30::ZERO.asin(), Ok(Q2_30::ZERO));
        assert_eq!(Q2_30::ONE.asin(), Ok(Q2_30::FRAC_PI_2));
        let minus_one = Q2_30::from_bits(-(1 << 30));
        assert_eq!(
            minus_one.asin().map(Q2_30::to_bits),
            Ok(-Q2_30::FRAC_PI_2.to_bits())
        );
        assert_eq!(Q2_30::from_bits((1 << 30) + 1).asin(), Err(FxError::Domain));
        assert_eq!(
            Q2_30::from_bits(-(1 << 30) - 1).asin(),
            Err(FxError::Domain)
        );
        assert_eq!(Q2_30::MIN.asin(), Err(FxError::Domain));
        assert_eq!(Q2_30::MAX.asin(), Err(FxError::Domain));
        assert_eq!(Q2_30::ULP.asin(), Ok(Q2_30::ULP));
        // asin(1/2) = pi/6
        let half = Q2_30::from_bits(1 << 29).asin().unwrap().to_f64();
        assert!((half - core::f64::consts::FRAC_PI_6).abs() <= 1.5 * ULP);
    }

    #[test]
    fn asin_dense_sweep_absolute_and_relative() {
        let mut worst_abs: f64 = 0.0;
        // 1M points over [-1, 1], plus every input within 20k ulps of +-1, +-1/2 and 0.
        let n = 1_000_000i64;
        let grid = (0..=n).map(|i| (-(1i64 << 30) + i * (2i64 << 30) / n) as i32);
        let near = |c: i32| (c - 20_000..=c + 20_000).filter(|b| b.abs() <= 1 << 30);
        for bits in grid
            .chain(near(1 << 30))
            .chain(near(-(1 << 30)))
            .chain(near(1 << 29))
            .chain(near(-(1 << 29)))
            .chain(near(0))
        {
            worst_abs = worst_abs.max(err_ulps(bits).abs());
        }
        // Relative error for |z| from 1 ulp to 0.01, log-spaced.
        let mut worst_rel: f64 = 0.0;
        let mut bits = 1.0f64;
        while bits < 0.01 * (1u64 << 30) as f64 {
            for b in [bits as i32, -(bits as i32)] {
                let z = Q2_30::from_bits(b);
                let exact = z.to_f64().asin();
                let got = z.asin().unwrap().to_f64();
                worst_rel = worst_rel.max(((got - exact) / exact).abs());
            }
            bits *= 1.0007;
        }
        eprintln!("asin: max abs error {worst_abs} ulp, max rel error {worst_rel:e}");
        assert!(worst_abs <= 1.0, "asin abs error {worst_abs} ulps");
        assert!(worst_rel <= 1e-6, "asin rel error {worst_rel:e}");
    }

    #[test]
    fn asin_is_odd_and_monotone_on_a_sweep() {
        let mut previous = Q2_30::from_bits(-(1 << 30)).asin().unwrap();
        for bits in (-(1 << 30)..=(1 << 30)).step_by(997) {
            let z = Q2_30::from_bits(bits);
            let y = z.asin().unwrap();
            assert_eq!(
                Q2_30::from_bits(-bits).asin().unwrap().to_bits(),
                -y.to_bits()
            );
            assert!(y >= previous, "not monotone at {z:?}");
            previous = y;
        }
    }

    proptest! {
        #[test]
        fn asin_never_panics(bits in any::<i32>()) {
            match Q2_30::from_bits(bits).asin() {
                Ok(_) => {
                    prop_assert!(bits.unsigned_abs() <= 1 << 30);
                    prop_assert!(err_ulps(bits).abs() <= 1.0);
                }
                Err(e) => prop_assert_eq!(e, FxError::Domain),
            }
        }
    }
}
