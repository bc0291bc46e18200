//! Sine and cosine of a phase given as a `u32` fraction of a full turn (`2^32` = 2 pi), so a
//! phase accumulator advanced with `wrapping_add` wraps exactly like the angle. For the cube-model
//! quadrature over a half period, lock-in demodulation and drive synthesis.
//!
//! Method: the top two bits pick the quadrant. Within it, the nearest of 257 table points `a`
//! (spacing pi/512, table generated at compile time) and the offset `d` (|d| <= pi/1024 =
//! 3.1e-3 rad) give `sin(a + d) = S cos d + C sin d` with `S = sin a`, `C = cos a` (read from
//! the same table backwards), `cos d = 1 - d^2/2` and `sin d = d - d^3/6` (truncation 4e-12).
//! Four rounded multiply-high steps per output; no division, no branch except the quadrant.

use super::ctmath::sin_f64;
use super::q::{Q1_31, Q3_29};
use super::raw::mul_hi_round;

/// `sin(i pi / 512)` in Q1.31 for `i` in `0..=256`, generated at compile time. The last entry,
/// 1.0, is stored as `i32::MAX` (1 - 2^-31): Q1.31 cannot hold 1.0.
const SIN_TABLE: [i32; 257] = {
    let mut table = [0i32; 257];
    let mut i = 0;
    while i <= 256 {
        let angle = i as f64 * (core::f64::consts::FRAC_PI_2 / 256.0);
        let bits = (sin_f64(angle) * 2147483648.0 + 0.5) as i64;
        table[i] = if bits > i32::MAX as i64 {
            i32::MAX
        } else {
            bits as i32
        };
        i += 1;
    }
    table
};

/// pi and pi/3 in Q3.29, for converting the phase offset to radians.
const PI_Q29: i32 = Q3_29::PI.to_bits();
const FRAC_PI_3_Q29: i32 = Q3_29::from_f64_const(core::f64::consts::FRAC_PI_3).to_bits();

/// `(sin, cos)` of `u * (pi/2) / 2^30` for `u` in `[0, 2^30)` (a position inside a quadrant),
/// both in Q1.31 and both in `[0, 2^31)`.
#[inline(always)]
const fn quadrant_sin_cos(u: u32) -> (i32, i32) {
    let i = (u + (1 << 21)) >> 22; // nearest table point, 0..=256
    let d = u as i32 - (i << 22) as i32; // offset in 2^-30 quadrants, [-2^21, 2^21)
    let s_a = SIN_TABLE[i as usize];
    let c_a = SIN_TABLE[256 - i as usize];
    // d in radians, Q.32: d (pi/2) 2^-30 2^32 = 2 pi d = (16 d) PI_Q29 / 2^32, one SMMULR;
    // |dr| <= 1.4e7. The same for dr/3 (used only in the 4.8e-9 cubic term).
    let dr = mul_hi_round(d << 4, PI_Q29);
    let dr_third = mul_hi_round(d << 4, FRAC_PI_3_Q29);
    let half_d2 = ((dr as i64 * dr as i64 + (1 << 32)) >> 33) as i32; // d^2/2, Q.32
    let sin_d = dr - mul_hi_round(half_d2, dr_third); // d - d^3/6, Q.32
    // At i = 256 (s_a = MAX) d <= 0, so sin_d <= 0 and the sum cannot pass MAX; likewise for
    // the cosine at i = 0 (c_a = MAX, d >= 0).
    let sin = s_a - mul_hi_round(s_a, half_d2) + mul_hi_round(c_a, sin_d);
    let cos = c_a - mul_hi_round(c_a, half_d2) - mul_hi_round(s_a, sin_d);
    (sin, cos)
}

/// `(sin, cos)` of `phase * 2 pi / 2^32`, in Q1.31.
///
/// Error <= 1e-9 absolute (2.2 ulp of Q1.31; 0.94e-9 measured over all 2^32 phases). +1.0 is
/// not representable and comes out as `MAX` = 1 - 2^-31. Cost: about 36 instructions for the
/// pair.
#[inline]
pub const fn sin_cos(phase: u32) -> (Q1_31, Q1_31) {
    let (s, c) = quadrant_sin_cos(phase & 0x3FFF_FFFF);
    // Values are in [0, 2^31), so the negations cannot overflow.
    let (sin, cos) = match phase >> 30 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    };
    (Q1_31::from_bits(sin), Q1_31::from_bits(cos))
}

