//! Exponential: `e^-x` for the Dahl decay and the cube-model weights, and `e^x` of either sign
//! with overflow detection.
//!
//! `e^-x` ([`Q::exp_neg`], the hot path) uses a table and a short polynomial. For `x` in
//! [0, 2), `j = floor(32 x)` picks `E_j = e^-(j+1)/32` (Q.32, 64 entries, each within 0.5 unit)
//! and `v = (j + 1)/32 - x` in (0, 1/32] is exact in Q.34, so `e^-x = E_j e^v` with
//! `e^v = 1 + q(v)`, `q(v) = v + v^2 (1/2 + c3 v + c4 v^2)`: a minimax fit with `1/2` and `c4`
//! pinned to values a single instruction loads, `c3` refitted (error 1.0e-11 = 0.011 ulp of
//! Q2.30 over (0, 1/32]). `E_j (1 + q)` is formed as `E_j + floor(E_j q)` in Q.32, and the only
//! rounding is the last one, to Q2.30. Beyond 2 (coarse formats only), `x = k ln2 + r` with
//! `r` in [0, ln2) exact to 2^-40, and the same core gives `e^-r` before a shift by `k`.
//!
//! `e^y` of either sign ([`Q::exp`]): `y = k ln2 + r` with `k = round(y / ln2)` and
//! `|r| <= ln2 / 2`, then `e^y = 2^k (1 + r + r^2 s(r))` where `s` is a degree-5 weighted minimax
//! fit of `(e^r - 1 - r) / r^2` (relative error of the bracket 1.0e-10). `1 + r` is kept exact so
//! that `e^0 = 1` exactly and small arguments keep their precision. The reduction subtracts
//! `k ln2` with ln2 to 2^-40, so `r` is exact to 2^-33 for any input.
//!
//! The coefficients came from Remez exchanges run offline in double precision (for `s`: weight
//! `r^2 e^-r`, |r| <= 0.3466; for `q`: weight `v^2`, v in [0, 1/32]) and were rounded to the
//! formats below; the dense sweeps below are what vouches for them.

use super::ctmath::{LN2_Q40, LN2_Q62};
use super::error::FxError;
use super::q::{Q, Q2_30};
use super::raw::{mul_hi, mul_hi_round};

/// 1/ln2 in Q2.30, for the range reduction.
const INV_LN2_Q30: i64 = Q2_30::from_f64_const(core::f64::consts::LOG2_E).to_bits() as i64;
/// ln2 in Q.32 (as the low word of `k ln2`) and the rest of ln2 to 2^-40:
/// `ln2 2^40 = LN2_Q32 2^8 + LN2_RESIDUE_Q40`.
const LN2_Q32: u32 = ((LN2_Q62 + (1 << 29)) >> 30) as u32;
const LN2_RESIDUE_Q40: i32 = (LN2_Q40 - ((LN2_Q32 as i64) << 8)) as i32;
/// Q.32 coefficients `a1..a5` of `s(r) = (e^r - 1 - r) / r^2 = a0 + a1 r + ... + a5 r^5`
/// (about 1/6, 1/24, 1/120, 1/720, 1/5040), and `a0 - 1/2` (about 1.6e-8) in Q.32.
const S_COEFFS: [i32; 5] = [715827887, 178955141, 35791191, 5990874, 855024];
const S0_MINUS_HALF: i32 = 35;

/// `e^v` for `v` in series form, `|v| <= 2` (compile time only: the table below). The terms
/// fall below 2^-60 of the sum long before the 40th.
const fn exp_series(v: f64) -> f64 {
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1;
    while k < 40 {
        term = term * v / k as f64;
        sum += term;
        k += 1;
    }
    sum
}

