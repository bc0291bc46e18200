//! Integer kernels behind the fixed-point operations: rounding shifts, range checks, quotients,
//! and the multiply-high steps of the polynomial evaluations.
//!
//! Everything here works on raw two's-complement bits. The shift amounts are compile-time
//! constants at every call site that matters (they come from the const-generic formats), so the
//! branches fold away after inlining.

use super::error::{FxError, Sat};

/// `v` as an `i32`, or `Overflow` when it does not fit.
pub(crate) const fn fit_i32(v: i64) -> Result<i32, FxError> {
    if v > i32::MAX as i64 || v < i32::MIN as i64 {
        Err(FxError::Overflow)
    } else {
        Ok(v as i32)
    }
}

/// `v` clamped to the `i32` range, flagged when clamped.
pub(crate) const fn clamp_i32(v: i64) -> Sat<i32> {
    if v > i32::MAX as i64 {
        Sat::clamped(i32::MAX)
    } else if v < i32::MIN as i64 {
        Sat::clamped(i32::MIN)
    } else {
        Sat::exact(v as i32)
    }
}

/// `round(v / 2^shift)` as an `i64`, ties toward +infinity, for `shift` in `1..=63`.
///
/// Written as `floor((floor(v / 2^(shift-1)) + 1) / 2)`, which equals `floor(v / 2^shift + 1/2)`
/// and cannot overflow for any `v` (adding the half-ulp first could, for `v` near `i64::MAX`).
pub(crate) const fn shr_round_i64(v: i64, shift: u32) -> i64 {
    let t = v >> (shift - 1);
    (t >> 1) + (t & 1)
}

/// `round(v * 2^-shift)` as an `i32` for any `shift` (negative = left shift), ties toward
/// +infinity; `Overflow` when the rounded result does not fit.
pub(crate) const fn rescale(v: i64, shift: i32) -> Result<i32, FxError> {
    if shift > 0 {
        if shift >= 64 {
            // |v| <= 2^63, so |v / 2^shift| <= 1/2 and the round-half-up result is 0.
            return Ok(0);
        }
        fit_i32(shr_round_i64(v, shift as u32))
    } else if shift == 0 {
        fit_i32(v)
    } else {
        let k = shift.unsigned_abs();
        if v == 0 {
            Ok(0)
        } else if k > 31 || v > (i32::MAX >> k) as i64 || v < (i32::MIN >> k) as i64 {
            Err(FxError::Overflow)
        } else {
            Ok((v << k) as i32)
        }
    }
}

/// Like [`rescale`], but clamps to the `i32` range instead of failing.
pub(crate) const fn rescale_saturating(v: i64, shift: i32) -> Sat<i32> {
    match rescale(v, shift) {
        Ok(bits) => Sat::exact(bits),
        Err(_) => {
            if v < 0 {
                Sat::clamped(i32::MIN)
            } else {
                Sat::clamped(i32::MAX)
            }
        }
    }
}

