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
//!
//! The Littmann law needs `(2/pi) asin(z)` ([`Q2_30::asin_frac_2_pi`], crate-internal), which
//! folds the gain into `R(t) = (2/pi) asin(sqrt t) / sqrt t` on [0, 1/4], a table of 16
//! minimax cubics (Q.32, weight `2 sqrt t`, fit within 0.025 ulp of Q2.30) serving both
//! branches: `z R(z^2)` for `|z| <= 1/2` and `1 - 2 w R(w^2)`, `w = sqrt((1 - |z|)/2)`, above,
//! with `2 w` from a square root by two Newton steps on the hardware divider (`UDIV`, a single
//! instruction on the Cortex-M4, 2-12 cycles) seeded from a 256-entry table.

use core::num::{NonZeroU16, NonZeroU32};

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

/// `R(t) ~ (2/pi) asin(sqrt t) / sqrt t` on [0, 1/4] in 16 pieces: piece `k` (0..=16) is the
/// cubic `c0 + c1 d + c2 d^2 + c3 d^3` in `d = t - k/64`, |d| <= 1/128 (one-sided at both
/// ends), Q.32 coefficients (`c0 ~ R(k/64)`, from 0.637 to 2/3: above 2^31, added modulo
/// 2^32). Remez exchange per piece, weight `2 sqrt(t)` (the factor `|z|` or `2 w` that
/// multiplies `R`'s error in either branch): max weighted error 2.3e-11 (0.025 ulp of Q2.30);
/// with the rounding of the coefficients and of the last Horner step, `R` is within 1.1 units
/// of 2^-32 (0.98 unit weighted; measured on every 7th `t` up to 2^30).
/// Rows 17..32 repeat row 16 and are never used: the index needs no bounds check.
const RATIO_PIECES: [[u32; 4]; 32] = {
    const USED: [[u32; 4]; 17] = [
        [2_734_261_102, 455_710_203, 205_060_922, 123_538_654],
        [2_741_432_110, 462_209_293, 210_920_730, 127_508_489],
        [2_748_706_115, 468_895_084, 217_024_996, 133_129_735],
        [2_756_086_097, 475_775_853, 223_402_866, 139_129_468],
        [2_763_575_172, 482_860_413, 230_071_264, 145_510_054],
        [2_771_176_595, 490_158_122, 237_048_402, 152_296_984],
        [2_778_893_775, 497_678_931, 244_353_954, 159_521_649],
        [2_786_730_279, 505_433_431, 252_009_207, 167_219_527],
        [2_794_689_845, 513_432_903, 260_037_221, 175_430_081],
        [2_802_776_396, 521_689_382, 268_463_018, 184_197_021],
        [2_810_994_044, 530_215_715, 277_313_778, 193_568_763],
        [2_819_347_113, 539_025_635, 286_619_081, 203_598_986],
        [2_827_840_149, 548_133_843, 296_411_155, 214_347_284],
        [2_836_477_932, 557_556_088, 306_725_183, 225_879_932],
        [2_845_265_500, 567_309_273, 317_599_623, 238_270_785],
        [2_854_208_164, 577_411_555, 329_076_599, 251_602_308],
        [2_863_311_531, 587_882_445, 341_169_867, 262_246_886],
    ];
    let mut table = [USED[16]; 32];
    let mut k = 0;
    while k < 17 {
        table[k] = USED[k];
        k += 1;
    }
    table
};

/// `R(t)` in Q.32 for `t` in Q.32, `t <= 2^30`: the piece nearest `t` (index `round(64 t)`),
/// `d` its signed offset (a bit-field extract), and three `SMMLA`/`SMMLAR` steps. The inner
/// truncations are scaled by |d| <= 2^-7; the last step rounds (0.5 unit of 2^-32).
#[inline(always)]
const fn littmann_ratio(t: u32) -> u32 {
    let [c0, c1, c2, c3] = RATIO_PIECES[((t + (1 << 25)) >> 26) as usize & 31];
    let d = ((t << 6) as i32) >> 6; // t - k 2^26 in [-2^25, 2^25)
    let mut p = c2 as i32 + mul_hi(d, c3 as i32);
    p = c1 as i32 + mul_hi(d, p);
    (c0 as i32).wrapping_add(mul_hi_round(d, p)) as u32
}

/// Half the square root seeds: `round(sqrt((i + 1/2) 2^24) / 2)` for `i` in `64..256` (the top
/// byte of a normalised argument in [2^30, 2^32)), within 2^-8 of the root; entries below 64
/// never occur and hold the first used one, so that the byte needs no bounds check. Halves,
/// because `2 h` is then a divisor the type system knows to be nonzero.
const HALF_ROOT_SEEDS: [NonZeroU16; 256] = {
    let mut table = [NonZeroU16::MIN; 256];
    let mut i = 0;
    while i < 256 {
        let centre = if i < 64 { 64 } else { i as u64 };
        // sqrt((2 i + 1) 2^23) / 2 = sqrt((2 i + 1) 2^21), rounded: compare with (r + 1/2)^2.
        let x = (2 * centre + 1) << 21;
        let r = x.isqrt();
        let half = if x - r * r > r { r + 1 } else { r };
        table[i] = match NonZeroU16::new(half as u16) {
            Some(h) => h,
            None => panic!("seeds are >= 2^14"),
        };
        i += 1;
    }
    table
};