/// `E_j = round(e^-(j+1)/32 2^32)` for `j` in `0..64` (x in [0, 2) in steps of 1/32); every
/// entry lies in (0.13, 0.97) of 2^32. Generated at compile time.
const EXP_NEG_STEPS: [u32; 64] = {
    let mut table = [0u32; 64];
    let mut j = 0;
    while j < 64 {
        let e = exp_series(-((j + 1) as f64) / 32.0);
        table[j] = (e * 4294967296.0 + 0.5) as u32;
        j += 1;
    }
    table
};
/// `q(v) = v + v^2 (Q_C2 + Q_C3 v + Q_C4 v^2) ~ e^v - 1` on (0, 1/32]: `1/2` in Q.30, the
/// refitted `c3 ~ 1/6` in Q.28 and `c4 = 172 2^-12 ~ 1/24` in Q.26 (both pinned constants load
/// with one `MOV`). The formats step by 2 bits per Horner step because `v` is in Q.34.
const Q_C2: i32 = 1 << 29;
const Q_C3: i32 = 44_738_624;
const Q_C4: i32 = 0xAC << 14;
/// ceil(31 ln2 2^32): from here on `e^-x <= 2^-31`, which rounds to 0 in Q2.30.
const EXP_NEG_ZERO_FROM_Q32: u64 = ((31 * LN2_Q62 as i128 + (1 << 30) - 1) >> 30) as u64;
/// 1/ln2 in Q.30 rounded down, so that the reduction's `k` never exceeds `floor(x / ln2)`.
const INV_LN2_Q30_FLOOR: u64 = 1_549_082_004;

/// `E_j (1 + q(v))` in Q.32 (floor) for `j = floor(32 x)` in `0..64` and the low bits of
/// `x > 0` in Q.32 (`x_low = x 2^32 mod 2^32`), which give `v = (j + 1)/32 - x` in (0, 1/32]:
/// exactly `2^29 - (x_low mod 2^27) 2^2` in Q.34. (At x = 0 the product would be 2^32, one
/// past the range: the callers answer that case themselves.)
///
/// The Horner steps run on `-v` with `-c3`: the products are the same, and with a multiplier
/// of unknown sign each step is one `SMMLA` (for operands known to be positive the compiler
/// picks `UMULL` and an add).
#[inline(always)]
const fn exp_neg_core(j: usize, x_low: u32) -> u32 {
    let e = EXP_NEG_STEPS[j & 63];
    let minus_v = (((x_low << 5) >> 3) as i32) - (1 << 29); // -v in Q.34, in [-2^29, -2^2]
    let minus_c3 = mul_hi(minus_v, Q_C4) - Q_C3; // -(c3 + c4 v) in Q.28 (floor of -c4 v)
    let w = Q_C2 + mul_hi(minus_v, minus_c3); // 1/2 + c3 v + c4 v^2 in Q.30
    let minus_vw = mul_hi(minus_v, w); // -v w in Q.32, > -2^26
    let q = mul_hi_round(minus_v, minus_vw) - minus_v; // v + v^2 w = e^v - 1 in Q.34, < 2^30
    // E_j + floor(E_j q 2^-34) < 2^32 for x > 0 (the error bound leaves room: tested).
    e + ((e as u64 * q as u64) >> 34) as u32
}

/// `round(e^y * 2^out)` for `y` in Q.32 (any `i64`), or `Overflow`.
#[inline(always)]
const fn exp_q32(y: i64, out: u32) -> Result<i32, FxError> {
    if y < -(64i64 << 32) {
        return Ok(0); // e^-64 < 2^-92: zero in every format
    }
    if y > 22i64 << 32 {
        return Err(FxError::Overflow); // e^22 > 2^31: beyond every format
    }
    // k = round(y / ln2) from y in Q.24 (|y| <= 64 fits an i32); the truncation only moves |r|
    // past ln2/2 by ~1e-7, inside the fitted interval.
    let y24 = (y >> 8) as i32;
    let k = ((y24 as i64 * INV_LN2_Q30 + (1 << 53)) >> 54) as i32; // |k| <= 93
    // r = y - k ln2 in Q.32. |r| < 2^31 units, so the low words alone give y - k LN2_Q32
    // exactly (the wrapping arithmetic is modulo 2^32 on purpose); the residue of ln2 below
    // 2^-32 is added back to 2^-40 (|k residue| < 2^13).
    let r_hi = (y as u32).wrapping_sub((k as u32).wrapping_mul(LN2_Q32)) as i32;
    let r = r_hi + ((128 - k * LN2_RESIDUE_Q40) >> 8); // Q.32, |r| <= 0.3466
    // s(r) - 1/2 by Horner in Q.32: one SMMULR and one add per step.
    let mut t = S_COEFFS[4];
    t = S_COEFFS[3] + mul_hi_round(r, t);
    t = S_COEFFS[2] + mul_hi_round(r, t);
    t = S_COEFFS[1] + mul_hi_round(r, t);
    t = S_COEFFS[0] + mul_hi_round(r, t);
    let s_minus_half = S0_MINUS_HALF + mul_hi_round(r, t);
    // r s = r/2 + r (s - 1/2); its error (< 2^-32) is multiplied by r < 0.35 below.
    let r_s = (r >> 1) + mul_hi_round(r, s_minus_half); // Q.32, |r s| < 0.2
    let p_minus_1 = r + mul_hi_round(r, r_s); // Q.32: e^r - 1 = r + r^2 s, in [-0.30, 0.42]
    // Result bits = p 2^(k + out - 32) with p = 2^32 + p_minus_1 < 2^33. Work on
    // half = floor(p / 2), a u32: for shifts >= 2 dropping p's last bit never changes the
    // round-half-up result, since floor((floor(p/2) + 2^(n-2)) / 2^(n-1)) = round(p / 2^n).
    let half = (1u32 << 31).wrapping_add_signed(p_minus_1 >> 1);
    let shift = 32 - out as i32 - k;
    if shift <= 0 {
        Err(FxError::Overflow) // p >= 0.7 * 2^32 > 2^31
    } else if shift == 1 {
        // round(p / 2) = floor(p / 2) + last bit of p
        let rounded = half as u64 + (p_minus_1 & 1) as u64;
        if rounded > i32::MAX as u64 {
            Err(FxError::Overflow)
        } else {
            Ok(rounded as i32)
        }
    } else if shift >= 34 {
        Ok(0) // p < 2^33, so p / 2^shift < 1/2
    } else {
        // (half >> (shift - 2)) + 1 <= 2^32 - 1 and the result is below 2^31.
        Ok((((half >> (shift - 2)) + 1) >> 1) as i32)
    }
}

