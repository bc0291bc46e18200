//! Integer arithmetic on [`Scaled`] values (`mantissa * 2^exp2`, mantissa Q2.30 in [1, 2)):
//! product, reciprocal, sum and conversions from and to the `Q` formats.
//!
//! The Coulomb and Dahl hot paths need quantities that span more decades than any 32-bit
//! format holds (physics-notes §5): the stiffness-amplitude product kappa x_a = k_t x_a / (mu W)
//! runs from 1e-9 to 1e13 over the project's domain (k_t up to 1e10 N/m, x_a up to 50 um, W
//! down to 1 mN), 1/W from 2e-5 to 1e3 1/N, velocity ratios from 0 to 1e8. These helpers carry
//! them with 30 significant bits (relative resolution 9.3e-10) using only 32x32->64 multiplies,
//! shifts and a count-leading-zeros: no float, no division (`Q::checked_div` is a 64-bit
//! library division, about 200 instructions; [`recip`] is the fast reciprocal).
//!
//! ```
//! use sonolube::fx::{Q16_16, wide};
//!
//! // A load of 3 N (Q16.16) as a wide value, its reciprocal by Newton steps, and their product.
//! let load = wide::from_q(Q16_16::from_f64(3.0)?).expect("positive");
//! let inverse = wide::recip(load);
//! assert!((inverse.to_f64() - 1.0 / 3.0).abs() < 1e-9);
//! assert!((wide::mul(load, inverse).to_f64() - 1.0).abs() < 2e-9);
//! // Zero has no wide value: the caller handles it.
//! assert_eq!(wide::from_q(Q16_16::ZERO), None);
//! # Ok::<(), sonolube::fx::FxError>(())
//! ```
//!
//! [`Scaled`] cannot hold zero or negative values; callers test for zero before converting
//! ([`from_q`] returns `None`) and handle signs themselves.

use super::{FxError, Q, Q2_30, Sat, ln_scaled};
use crate::fx::scaled::Scaled;

/// Mantissa bits of 1.0 in Q2.30.
pub(crate) const ONE_BITS: u64 = 1 << 30;

/// Builds a [`Scaled`] from raw mantissa bits in `[2^30, 2^31)` and an exponent.
pub(crate) const fn make(mantissa_bits: u64, exp2: i32) -> Scaled {
    Scaled {
        mantissa: Q2_30::from_bits(mantissa_bits as i32),
        exp2,
    }
}

/// `round(wide / 2^shift)` normalised into a [`Scaled`] mantissa, for `wide` in
/// `[2^(30 + shift), 2^(32 + shift))` and `shift` in 1..=33 (the product or sum of two
/// mantissas): picks the shift that lands in `[2^30, 2^31)` and renormalises a round-up to 2^31.
fn normalise(wide: u64, shift: u32, exp2: i32) -> Scaled {
    let (shift, exp2) = if wide >> (shift + 31) != 0 {
        (shift + 1, exp2.saturating_add(1))
    } else {
        (shift, exp2)
    };
    let rounded = (wide + (1 << (shift - 1))) >> shift;
    if rounded >> 31 != 0 {
        make(ONE_BITS, exp2.saturating_add(1))
    } else {
        make(rounded, exp2)
    }
}

/// The value of a positive `q`, exactly (`None` for `q <= 0`). Cost: a CLZ and a shift.
pub fn from_q<const F: u32>(q: Q<F>) -> Option<Scaled> {
    let bits = q.to_bits();
    if bits <= 0 {
        return None;
    }
    let lz = (bits as u32).leading_zeros(); // >= 1
    // bits 2^-F = (bits << (lz - 1)) 2^-30 2^(31 - F - lz)
    Some(make(
        ((bits as u32) << (lz - 1)) as u64,
        31 - F as i32 - lz as i32,
    ))
}

/// `a * b`, rounded to nearest (relative error <= 2^-31). Cost: one `UMULL` and a few
/// instructions.
pub fn mul(a: Scaled, b: Scaled) -> Scaled {
    let product = umul(a.mantissa.to_bits() as u32, b.mantissa.to_bits() as u32); // [2^60, 2^62)
    normalise(product, 30, a.exp2.saturating_add(b.exp2))
}

