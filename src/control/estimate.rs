//! Friction estimate from the two load cells, and the natural friction coefficient `mu0`.
//!
//! - Normal force `F_n`, tangential force `F_t` (Q16.16 N) and sliding velocity (Q8.24 m/s)
//!   each pass a first-order low-pass ([`super::filter`]) with its own bandwidth: the friction
//!   force must follow the drive (a few hundred hertz), the load and the speed change slowly
//!   and are filtered harder, since their noise enters the ratio one for one.
//! - `mu = |F_t| / max(F_n, F_n_min)` in Q2.30 (clamped to [0, 2)). The friction magnitude is
//!   used, so the sign convention of the tangential cell does not matter. Below `F_n_min` the
//!   contact is reported unloaded (`load_ok` false): the coefficient is then meaningless and
//!   the loop does not run, and the guard keeps the reciprocal bounded.
//! - `mu0`, the coefficient without vibration, starts at the scene's value (the prior, worth
//!   `prior_weight` samples) and is learned only while sliding with the drive off: a running
//!   mean `mu0 += (mu - mu0) / n` with `n` growing to `window` samples, then an exponential
//!   average over `window` samples (follows slow drift of the surfaces). The natural friction
//!   is what the reduction and ratio targets are relative to, so an error in `mu0` is a
//!   steady-state error of the loop that no feedback can see: learning it is the way to cope
//!   with a scene whose `mu` is off (the acceptance scene's +-20 %).

use core::num::NonZeroU32;

use super::SampleBlock;
use super::filter::{LowPass, LowPassCoef};
use super::recip::Reciprocal;
use crate::fx::{Q2_30, Q8_24, Q16_16};

/// The smallest natural friction coefficient kept, 1e-3 (Q2.30): a contact reading no
/// friction at all would otherwise make every ratio infinite.
pub const MIN_NATURAL_COEF: Q2_30 = Q2_30::from_f64_const(1e-3);

/// Configuration of the friction estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EstimatorConfig {
    /// Low-pass of the normal force.
    pub normal: LowPassCoef,
    /// Low-pass of the tangential force (and of the controller's prediction of it).
    pub tangential: LowPassCoef,
    /// Low-pass of the sliding velocity.
    pub velocity: LowPassCoef,
    /// Smallest normal force for a valid coefficient, Q16.16 N, > 0.
    pub min_normal_force: Q16_16,
}

/// One step's friction estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrictionEstimate {
    /// Filtered normal force, Q16.16 N (may be negative or tiny: see `load_ok`).
    pub normal_force: Q16_16,
    /// Filtered tangential force, Q16.16 N, signed as the load cell reads it.
    pub tangential_force: Q16_16,
    /// Filtered sliding velocity, Q8.24 m/s, signed.
    pub sliding_velocity: Q8_24,
    /// Friction coefficient `|F_t| / max(F_n, F_n_min)`, Q2.30 in [0, 2).
    pub coefficient: Q2_30,
    /// True when the filtered normal force is at least `F_n_min`.
    pub load_ok: bool,
    /// `1 / max(F_n, F_n_min)` (per newton), for the force target.
    pub normal_reciprocal: Reciprocal,
}

/// Filter state of the friction estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrictionEstimator {
    normal: LowPass<16>,
    tangential: LowPass<16>,
    velocity: LowPass<24>,
    primed: bool,
}

impl FrictionEstimator {
    /// Filters that start at rest at their first sample (no start-up transient: the two
    /// forces would rise at different rates and fake a coefficient).
    pub const fn new() -> Self {
        Self {
            normal: LowPass::new(Q16_16::ZERO),
            tangential: LowPass::new(Q16_16::ZERO),
            velocity: LowPass::new(Q8_24::ZERO),
            primed: false,
        }
    }

    /// Filters one sample of each sensor and forms the coefficient. Any input bits are fine:
    /// nothing overflows or panics.
    pub fn update(
        &mut self,
        config: &EstimatorConfig,
        normal_force: Q16_16,
        tangential_force: Q16_16,
        sliding_velocity: Q8_24,
    ) -> FrictionEstimate {
        if !self.primed {
            self.normal.reset(normal_force);
            self.tangential.reset(tangential_force);
            self.velocity.reset(sliding_velocity);
            self.primed = true;
        }
        let normal = config.normal.process(&mut self.normal, normal_force);
        let tangential = config
            .tangential
            .process(&mut self.tangential, tangential_force);
        let velocity = config
            .velocity
            .process(&mut self.velocity, sliding_velocity);
        let load_ok = normal >= config.min_normal_force;
        let guarded = if load_ok {
            normal
        } else {
            config.min_normal_force
        };
        // The configuration guarantees a positive minimum; the fallback is never taken.
        let normal_reciprocal = Reciprocal::of(guarded).unwrap_or(Reciprocal::ONE);
        let coefficient = normal_reciprocal
            .times(tangential.saturating_abs().value)
            .value;
        FrictionEstimate {
            normal_force: normal,
            tangential_force: tangential,
            sliding_velocity: velocity,
            coefficient,
            load_ok,
            normal_reciprocal,
        }
    }
}

impl Default for FrictionEstimator {
    fn default() -> Self {
        Self::new()
    }
}

/// Configuration of the natural-friction learning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NaturalConfig {
    /// The scene's friction coefficient, the starting value, Q2.30 in [1e-3, 2).
    pub prior: Q2_30,
    /// How many samples the prior is worth (0: the first sample learned replaces it).
    pub prior_weight: u32,
    /// Length of the averaging window once learned, samples (>= `prior_weight`).
    pub window: u32,
}

/// The learned natural friction coefficient `mu0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NaturalFriction {
    coefficient: Q2_30,
    weight: u32,
    reciprocal: Reciprocal,
}

