//! Per-node kernels of the cube model's quadrature (seed 000 eq 15; physics-notes §4-5).
//!
//! At a node with c = cos theta the weight is G = e^(-K c) (1 + Y c)^-3 (K = 2 lambda v / R_q
//! and Y = v / d at the node's amplitude, both Q8.24). In the default window (c >= 0, G <= 1)
//! it costs one `exp_neg` and an inline Newton reciprocal of 1 + Y c (no division, no `ln`):
//! this is the inner loop of the control step. The literal-window variant, where G > 1 and
//! 1 + Y c can approach 0, goes through logarithms and wide values instead (not cost-optimised).

use crate::fx::{Q6_26, Q8_24};

use super::ModelError;
use super::fx_error;
use super::horn::UPhase;
use super::quadrature::Quadrature;
use crate::fx::Scaled;

/// Window averages W0 = <G> and W1 = <G P_u> in Q.30 (`i64`), and whether a G saturated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Sums {
    pub(crate) mean: i64,
    pub(crate) u_mean: i64,
    pub(crate) saturated: bool,
}

/// Seeds of 1/m for m in [1, 2) on 128 intervals: round(2^31 / (1 + (j + 1/2) / 128)) =
/// round(2^39 / (257 + 2 j)), relative error below 2^-8.
const RECIP_SEED: [u32; 128] = {
    let mut table = [0u32; 128];
    let mut j = 0;
    while j < 128 {
        let den = 257 + 2 * j as u64;
        table[j] = (((1u64 << 39) + den / 2) / den) as u32;
        j += 1;
    }
    table
};

/// For x > 0: `(r, lz)` with m = x << lz in [2^31, 2^32) (a Q1.31 mantissa in [1, 2)) and
/// r = 1/m in Q1.31 (r <= 2^31), so that 1/x = r 2^(lz - 62). A table seed (2^-8) and two
/// Newton steps r <- r (2 - m r) give about 2^-32 relative; 32-bit operands everywhere, so every
/// product is one UMULL on the Cortex-M4. About 20 instructions, no division. `fx` has no fast
/// reciprocal (its division is a 64-bit library call of about 200 instructions).
#[inline(always)]
pub(crate) fn normalised_reciprocal(x: u32) -> (u32, u32) {
    let lz = x.leading_zeros();
    let m = x << lz;
    let mut r = RECIP_SEED[((m >> 24) & 127) as usize];
    for _ in 0..2 {
        let t = (1u64 << 63) - m as u64 * r as u64; // 2 - m r in Q2.62, about 2^62
        let t = ((t + (1 << 30)) >> 31) as u32; // Q1.31
        r = ((r as u64 * t as u64 + (1 << 30)) >> 31) as u32; // r <= 2^31: x (2 - x) <= 1
    }
    (r, lz)
}

/// (1/z, 1/z^3) in Q.30 for z in Q8.24, 1 <= z < 128 (bits in [2^24, 2^31)). Error <= 1 ulp of
/// Q.30 for 1/z and 2.5 ulp for 1/z^3 (measured 0.97 and 2.08 over 2e6 points); z = 1 gives
/// exactly 1 (tested). About 35 instructions.
#[inline(always)]
pub(crate) fn reciprocal_and_cube(z: u32) -> (i32, i32) {
    let (r, lz) = normalised_reciprocal(z);
    let e = 7 - lz; // z = m 2^e, lz in 1..=7
    let r2 = ((r as u64 * r as u64 + (1 << 30)) >> 31) as u32;
    let r3 = ((r2 as u64 * r as u64 + (1 << 30)) >> 31) as u32;
    // Q1.31 -> Q.30 with the 2^-e (2^-3e) of the exponent, rounded (no u32 overflow: r <= 2^31).
    let inv = (r + (1 << e)) >> (1 + e);
    let inv3 = (r3 + (1 << (3 * e))) >> (1 + 3 * e);
    (inv as i32, inv3 as i32)
}