/// `1 / a`, correctly rounded (relative error <= 2^-31).
///
/// Method: `r = 2^61 / m` for the mantissa bits `m` (the mantissa of `1/a` up to a power of 2)
/// by three Newton steps `r <- r (2 - d r)` from the linear minimax seed `48/17 - 32/17 d`
/// (relative error 1/17 -> 3.5e-3 -> 1.2e-5 -> 1.5e-10; the first two on the high word of the
/// error, the last on 46 bits), then one exact remainder test. Every product is one 32x32->64
/// `UMULL`/`SMULL`. Cost: 69 instructions on the Cortex-M4 (measured), no division.
pub fn recip(a: Scaled) -> Scaled {
    let m = a.mantissa.to_bits() as u32; // [2^30, 2^31)
    if m == 1 << 30 {
        return make(ONE_BITS, a.exp2.saturating_neg());
    }
    let d = m << 1; // Q0.32 in (0.5, 1)
    const SEED_OFFSET: u32 = ((48u64 << 30) / 17) as u32; // 48/17 in Q2.30
    const SEED_SLOPE: u32 = ((32u64 << 30) / 17) as u32; // 32/17 in Q2.30
    let mut r = SEED_OFFSET - (umul(SEED_SLOPE, d) >> 32) as u32; // Q2.30 in (1, 2)
    // 1 - d r in Q.62 (the wrapping difference is the exact signed error, |.| < 2^59).
    let error = |r: u32| (1u64 << 62).wrapping_sub(umul(d, r)) as i64;
    for _ in 0..2 {
        let e = (error(r) >> 32) as i32; // Q.30
        r = (r as i64 + ((r as i64 * e as i64) >> 30)) as u32;
    }
    let e = (error(r) >> 16) as i32; // Q.46, |.| < 2^30 after two steps
    r = (r as i64 + ((r as i64 * e as i64) >> 46)) as u32;
    // Exact rounding: r = round(2^61 / m) <=> |2^61 - r m| <= m / 2 (r is within one unit).
    let remainder = (1i64 << 61) - umul(r, m) as i64;
    if 2 * remainder > m as i64 {
        r += 1;
    } else if 2 * remainder < -(m as i64) {
        r -= 1;
    }
    // 1/(m 2^(e-30)) = r 2^-31 2^-e: r in (2^30, 2^31) for m in (2^30, 2^31).
    make(r as u64, a.exp2.saturating_neg().saturating_sub(1))
}

/// `a * b` for two `u32`: one `UMULL`.
#[inline(always)]
pub(crate) fn umul(a: u32, b: u32) -> u64 {
    a as u64 * b as u64
}

/// `a + b`, rounded to nearest (relative error <= 2^-31).
pub fn add(a: Scaled, b: Scaled) -> Scaled {
    let (big, small) = if a.exp2 >= b.exp2 { (a, b) } else { (b, a) };
    let gap = big.exp2.saturating_sub(small.exp2) as u32;
    let big_bits = (big.mantissa.to_bits() as u32 as u64) << 31;
    let small_bits = if gap >= 62 {
        0
    } else {
        ((small.mantissa.to_bits() as u32 as u64) << 31) >> gap
    };
    normalise(big_bits + small_bits, 31, big.exp2)
}

/// Orders two non-negative values given as `Option<Scaled>` (`None` = 0).
pub fn cmp(a: Option<Scaled>, b: Option<Scaled>) -> core::cmp::Ordering {
    match (a, b) {
        (None, None) => core::cmp::Ordering::Equal,
        (None, Some(_)) => core::cmp::Ordering::Less,
        (Some(_), None) => core::cmp::Ordering::Greater,
        (Some(a), Some(b)) => a
            .exp2
            .cmp(&b.exp2)
            .then(a.mantissa.to_bits().cmp(&b.mantissa.to_bits())),
    }
}

/// True when `a >= 1`.
pub fn at_least_one(a: Scaled) -> bool {
    a.exp2 >= 0
}

/// `a` in the format `OUT`, rounded to nearest, clamped to `MAX` and flagged when it does not
/// fit. Values below half an ulp give zero (not flagged).
pub fn to_q<const OUT: u32>(a: Scaled) -> Sat<Q<OUT>> {
    mul_q::<OUT, 30>(a, Q2_30::ONE)
}

