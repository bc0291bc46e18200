//! Arithmetic on [`Q`]: add, subtract, negate, multiply (same format and format-changing),
//! shift, interpolate (division is in `div`). Every operation is checked (`Result`) or
//! saturating with a flag ([`Sat`]); none panics or wraps.
//!
//! Rounding: products and right shifts round to nearest: they add a half-ulp and shift
//! arithmetically (ties toward +infinity: one `SMLAL`-friendly add on Cortex-M4). Truncation
//! would bias a Dahl state that changes by ~1e-3 per step over 1e4 steps (physics-notes §5);
//! round-to-nearest does not.

use super::error::{FxError, Sat};
use super::q::{Q, Q2_30};
use super::raw;

/// Wraps raw bits from a kernel into a `Q`, passing errors through (const-compatible `map`).
const fn wrap<const F: u32>(r: Result<i32, FxError>) -> Result<Q<F>, FxError> {
    match r {
        Ok(bits) => Ok(Q::<F>::from_bits(bits)),
        Err(e) => Err(e),
    }
}

/// Wraps a clamped raw result into a `Q`.
const fn wrap_sat<const F: u32>(s: Sat<i32>) -> Sat<Q<F>> {
    Sat {
        value: Q::<F>::from_bits(s.value),
        saturated: s.saturated,
    }
}

impl<const FRAC: u32> Q<FRAC> {
    /// `self + rhs`, or `Overflow`. Exact. Cost: 1-3 instructions.
    pub const fn checked_add(self, rhs: Self) -> Result<Self, FxError> {
        wrap(raw::fit_i32(self.to_bits() as i64 + rhs.to_bits() as i64))
    }

    /// `self + rhs` clamped to `[MIN, MAX]`, flagged when clamped (`QADD` on Cortex-M4).
    pub const fn saturating_add(self, rhs: Self) -> Sat<Self> {
        wrap_sat(raw::clamp_i32(self.to_bits() as i64 + rhs.to_bits() as i64))
    }

    /// `self - rhs`, or `Overflow`. Exact.
    pub const fn checked_sub(self, rhs: Self) -> Result<Self, FxError> {
        wrap(raw::fit_i32(self.to_bits() as i64 - rhs.to_bits() as i64))
    }

    /// `self - rhs` clamped to `[MIN, MAX]`, flagged when clamped.
    pub const fn saturating_sub(self, rhs: Self) -> Sat<Self> {
        wrap_sat(raw::clamp_i32(self.to_bits() as i64 - rhs.to_bits() as i64))
    }

    /// `-self`, or `Overflow` for `MIN`.
    pub const fn checked_neg(self) -> Result<Self, FxError> {
        wrap(raw::fit_i32(-(self.to_bits() as i64)))
    }

    /// `-self`; `MIN` gives `MAX`, flagged.
    pub const fn saturating_neg(self) -> Sat<Self> {
        wrap_sat(raw::clamp_i32(-(self.to_bits() as i64)))
    }

    /// `|self|`, or `Overflow` for `MIN`.
    pub const fn checked_abs(self) -> Result<Self, FxError> {
        wrap(raw::fit_i32((self.to_bits() as i64).abs()))
    }

    /// `|self|`; `MIN` gives `MAX`, flagged.
    pub const fn saturating_abs(self) -> Sat<Self> {
        wrap_sat(raw::clamp_i32((self.to_bits() as i64).abs()))
    }

    /// `self * rhs` in the same format, rounded to nearest (error <= 0.5 ulp), or `Overflow`.
    /// Cost: `SMULL` + add-half + shift + range check, about 10 instructions.
    pub const fn checked_mul(self, rhs: Self) -> Result<Self, FxError> {
        self.checked_mul_to::<FRAC, FRAC>(rhs)
    }

    /// `self * rhs` in the same format, rounded, clamped and flagged.
    pub const fn saturating_mul(self, rhs: Self) -> Sat<Self> {
        self.saturating_mul_to::<FRAC, FRAC>(rhs)
    }

    /// `self * rhs` with the result in the caller's format `OUT`, rounded to nearest from the
    /// exact 64-bit product (error <= 0.5 ulp of `OUT`), or `Overflow`. Example:
    /// `ratio.checked_mul_to::<31, _>(state)` multiplies a Q2.30 by a Q1.31 into a Q1.31.
    pub const fn checked_mul_to<const OUT: u32, const R: u32>(
        self,
        rhs: Q<R>,
    ) -> Result<Q<OUT>, FxError> {
        let product = self.to_bits() as i64 * rhs.to_bits() as i64;
        wrap(raw::rescale(product, (FRAC + R) as i32 - OUT as i32))
    }

