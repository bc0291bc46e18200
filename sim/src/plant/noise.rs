//! Deterministic Gaussian noise for the simulated load cells.
//!
//! Uniform bits come from xoshiro128** (Blackman and Vigna's 32-bit generator: four words of
//! state, shifts, rotations and one multiply, so it is cheap on a Cortex-M4), seeded through
//! splitmix64 so that any 64-bit seed, 0 included, gives a well-mixed state. Normal deviates
//! come from the Box-Muller transform in `f32` with `libm`'s `logf`, `sqrtf` and `sincosf`:
//! integer generator plus correctly specified IEEE-754 single-precision operations, so the host
//! and the firmware draw bit-identical sequences for the same seed.

use core::f32::consts::TAU;

/// Uniform 32-bit generator: xoshiro128**.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Xoshiro128 {
    state: [u32; 4],
}

impl Xoshiro128 {
    /// A generator whose state is expanded from `seed` by splitmix64 (never all zero).
    pub fn from_seed(seed: u64) -> Self {
        let mut mix = seed;
        let mut next = || {
            mix = mix.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = mix;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let (a, b) = (next(), next());
        let mut state = [a as u32, (a >> 32) as u32, b as u32, (b >> 32) as u32];
        if state == [0; 4] {
            state[0] = 1;
        }
        Self { state }
    }

    /// The next 32 uniformly distributed bits.
    pub fn next_u32(&mut self) -> u32 {
        let [s0, s1, s2, s3] = self.state;
        let result = s1.wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s1 << 9;
        let s2 = s2 ^ s0;
        let s3 = s3 ^ s1;
        let s1 = s1 ^ s2;
        let s0 = s0 ^ s3;
        let s2 = s2 ^ t;
        let s3 = s3.rotate_left(11);
        self.state = [s0, s1, s2, s3];
        result
    }

    /// A uniform deviate in (0, 1], with 24 bits of resolution (exact in `f32`).
    pub fn next_open01(&mut self) -> f32 {
        ((self.next_u32() >> 8) + 1) as f32 * (1.0 / 16_777_216.0)
    }
}

/// Standard normal deviates (mean 0, standard deviation 1), in pairs from Box-Muller. Their
/// magnitude is bounded by sqrt(-2 ln 2^-24) = 5.77 (the uniform's resolution).
#[derive(Debug, Clone, PartialEq)]
pub struct Gaussian {
    uniform: Xoshiro128,
    spare: Option<f32>,
}

impl Gaussian {
    /// A source seeded with `seed` (any value).
    pub fn from_seed(seed: u64) -> Self {
        Self {
            uniform: Xoshiro128::from_seed(seed),
            spare: None,
        }
    }

    /// The next standard normal deviate.
    pub fn sample(&mut self) -> f32 {
        if let Some(spare) = self.spare.take() {
            return spare;
        }
        let radius = libm::sqrtf(-2.0 * libm::logf(self.uniform.next_open01()));
        let (sin, cos) = libm::sincosf(TAU * self.uniform.next_open01());
        self.spare = Some(radius * sin);
        radius * cos
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_gives_the_same_sequence() {
        let mut a = Gaussian::from_seed(42);
        let mut b = Gaussian::from_seed(42);
        let mut c = Gaussian::from_seed(43);
        let mut differs = false;
        for _ in 0..1000 {
            let (x, y, z) = (a.sample(), b.sample(), c.sample());
            assert_eq!(x.to_bits(), y.to_bits());
            differs |= x.to_bits() != z.to_bits();
        }
        assert!(differs, "seeds 42 and 43 gave the same sequence");
    }

    #[test]
    fn xoshiro_matches_the_published_algorithm() {
        // Output of the reference xoshiro128** from the state {1, 2, 3, 4}.
        let mut uniform = Xoshiro128 {
            state: [1, 2, 3, 4],
        };
        let words: [u32; 6] = core::array::from_fn(|_| uniform.next_u32());
        assert_eq!(words, [11520, 0, 5927040, 70819200, 2031721883, 1637235492]);
    }

    #[test]
    fn the_normal_sequence_is_pinned() {
        // Host and firmware must draw exactly these bits; a change of algorithm or of libm's
        // results shows here first.
        let mut normal = Gaussian::from_seed(7);
        let first: [u32; 4] = core::array::from_fn(|_| normal.sample().to_bits());
        assert_eq!(first, [3210360435, 1065401404, 1054801825, 3208305519]);
    }

    #[test]
    fn deviates_have_zero_mean_and_unit_deviation() {
        let mut source = Gaussian::from_seed(2024);
        let n = 200_000;
        let (mut sum, mut sum_sq, mut beyond_2sigma) = (0.0f64, 0.0f64, 0u32);
        for _ in 0..n {
            let z = f64::from(source.sample());
            sum += z;
            sum_sq += z * z;
            beyond_2sigma += u32::from(z.abs() > 2.0);
        }
        let mean = sum / f64::from(n);
        let std = (sum_sq / f64::from(n) - mean * mean).sqrt();
        // Standard error of the mean: 1 / sqrt(n) = 0.0022; allow 4 of them.
        assert!(mean.abs() < 0.009, "mean {mean}");
        assert!((std - 1.0).abs() < 0.01, "std {std}");
        // P(|z| > 2) = 4.55 % for a normal distribution.
        let tail = f64::from(beyond_2sigma) / f64::from(n);
        assert!((tail - 0.0455).abs() < 0.002, "tail {tail}");
    }

    #[test]
    fn uniforms_are_in_the_open_closed_unit_interval() {
        let mut uniform = Xoshiro128::from_seed(u64::MAX);
        let (mut low, mut high) = (1.0f32, 0.0f32);
        for _ in 0..100_000 {
            let u = uniform.next_open01();
            assert!(u > 0.0 && u <= 1.0);
            low = low.min(u);
            high = high.max(u);
        }
        assert!(low < 1e-4 && high > 0.9999, "{low} {high}");
    }
}