impl NaturalFriction {
    /// Starts from the prior.
    pub fn new(config: &NaturalConfig) -> Self {
        let coefficient = config.prior.max(MIN_NATURAL_COEF);
        Self {
            coefficient,
            weight: config.prior_weight,
            reciprocal: Reciprocal::of(coefficient).unwrap_or(Reciprocal::ONE),
        }
    }

    /// Takes one coefficient measured while sliding with the drive off.
    pub fn learn(&mut self, config: &NaturalConfig, coefficient: Q2_30) {
        self.weight = self.weight.saturating_add(1).min(config.window.max(1));
        let n = NonZeroU32::new(self.weight).unwrap_or(NonZeroU32::MIN);
        // 1/n in Q2.30 by a 32-bit hardware division (UDIV, 2-12 cycles), only while learning.
        let gain = Q2_30::from_bits(((1u32 << 30) / n) as i32);
        let sample = coefficient.max(MIN_NATURAL_COEF);
        // Between two values in [1e-3, 2) with a gain in (0, 1]: cannot fail.
        self.coefficient = self.coefficient.lerp(sample, gain).unwrap_or(sample);
        self.reciprocal = Reciprocal::of(self.coefficient).unwrap_or(Reciprocal::ONE);
    }

    /// The natural friction coefficient, Q2.30 in [1e-3, 2).
    pub const fn coefficient(&self) -> Q2_30 {
        self.coefficient
    }

    /// `1 / mu0`.
    pub const fn reciprocal(&self) -> Reciprocal {
        self.reciprocal
    }

    /// The weight of the present value in samples (prior weight plus samples learned, up to
    /// the window).
    pub const fn weight(&self) -> u32 {
        self.weight
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn config() -> EstimatorConfig {
        EstimatorConfig {
            normal: LowPassCoef::from_bandwidth(200.0, 10_000.0).unwrap(),
            tangential: LowPassCoef::from_bandwidth(600.0, 10_000.0).unwrap(),
            velocity: LowPassCoef::from_bandwidth(200.0, 10_000.0).unwrap(),
            min_normal_force: Q16_16::from_f64(0.5).unwrap(),
        }
    }

    fn q16(x: f64) -> Q16_16 {
        Q16_16::from_f64(x).unwrap()
    }

    #[test]
    fn coefficient_of_steady_forces_and_the_tiny_load_guard() {
        let cfg = config();
        let mut est = FrictionEstimator::new();
        let mut e = est.update(&cfg, q16(40.0), q16(-12.0), Q8_24::ZERO);
        for _ in 0..2_000 {
            e = est.update(&cfg, q16(40.0), q16(-12.0), Q8_24::from_f64(0.038).unwrap());
        }
        assert!(e.load_ok);
        assert_eq!(e.normal_force, q16(40.0));
        assert!((e.coefficient.to_f64() - 0.3).abs() < 1e-8);
        assert!((e.sliding_velocity.to_f64() - 0.038).abs() < 1e-7);
        // Load lifted: 0.01 N with 1 N of tangential reading. The guard divides by 0.5 N.
        for _ in 0..2_000 {
            e = est.update(&cfg, q16(0.01), q16(1.0), Q8_24::ZERO);
        }
        assert!(!e.load_ok);
        assert!((e.coefficient.to_f64() - 1.999_999).abs() < 1e-5 || e.coefficient == Q2_30::MAX);
    }

    #[test]
    fn natural_friction_learns_the_mean_and_keeps_the_prior_until_then() {
        let cfg = NaturalConfig {
            prior: Q2_30::from_f64(0.3).unwrap(),
            prior_weight: 16,
            window: 2_000,
        };
        let mut natural = NaturalFriction::new(&cfg);
        assert_eq!(natural.coefficient(), cfg.prior);
        // The true coefficient is 20 % higher, seen through +-0.02 alternating noise.
        for k in 0..1_000 {
            let noise = if k % 2 == 0 { 0.02 } else { -0.02 };
            natural.learn(&cfg, Q2_30::from_f64(0.36 + noise).unwrap());
        }
        // Running mean with the prior worth 16 of 1016 samples: 0.36 - 0.06 * 16 / 1016.
        let want = 0.36 - 0.06 * 16.0 / 1016.0;
        assert!(
            (natural.coefficient().to_f64() - want).abs() < 2e-4,
            "{natural:?}"
        );
        assert_eq!(natural.weight(), 1_016);
        let recip_err = natural
            .reciprocal()
            .times::<30, 30>(natural.coefficient())
            .value;
        assert!((recip_err.to_f64() - 1.0).abs() < 1e-8);
        // Zero readings cannot drive mu0 to zero. (The running mean's rounding leaves it
        // within window / 2 ulps, 1e-6, of where it heads.)
        for _ in 0..100_000 {
            natural.learn(&cfg, Q2_30::ZERO);
        }
        assert!(natural.coefficient() >= MIN_NATURAL_COEF);
        assert!(natural.coefficient().to_f64() - MIN_NATURAL_COEF.to_f64() < 1e-6);
    }

    proptest! {
        #[test]
        fn garbage_sensor_bits_never_panic(
            samples in proptest::collection::vec((any::<i32>(), any::<i32>(), any::<i32>()), 1..50)
        ) {
            let cfg = config();
            let mut est = FrictionEstimator::new();
            for (n, t, v) in samples {
                let e = est.update(&cfg, Q16_16::from_bits(n), Q16_16::from_bits(t), Q8_24::from_bits(v));
                prop_assert!(!e.coefficient.is_negative());
                prop_assert_eq!(e.load_ok, e.normal_force >= cfg.min_normal_force);
            }
        }
    }
}