    /// Like [`Self::checked_mul_to`] but clamped to `OUT`'s range and flagged.
    pub const fn saturating_mul_to<const OUT: u32, const R: u32>(self, rhs: Q<R>) -> Sat<Q<OUT>> {
        let product = self.to_bits() as i64 * rhs.to_bits() as i64;
        wrap_sat(raw::rescale_saturating(
            product,
            (FRAC + R) as i32 - OUT as i32,
        ))
    }

    /// `self * n` for an integer `n`, exact, or `Overflow`.
    pub const fn checked_mul_int(self, n: i32) -> Result<Self, FxError> {
        wrap(raw::fit_i32(self.to_bits() as i64 * n as i64))
    }

    /// `self * 2^n`, exact, or `Overflow`.
    pub const fn checked_shl(self, n: u32) -> Result<Self, FxError> {
        if n >= 32 {
            if self.to_bits() == 0 {
                Ok(self)
            } else {
                Err(FxError::Overflow)
            }
        } else {
            wrap(raw::fit_i32((self.to_bits() as i64) << n))
        }
    }

    /// `self * 2^n` clamped to `[MIN, MAX]`, flagged when clamped.
    pub const fn saturating_shl(self, n: u32) -> Sat<Self> {
        match self.checked_shl(n) {
            Ok(v) => Sat::exact(v),
            Err(_) => {
                if self.to_bits() < 0 {
                    Sat::clamped(Self::MIN)
                } else {
                    Sat::clamped(Self::MAX)
                }
            }
        }
    }

    /// `self * 2^-n` rounded to nearest (ties toward +infinity). Never fails; 0 for `n >= 32`.
    pub const fn shr_round(self, n: u32) -> Self {
        if n == 0 {
            self
        } else if n >= 32 {
            // |bits| <= 2^31, so |bits / 2^n| <= 1/2, which rounds (half up) to 0.
            Self::ZERO
        } else {
            Self::from_bits(raw::shr_round_i64(self.to_bits() as i64, n) as i32)
        }
    }

    /// `self + (toward - self) * weight`, rounded to nearest from the exact 64-bit product.
    ///
    /// With `weight` in [0, 1] the result lies between `self` and `toward` and never fails;
    /// `Overflow` is possible only for weights outside [0, 1]. This is the exact Dahl update
    /// `f_new = s + (f_old - s) exp(-kappa |dx|)` as `s.lerp(f_old, decay)` (physics-notes §2).
    /// Cost: about 15 instructions (one 32x64 multiply).
    pub const fn lerp(self, toward: Self, weight: Q2_30) -> Result<Self, FxError> {
        let span = toward.to_bits() as i64 - self.to_bits() as i64; // |span| < 2^32
        // |span * weight| < 2^32 * 2^31 = 2^63: fits i64.
        let step = raw::shr_round_i64(span * weight.to_bits() as i64, 30);
        wrap(raw::fit_i32(self.to_bits() as i64 + step))
    }
}

#[cfg(test)]
mod tests {
    use super::super::q::{Q1_31, Q16_16};
    use super::*;
    use proptest::prelude::*;

    fn q16(x: f64) -> Q16_16 {
        Q16_16::from_f64(x).unwrap()
    }

    #[test]
    fn add_sub_report_overflow() {
        assert_eq!(q16(1.5).checked_add(q16(2.25)), Ok(q16(3.75)));
        assert_eq!(Q16_16::MAX.checked_add(Q16_16::ULP), Err(FxError::Overflow));
        let s = Q16_16::MAX.saturating_add(Q16_16::ULP);
        assert_eq!((s.value, s.saturated), (Q16_16::MAX, true));
        let s = Q16_16::MIN.saturating_sub(Q16_16::ULP);
        assert_eq!((s.value, s.saturated), (Q16_16::MIN, true));
        let s = q16(-3.0).saturating_sub(q16(4.0));
        assert_eq!((s.value, s.saturated), (q16(-7.0), false));
        assert_eq!(Q16_16::MIN.checked_sub(Q16_16::ULP), Err(FxError::Overflow));
        assert_eq!(Q16_16::MIN.checked_neg(), Err(FxError::Overflow));
        assert_eq!(Q16_16::MIN.checked_abs(), Err(FxError::Overflow));
        assert_eq!(q16(-2.0).checked_abs(), Ok(q16(2.0)));
        let s = Q16_16::MIN.saturating_neg();
        assert_eq!((s.value, s.saturated), (Q16_16::MAX, true));
        let s = Q16_16::MIN.saturating_abs();
        assert_eq!((s.value, s.saturated), (Q16_16::MAX, true));
    }

