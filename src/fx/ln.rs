//! Natural logarithm of a positive value of any format or scale, into the caller's format.
//!
//! Method: `x = m 2^e` with `m` in [1, 2) (CLZ normalisation; a `u64` mantissa is rounded to
//! 32 bits). A 64-entry table gives `r ~ 1/m` on the 1/64-wide interval holding `m`, so
//! `u = m r - 1` is within 2^-7 of 0, and `ln x = e ln2 - ln r + ln(1 + u)`, with `ln(1 + u)`
//! from its Taylor series to `u^4` (truncation < 6e-12). No division. `e ln2` uses ln2 to
//! 2^-46. Internal error below 8e-10 before the final rounding to the output format.

use super::ctmath::{LN2_Q62, ln_f64, to_fixed_u32};
use super::error::FxError;
use super::q::Q;
use super::raw::{self, mul_hi, mul_hi_round};

/// `r_j = round(2^32 / (1 + (j + 1/2) / 64)) = round(2^39 / (129 + 2 j))`: Q0.32 reciprocals of
/// the interval centres.
const RECIP: [u32; 64] = {
    let mut table = [0u32; 64];
    let mut j = 0;
    while j < 64 {
        let d = 129 + 2 * j as u64;
        // round(2^39 / d) = ceil(floor(2^40 / d) / 2)
        table[j] = ((1u64 << 40) / d).div_ceil(2) as u32;
        j += 1;
    }
    table
};

/// `-ln(r_j / 2^32)` in Q0.32, for the rounded `r_j` actually stored (so the table pair is
/// self-consistent), computed at compile time.
const LN_INV_RECIP: [u32; 64] = {
    let mut table = [0u32; 64];
    let mut j = 0;
    while j < 64 {
        let centre = 4294967296.0 / RECIP[j] as f64;
        table[j] = to_fixed_u32(ln_f64(centre), 32);
        j += 1;
    }
    table
};

/// ln 2 in Q.46: `e ln2` for |e| <= 2^15 + 64 stays below 2^62 and is exact to 2^-32.
const LN2_Q46: i64 = (LN2_Q62 + (1 << 15)) >> 16;

/// Taylor coefficients of `ln(1 + u)` in Q.31, computed exactly (1/3 truncated by 2^-33).
const HALF_Q31: i32 = 1 << 30;
const THIRD_Q31: i32 = ((1i64 << 31) / 3) as i32;
const QUARTER_Q31: i32 = 1 << 29;

/// `ln(m 2^e)` in Q.32 for `m` in Q1.31 with its top bit set (value in [1, 2)).
#[inline(always)]
const fn ln_q32(m: u32, e: i32) -> i64 {
    let j = ((m >> 25) & 63) as usize;
    // m r in Q1.63 is within 2^-7 of 1: the wrapping difference is the exact signed u.
    let u63 = (m as u64 * RECIP[j] as u64).wrapping_sub(1 << 63) as i64;
    let u = ((u63 + (1 << 30)) >> 31) as i32; // Q.32, |u| < 0.0078 * 2^32
    // ln(1 + u) = u - u w with w = u (1/2 - u (1/3 - u/4)): one SMMUL(S) per step.
    let mut t = THIRD_Q31 - mul_hi(u, QUARTER_Q31); // Q.31
    t = HALF_Q31 - mul_hi(u, t); // Q.31
    let w = mul_hi(u, t); // Q.31, |w| < 0.004
    let ln_1pu = u - mul_hi_round(u, w << 1); // Q.32
    let e_ln2 = (e as i64 * LN2_Q46 + (1 << 13)) >> 14; // Q.32
    e_ln2 + LN_INV_RECIP[j] as i64 + ln_1pu as i64
}