/// `sin(phase * 2 pi / 2^32)` in Q1.31. Error <= 1e-9 absolute (see [`sin_cos`]).
/// Cost: about 32 instructions.
#[inline]
pub const fn sin(phase: u32) -> Q1_31 {
    sin_cos(phase).0
}

/// `cos(phase * 2 pi / 2^32)` in Q1.31, i.e. the sine a quarter turn later. Error <= 1e-9
/// absolute (see [`sin_cos`]). Cost: about 32 instructions.
#[inline]
pub const fn cos(phase: u32) -> Q1_31 {
    sin_cos(phase).1
}

/// A phase in turns, U0.32: `2^32` per turn, so its `u32` covers one turn, [0, 1), and adding
/// two phases wraps exactly like the angle (a numerically controlled oscillator's
/// accumulator). The resolution is 2^-32 turn (1.5e-9 rad). A negative phase is its wrap:
/// -1/4 turn is 3/4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Turns(u32);

impl Turns {
    /// Zero phase.
    pub const ZERO: Self = Self(0);
    /// A quarter turn (pi/2).
    pub const QUARTER: Self = Self(1 << 30);
    /// Half a turn (pi).
    pub const HALF: Self = Self(1 << 31);

    /// The phase whose U0.32 bits are `bits` (`bits / 2^32` of a turn).
    pub const fn from_bits(bits: u32) -> Self {
        Self(bits)
    }

    /// The U0.32 bits, `2^32` per turn.
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The phase of `turns` (any finite number of turns, either sign): its fraction of a turn,
    /// rounded to the nearest 2^-32 turn, wrapped into [0, 1). `None` when `turns` is not
    /// finite. Set-up and tools (`f64`).
    pub fn from_turns(turns: f64) -> Option<Self> {
        if !turns.is_finite() {
            return None;
        }
        let fraction = turns - libm::floor(turns); // [0, 1]: 1 only by rounding of tiny negatives
        let bits = libm::round(fraction * 4_294_967_296.0) as u64;
        Some(Self((bits & 0xFFFF_FFFF) as u32))
    }

    /// The phase as a fraction of a turn, [0, 1), exact in `f64`.
    pub fn to_turns(self) -> f64 {
        f64::from(self.0) / 4_294_967_296.0
    }

    /// The sum of two phases, wrapped to one turn.
    pub const fn wrapping_add(self, other: Self) -> Self {
        Self(self.0.wrapping_add(other.0))
    }