    #[test]
    fn multiplication_rounds_to_nearest_and_changes_format() {
        assert_eq!(q16(1.5).checked_mul(q16(-2.5)), Ok(q16(-3.75)));
        // 2^-16 * 0.5 = exact tie, rounds toward +infinity; the negative tie rounds up to 0.
        assert_eq!(Q16_16::ULP.checked_mul(q16(0.5)), Ok(Q16_16::ULP));
        assert_eq!(
            Q16_16::from_bits(-1).checked_mul(q16(0.5)),
            Ok(Q16_16::ZERO)
        );
        assert_eq!(Q16_16::from_bits(3).checked_mul(q16(0.25)), Ok(Q16_16::ULP));
        assert_eq!(q16(200.0).checked_mul(q16(200.0)), Err(FxError::Overflow));
        let s = q16(200.0).saturating_mul(q16(-200.0));
        assert_eq!((s.value, s.saturated), (Q16_16::MIN, true));
        // Format-changing: Q16.16 x Q2.30 -> Q1.31 and -> Q16.16.
        let half = Q2_30::from_f64(0.5).unwrap();
        let r: Q1_31 = q16(0.75).checked_mul_to(half).unwrap();
        assert_eq!(r.to_f64(), 0.375);
        assert_eq!(
            q16(3.0).checked_mul_to::<31, 30>(half),
            Err(FxError::Overflow)
        );
        assert_eq!(q16(-2.0).checked_mul_to::<31, 30>(half), Ok(Q1_31::MIN));
        let s = q16(3.0).saturating_mul_to::<31, 30>(half);
        assert_eq!((s.value, s.saturated), (Q1_31::MAX, true));
        // Widest shifts: Q1.31 x Q1.31 -> Q32.0 and Q0-format inputs -> Q1.31.
        assert_eq!(
            Q1_31::MIN
                .checked_mul_to::<0, 31>(Q1_31::MIN)
                .unwrap()
                .to_bits(),
            1
        );
        assert_eq!(
            Q::<0>::from_bits(-1).checked_mul_to::<31, 0>(Q::<0>::from_bits(1)),
            Ok(Q1_31::MIN)
        );
        assert_eq!(
            Q::<0>::from_bits(1).checked_mul_to::<31, 0>(Q::<0>::from_bits(1)),
            Err(FxError::Overflow)
        );
        assert_eq!(q16(1.25).checked_mul_int(-4), Ok(q16(-5.0)));
        assert_eq!(q16(10000.0).checked_mul_int(4), Err(FxError::Overflow));
    }

    #[test]
    fn shifts_are_exact_or_rounded() {
        assert_eq!(q16(1.5).checked_shl(3), Ok(q16(12.0)));
        assert_eq!(q16(1.5).checked_shl(15), Err(FxError::Overflow));
        assert_eq!(q16(-1.0).checked_shl(15), Ok(Q16_16::MIN));
        assert_eq!(Q16_16::ZERO.checked_shl(40), Ok(Q16_16::ZERO));
        assert_eq!(Q16_16::ULP.checked_shl(40), Err(FxError::Overflow));
        let s = q16(-3.0).saturating_shl(20);
        assert_eq!((s.value, s.saturated), (Q16_16::MIN, true));
        assert_eq!(Q16_16::from_bits(3).shr_round(1), Q16_16::from_bits(2));
        assert_eq!(Q16_16::from_bits(-3).shr_round(1), Q16_16::from_bits(-1));
        assert_eq!(Q16_16::MAX.shr_round(31), Q16_16::from_bits(1));
        assert_eq!(Q16_16::MIN.shr_round(32), Q16_16::ZERO);
        assert_eq!(Q16_16::MIN.shr_round(31), Q16_16::from_bits(-1));
        assert_eq!(q16(5.0).shr_round(0), q16(5.0));
    }