impl<const FRAC: u32> Q<FRAC> {
    /// `e^-x` for `x = self >= 0`, in Q2.30 (exact 1.0 at x = 0, graceful underflow to 0 for
    /// x > 21.5). Accepts any input format: pass `kappa |dx|` in the finest format that holds
    /// it (Q2.30 for per-step Dahl arguments below 2, Q16.16 up to 32767).
    ///
    /// Error < 0.75 ulp of Q2.30 (7e-10 absolute; 0.65 ulp measured over every Q2.30 input
    /// and every Q16.16 input below 24, 0.73 before the table form): the final rounding, the
    /// table's rounding (<= 0.125 ulp) and the polynomial's (<= 0.05 ulp). Error: `Domain` for
    /// negative `x`. Cost: about 25 instructions for inputs below 2 (table and degree-4
    /// polynomial, module docs), about 40 with the reduction by `k ln2` beyond; no division.
    #[inline]
    pub const fn exp_neg(self) -> Result<Q2_30, FxError> {
        match self.exp_neg_parts() {
            // round(m 2^-(k + 2)), half up; k + 1 <= 31
            Ok((m, k)) => Ok(Q2_30::from_bits((((m >> (k + 1)) + 1) >> 1) as i32)),
            Err(e) => Err(e),
        }
    }

    /// `e^-x` as `(m, k)`: `e^-x ~ m 2^-(32 + k)`, for `x = self >= 0`, with `m` the floor
    /// of the computed `E_j (1 + q)` in Q.32 (so that `round(m 2^-n)` for `n >= 1` is the
    /// correctly rounded value of that product: a single rounding) and `k` in `0..=30`. `x = 0`
    /// gives `m = 2^32 - 1` (1 - 2^-32: the one value `m` cannot hold exactly); `x >= 31 ln2`
    /// gives `(0, 0)`. Error `Domain` for negative `x`.
    ///
    /// Error of `m 2^-(32 + k)` against `e^-x`, in units of `2^-(32 + k)`: within [-1.7, +0.7]
    /// for x < 2 (the table's rounding <= 0.5, `q`'s <= 0.16 and its fit 0.04, and the floor;
    /// [-1.59, +0.57] measured), and within [-2.3, +1.3] beyond (the reduced `r` adds <= 0.6).
    /// The Dahl update uses it to multiply by the decay and round once.
    #[inline(always)]
    pub(crate) const fn exp_neg_parts(self) -> Result<(u32, u32), FxError> {
        let bits = self.to_bits();
        if bits < 0 {
            return Err(FxError::Domain);
        }
        let x_q32 = (bits as u64) << (32 - FRAC); // x in Q.32, exact (< 2^63)
        if bits == 0 {
            return Ok((u32::MAX, 0));
        }
        if FRAC >= 30 || x_q32 < 2 << 32 {
            // 0 < x < 2: no reduction (the only path for Q2.30 and Q1.31 inputs).
            return Ok((exp_neg_core((x_q32 >> 27) as usize, x_q32 as u32), 0));
        }
        if x_q32 >= EXP_NEG_ZERO_FROM_Q32 {
            return Ok((0, 0));
        }
        // k = floor(x / ln2) or one less (x / ln2 within 1.2e-7 above an integer), from x in
        // Q.24 (< 2^29) and 1/ln2 rounded down: k <= 30, and r = x - k ln2 lies in
        // (-2^-32, ln2 + 1e-7).
        let k = (((x_q32 >> 8) * INV_LN2_Q30_FLOOR) >> 54) as u32;
        // r in Q.32: the low words alone give x - k LN2_Q32 exactly (|r| < 2^32, wrapping on
        // purpose), then the residue of ln2 below 2^-32 (|k residue| < 2^12) is taken off.
        let r_hi = (x_q32 as u32).wrapping_sub(k.wrapping_mul(LN2_Q32));
        let r = r_hi.wrapping_add_signed((128 - k as i32 * LN2_RESIDUE_Q40) >> 8);
        // r = 0, or a rounding step below it (at most 2^-32, wrapped to the top of the range):
        // e^-r is 1 to within 2^-32.
        if r == 0 || r >= 3 << 30 {
            return Ok((u32::MAX, k));
        }
        Ok((exp_neg_core((r >> 27) as usize, r), k))
    }