/// `ln(mantissa * 2^exp2)` in the format `OUT`, rounded to nearest.
///
/// Accepts any positive value given as an integer and a binary exponent: a `Q<F>` raw value
/// (`exp2 = -F`), an ADC count, a load in millinewtons (`ln_scaled(load_mn, 0)` minus
/// `ln 1000`), a 64-bit wide quantity. Error <= 0.5 ulp of `OUT` + 8e-10 (Q5.27: 4.5e-9;
/// Q6.26: 8.3e-9; Q16.16: 7.6e-6). Errors: `Domain` for `mantissa == 0`, `Overflow` when the
/// logarithm does not fit `OUT`. Usable in `const` items. Cost: about 55 instructions (plus
/// about 15 for a mantissa wider than 32 bits).
pub const fn ln_scaled<const OUT: u32>(mantissa: u64, exp2: i16) -> Result<Q<OUT>, FxError> {
    if mantissa == 0 {
        return Err(FxError::Domain);
    }
    let lz = mantissa.leading_zeros();
    let norm = mantissa << lz;
    let mut m = (norm >> 32) as u32; // Q1.31 in [1, 2)
    let mut e = exp2 as i32 + 63 - lz as i32;
    if (norm as u32) >= 1 << 31 {
        // round the dropped low word (ties up); 2.0 renormalises to 1.0 * 2
        if m == u32::MAX {
            m = 1 << 31;
            e += 1;
        } else {
            m += 1;
        }
    }
    match raw::rescale(ln_q32(m, e), 32 - OUT as i32) {
        Ok(bits) => Ok(Q::<OUT>::from_bits(bits)),
        Err(err) => Err(err),
    }
}