/// `round(a * 2^shift / b)` for `shift` in `-63..=63`, ties away from zero.
///
/// Works on magnitudes in `u64` so that no intermediate exceeds 64 bits: for `shift > 32` the
/// quotient is formed in two steps (long division by 2^32 digits). Uses the 64-bit division of
/// the runtime library on Cortex-M4 (tens to ~100 cycles): keep it out of the 10 kHz inner loop
/// where a multiplication by a precomputed reciprocal will do.
pub(crate) const fn div_round(a: i32, b: i32, shift: i32) -> Result<i32, FxError> {
    if b == 0 {
        return Err(FxError::DivisionByZero);
    }
    let n = a.unsigned_abs() as u64;
    let d = b.unsigned_abs() as u64;
    let negative = (a < 0) != (b < 0);
    if n == 0 {
        return Ok(0);
    }
    // The magnitude of the rounded quotient; u64::MAX stands for "certainly too large".
    let magnitude = if shift >= 0 && shift <= 32 {
        let num = n << shift;
        let (q, r) = (num / d, num % d);
        q + (2 * r >= d) as u64
    } else if shift > 32 {
        let extra = (shift - 32) as u32;
        let num = n << 32;
        let (q_hi, r_hi) = (num / d, num % d);
        if extra >= 32 || q_hi > (1u64 << 31) >> extra {
            u64::MAX
        } else {
            let num_lo = r_hi << extra;
            let (q_lo, r) = (num_lo / d, num_lo % d);
            (q_hi << extra) + q_lo + (2 * r >= d) as u64
        }
    } else {
        let k = shift.unsigned_abs();
        if k >= 33 {
            // d * 2^k >= 2^33 > 2 n: the quotient is below one half.
            0
        } else {
            let div = d << k;
            let (q, r) = (n / div, n % div);
            q + (2 * r >= div) as u64
        }
    };
    if negative {
        if magnitude > 1u64 << 31 {
            Err(FxError::Overflow)
        } else {
            Ok((magnitude as i64).wrapping_neg() as i32)
        }
    } else if magnitude > i32::MAX as u64 {
        Err(FxError::Overflow)
    } else {
        Ok(magnitude as i32)
    }
}

/// `floor(a * b / 2^32)`: one `SMULL` (the high word) on Cortex-M4.
#[inline(always)]
pub(crate) const fn mul_hi(a: i32, b: i32) -> i32 {
    ((a as i64 * b as i64) >> 32) as i32
}

/// `round(a * b / 2^32)`, ties toward +infinity: `SMMULR` on Cortex-M4. Always fits `i32`
/// (`|a b| <= 2^62`).
#[inline(always)]
pub(crate) const fn mul_hi_round(a: i32, b: i32) -> i32 {
    ((a as i64 * b as i64 + (1 << 31)) >> 32) as i32
}