/// `a * q` in the format `OUT`, rounded once from the exact 64-bit product (error <= 0.5 ulp
/// of `OUT`), clamped to `[MIN, MAX]` and flagged when it does not fit. `q` may be negative.
/// Cost: one `SMULL` and a variable shift.
pub fn mul_q<const OUT: u32, const F: u32>(a: Scaled, q: Q<F>) -> Sat<Q<OUT>> {
    let product = a.mantissa.to_bits() as i64 * q.to_bits() as i64; // |.| < 2^62
    // value = product 2^(exp2 - 30 - F); bits of OUT = product 2^(exp2 - 30 - F + OUT)
    let shift = a
        .exp2
        .saturating_sub(30 + F as i32)
        .saturating_add(OUT as i32);
    let clamp = |negative: bool| {
        Sat::clamped(if negative {
            Q::<OUT>::MIN
        } else {
            Q::<OUT>::MAX
        })
    };
    if product == 0 {
        return Sat::exact(Q::<OUT>::ZERO);
    }
    let bits = if shift >= 0 {
        if shift >= 32 {
            return clamp(product < 0);
        }
        let limit = i32::MAX as i64 >> shift;
        if product > limit || product < -limit - 1 {
            return clamp(product < 0);
        }
        product << shift
    } else if shift <= -63 {
        0
    } else {
        let t = product >> (-shift - 1);
        (t >> 1) + (t & 1) // round half up
    };
    if bits > i32::MAX as i64 || bits < i32::MIN as i64 {
        clamp(bits < 0)
    } else {
        Sat::exact(Q::<OUT>::from_bits(bits as i32))
    }
}

/// Largest magnitude of the wide Q.30 values of [`mul_q_q30`] and [`from_q30`]: 2^56, i.e.
/// 6.7e7 in value (a decay exponent that large is as good as infinite).
pub const Q30_CAP: i64 = 1 << 56;

/// `a * q` as an `i64` in Q.30 (value * 2^30), rounded to nearest, clamped to +-[`Q30_CAP`]:
/// for decay exponents, which may far exceed any 32-bit range yet need 1e-9 resolution when
/// small. `q` may be negative. Cost: one `SMULL` and a variable shift.
pub fn mul_q_q30<const F: u32>(a: Scaled, q: Q<F>) -> i64 {
    let product = a.mantissa.to_bits() as i64 * q.to_bits() as i64; // |.| < 2^62
    let shift = a.exp2.saturating_sub(F as i32); // exp2 - 30 - F + 30
    let bits = if product == 0 {
        0
    } else if shift >= 0 {
        if shift >= 56 || product.abs() > Q30_CAP >> shift {
            return if product < 0 { -Q30_CAP } else { Q30_CAP };
        }
        product << shift
    } else if shift <= -63 {
        0
    } else {
        let t = product >> (-shift - 1);
        (t >> 1) + (t & 1)
    };
    bits.clamp(-Q30_CAP, Q30_CAP)
}

/// The positive Q.30 value `x` (value * 2^30, an `i64`) as a [`Scaled`], rounded to 31 bits;
/// `None` for `x <= 0`.
pub fn from_q30(x: i64) -> Option<Scaled> {
    if x <= 0 {
        return None;
    }
    from_u64(x as u64, -30)
}

/// The positive Q.24 value `x` (value * 2^24, an `i64`) as a [`Scaled`], rounded to 31 bits;
/// `None` for `x <= 0`.
pub fn from_q24(x: i64) -> Option<Scaled> {
    if x <= 0 {
        return None;
    }
    from_u64(x as u64, -24)
}

/// `x * 2^exp2` as a [`Scaled`], rounded to 31 bits; `None` for `x = 0`.
fn from_u64(x: u64, exp2: i32) -> Option<Scaled> {
    if x == 0 {
        return None;
    }
    let shift = 64 - x.leading_zeros() as i32 - 31; // brings the top bit to bit 30
    let exp2 = exp2.saturating_add(shift + 30);
    Some(if shift > 0 {
        let rounded = (x + (1 << (shift - 1))) >> shift;
        if rounded >> 31 != 0 {
            make(ONE_BITS, exp2.saturating_add(1))
        } else {
            make(rounded, exp2)
        }
    } else {
        make(x << (-shift) as u32, exp2)
    })
}

