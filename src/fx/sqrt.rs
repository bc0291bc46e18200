//! Square root: an exact integer square root of a `u64` and the correctly rounded square root of
//! a [`Q`] value in any output format.
//!
//! Method (no division, no loop): normalise by an even shift so the argument has its top bit in
//! place, take a 5-bit-accurate reciprocal square root from a 64-entry table (48 entries used),
//! refine it with two Newton steps `y <- y (3 - x y^2) / 2` (1.6e-2 -> 3.7e-4 -> 2e-7), form
//! `s = x y` and apply one Markstein correction `s <- s + (x - s^2) y / 2` computed from the
//! exact 64-bit remainder. The estimate is then within 1.02 of the true root, and one
//! compare-and-step each way makes the floor exact. Every product is a 32x32->64
//! `UMULL`/`SMULL`.

use super::error::FxError;
use super::q::Q;

/// `round(2^14 / sqrt((i + 1/2) / 64))` for `i` in `16..64`: reciprocal square root (Q2.14) at
/// the centre of each 1/64-wide interval of the normalised argument in [1/4, 1), generated at
/// compile time (relative error of a seed <= 1.6 %). Indices below 16 never occur (the top two
/// bits of a normalised argument are not both zero); they are filled so that the index can be
/// masked instead of bounds-checked.
const RSQRT_SEED: [u16; 64] = {
    let mut table = [0u16; 64];
    let mut i = 0;
    while i < 64 {
        let centre = if i < 16 { 16 } else { i as u64 };
        // 2^14 sqrt(64 / (i + 1/2)) = sqrt(2^35 / (2 i + 1))
        table[i] = ((1u64 << 35) / (2 * centre + 1)).isqrt() as u16;
        i += 1;
    }
    table
};

/// One Newton step for `1/sqrt(x)`, `y <- y + y (1 - x y^2) / 2`: `x` in Q0.32 (value in
/// [1/4, 1)), `y` in Q2.30 (value < 2). Two `UMULL` high words, one subtract, one `SMMLA`.
/// `x y^2` is kept to 2^-28 only: enough, since the Markstein step below needs `y` to 1e-7.
#[inline(always)]
const fn rsqrt_step(x: u32, y: u32) -> u32 {
    let xy = ((x as u64 * y as u64) >> 32) as u32; // x y 2^30
    let xyy = ((xy as u64 * y as u64) >> 32) as u32; // x y^2 2^28, within 3.2 % of 2^28
    let half_err = (1u32 << 31).wrapping_sub(xyy << 3) as i32; // (1 - x y^2)/2 in Q.32
    // y < 2^31 as bits (Newton undershoots 1/sqrt(x) <= 2), so it is a positive i32.
    (y as i32 + ((y as i32 as i64 * half_err as i64) >> 32) as i32) as u32
}

/// Approximate `sqrt(norm)` for `norm` in `[2^62, 2^64)`, as `s0 + ds` (`ds` is returned
/// separately so that each caller adds it with the overflow care it needs). `s0 + ds` is within
/// `[-1.02, +0.02]` of the true root (checked by the tests against `u64::isqrt`).
#[inline(always)]
const fn sqrt_normalized(norm: u64) -> (u32, i32) {
    let x = (norm >> 32) as u32; // Q0.32 in [1/4, 1)
    let mut y = (RSQRT_SEED[(x >> 26) as usize & 63] as u32) << 16; // Q2.30
    y = rsqrt_step(x, y);
    y = rsqrt_step(x, y);
    // s0 = x y ~ sqrt(x) 2^32 = sqrt(norm). Newton undershoots, but the truncations in the
    // steps can leave y a hair high, so clamp rather than trust s0 < 2^32.
    let s0_wide = (x as u64 * y as u64) >> 30;
    let s0 = if s0_wide > u32::MAX as u64 {
        u32::MAX
    } else {
        s0_wide as u32
    };
    // Markstein: s0 is within ~1000 of the root, so |norm - s0^2| < 2^44 and the wrapping
    // difference is the exact signed remainder. ds = d / (2 s0) = d y / 2^63, |ds| < 2^12.
    let d = norm.wrapping_sub(s0 as u64 * s0 as u64) as i64;
    let ds = (((d >> 16) as i32 as i64 * y as i32 as i64) >> 47) as i32;
    (s0, ds)
}

/// `sqrt(x)` within `(-1.51, +0.02]`, clamped below 2^32 (before exactness fix-ups).
/// `x = 0` gives 0.
#[inline(always)]
const fn isqrt_approx(x: u64) -> u32 {
    if x == 0 {
        return 0;
    }
    let half_shift = x.leading_zeros() / 2;
    let (s0, ds) = sqrt_normalized(x << (2 * half_shift));
    // Near u64::MAX the estimate may reach 2^32, one above the largest root.
    s0.saturating_add_signed(ds) >> half_shift
}