/// `numerator / denominator` for two positive values of the same format, as Q8.24, rounded;
/// `None` when the quotient is 128 or more. About 30 instructions (no library division).
pub(crate) fn quotient_q8_24(numerator: u32, denominator: u32) -> Option<u32> {
    if denominator == 0 {
        return None;
    }
    let (r, lz) = normalised_reciprocal(denominator);
    // n / d = n r 2^(lz - 62); in Q.24: n r 2^(lz - 38), shift 38 - lz in [7, 38].
    let shift = 38 - lz;
    let q = (numerator as u64 * r as u64 + (1 << (shift - 1))) >> shift;
    u32::try_from(q).ok().filter(|&q| q < 1 << 31)
}

/// G and 1/(1 + Y c) in Q.30 at a node of the default window (c in [0, 1) as Q1.31 bits,
/// `decay` = K and `lift` = Y as Q8.24 bits, Y < 127). Error of G below 1e-7 relative: 1 + Y c
/// is rounded to Q8.24 (3e-8) and cubed.
#[inline(always)]
pub(crate) fn apart_node(decay: i32, lift: i32, c: i32) -> Result<(i32, i32), ModelError> {
    // K c in Q6.26 (finer than K itself); above 32, e^-Kc < 2^-46 rounds to 0 anyway.
    let kc = ((decay as i64 * c as i64 + (1 << 28)) >> 29).min(i32::MAX as i64) as i32;
    let z = (1 << 24) + ((lift as i64 * c as i64 + (1 << 30)) >> 31) as i32; // [1, 128) Q8.24
    let (inv, inv3) = reciprocal_and_cube(z as u32);
    let e = Q6_26::from_bits(kc).exp_neg().map_err(fx_error("G"))?;
    let g = (e.to_bits() as i64 * inv3 as i64 + (1 << 29)) >> 30; // <= 2^30
    Ok((g as i32, inv))
}

/// Default window: ceil(N/2) nodes, c in [0, 1), G in Q2.30 (G <= 1). W1 (in-phase u) only
/// when `WITH_U`.
pub(crate) fn apart_sums<const WITH_U: bool>(
    q: &Quadrature,
    decay: i32,
    lift: i32,
) -> Result<Sums, ModelError> {
    let (mut s0, mut s1) = (0i64, 0i64);
    for (&cos, &weight) in q.cos().iter().zip(q.weights()) {
        let c = cos.to_bits();
        let (g, _) = apart_node(decay, lift, c)?;
        let wg = weight.to_bits() as i64 * g as i64; // Q.60, sum <= 2^60
        s0 += wg;
        if WITH_U {
            s1 += ((wg + (1 << 29)) >> 30) * c as i64; // Q.61, sum < 2^61
        }
    }
    Ok(Sums {
        mean: (s0 + (1 << 29)) >> 30,
        u_mean: (s1 + (1 << 30)) >> 31,
        saturated: false,
    })
}