    #[test]
    fn lerp_is_the_dahl_update_and_stays_between_its_ends() {
        let one = Q2_30::ONE;
        let minus_one = Q2_30::from_int(-1).unwrap();
        let decay = Q2_30::from_f64((-0.3f64).exp()).unwrap();
        let f = minus_one.lerp(one, decay).unwrap();
        let exact = -1.0 + 2.0 * decay.to_f64();
        assert!((f.to_f64() - exact).abs() <= 0.5 * Q2_30::ULP.to_f64());
        assert_eq!(one.lerp(minus_one, Q2_30::ZERO), Ok(one));
        assert_eq!(one.lerp(minus_one, Q2_30::ONE), Ok(minus_one));
        assert_eq!(Q2_30::MIN.lerp(Q2_30::MAX, Q2_30::ONE), Ok(Q2_30::MAX));
        assert_eq!(Q2_30::MAX.lerp(Q2_30::MIN, Q2_30::ONE), Ok(Q2_30::MIN));
        assert_eq!(
            Q2_30::MAX.lerp(Q2_30::MIN, Q2_30::MIN),
            Err(FxError::Overflow)
        );
    }

    /// Round-to-nearest has no drift: 1e4 small products accumulated in Q1.31 stay within a
    /// random-walk distance of the f64 sum, where truncation would drift by ~N/2 ulps.
    #[test]
    fn rounding_has_no_bias_over_ten_thousand_products() {
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let n = 10_000;
        let mut sum = Q1_31::ZERO;
        let mut sum_trunc: i64 = 0;
        let mut exact = 0.0f64;
        for _ in 0..n {
            // factors of about 1e-2 and +-1e-1: products ~1e-3 (a Dahl step, physics-notes §5)
            let a = Q1_31::from_bits((next() >> 33) as i32 / 64);
            let b = Q1_31::from_bits((next() >> 32) as i32 / 8);
            let p: Q1_31 = a.checked_mul(b).unwrap();
            sum = sum.checked_add(p).unwrap();
            sum_trunc += (a.to_bits() as i64 * b.to_bits() as i64) >> 31;
            exact += a.to_f64() * b.to_f64();
        }
        let ulp = Q1_31::ULP.to_f64();
        let err_ulps = (sum.to_f64() - exact) / ulp;
        let trunc_err_ulps = (sum_trunc as f64 * ulp - exact) / ulp;
        // sqrt(n / 12) = 29 ulps is one standard deviation of the rounding random walk.
        assert!(err_ulps.abs() < 150.0, "rounded sum off by {err_ulps} ulps");
        assert!(
            trunc_err_ulps < -4000.0,
            "truncation should drift: {trunc_err_ulps}"
        );
    }

    proptest! {
        #[test]
        fn arithmetic_never_panics_and_matches_f64(
            a in any::<i32>(),
            b in any::<i32>(),
            n in 0u32..40,
        ) {
            let (x, y) = (Q16_16::from_bits(a), Q16_16::from_bits(b));
            let exact_sum = x.to_f64() + y.to_f64();
            match x.checked_add(y) {
                Ok(s) => prop_assert_eq!(s.to_f64(), exact_sum),
                Err(_) => prop_assert!(!(-32768.0..32768.0).contains(&exact_sum)),
            }
            let s = x.saturating_add(y);
            prop_assert_eq!(s.saturated, x.checked_add(y).is_err());
            let _ = (x.checked_sub(y), x.saturating_sub(y), x.checked_neg(), x.saturating_abs());
            let exact_product = x.to_f64() * y.to_f64();
            match x.checked_mul(y) {
                Ok(p) => prop_assert!((p.to_f64() - exact_product).abs() <= 0.5 / 65536.0),
                Err(_) => prop_assert!(exact_product.abs() >= 32767.0),
            }
            let _ = x.saturating_mul(y);
            let _ = x.checked_mul_to::<31, 16>(y);
            let _ = x.saturating_mul_to::<0, 16>(y);
            let _ = Q1_31::from_bits(a).saturating_mul_to::<31, 0>(Q::<0>::from_bits(b));
            let _ = x.checked_mul_int(b);
            let _ = (x.checked_shl(n), x.saturating_shl(n), x.shr_round(n));
            let _ = x.lerp(y, Q2_30::from_bits(b));
        }
    }
}