/// `sqrt(x 2^32)` for a `u32` (the square root of a Q0.32 fraction, in Q0.32), within
/// `(-1.51, +0.02]`: the fast path used by `asin`, which does not need the last bit exact.
/// Cheaper than the `u64` path: the normalisation is a 32-bit shift and the low word of the
/// normalised argument is zero. `x = 0` gives 0.
#[inline(always)]
pub(crate) const fn sqrt_q32_approx(x: u32) -> u32 {
    if x == 0 {
        return 0;
    }
    let half_shift = x.leading_zeros() / 2;
    let (s0, ds) = sqrt_normalized(((x << (2 * half_shift)) as u64) << 32);
    // The root of x 2^32 <= (2^32 - 1) 2^32 is below 2^32 - 1/2, and s0 + ds exceeds the
    // root by at most 0.02, so the sum stays below 2^32: the add cannot wrap.
    s0.wrapping_add_signed(ds) >> half_shift
}

/// `floor(sqrt(x))`, exact for every `u64`. Cost on Cortex-M4: about 75 instructions, no
/// division, no loop.
#[inline]
pub const fn isqrt_u64(x: u64) -> u32 {
    let mut r = isqrt_approx(x) as u64;
    // The estimate is off by at most one either way; r < 2^32, so r^2 fits in u64.
    if r * r > x {
        r -= 1;
    } else if x - r * r > 2 * r {
        r += 1;
    }
    r as u32
}

impl<const FRAC: u32> Q<FRAC> {
    /// `sqrt(self)` in the same format, correctly rounded (error <= 0.5 ulp). Error: `Domain`
    /// for negative input; never overflows (even in Q1.31 the root of `MAX` rounds to `MAX`).
    /// Cost: about 95 instructions.
    pub const fn sqrt(self) -> Result<Self, FxError> {
        self.sqrt_to::<FRAC>()
    }