    /// `e^x` for `x = self` of either sign, in the format `OUT`.
    ///
    /// Error <= 1 ulp of `OUT` or 1.5e-9 relative, whichever is larger (the bracket carries
    /// 2^-32 relative precision; large results in coarse formats are shifted up). Results
    /// below half an ulp round to 0. Error: `Overflow` when `e^x` does not fit `OUT` (e.g.
    /// x >= 10.39721 = ln 32768 for Q16.16, x >= ln 2 for Q2.30). Cost: about 50 instructions.
    pub const fn exp<const OUT: u32>(self) -> Result<Q<OUT>, FxError> {
        let y = (self.to_bits() as i64) << (32 - FRAC);
        match exp_q32(y, OUT) {
            Ok(bits) => Ok(Q::<OUT>::from_bits(bits)),
            Err(e) => Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::q::{Q1_31, Q16_16};
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn constants_are_right() {
        assert_eq!(INV_LN2_Q30, 1549082005);
        // ln2 * 2^32 = 2977044471.82..., ln2 * 2^40 = 762123384786.43...
        assert_eq!(LN2_Q32, 2977044472);
        assert_eq!(LN2_RESIDUE_Q40 as i64, 762123384786 - 2977044472 * 256);
        // The fitted s(r) starts like the Taylor series 1/2 + r/6 + r^2/24 + ...
        let a1 = S_COEFFS[0] as f64 / 4294967296.0;
        assert!((a1 - 1.0 / 6.0).abs() < 1e-8 && S0_MINUS_HALF.abs() < 100);
    }

    #[test]
    fn exp_neg_table_and_constants_are_right() {
        // Every step value within half a unit of e^-(j+1)/32 in Q.32 (f64 carries 2^-20 unit).
        for (j, &e) in EXP_NEG_STEPS.iter().enumerate() {
            let exact = (-((j + 1) as f64) / 32.0).exp() * 4294967296.0;
            assert!(
                (e as f64 - exact).abs() <= 0.5 + 1e-5,
                "step {j}: {e} vs {exact}"
            );
        }
        // 1/ln2 rounded down; 31 ln2 rounded up (31 ln2 2^32 = 92288378626.41...).
        assert_eq!(INV_LN2_Q30_FLOOR, INV_LN2_Q30 as u64 - 1);
        assert!((INV_LN2_Q30_FLOOR as f64) < (1u64 << 30) as f64 / core::f64::consts::LN_2);
        assert_eq!(EXP_NEG_ZERO_FROM_Q32, 92288378627);
        // The pinned and refitted coefficients: near the Taylor values 1/2, 1/6 and 1/24.
        assert_eq!(Q_C2, 1 << 29);
        assert!((Q_C3 as f64 / (1u64 << 28) as f64 - 1.0 / 6.0).abs() < 2e-4);
        assert!((Q_C4 as f64 / (1u64 << 26) as f64 - 1.0 / 24.0).abs() < 1e-3);
    }

    /// The polynomial core against `e^v` over its whole interval, in units of Q.32 (the
    /// documented [-1.7, +0.7] error of `m`), including both ends of each 1/32 step.
    #[test]
    fn exp_neg_core_error_in_q32_units() {
        let (mut lo, mut hi) = (0.0f64, 0.0f64);
        for j in 0..64usize {
            for i in (0..(1u32 << 27)).step_by(4099).chain([1, 2, (1 << 27) - 1]) {
                if j == 0 && i == 0 {
                    continue; // x = 0 never reaches the core
                }
                let x_low = ((j as u32) << 27) | i; // x = (j + i 2^-27) / 32, in Q.32 mod 1
                let x = (j as f64 + i as f64 / (1u64 << 27) as f64) / 32.0;
                let got = exp_neg_core(j, x_low) as f64;
                let err = got - (-x).exp() * 4294967296.0;
                lo = lo.min(err);
                hi = hi.max(err);
            }
        }
        eprintln!("exp_neg core: error of m in [{lo:.3}, {hi:.3}] units of 2^-32");
        assert!(lo >= -1.7 && hi <= 0.7, "[{lo}, {hi}]");
        // The smallest x keep below 2^32 (x = 0 itself is answered before the core).
        assert!(exp_neg_core(0, 1) >= u32::MAX - 2);
        assert_eq!(Q1_31::ZERO.exp_neg_parts(), Ok((u32::MAX, 0)));
        assert_eq!(
            Q16_16::from_bits(1 << 16).exp_neg_parts().map(|p| p.1),
            Ok(0)
        );
    }

    #[test]
    fn exp_neg_exact_points_and_extremes() {
        assert_eq!(Q16_16::ZERO.exp_neg(), Ok(Q2_30::ONE));
        assert_eq!(Q1_31::ZERO.exp_neg(), Ok(Q2_30::ONE));
        assert_eq!(Q16_16::from_bits(-1).exp_neg(), Err(FxError::Domain));
        assert_eq!(Q16_16::MAX.exp_neg(), Ok(Q2_30::ZERO));
        assert_eq!(Q::<0>::MAX.exp_neg(), Ok(Q2_30::ZERO));
        assert_eq!(Q16_16::from_int(22).unwrap().exp_neg(), Ok(Q2_30::ZERO));
        // e^-20 = 2.06e-9 = 2.2 ulps
        assert_eq!(
            Q16_16::from_int(20).unwrap().exp_neg(),
            Ok(Q2_30::from_bits(2))
        );
        assert_eq!(
            Q16_16::LN_2.exp_neg().unwrap().to_bits(),
            (0.5f64.powf(Q16_16::LN_2.to_f64() / core::f64::consts::LN_2) * (1u64 << 30) as f64)
                .round() as i32
        );
        // one ulp of Q1.31 input: e^-(2^-31) = 1 - 4.7e-10 rounds to 1 - 1 ulp or 1
        assert!(Q1_31::ULP.exp_neg().unwrap().to_bits() >= (1 << 30) - 1);
        // Around the underflow threshold 31 ln2 = 21.4875 (e^-x = 2^-31, half an ulp) and the
        // start of the reduction at x = 2 (Q16.16 and Q<0> inputs).
        assert_eq!(Q16_16::from_f64(21.48).unwrap().exp_neg(), Ok(Q2_30::ULP));
        assert_eq!(Q16_16::from_f64(21.49).unwrap().exp_neg(), Ok(Q2_30::ZERO));
        for bits in [(2 << 16) - 1, 2 << 16, (2 << 16) + 1] {
            let x = Q16_16::from_bits(bits);
            let want = (-x.to_f64()).exp() * (1u64 << 30) as f64;
            let got = x.exp_neg().unwrap().to_bits() as f64;
            assert!((got - want).abs() <= 0.75, "{x:?}");
        }
        assert_eq!(
            Q::<0>::from_bits(1).exp_neg().map(Q2_30::to_bits),
            Ok(395_007_542)
        );
    }

    fn max_err_ulps<const F: u32>(start: i32, end: i32, step: usize) -> f64 {
        let mut worst: f64 = 0.0;
        for bits in (start..=end).step_by(step) {
            let x = Q::<F>::from_bits(bits);
            let got = x.exp_neg().unwrap().to_bits() as f64;
            let exact = (-x.to_f64()).exp() * (1u64 << 30) as f64;
            worst = worst.max((got - exact).abs());
        }
        worst
    }

    #[test]
    fn exp_neg_dense_sweeps() {
        // Q16.16: every input in [0, 24) (1.57 million points).
        let q16 = max_err_ulps::<16>(0, 24 << 16, 1);
        // Q2.30: [0, 2) in 500k steps, and the first 100k ulps.
        let q30 = max_err_ulps::<30>(0, i32::MAX, 4295);
        let q30_small = max_err_ulps::<30>(0, 100_000, 1);
        // Q2.30 within 64 ulps of each 1/32 step (both sides of every table switch), and 2.
        let mut q30_steps: f64 = 0.0;
        for j in 1..64 {
            q30_steps = q30_steps.max(max_err_ulps::<30>((j << 25) - 64, (j << 25) + 64, 1));
        }
        // Q1.31 near 0 and Q<0> integers.
        let q31_small = max_err_ulps::<31>(0, 100_000, 1);
        let q0 = max_err_ulps::<0>(0, 40, 1);
        let worst = q16
            .max(q30)
            .max(q30_small)
            .max(q30_steps)
            .max(q31_small)
            .max(q0);
        eprintln!(
            "exp_neg max error ulps: q16 {q16} q30 {q30} q30_small {q30_small} \
             q30_steps {q30_steps} q31_small {q31_small} q0 {q0}"
        );
        assert!(worst <= 0.75, "exp_neg max error {worst} ulps");
    }

    #[test]
    fn exp_both_signs_into_several_formats() {
        fn sweep<const F: u32, const OUT: u32>(lo: f64, hi: f64, n: usize) -> f64 {
            let mut worst: f64 = 0.0;
            for i in 0..=n {
                let x = Q::<F>::from_f64(lo + (hi - lo) * i as f64 / n as f64).unwrap();
                let exact = x.to_f64().exp();
                let scaled = exact * (1u64 << OUT) as f64;
                match x.exp::<OUT>() {
                    Ok(v) => {
                        let err = (v.to_bits() as f64 - scaled).abs() / scaled.max(1.0);
                        let tol = 1.0f64.max(1.5e-9 * scaled);
                        worst = worst.max((v.to_bits() as f64 - scaled).abs() / tol);
                        assert!(err.is_finite());
                    }
                    Err(e) => {
                        assert_eq!(e, FxError::Overflow);
                        assert!(
                            scaled >= i32::MAX as f64 - 1.0,
                            "exp({x:?}) -> Q<{OUT}> should fit"
                        );
                    }
                }
            }
            worst
        }
        let worst = [
            sweep::<16, 16>(-12.0, 10.5, 200_000),
            sweep::<24, 16>(-30.0, 10.39, 200_000),
            sweep::<16, 30>(-25.0, 0.7, 200_000),
            sweep::<27, 0>(-1.0, 15.99, 100_000),
            sweep::<30, 31>(-2.0, 0.0, 100_000),
        ]
        .into_iter()
        .fold(0.0f64, f64::max);
        eprintln!("exp: worst {worst} of the bound");
        assert!(worst <= 1.0, "exp error {worst} of the documented bound");
        assert_eq!(
            Q16_16::from_f64(10.3973).unwrap().exp::<16>(),
            Err(FxError::Overflow)
        );
        assert!(Q16_16::from_f64(10.397).unwrap().exp::<16>().is_ok());
        assert_eq!(Q16_16::MAX.exp::<0>(), Err(FxError::Overflow));
        assert_eq!(Q16_16::MIN.exp::<31>(), Ok(Q1_31::ZERO));
        assert_eq!(Q16_16::ZERO.exp::<31>(), Err(FxError::Overflow));
        assert_eq!(Q16_16::ZERO.exp::<30>(), Ok(Q2_30::ONE));
        assert_eq!(Q16_16::ZERO.exp::<0>().map(Q::to_bits), Ok(1));
    }

    proptest! {
        #[test]
        fn exp_never_panics(bits in any::<i32>()) {
            let _ = Q16_16::from_bits(bits).exp_neg();
            let _ = Q::<0>::from_bits(bits).exp_neg();
            let _ = Q1_31::from_bits(bits).exp_neg();
            let _ = Q::<0>::from_bits(bits).exp::<31>();
            let _ = Q::<0>::from_bits(bits).exp::<0>();
            let _ = Q1_31::from_bits(bits).exp::<31>();
            let _ = Q16_16::from_bits(bits).exp::<16>();
        }
    }
}