/// `a - b` for `a >= b`, rounded to 31 bits (an absolute error of 2^-31 |a|, so the relative
/// error grows by |a| / (a - b) where the two nearly cancel); `None` when `a <= b`.
pub fn sub(a: Scaled, b: Scaled) -> Option<Scaled> {
    if cmp(Some(a), Some(b)) != core::cmp::Ordering::Greater {
        return None;
    }
    let gap = a.exp2.saturating_sub(b.exp2) as u32; // a > b: gap >= 0
    let big = (a.mantissa.to_bits() as u32 as u64) << 31;
    let small = if gap >= 62 {
        0
    } else {
        ((b.mantissa.to_bits() as u32 as u64) << 31) >> gap
    };
    from_u64(big - small, a.exp2.saturating_sub(61))
}

/// `ln(a)` in the format `OUT` (error <= 0.5 ulp of `OUT` + 8e-10, see [`ln_scaled`]).
/// Errors: `Overflow` when the logarithm does not fit `OUT` or `exp2` is beyond +-32000.
pub fn ln<const OUT: u32>(a: Scaled) -> Result<Q<OUT>, FxError> {
    let exp2 = a.exp2.saturating_sub(30);
    if !(-32_000..=32_000).contains(&exp2) {
        return Err(FxError::Overflow);
    }
    ln_scaled::<OUT>(a.mantissa.to_bits() as u32 as u64, exp2 as i16)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q1_31, Q8_24, Q16_16};
    use crate::model::{ModelError, scaled_from_f64 as from_f64};
    use proptest::prelude::*;

    fn s(x: f64) -> Scaled {
        from_f64(x, "x").unwrap()
    }

    fn rel(got: Scaled, want: f64) -> f64 {
        (got.to_f64() / want - 1.0).abs()
    }

    #[test]
    fn conversions_are_exact_or_rounded_once() {
        assert_eq!(s(1.0).to_f64(), 1.0);
        assert_eq!(s(0.75).to_f64(), 0.75);
        assert_eq!(s(3.0 * 2f64.powi(-40)).to_f64(), 3.0 * 2f64.powi(-40));
        assert!(rel(s(1e-300), 1e-300) < 5e-10 && rel(s(1e300), 1e300) < 5e-10);
        assert_eq!(
            from_f64(f64::NAN, "x"),
            Err(ModelError::NonFinite { input: "x" })
        );
        assert!(matches!(
            from_f64(0.0, "x"),
            Err(ModelError::OutOfDomain { .. })
        ));
        assert_eq!(from_q(Q16_16::ZERO), None);
        assert_eq!(from_q(Q16_16::from_bits(-5)), None);
        for q in [Q16_16::ULP, Q16_16::MAX, Q16_16::from_f64(3.25).unwrap()] {
            assert_eq!(from_q(q).unwrap().to_f64(), q.to_f64());
        }
        assert_eq!(from_q(Q1_31::MAX).unwrap().to_f64(), Q1_31::MAX.to_f64());
        let third = to_q::<31>(s(1.0 / 3.0));
        assert!(!third.saturated && third.value == Q1_31::from_ratio(1, 3).unwrap());
        assert!(to_q::<31>(s(1.0)).saturated);
        assert!(to_q::<16>(s(1e9)).saturated);
        assert_eq!(to_q::<16>(s(1e-9)).value, Q16_16::ZERO);
    }

    #[test]
    fn products_sums_and_reciprocals() {
        assert_eq!(mul(s(1.5), s(2.0)).to_f64(), 3.0);
        assert!(rel(mul(s(1e10), s(3e-7)), 3e3) < 1e-9);
        assert_eq!(recip(s(2.0)).to_f64(), 0.5);
        assert_eq!(recip(s(0.5)).to_f64(), 2.0);
        assert_eq!(add(s(1.0), s(0.5)).to_f64(), 1.5);
        assert_eq!(add(s(1.0), s(1e-30)).to_f64(), 1.0);
        assert!(at_least_one(s(1.0)) && !at_least_one(s(0.999_999_999)));
        use core::cmp::Ordering::{Equal, Greater, Less};
        assert_eq!(cmp(Some(s(3.0)), Some(s(2.5))), Greater);
        assert_eq!(cmp(Some(s(0.5)), Some(s(2.5))), Less);
        assert_eq!(cmp(None, Some(s(1e-300))), Less);
        assert_eq!(cmp(None, None), Equal);
        let m = mul_q::<24, 30>(s(1e9), Q2_30::from_f64(-0.5).unwrap());
        assert_eq!((m.value, m.saturated), (Q8_24::MIN, true));
        let m = mul_q::<24, 30>(s(100.0), Q2_30::from_f64(-0.5).unwrap());
        assert_eq!((m.value.to_f64(), m.saturated), (-50.0, false));
        let l: Q8_24 = ln(s(1e10)).unwrap();
        assert!((l.to_f64() - 1e10f64.ln()).abs() < 1e-7);
    }

    /// Every reciprocal of a dense sweep of mantissas is the correctly rounded one.
    #[test]
    fn reciprocal_is_correctly_rounded() {
        assert_eq!(recip(make(ONE_BITS, 3)).to_f64(), 0.125);
        for i in 1..200_000u64 {
            let m = (1 << 30) + i * 5_368 + (i % 7);
            let r = recip(make(m, 0)).mantissa.to_bits() as u64;
            let exact = (1u128 << 61) as f64 / m as f64;
            assert!(
                (r as f64 - exact).abs() <= 0.5 + 1e-6,
                "m {m}: {r} vs {exact}"
            );
        }
    }

    #[test]
    fn wide_q30_values() {
        assert_eq!(mul_q_q30(s(3.0), Q2_30::from_f64(0.5).unwrap()), 3 << 29);
        assert_eq!(mul_q_q30(s(1e30), Q2_30::ONE), Q30_CAP);
        assert_eq!(mul_q_q30(s(1e30), Q2_30::from_bits(-1)), -Q30_CAP);
        assert_eq!(mul_q_q30(s(1e-30), Q2_30::ONE), 0);
        assert_eq!(mul_q_q30(s(1e6), Q8_24::ONE), 1_000_000 << 30);
        let big = 1e6 * 1_073_741_824.0;
        assert!(rel(from_q30(big as i64).unwrap(), 1e6) < 1e-9);
        assert_eq!(from_q30(1 << 30).unwrap().to_f64(), 1.0);
        assert_eq!(from_q30(3).unwrap().to_f64(), 3.0 / 1_073_741_824.0);
        assert_eq!(from_q30(0), None);
        assert_eq!(from_q24(1 << 24).unwrap().to_f64(), 1.0);
        assert_eq!(from_q24((1 << 40) - 1).unwrap().to_f64(), 65536.0); // rounds up to 2^16
        assert_eq!(sub(s(3.0), s(1.0)).unwrap().to_f64(), 2.0);
        assert_eq!(sub(s(1.0), s(1.0)), None);
        assert_eq!(sub(s(1.0), s(2.0)), None);
        assert!(rel(sub(s(1.0), s(1.0 - 1e-6)).unwrap(), 1e-6) < 1e-3);
        assert_eq!(sub(s(1.0), s(1e-30)).unwrap().to_f64(), 1.0);
    }

    proptest! {
        #[test]
        fn arithmetic_matches_f64(a in -200.0f64..200.0, b in -200.0f64..200.0, q in any::<i32>()) {
            let (x, y) = (2f64.powf(a), 2f64.powf(b));
            // Each conversion from f64 and each operation rounds once (2^-31 = 4.7e-10).
            prop_assert!(rel(mul(s(x), s(y)), x * y) < 1.5e-9);
            prop_assert!(rel(add(s(x), s(y)), x + y) < 1.5e-9);
            prop_assert!(rel(recip(s(x)), 1.0 / x) < 1e-9);
            let qq = Q16_16::from_bits(q);
            let got = mul_q::<16, 16>(s(x), qq);
            let want = x * qq.to_f64();
            if want.abs() < 32767.0 {
                prop_assert!(!got.saturated);
                let gap = (got.value.to_f64() - want).abs();
                prop_assert!(gap <= 0.5 / 65536.0 + 1e-9 * want.abs());
            } else if want.abs() > 32768.0 {
                prop_assert!(got.saturated && got.value.is_negative() == (want < 0.0));
            }
        }
    }
}