    /// `(sin, cos)` of the phase, Q1.31: [`sin_cos`].
    pub const fn sin_cos(self) -> (Q1_31, Q1_31) {
        sin_cos(self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_phase_in_turns_converts_at_its_extremes() {
        // Zero, the last step below a full turn, a full turn (wraps to zero), a half.
        assert_eq!(Turns::from_turns(0.0), Some(Turns::ZERO));
        assert_eq!(Turns::from_turns(1.0), Some(Turns::ZERO));
        assert_eq!(Turns::from_turns(0.5), Some(Turns::HALF));
        assert_eq!(Turns::from_turns(0.25), Some(Turns::QUARTER));
        let last = Turns::from_bits(u32::MAX);
        assert_eq!(last.to_turns(), 1.0 - 1.0 / 4_294_967_296.0);
        assert_eq!(Turns::from_turns(last.to_turns()), Some(last));
        // Negative turns are their wrap; rounding just below a whole turn wraps to zero.
        assert_eq!(Turns::from_turns(-0.25), Some(Turns::from_bits(3 << 30)));
        assert_eq!(Turns::from_turns(-1e-12), Some(Turns::ZERO));
        assert_eq!(Turns::from_turns(1e9 + 0.5), Some(Turns::HALF));
        assert_eq!(Turns::from_turns(f64::NAN), None);
        assert_eq!(Turns::from_turns(f64::INFINITY), None);
        // Addition wraps like the angle.
        assert_eq!(last.wrapping_add(Turns::from_bits(1)), Turns::ZERO);
        assert_eq!(Turns::HALF.wrapping_add(Turns::HALF), Turns::ZERO);
        // The sine of a phase against the f64 reference at the quadrant edges.
        for phase in [
            Turns::ZERO,
            Turns::QUARTER,
            Turns::HALF,
            Turns::from_bits(3 << 30),
            last,
        ] {
            let angle = phase.to_turns() * core::f64::consts::TAU;
            let (s, c) = phase.sin_cos();
            assert!((s.to_f64() - angle.sin()).abs() < 1e-9, "{phase:?}");
            assert!((c.to_f64() - angle.cos()).abs() < 1e-9, "{phase:?}");
        }
    }
    use proptest::prelude::*;

    fn angle(phase: u32) -> f64 {
        phase as f64 * (core::f64::consts::TAU / 4294967296.0)
    }

    /// Absolute error of the pair against f64, in units of 1e-9.
    fn err_nano(phase: u32) -> f64 {
        let (s, c) = sin_cos(phase);
        let a = angle(phase);
        let es = (s.to_f64() - a.sin()).abs();
        let ec = (c.to_f64() - a.cos()).abs();
        es.max(ec) * 1e9
    }

    #[test]
    fn table_matches_std() {
        for (i, &entry) in SIN_TABLE.iter().enumerate() {
            let exact = (i as f64 * core::f64::consts::PI / 512.0).sin() * 2147483648.0;
            let want = (exact.round() as i64).min(i32::MAX as i64);
            assert_eq!(entry as i64, want, "entry {i}");
        }
    }

    #[test]
    fn cardinal_points() {
        assert_eq!(sin_cos(0), (Q1_31::ZERO, Q1_31::MAX));
        assert_eq!(sin_cos(1 << 30), (Q1_31::MAX, Q1_31::ZERO));
        assert_eq!(sin_cos(2 << 30), (Q1_31::ZERO, Q1_31::from_bits(-i32::MAX)));
        assert_eq!(sin_cos(3 << 30), (Q1_31::from_bits(-i32::MAX), Q1_31::ZERO));
        assert_eq!(
            sin(1 << 29).to_bits(),
            (0.5f64.sqrt() * 2147483648.0).round() as i32
        );
        assert_eq!(cos(1 << 29), sin(1 << 29));
    }

    #[test]
    fn dense_sweep_and_quadrant_edges() {
        let mut worst: f64 = 0.0;
        // 1M phases spread over the whole turn (odd step, so every low-bit pattern occurs).
        let mut phase: u32 = 12_345;
        for _ in 0..1_000_000 {
            worst = worst.max(err_nano(phase));
            phase = phase.wrapping_add(4_294_963);
        }
        // Every phase within 2^21 of a quadrant boundary: the table ends, where the saturated
        // entry and the sign of the offset matter (also proves no overflow there).
        for q in 0..4u32 {
            let centre = q << 30;
            for k in 0..(1u32 << 22) {
                let p = centre.wrapping_add(k).wrapping_sub(1 << 21);
                if k % 8 == 0 || !(4096..=(1 << 22) - 4096).contains(&k) {
                    worst = worst.max(err_nano(p));
                } else {
                    let _ = sin_cos(p);
                }
            }
        }
        eprintln!("sin/cos: max abs error {worst:.3}e-9");
        assert!(worst <= 1.0, "sin/cos error {worst}e-9");
    }

    #[test]
    fn phase_accumulator_wraps_like_the_angle() {
        let step = 107_374_182u32; // 1/40 turn, rounded
        let mut phase = u32::MAX - 5;
        for _ in 0..100 {
            let next = phase.wrapping_add(step);
            let exact = angle(next).sin();
            assert!((sin(next).to_f64() - exact).abs() < 1e-9);
            phase = next;
        }
    }

    proptest! {
        #[test]
        fn sin_cos_never_panics_and_is_accurate(phase in any::<u32>()) {
            prop_assert!(err_nano(phase) <= 1.0);
            let (s, c) = sin_cos(phase);
            prop_assert_eq!(sin(phase), s);
            prop_assert_eq!(cos(phase), c);
        }
    }
}
