//! Complex amplitudes of the drive current, phase angles, and the conversion from in-phase /
//! quadrature components to amplitude and phase (CORDIC vectoring: shifts and adds, no
//! division, no square root).

use crate::fx::Q2_30;

/// A phase angle as a signed binary angle: `bits * 2 pi / 2^32` rad, range [-pi, pi),
/// resolution 1.46e-9 rad. Arithmetic wraps like the angle (`pi + pi/2` is `-pi/2`), so phase
/// differences never need a range check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Angle(i32);

impl Angle {
    /// Zero.
    pub const ZERO: Self = Self(0);
    /// A quarter turn, pi/2.
    pub const QUARTER_TURN: Self = Self(1 << 30);
    /// Half a turn: -pi (the same angle as +pi, which the format cannot hold).
    pub const HALF_TURN: Self = Self(i32::MIN);

    /// The angle `bits * 2 pi / 2^32` rad.
    pub const fn from_bits(bits: i32) -> Self {
        Self(bits)
    }

    /// The raw bits (`2^32` per turn, signed).
    pub const fn to_bits(self) -> i32 {
        self.0
    }

    /// The angle of a `u32` turn fraction (the phase accumulators' unit, `2^32` = one turn).
    pub const fn from_turns(turns: u32) -> Self {
        Self(turns as i32)
    }

    /// The angle as a `u32` turn fraction in [0, 2^32).
    pub const fn to_turns(self) -> u32 {
        self.0 as u32
    }

    /// `x` radians, wrapped into [-pi, pi) (set-up and tests only: f64). NaN gives zero.
    pub fn from_radians(x: f64) -> Self {
        let turns = x / core::f64::consts::TAU;
        // Keep the fractional part before scaling so large angles do not saturate the cast.
        let fraction = turns - libm::floor(turns);
        Self(libm::round(fraction * 4_294_967_296.0) as i64 as u32 as i32)
    }

    /// The angle in radians, in [-pi, pi) (telemetry and tests: f64).
    pub fn to_radians(self) -> f64 {
        f64::from(self.0) * (core::f64::consts::TAU / 4_294_967_296.0)
    }

    /// `self + rhs`, wrapped.
    pub const fn wrapping_add(self, rhs: Self) -> Self {
        Self(self.0.wrapping_add(rhs.0))
    }

    /// `self - rhs`, wrapped into [-pi, pi): the shortest signed turn from `rhs` to `self`.
    pub const fn wrapping_sub(self, rhs: Self) -> Self {
        Self(self.0.wrapping_sub(rhs.0))
    }

    /// `|self|` in binary-angle units, 0 to `2^31` (`2^31` is pi).
    pub const fn unsigned_abs(self) -> u32 {
        self.0.unsigned_abs()
    }
}

/// A sinusoid at the drive frequency as in-phase and quadrature components relative to the
/// drive voltage `V cos(theta)`: the signal is `in_phase cos(theta) - quadrature sin(theta)`,
/// i.e. the complex amplitude `in_phase + j quadrature`. A positive quadrature leads the
/// voltage (capacitive current).
///
/// Unit: fraction of the current sensor's full scale (the readings the lock-in is fed), Q2.30,
/// each component in [-2, 2). A full-scale sinusoid has amplitude 1; a full-scale square wave's
/// fundamental, the largest the lock-in can report, has 4/pi = 1.27.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Phasor {
    /// Component in phase with the drive voltage (the conductance part of the current).
    pub in_phase: Q2_30,
    /// Component leading the voltage by a quarter period (the susceptance part).
    pub quadrature: Q2_30,
}

/// Amplitude and phase of a [`Phasor`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Polar {
    /// Amplitude, same unit as the phasor, Q2.30 in [0, 2); saturated to `Q2_30::MAX` for
    /// components whose magnitude reaches 2 (then `saturated` is set).
    pub amplitude: Q2_30,
    /// Phase relative to the drive voltage, positive when leading. Zero for a zero phasor.
    pub phase: Angle,
    /// Whether the amplitude was clamped.
    pub saturated: bool,
}

/// Number of CORDIC stages: the residual angle after stage `i` is below `atan(2^-i)`, so 31
/// stages leave less than 2^-30 rad (0.7 binary-angle units), below the rounding of the table.
const STAGES: usize = 31;