    /// `sqrt(self)` in the format `OUT`, correctly rounded from the exact root (error <= 0.5
    /// ulp of `OUT`). Errors: `Domain` for negative input, `Overflow` when the root does not fit
    /// `OUT`. Example: `x.sqrt_to::<31>()` keeps full precision for a Q2.30 ratio below 1.
    pub const fn sqrt_to<const OUT: u32>(self) -> Result<Q<OUT>, FxError> {
        let bits = self.to_bits();
        if bits < 0 {
            return Err(FxError::Domain);
        }
        let x = bits as u64;
        // root * 2^OUT = sqrt(x * 2^(2 OUT - FRAC))
        let e = 2 * OUT as i32 - FRAC as i32;
        let root = if e >= 0 {
            if x > u64::MAX >> e {
                // the root would be >= 2^32
                return Err(FxError::Overflow);
            }
            let m = x << e;
            let r = isqrt_u64(m) as u64;
            // round half up: m >= (r + 1/2)^2 <=> m - r^2 > r (m is an integer)
            r + (m - r * r > r) as u64
        } else {
            // Take j extra bits so the shift is even and non-negative, then round them off:
            // floor then round-half-up of the shifted floor is exact rounding of the root.
            let j = ((1 - e) / 2) as u32;
            let r = isqrt_u64(x << (e + 2 * j as i32)) as u64;
            (r + (1 << (j - 1))) >> j
        };
        if root > i32::MAX as u64 {
            Err(FxError::Overflow)
        } else {
            Ok(Q::<OUT>::from_bits(root as i32))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::q::{Q1_31, Q2_30, Q16_16};
    use super::*;
    use proptest::prelude::*;

    fn check_isqrt(x: u64) {
        assert_eq!(isqrt_u64(x) as u64, x.isqrt(), "isqrt({x:#x})");
    }

    #[test]
    fn isqrt_is_exact_at_squares_and_neighbours() {
        for r in (0u64..=0xFFFF_FFFF)
            .step_by(65_521)
            .chain([0xFFFF_FFFF, 1 << 31, (1 << 31) - 1])
        {
            let sq = r * r;
            check_isqrt(sq);
            check_isqrt(sq.saturating_sub(1));
            check_isqrt(sq.saturating_add(1));
            check_isqrt(sq.saturating_add(2 * r)); // (r+1)^2 - 1
        }
        for k in 0..64 {
            check_isqrt(1u64 << k);
            check_isqrt((1u64 << k) - 1);
            check_isqrt(u64::MAX >> k);
        }
        check_isqrt(u64::MAX);
    }

    #[test]
    fn isqrt_dense_sweep_and_estimate_bound() {
        // Every normalised mantissa class: walk [2^62, 2^64) in 400k steps and check both the
        // exact floor and the documented bound of the estimate.
        let step = (3u64 << 62) / 400_000;
        let mut worst: f64 = 0.0;
        let mut norm = 1u64 << 62;
        for _ in 0..400_000 {
            let (s0, ds) = sqrt_normalized(norm);
            let est = s0 as f64 + ds as f64;
            let exact = (norm as f64).sqrt();
            let err = est - exact;
            worst = worst.max(err.abs());
            assert!(
                (-1.02..=0.02).contains(&err),
                "sqrt({norm:#x}): est {est} exact {exact}"
            );
            check_isqrt(norm);
            check_isqrt(norm >> 17);
            check_isqrt(norm >> 40);
            norm += step;
        }
        assert!(worst < 1.02);
    }

    #[test]
    fn q32_fraction_sqrt_estimate_bound() {
        let mut x: u32 = 1;
        for _ in 0..300_000 {
            // x 2^32 is exact in f64 and its rounded root is within 5e-7 of the true one.
            let exact = (x as f64 * 4294967296.0).sqrt();
            let err = sqrt_q32_approx(x) as f64 - exact;
            assert!(
                (-1.51..=0.02).contains(&err),
                "sqrt_q32_approx({x:#x}) off by {err}"
            );
            x = x.wrapping_mul(69_069).wrapping_add(12_345) | 1;
        }
        assert_eq!(sqrt_q32_approx(0), 0);
        assert!(sqrt_q32_approx(u32::MAX).abs_diff(u32::MAX) <= 1);
    }

    #[test]
    fn fixed_point_sqrt_is_correctly_rounded() {
        assert_eq!(
            Q16_16::from_int(4).unwrap().sqrt(),
            Ok(Q16_16::from_int(2).unwrap())
        );
        assert_eq!(Q16_16::ZERO.sqrt(), Ok(Q16_16::ZERO));
        assert_eq!(Q16_16::from_bits(-1).sqrt(), Err(FxError::Domain));
        assert_eq!(Q2_30::ONE.sqrt(), Ok(Q2_30::ONE));
        // sqrt(1 - 2^-31) * 2^31 = 2^31 - 0.5 - 2^-33: rounds down to MAX.
        assert_eq!(Q1_31::MAX.sqrt(), Ok(Q1_31::MAX));
        assert_eq!(
            Q1_31::from_bits(i32::MAX - 2).sqrt(),
            Ok(Q1_31::from_bits(i32::MAX - 1))
        );
        assert_eq!(Q2_30::ONE.sqrt_to::<31>(), Err(FxError::Overflow));
        assert_eq!(Q16_16::MAX.sqrt_to::<31>(), Err(FxError::Overflow));
        assert_eq!(Q::<0>::MAX.sqrt_to::<0>(), Ok(Q::<0>::from_bits(46341)));
        assert_eq!(Q1_31::ULP.sqrt_to::<0>(), Ok(Q::<0>::ZERO));
        assert_eq!(Q1_31::MAX.sqrt_to::<0>(), Ok(Q::<0>::from_bits(1)));
        // odd negative exponent: Q1.31 -> Q8.24 (e = 17) and Q1.31 -> Q<1> (e = -29)
        let x = Q1_31::from_f64(0.3).unwrap();
        let r = x.sqrt_to::<1>().unwrap();
        assert_eq!(r.to_bits(), (x.to_f64().sqrt() * 2.0).round() as i32);
    }

    /// Exact rounding over dense sweeps of several formats, against f64 (whose correctly
    /// rounded sqrt of a < 2^53 integer is within 2^-20 ulp of ours, far from any tie).
    #[test]
    fn fixed_point_sqrt_dense_sweep() {
        fn sweep<const F: u32, const OUT: u32>() {
            let n = 50_000u64;
            for i in 0..=n {
                let bits = ((i * i32::MAX as u64) / n) as i32;
                let x = Q::<F>::from_bits(bits);
                let exact = x.to_f64().sqrt() * (1u64 << OUT) as f64;
                match x.sqrt_to::<OUT>() {
                    Ok(r) => {
                        let err = (r.to_bits() as f64 - exact).abs();
                        assert!(err <= 0.5 + 1e-6, "sqrt {x:?} -> Q<{OUT}>: {r:?} err {err}");
                    }
                    Err(e) => assert!(e == FxError::Overflow && exact >= i32::MAX as f64),
                }
            }
        }
        sweep::<16, 16>();
        sweep::<30, 30>();
        sweep::<30, 31>();
        sweep::<31, 31>();
        sweep::<0, 16>();
        sweep::<31, 0>();
        sweep::<27, 5>();
    }

    proptest! {
        #[test]
        fn isqrt_matches_core(x in any::<u64>()) {
            prop_assert_eq!(isqrt_u64(x) as u64, x.isqrt());
        }

        #[test]
        fn sqrt_never_panics(bits in any::<i32>()) {
            let _ = Q16_16::from_bits(bits).sqrt();
            let _ = Q::<0>::from_bits(bits).sqrt_to::<31>();
            let _ = Q1_31::from_bits(bits).sqrt_to::<0>();
            let _ = Q1_31::from_bits(bits).sqrt();
            if let Ok(r) = Q2_30::from_bits(bits).sqrt() {
                let exact = Q2_30::from_bits(bits).to_f64().sqrt();
                let tol = 0.5 * Q2_30::ULP.to_f64() * (1.0 + 1e-6);
                prop_assert!((r.to_f64() - exact).abs() <= tol);
            }
        }
    }
}