/// `sqrt(x / 2^32)` in Q.32 for `x` in Q.32, `x` a nonzero multiple of 4: within one unit
/// (`(-1.0, +0.988]`, checked over every such `x` while developing), below 2^32. Normalise by
/// an even shift to `xn` in [2^30, 2^32), seed `s_a` (8 bits) from the top byte, one Newton
/// step in Q.16, `s0 = (s_a + xn / s_a) / 2` (within [-1, +0.25] of the root), and one in
/// Q.32 whose quotient `xn / s0` is completed to 32 bits by dividing the remainder:
/// `s1 = (s0 + q + rem / s0) / 2`. Three `UDIV`, no bounds or zero checks, no overflow:
/// `s0 + q <= 2^17 - 1` because `xn <= 2^32 - 4`.
#[inline(always)]
fn sqrt_frac_q32(x: u32) -> u32 {
    let n = x.leading_zeros() & !1; // x != 0, so n <= 30
    let xn = x << n;
    let half = NonZeroU32::from(HALF_ROOT_SEEDS[(xn >> 24) as usize]);
    let seed = half.saturating_add(half.get()); // 2 h < 2^17: never saturates
    let q1 = xn / seed; // Q.16, < 2^17
    let s0 = half.saturating_add(q1 >> 1); // (s_a + q1) / 2 in Q.16, < 2^17: never saturates
    let q = xn / s0;
    let rem = xn - q * s0.get(); // < s0 <= 2^16, so rem 2^15 fits
    let s1 = ((s0.get() + q) << 15) + (rem << 15) / s0;
    s1 >> (n / 2)
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

    /// `(2/pi) asin(self)` in Q2.30 (range [-1, 1]), for `self` in [-1, 1]: the Littmann ratio
    /// mu_i (physics-notes §1) in one pass, without rounding the angle first (module docs).
    ///
    /// Error <= 1 ulp (9.3e-10; 0.62 ulp measured for |z| <= 1/2 and 0.88 above, over every
    /// input): the final rounding (0.5), `R`'s error (<= 1.1 units of 2^-32 from its fit, the
    /// rounding of its coefficients and of its last step, times |z| <= 1/2 or 2w <= 1:
    /// <= 0.28 ulp) and, above 1/2, the square root's (< 1 unit of 2^-32 times R <= 2/3:
    /// <= 0.17 ulp). Relative error < 1e-6 wherever the result is above 1e-3. Exact 0 and +-1
    /// at 0 and +-1, odd, nondecreasing (checked over every input while developing). Error
    /// `Domain` for |z| > 1. Cost: about 40 instructions for |z| <= 1/2 and 60 above, call
    /// included (see `model::littmann::mu_i`); the three `UDIV` of the square root take 2-12
    /// cycles each on the Cortex-M4.
    #[inline(always)]
    pub(crate) fn asin_frac_2_pi(self) -> Result<Self, FxError> {
        const ONE: u32 = 1 << 30;
        let z = self.to_bits();
        let a = z.unsigned_abs(); // |z| in Q.30
        let magnitude = if a <= ONE / 2 {
            // z R(z^2): |z| in Q.32 (<= 2^31) squared, then round(|z| R) in Q.30
            let a32 = a << 2;
            let t = ((a32 as u64 * a32 as u64) >> 32) as u32; // z^2 in Q.32, <= 2^30
            // round(|z| R) with R = R_s + 2^32 (R_s its bits as an i32): |z| + round(|z| R_s),
            // written as |z| - (-|z|) R_s for one SMMLSR (with |z| alone, known positive, the
            // compiler widens to an unsigned product and fixes the sign up).
            let ratio = littmann_ratio(t) as i32 as i64;
            let minus_a = -(a as i32) as i64;
            ((((a as i64) << 32) - minus_a * ratio + (1 << 31)) >> 32) as u32
        } else if a < ONE {
            // 1 - 2 w R(w^2) with w^2 = (1 - |z|)/2 = u/2: exact in Q.32 as u 2^1 (u in Q.30).
            let u = ONE - a; // (0, 2^29)
            let ratio = littmann_ratio(u << 1) as u64;
            let two_w = sqrt_frac_q32(u << 3) as u64; // sqrt(2u) in Q.32 (2u < 1)
            // 1 - round(2w R) in Q.30: the floor of the product's high word loses nothing
            // (round(p / 4) = (floor(p) + 2) >> 2 for p >= 0).
            ONE - ((((two_w * ratio) >> 32) as u32 + 2) >> 2)
        } else if a == ONE {
            ONE // exact, rather than (pi/2)(2/pi) rounded
        } else {
            return Err(FxError::Domain);
        };
        // magnitude <= 2^30
        Ok(Self::from_bits(if z < 0 {
            -(magnitude as i32)
        } else {
            magnitude as i32
        }))
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

    #[test]
    fn square_root_seeds_and_kernel() {
        // Seeds: within 2^-8 of the root over their whole byte (checked at both ends).
        for i in 64..256u64 {
            let seed = 2.0 * HALF_ROOT_SEEDS[i as usize].get() as f64;
            for x in [i << 24, ((i + 1) << 24) - 1] {
                let root = (x as f64).sqrt();
                assert!((seed - root).abs() <= root / 256.0, "seed {i}");
            }
        }
        // The root of every 64th multiple of 4 and of the extremes, within one unit of 2^-32
        // (every multiple of 4 was checked while developing: (-1.0, +0.988]).
        let mut worst: f64 = 0.0;
        let edges = [
            4u32,
            8,
            12,
            1 << 30,
            (1 << 30) + 4,
            u32::MAX - 3,
            u32::MAX - 7,
        ];
        for x in (4..=u32::MAX - 3).step_by(256).chain(edges) {
            let exact = (x as f64 * 4294967296.0).sqrt();
            let got = sqrt_frac_q32(x) as f64;
            worst = worst.max((got - exact).abs());
        }
        assert!(worst <= 1.0, "square root error {worst} units");
    }

    fn frac_2_pi_err_ulps(bits: i32) -> f64 {
        let z = Q2_30::from_bits(bits);
        let got = z.asin_frac_2_pi().unwrap().to_f64();
        (got - core::f64::consts::FRAC_2_PI * z.to_f64().asin()) / ULP
    }

    #[test]
    fn asin_frac_2_pi_ends_domain_and_sweep() {
        assert_eq!(Q2_30::ZERO.asin_frac_2_pi(), Ok(Q2_30::ZERO));
        assert_eq!(Q2_30::ONE.asin_frac_2_pi(), Ok(Q2_30::ONE));
        assert_eq!(
            Q2_30::from_bits(-(1 << 30)).asin_frac_2_pi(),
            Ok(Q2_30::from_bits(-(1 << 30)))
        );
        for bad in [(1 << 30) + 1, -(1 << 30) - 1, i32::MIN, i32::MAX] {
            assert_eq!(Q2_30::from_bits(bad).asin_frac_2_pi(), Err(FxError::Domain));
        }
        // R(0) = 2/pi: the smallest inputs come back as round(2 z / pi).
        assert_eq!(
            Q2_30::from_bits(1).asin_frac_2_pi(),
            Ok(Q2_30::from_bits(1))
        );
        assert_eq!(
            Q2_30::from_bits(3).asin_frac_2_pi(),
            Ok(Q2_30::from_bits(2))
        );
        // Both branches and both sides of 1/2 and of 1: every input within 2^16 ulps, and
        // 2^21 points over the range; odd.
        let near = |c: i32| (c - (1 << 16)..=c + (1 << 16)).filter(|b| b.abs() < 1 << 30);
        let (mut small, mut large): (f64, f64) = (0.0, 0.0);
        for bits in (0..(1 << 30))
            .step_by(509)
            .chain(near(0))
            .chain(near(1 << 29))
            .chain(near(1 << 30))
        {
            let err = frac_2_pi_err_ulps(bits).abs();
            if bits.abs() <= 1 << 29 {
                small = small.max(err);
            } else {
                large = large.max(err);
            }
            let z = Q2_30::from_bits(bits);
            assert_eq!(
                Q2_30::from_bits(-bits).asin_frac_2_pi().map(Q2_30::to_bits),
                z.asin_frac_2_pi().map(|y| -y.to_bits())
            );
        }
        eprintln!("(2/pi) asin: max error {small} ulp for |z| <= 1/2, {large} above");
        assert!(small.max(large) <= 1.0, "{small} {large}");
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
            match Q2_30::from_bits(bits).asin_frac_2_pi() {
                Ok(_) => prop_assert!(frac_2_pi_err_ulps(bits).abs() <= 1.0),
                Err(e) => {
                    prop_assert!(bits.unsigned_abs() > 1 << 30);
                    prop_assert_eq!(e, FxError::Domain);
                }
            }
        }

        #[test]
        fn square_root_within_one_unit(x in 1u32..(1 << 30)) {
            let x = x << 2;
            let exact = (x as f64 * 4294967296.0).sqrt();
            prop_assert!((sqrt_frac_q32(x) as f64 - exact).abs() <= 1.0);
        }
    }
}