/// Extra fractional bits of the angle accumulator below the binary-angle unit, so that the
/// rounding of 31 table entries (up to 15.5 of their ulps) stays below one output unit.
const ANGLE_EXTRA_BITS: u32 = 8;

/// `atan(2^-i)` in units of `2^-(32 + ANGLE_EXTRA_BITS)` turn, exactly rounded to f64
/// precision, computed at compile time from the alternating series (|x| <= 1/2 converges to
/// f64 precision in 30 terms; the `i = 0` entry is pi/4, exactly `2^(29 + ANGLE_EXTRA_BITS)`).
const ATAN_TABLE: [i64; STAGES] = {
    let mut table = [0i64; STAGES];
    table[0] = 1 << (29 + ANGLE_EXTRA_BITS);
    let mut i = 1;
    while i < STAGES {
        let x = 1.0 / (1u64 << i) as f64;
        let x2 = x * x;
        let mut power = x;
        let mut sum = 0.0;
        let mut k = 0;
        while k < 30 {
            let term = power / (2 * k + 1) as f64;
            sum = if k % 2 == 0 { sum + term } else { sum - term };
            power *= x2;
            k += 1;
        }
        let units_per_rad = (1u64 << (32 + ANGLE_EXTRA_BITS)) as f64 / core::f64::consts::TAU;
        table[i] = (sum * units_per_rad + 0.5) as i64;
        i += 1;
    }
    table
};

/// `1 / K`, the inverse of the CORDIC gain `K = prod sqrt(1 + 2^-2i)` (converged to far below
/// 2^-30 after 31 stages: 0.607252935008881...), in Q2.30. The tests recompute it.
const INV_GAIN_Q30: i64 = 652_032_874;

/// Guard bits below Q2.30 during the iterations: each stage truncates one shifted value, and
/// 28 bits keep the accumulated truncation (31 stages) far below one Q2.30 ulp. Headroom:
/// |x|, |y| <= 2^31 as Q2.30 bits, grown by at most `sqrt(2) K` = 2.33: 2^(31 + 28 + 1.22)
/// < 2^63.
const GUARD_BITS: u32 = 28;

impl Phasor {
    /// The zero phasor (no signal).
    pub const ZERO: Self = Self {
        in_phase: Q2_30::ZERO,
        quadrature: Q2_30::ZERO,
    };

    /// A phasor from its components.
    pub const fn new(in_phase: Q2_30, quadrature: Q2_30) -> Self {
        Self {
            in_phase,
            quadrature,
        }
    }

    /// Whether the amplitude is below `threshold` (a non-negative Q2.30), exactly, without the
    /// CORDIC: `re^2 + im^2 < t^2` in `u64` (each square <= 2^62, the sum <= 2^63). A
    /// negative threshold is never reached. For the per-window no-current check.
    pub const fn is_below(self, threshold: Q2_30) -> bool {
        if threshold.to_bits() < 0 {
            return false;
        }
        let x = self.in_phase.to_bits().unsigned_abs() as u64;
        let y = self.quadrature.to_bits().unsigned_abs() as u64;
        let t = threshold.to_bits() as u64;
        x * x + y * y < t * t
    }