impl<const FRAC: u32> Q<FRAC> {
    /// `ln(self)` in the format `OUT`, rounded to nearest. Error <= 0.5 ulp of `OUT` + 8e-10
    /// (see [`ln_scaled`]). Errors: `Domain` for `self <= 0`, `Overflow` when the result does
    /// not fit `OUT`. Example: `load.ln::<26>()` for a Q16.16 load. Cost: about 50 instructions
    /// (a positive `i32` normalises exactly, without 64-bit work).
    pub const fn ln<const OUT: u32>(self) -> Result<Q<OUT>, FxError> {
        let bits = self.to_bits();
        if bits <= 0 {
            return Err(FxError::Domain);
        }
        // A positive i32 normalises exactly into Q1.31: no rounding, no 64-bit work.
        let lz = (bits as u32).leading_zeros();
        let m = (bits as u32) << lz;
        let e = 31 - lz as i32 - FRAC as i32;
        match raw::rescale(ln_q32(m, e), 32 - OUT as i32) {
            Ok(bits) => Ok(Q::<OUT>::from_bits(bits)),
            Err(err) => Err(err),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::q::{Q1_31, Q2_30, Q5_27, Q6_26, Q16_16};
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn tables_are_consistent() {
        for j in 0..64 {
            let centre = 1.0 + (j as f64 + 0.5) / 64.0;
            assert!((RECIP[j] as f64 / 4294967296.0 - 1.0 / centre).abs() < 2.5e-10);
            let want = (4294967296.0 / RECIP[j] as f64).ln() * 4294967296.0;
            assert!(
                (LN_INV_RECIP[j] as f64 - want).abs() <= 0.5 + 1e-6,
                "j = {j}"
            );
        }
    }

    #[test]
    fn exact_points_and_errors() {
        assert_eq!(Q16_16::ONE.ln::<27>(), Ok(Q5_27::ZERO));
        assert_eq!(ln_scaled::<26>(1, 0), Ok(Q6_26::ZERO));
        assert_eq!(ln_scaled::<26>(1 << 40, -40), Ok(Q6_26::ZERO));
        assert_eq!(ln_scaled::<26>(u64::MAX, -64), Ok(Q6_26::ZERO));
        assert_eq!(Q16_16::ZERO.ln::<27>(), Err(FxError::Domain));
        assert_eq!(Q16_16::from_bits(-5).ln::<27>(), Err(FxError::Domain));
        assert_eq!(ln_scaled::<16>(0, 3), Err(FxError::Domain));
        assert_eq!(ln_scaled::<27>(2, 0), Ok(Q5_27::LN_2));
        assert_eq!(ln_scaled::<30>(1, 1), Ok(Q2_30::LN_2));
        // ln(2^-31) = -21.5 does not fit Q5.27 but fits Q6.26
        assert_eq!(Q1_31::ULP.ln::<27>(), Err(FxError::Overflow));
        assert!(Q1_31::ULP.ln::<26>().is_ok());
        // Largest magnitudes: ln(u64::MAX 2^32767) = 22756.5 and ln(2^-32768) = -22713.0.
        let big = ln_scaled::<16>(u64::MAX, i16::MAX).unwrap().to_f64();
        let want = (i16::MAX as f64 + 64.0) * core::f64::consts::LN_2;
        assert!(
            (big - want).abs() <= 0.5 / 65536.0 + 8e-10,
            "{big} vs {want}"
        );
        let small = ln_scaled::<16>(1, i16::MIN).unwrap().to_f64();
        let want = i16::MIN as f64 * core::f64::consts::LN_2;
        assert!(
            (small - want).abs() <= 0.5 / 65536.0 + 8e-10,
            "{small} vs {want}"
        );
        assert_eq!(ln_scaled::<17>(1, i16::MIN), Err(FxError::Overflow));
        const LN_1000: Q6_26 = Q6_26::expect_const(ln_scaled(1000, 0));
        assert!((LN_1000.to_f64() - 1000f64.ln()).abs() < 0.5 / (1u64 << 26) as f64 + 8e-10);
    }

    /// Internal accuracy, measured in Q1.31-sized units through a Q<31> output near ln = 0 and
    /// through Q6.26 over the full range of Q16.16 and Q2.30 inputs.
    #[test]
    fn ln_dense_sweeps() {
        let mut worst: f64 = 0.0; // absolute error minus the output half-ulp
        // Every mantissa class: x in [1, 2) as Q2.30 in 400k steps, output Q2.30.
        for i in 0..400_000u32 {
            let bits = (1 << 30) + (i as u64 * (1u64 << 30) / 400_000) as i32;
            let x = Q2_30::from_bits(bits);
            let got = x.ln::<30>().unwrap().to_f64();
            worst = worst.max((got - x.to_f64().ln()).abs() - 0.5 / (1u64 << 30) as f64);
        }
        // Q16.16 inputs over the whole positive range into Q5.27 (ln from -11.1 to 10.4).
        for i in 1..=300_000u64 {
            let bits = ((i * i * (i32::MAX as u64 / 300_000)) / 300_000).max(1) as i32;
            let x = Q16_16::from_bits(bits);
            let got = x.ln::<27>().unwrap().to_f64();
            worst = worst.max((got - x.to_f64().ln()).abs() - 0.5 / (1u64 << 27) as f64);
        }
        // Loads from 1 mN to 50 kN as integer millinewtons, minus ln 1000, into Q6.26.
        let ln_1000 = ln_scaled::<26>(1000, 0).unwrap();
        for i in 0..200_000u64 {
            let load_mn = 1 + i * i * 5 / 4_000; // 1 .. 5e7 mN, denser at low loads
            let ln_load = ln_scaled::<26>(load_mn, 0)
                .unwrap()
                .checked_sub(ln_1000)
                .unwrap();
            let exact = (load_mn as f64 / 1000.0).ln();
            // two roundings to Q6.26
            worst = worst.max((ln_load.to_f64() - exact).abs() - 1.0 / (1u64 << 26) as f64);
        }
        // Loads from 1 mN to 50 kN carried as Q32.32 newtons in a u64, log-spaced.
        let mut load_n = 1e-3f64;
        while load_n <= 5e4 {
            let raw = (load_n * 4294967296.0).round() as u64;
            let got = ln_scaled::<26>(raw, -32).unwrap().to_f64();
            let exact = (raw as f64 / 4294967296.0).ln();
            worst = worst.max((got - exact).abs() - 0.5 / (1u64 << 26) as f64);
            load_n *= 1.0001;
        }
        eprintln!("ln: worst error beyond output rounding {worst:e}");
        assert!(worst <= 8e-10, "ln internal error {worst:e}");
    }

    proptest! {
        #[test]
        fn ln_never_panics_and_is_accurate(
            m in any::<u64>(),
            e in any::<i16>(),
            bits in any::<i32>(),
        ) {
            if let Ok(v) = ln_scaled::<26>(m, e % 64) {
                let exact = (m as f64).ln() + (e % 64) as f64 * core::f64::consts::LN_2;
                let tol = 0.5 / (1u64 << 26) as f64 + 8e-10 + 1e-15 * exact.abs();
                prop_assert!((v.to_f64() - exact).abs() <= tol);
            }
            let _ = ln_scaled::<0>(m, e);
            let _ = ln_scaled::<31>(m, e);
            let _ = Q16_16::from_bits(bits).ln::<16>();
            let _ = Q1_31::from_bits(bits).ln::<31>();
            let _ = Q::<0>::from_bits(bits).ln::<0>();
        }
    }
}