/// Literal window: N nodes, c in (-1, 1). G = e^(-phi), phi = K c + 3 ln(1 + Y c), exceeds 1
/// on the approach side and grows without bound as v -> -d, so each G is formed as
/// `mantissa * 2^exp2` ([`Scaled::from_ln`]) and accumulated in `i128` (up to 2^31 per node; a
/// larger G saturates, which implies F'/F far beyond 128). Needs Y < 1 (checked by the caller).
pub(crate) fn literal_sums(
    q: &Quadrature,
    u_phase: UPhase,
    decay: i32,
    lift: i32,
) -> Result<Sums, ModelError> {
    let (decay, lift) = (decay as i64, lift as i64);
    let (mut s0, mut s1, mut saturated) = (0i128, 0i128, false);
    for i in 0..q.len() {
        let c = q.cos()[i].to_bits() as i64;
        let p = match u_phase {
            UPhase::InPhase => c,
            UPhase::Quadrature => q.sin()[i].to_bits() as i64,
        };
        let kc = (decay * c + (1 << 30)) >> 31; // Q.24, |K c| < 128
        let z = (1 << 24) + ((lift * c + (1 << 30)) >> 31); // 1 + Y c in (0, 2), Q.24
        let g = if z <= 0 {
            None // 1 + Y c rounded to <= 0: d + v -> 0
        } else {
            let ln_z = Q8_24::from_bits(z as i32)
                .ln::<26>()
                .map_err(fx_error("ln(1 + v/d)"))?;
            let exponent = -((kc << 2) + 3 * ln_z.to_bits() as i64); // ln G, Q.26
            if exponent < -22 * (1 << 26) {
                Some(0) // G < 2.8e-10: below half an ulp of Q.30
            } else {
                i32::try_from(exponent)
                    .ok()
                    .and_then(|e| Scaled::from_ln(Q6_26::from_bits(e)).to_q30_wide())
            }
        };
        let g = g.unwrap_or_else(|| {
            saturated = true;
            i64::MAX >> 1
        });
        let wg = q.weights()[i].to_bits() as i128 * g as i128; // Q.60
        s0 += wg;
        s1 += ((wg + (1 << 29)) >> 30) * p as i128; // Q.61
    }
    // |sums| < 2^62 unless a G saturated; clamp (keeping the sign) in any case.
    let limit = (i64::MAX >> 1) as i128;
    let to_q30 =
        |sum: i128, shift: u32| ((sum + (1 << (shift - 1))) >> shift).clamp(-limit, limit) as i64;
    Ok(Sums {
        mean: to_q30(s0, 30),
        u_mean: to_q30(s1, 31),
        saturated,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reciprocal_and_cube_are_accurate_over_the_whole_range() {
        assert_eq!(reciprocal_and_cube(1 << 24), (1 << 30, 1 << 30));
        assert_eq!(reciprocal_and_cube(2 << 24), (1 << 29, 1 << 27));
        let mut worst = (0.0f64, 0.0f64);
        for i in 0..2_000_000u64 {
            let bits = (1u64 << 24) + i * ((1u64 << 31) - (1 << 24) - 1) / 1_999_999;
            let z = bits as f64 / (1u64 << 24) as f64;
            let (inv, inv3) = reciprocal_and_cube(bits as u32);
            let scale = (1u64 << 30) as f64;
            worst.0 = worst.0.max((inv as f64 - scale / z).abs());
            worst.1 = worst.1.max((inv3 as f64 - scale / (z * z * z)).abs());
        }
        assert!(worst.0 <= 1.0 && worst.1 <= 2.5, "ulps {worst:?}");
    }

    #[test]
    fn quotients_match_f64() {
        for &(n, d) in &[
            (1u32, 1u32),
            (3, 7),
            (1 << 24, 3 << 22),
            (123_456_789, 987_654),
            (5, 1),
        ] {
            let want = n as f64 / d as f64 * (1u64 << 24) as f64;
            match quotient_q8_24(n, d) {
                Some(q) => assert!((q as f64 - want).abs() <= 0.51, "{n} / {d}"),
                None => assert!(want >= 2147483647.5, "{n} / {d}"),
            }
        }
        assert_eq!(quotient_q8_24(1, 0), None);
        assert_eq!(quotient_q8_24(u32::MAX >> 1, 1), None);
    }

    #[test]
    fn node_weight_matches_f64() {
        for &(k, y) in &[
            (0.0, 0.0),
            (1.1, 0.06),
            (6.7, 2.0),
            (50.0, 14.5),
            (127.0, 126.0),
        ] {
            let (kb, yb) = (Q8_24::from_f64(k).unwrap(), Q8_24::from_f64(y).unwrap());
            for step in 0..=100 {
                let c = Q8_24::from_f64(step as f64 / 100.0 * 0.999_999).unwrap();
                let c31 = c.to_bits() << 7;
                let (g, _) = apart_node(kb.to_bits(), yb.to_bits(), c31).unwrap();
                let cf = c31 as f64 / (1u64 << 31) as f64;
                let want = (-kb.to_f64() * cf).exp() / (1.0 + yb.to_f64() * cf).powi(3);
                let err = (g as f64 / (1u64 << 30) as f64 - want).abs();
                // 1 + Y c is rounded to Q8.24 (3e-8), cubed: about 1e-7 at most.
                assert!(err < 1e-7, "{k} {y} {cf}: {err:e}");
            }
        }
    }
}