    /// Amplitude and phase by CORDIC vectoring: the vector is rotated onto the positive
    /// in-phase axis by 31 shift-and-add micro-rotations while the rotation angles are summed.
    /// Amplitude error <= 2 ulp of Q2.30; phase error <= 2 binary-angle units (3e-9 rad)
    /// beyond what the input quantisation allows (about 1 ulp / amplitude rad). Cost: about 31 x 8
    /// instructions, no multiplication except the final gain correction, no division.
    pub const fn polar(self) -> Polar {
        let mut x = self.in_phase.to_bits() as i64;
        let mut y = self.quadrature.to_bits() as i64;
        if x == 0 && y == 0 {
            return Polar {
                amplitude: Q2_30::ZERO,
                phase: Angle::ZERO,
                saturated: false,
            };
        }
        // Vectoring converges for angles within +-99.9 degrees; a half-turn pre-rotation brings
        // the left half-plane into the right one.
        let mut angle: i64 = 0; // in 2^-(32 + ANGLE_EXTRA_BITS) turn; wraps when truncated
        if x < 0 {
            x = -x;
            y = -y;
            angle = 1 << (31 + ANGLE_EXTRA_BITS);
        }
        x <<= GUARD_BITS;
        y <<= GUARD_BITS;
        let mut i = 0;
        while i < STAGES {
            let (dx, dy) = (y >> i, x >> i);
            if y > 0 {
                x += dx;
                y -= dy;
                angle += ATAN_TABLE[i];
            } else {
                x -= dx;
                y += dy;
                angle -= ATAN_TABLE[i];
            }
            i += 1;
        }
        // x = K r with the guard bits: back to Q2.30 (rounded), then times 1/K.
        let scaled = (x + (1 << (GUARD_BITS - 1))) >> GUARD_BITS; // K r, below 2^32.3
        let r = (scaled * INV_GAIN_Q30 + (1 << 29)) >> 30; // below 2^62.3 before the shift
        let (amplitude, saturated) = if r > i32::MAX as i64 {
            (Q2_30::MAX, true)
        } else {
            (Q2_30::from_bits(r as i32), false)
        };
        // |angle| < 1.5 turns here; rounding to the binary angle then truncating to 32 bits
        // wraps it into [-pi, pi).
        let rounded = (angle + (1 << (ANGLE_EXTRA_BITS - 1))) >> ANGLE_EXTRA_BITS;
        Polar {
            amplitude,
            phase: Angle::from_bits(rounded as i32),
            saturated,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Phasors on the axes and the diagonals have exact binary angles: the CORDIC's angle
    /// (8 extra bits) is rounded to nearest, so 0, a quarter, half and an eighth of a turn come
    /// out exactly (a rounding that is off by half an ulp reads one ulp low everywhere).
    #[test]
    fn axes_and_diagonals_have_exact_angles() {
        let h = 1 << 29;
        for (x, y, turn) in [
            (h, 0, 0),
            (0, h, 1 << 30),
            (-h, 0, i32::MIN),
            (0, -h, -(1 << 30)),
            (h, h, 1 << 29),
            (-h, -h, -(3 << 29)),
            (12_345, 0, 0),
            (0, 77_777, 1 << 30),
        ] {
            let p = Phasor::new(Q2_30::from_bits(x), Q2_30::from_bits(y)).polar();
            assert_eq!(p.phase.to_bits(), turn, "({x}, {y})");
        }
    }
    use proptest::prelude::*;

    fn q(x: f64) -> Q2_30 {
        Q2_30::from_f64(x).unwrap()
    }

    /// Phase error in radians, wrapped.
    fn phase_error(got: Angle, want_rad: f64) -> f64 {
        got.wrapping_sub(Angle::from_radians(want_rad))
            .to_radians()
            .abs()
    }

    #[test]
    fn tables_match_std() {
        for (i, &entry) in ATAN_TABLE.iter().enumerate() {
            let exact = (0.5f64).powi(i as i32).atan() * (1u64 << (32 + ANGLE_EXTRA_BITS)) as f64
                / std::f64::consts::TAU;
            assert!((entry as f64 - exact).abs() <= 0.5, "atan(2^-{i})");
        }
        let gain: f64 = (0..STAGES)
            .map(|i| (1.0 + 0.25f64.powi(i as i32)).sqrt())
            .product();
        assert_eq!(INV_GAIN_Q30, (1073741824.0 / gain).round() as i64);
    }

    #[test]
    fn angle_wraps_like_the_circle() {
        let three_quarters = Angle::from_radians(1.5 * std::f64::consts::PI);
        assert_eq!(three_quarters, Angle::from_bits(-(1 << 30)));
        assert_eq!(
            Angle::HALF_TURN.wrapping_add(Angle::QUARTER_TURN),
            three_quarters
        );
        // From +179 degrees to -179 degrees is +2 degrees, not -358.
        let a = Angle::from_radians(179f64.to_radians());
        let b = Angle::from_radians(-179f64.to_radians());
        assert!((b.wrapping_sub(a).to_radians() - 2f64.to_radians()).abs() < 1e-9);
        assert_eq!(Angle::HALF_TURN.unsigned_abs(), 1 << 31);
        assert_eq!(Angle::from_turns(3 << 30).to_turns(), 3 << 30);
        assert_eq!(Angle::from_radians(f64::NAN), Angle::ZERO);
        assert!(
            (Angle::from_radians(-7.0).to_radians() - (-7.0 + std::f64::consts::TAU)).abs() < 1e-9
        );
        assert_eq!(Angle::from_radians(std::f64::consts::PI), Angle::HALF_TURN);
    }

    #[test]
    fn polar_matches_f64_around_the_circle() {
        let mut worst_amp: f64 = 0.0;
        let mut worst_phase: f64 = 0.0;
        for k in 0..3600 {
            let theta = k as f64 * std::f64::consts::TAU / 3600.0 - std::f64::consts::PI;
            for r in [1.0e-3, 0.05, 0.7, 1.27, 1.999 / std::f64::consts::SQRT_2] {
                let p = Phasor::new(q(r * theta.cos()), q(r * theta.sin()));
                let exact_r = p.in_phase.to_f64().hypot(p.quadrature.to_f64());
                let exact_phase = p.quadrature.to_f64().atan2(p.in_phase.to_f64());
                let polar = p.polar();
                assert!(!polar.saturated);
                worst_amp = worst_amp.max((polar.amplitude.to_f64() - exact_r).abs());
                let e = phase_error(polar.phase, exact_phase);
                worst_phase = worst_phase.max(e * r); // error scales as 1/r: compare r * error
            }
        }
        eprintln!(
            "CORDIC: amplitude error {worst_amp:.2e}, phase error * amplitude {worst_phase:.2e}"
        );
        assert!(worst_amp <= 2.0 * Q2_30::ULP.to_f64() + 2e-9, "{worst_amp}");
        assert!(worst_phase <= 1e-8, "{worst_phase}");
    }

    #[test]
    fn axes_zero_and_saturation() {
        let one = Q2_30::ONE;
        let minus = Q2_30::from_int(-1).unwrap();
        let cases = [
            (Phasor::new(one, Q2_30::ZERO), 0.0),
            (Phasor::new(Q2_30::ZERO, one), std::f64::consts::FRAC_PI_2),
            (Phasor::new(minus, Q2_30::ZERO), -std::f64::consts::PI),
            (
                Phasor::new(Q2_30::ZERO, minus),
                -std::f64::consts::FRAC_PI_2,
            ),
        ];
        for (p, want) in cases {
            let polar = p.polar();
            assert!((polar.amplitude.to_f64() - 1.0).abs() < 3e-9, "{p:?}");
            assert!(phase_error(polar.phase, want) < 1e-8, "{p:?}");
        }
        assert_eq!(Phasor::ZERO.polar(), Polar::default());
        // The exact no-current test, at the extremes of both formats.
        let corner = Phasor::new(Q2_30::MIN, Q2_30::MIN);
        assert!(!corner.is_below(Q2_30::MAX));
        assert!(Phasor::ZERO.is_below(Q2_30::from_bits(1)));
        assert!(!Phasor::ZERO.is_below(Q2_30::ZERO));
        assert!(!Phasor::ZERO.is_below(Q2_30::from_bits(-1)));
        let three_four = Phasor::new(Q2_30::from_bits(3 << 20), Q2_30::from_bits(-4 << 20));
        assert!(!three_four.is_below(Q2_30::from_bits(5 << 20)));
        assert!(three_four.is_below(Q2_30::from_bits((5 << 20) + 1)));
        // The largest components: magnitude 2 sqrt(2) does not fit Q2.30 and is flagged.
        let corner = Phasor::new(Q2_30::MIN, Q2_30::MIN).polar();
        assert!(corner.saturated);
        assert_eq!(corner.amplitude, Q2_30::MAX);
        assert!(phase_error(corner.phase, -0.75 * std::f64::consts::PI) < 1e-8);
        let edge = Phasor::new(Q2_30::MAX, Q2_30::ZERO).polar();
        assert!(!edge.saturated);
        assert!((edge.amplitude.to_bits() - i32::MAX).abs() <= 2);
    }

    proptest! {
        #[test]
        fn polar_never_panics_and_is_accurate(i in any::<i32>(), qd in any::<i32>()) {
            let p = Phasor::new(Q2_30::from_bits(i), Q2_30::from_bits(qd));
            let polar = p.polar();
            let exact_r = p.in_phase.to_f64().hypot(p.quadrature.to_f64());
            if exact_r < 1.999_999 {
                prop_assert!((polar.amplitude.to_f64() - exact_r).abs() <= 3e-9);
            }
            if exact_r > 1e-6 {
                let exact_phase = p.quadrature.to_f64().atan2(p.in_phase.to_f64());
                prop_assert!(phase_error(polar.phase, exact_phase) * exact_r <= 1e-8);
            }
        }
    }
}