/// `numerator / denominator` in `i64`, rounded to nearest (ties away from zero); 0 for
/// `denominator == 0` or `i64::MIN / -1`. Callers keep `|numerator| < 2^63 - |denominator|`
/// (beyond it the rounding bias saturates). Uses the runtime's 64-bit division.
pub(crate) const fn div_round_i64(numerator: i64, denominator: i64) -> i64 {
    let half = denominator.unsigned_abs() as i64 / 2;
    let biased = if (numerator < 0) == (denominator < 0) {
        numerator.saturating_add(if numerator < 0 { -half } else { half })
    } else {
        numerator.saturating_sub(if numerator < 0 { half } else { -half })
    };
    match biased.checked_div(denominator) {
        Some(quotient) => quotient,
        None => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_division_rounds_half_away_from_zero_in_every_quadrant() {
        assert_eq!(div_round_i64(7, 2), 4);
        assert_eq!(div_round_i64(-7, 2), -4);
        assert_eq!(div_round_i64(7, -2), -4);
        assert_eq!(div_round_i64(-7, -2), 4);
        assert_eq!(div_round_i64(5, 3), 2);
        assert_eq!(div_round_i64(4, 3), 1);
        assert_eq!(div_round_i64(1, 0), 0);
        assert_eq!(div_round_i64(i64::MIN, -1), 0);
        // The extremes the callers reach: 2^62 over the smallest and largest divisors.
        assert_eq!(div_round_i64(1 << 62, 3), ((1i64 << 62) + 1) / 3);
        assert_eq!(div_round_i64(-(1 << 62), i64::MAX), -1);
    }

    #[test]
    fn the_rounded_high_word_always_fits_i32() {
        assert_eq!(mul_hi_round(i32::MIN, i32::MIN), 1 << 30);
        assert_eq!(mul_hi_round(i32::MAX, i32::MIN), -(1 << 30) + 1);
        // 2^31 / 2^32 = 1/2 rounds up; -2^30 / 2^32 = -1/4 rounds to 0.
        assert_eq!(mul_hi_round(1 << 15, 1 << 16), 1);
        assert_eq!(mul_hi_round(-1, 1 << 30), 0);
    }

    #[test]
    fn shr_round_matches_float_rounding_at_the_extremes() {
        for &v in &[
            i64::MIN,
            i64::MIN + 1,
            -3,
            -2,
            -1,
            0,
            1,
            2,
            3,
            i64::MAX - 1,
            i64::MAX,
        ] {
            for shift in 1..=63u32 {
                let exact = (v as f64) / (shift as f64).exp2();
                let got = shr_round_i64(v, shift) as f64;
                assert!(
                    (got - exact).abs() <= 0.5 + 1e-9 * exact.abs(),
                    "{v} >> {shift}"
                );
                assert!(got - exact > -0.5 - 1e-9 * exact.abs() || v.abs() > 1 << 52);
            }
        }
        assert_eq!(shr_round_i64(-1, 1), 0); // -0.5 rounds up
        assert_eq!(shr_round_i64(1, 1), 1); // 0.5 rounds up
        assert_eq!(shr_round_i64(-3, 1), -1); // -1.5 rounds up
    }

    #[test]
    fn rescale_checks_both_directions() {
        assert_eq!(rescale(i32::MAX as i64, 0), Ok(i32::MAX));
        assert_eq!(rescale(i32::MAX as i64 + 1, 0), Err(FxError::Overflow));
        assert_eq!(rescale(-1 << 30, -1), Ok(i32::MIN));
        assert_eq!(rescale(1 << 30, -1), Err(FxError::Overflow));
        assert_eq!(rescale(1, -31), Err(FxError::Overflow));
        assert_eq!(rescale(-1, -31), Ok(i32::MIN));
        assert_eq!(rescale(i64::MAX, 64), Ok(0));
        assert_eq!(rescale(i64::MIN, 63), Ok(-1));
        assert_eq!(rescale(i64::MAX, 32), Err(FxError::Overflow));
    }

    #[test]
    fn div_round_is_exact_on_small_cases() {
        for a in -40..=40 {
            for b in -9..=9 {
                for shift in -3..=3 {
                    let got = div_round(a, b, shift);
                    if b == 0 {
                        assert_eq!(got, Err(FxError::DivisionByZero));
                        continue;
                    }
                    let exact = a as f64 * (shift as f64).exp2() / b as f64;
                    let want = exact.abs().add_half_floor() * exact.signum();
                    assert_eq!(got, Ok(want as i32), "{a} * 2^{shift} / {b}");
                }
            }
        }
        assert_eq!(div_round(i32::MIN, -1, 0), Err(FxError::Overflow));
        assert_eq!(div_round(i32::MIN, 1, 0), Ok(i32::MIN));
        assert_eq!(div_round(1, 1 << 30, 61), Err(FxError::Overflow));
        assert_eq!(div_round(-1, 1 << 30, 61), Ok(i32::MIN));
        assert_eq!(div_round(3, 1 << 30, 58), Ok(3 << 28));
        assert_eq!(div_round(1, 3, 62), Err(FxError::Overflow));
        // 2^62 / (2^31 - 1) = 2^31 + 1.0000000005: just above the positive range.
        assert_eq!(div_round(1, i32::MAX, 62), Err(FxError::Overflow));
        assert_eq!(div_round(-1, i32::MAX, 62), Err(FxError::Overflow));
        assert_eq!(div_round(-1, i32::MIN, 61), Ok(1 << 30));
        assert_eq!(div_round(-1, i32::MIN, 62), Err(FxError::Overflow));
        assert_eq!(div_round(i32::MAX, 1, -63), Ok(0));
        assert_eq!(div_round(i32::MIN, 1, -32), Ok(-1));
        assert_eq!(div_round(i32::MIN, 1, -33), Ok(0));
    }

    trait AddHalfFloor {
        fn add_half_floor(self) -> f64;
    }
    impl AddHalfFloor for f64 {
        fn add_half_floor(self) -> f64 {
            (self + 0.5).floor()
        }
    }
}
