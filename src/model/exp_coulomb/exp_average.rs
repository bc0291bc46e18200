//! Seed 002's exponential Coulomb law under a superimposed vibration, as a [`FrictionModel`].
//!
//! `crate::model::exp_coulomb` gives the law itself, mu(V) = mu_d + (mu_s - mu_d)
//! e^(-alpha_dc |V|) (seed 002 eq 10). Under a vibration along the sliding direction the
//! relative velocity is v = v_s + v_a cos(theta) (seed 003 eq 3), and the friction averaged
//! over the period, relative to the undriven friction, is
//!
//! F'/F = < mu(|v|) sgn v > / mu(v_s),
//!
//! the Littmann average (physics-notes §1) with a velocity-dependent coefficient. For
//! v_s < v_a the velocity reverses at cos(theta*) = -v_s / v_a, and the average splits into a
//! forward stretch [0, theta*] and a backward one [theta*, pi] (cos is even, so half a period
//! suffices): each integrand is smooth there, and composite Simpson with [`SIMPSON_INTERVALS`]
//! intervals per stretch integrates it to about 1e-7 for alpha_dc v_a <= 1 (seed 002 Table 1
//! with the seed 003 stack: 1.2e-3). Without reversal (v_s >= v_a) the ratio is the mean of mu
//! over the period, which by convexity is slightly above mu(v_s): ratios just over 1 are
//! correct here. With alpha_dc = 0 the result is the Littmann law exactly (to 1e-7).
//!
//! The coefficient at each node comes from the model's own fixed-point law
//! ([`ExpCoulombConstants::coefficient`]); the quadrature is `f32` with `libm` (the plant's
//! arithmetic, see [`super`]). The average is independent of the normal load.

use core::f32::consts::PI;

use crate::fx::{Q1_31, Q2_30, Q8_24};
use crate::model::exp_coulomb::ExpCoulombConstants;
use crate::model::{FrictionModel, ModelError, OperatingPoint};

/// Simpson intervals per stretch (even).
pub const SIMPSON_INTERVALS: u32 = 32;

/// The exponential Coulomb law averaged over the vibration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpCoulombVibrated {
    law: ExpCoulombConstants,
    /// Vibration velocity amplitude at full scale, 2 pi f x_a,max, m/s.
    full_scale_velocity: f32,
}

impl ExpCoulombVibrated {
    /// The law of seed 002 eq 10 (`mu_static` mu_s, `mu_dynamic` mu_d in [0, 128),
    /// `decay_s_per_m` alpha_dc >= 0) under a vibration of `full_scale_velocity_m_per_s`
    /// (> 0) at full amplitude. Errors: the law's validation; `OutOfDomain` for a
    /// non-positive velocity.
    pub fn new(
        mu_static: f64,
        mu_dynamic: f64,
        decay_s_per_m: f64,
        full_scale_velocity_m_per_s: f64,
    ) -> Result<Self, ModelError> {
        if !(full_scale_velocity_m_per_s.is_finite() && full_scale_velocity_m_per_s > 0.0) {
            return Err(ModelError::OutOfDomain {
                input: "v_a",
                reason: "the full-scale vibration velocity must be > 0",
            });
        }
        Ok(Self {
            law: ExpCoulombConstants::new(mu_static, mu_dynamic, decay_s_per_m)?,
            full_scale_velocity: full_scale_velocity_m_per_s as f32,
        })
    }

    /// mu(|v|) from the model's fixed-point law, as `f32`.
    fn coefficient(&self, speed: f32) -> Result<f32, ModelError> {
        let speed = Q8_24::from_f32_saturating(libm::fabsf(speed)).value;
        Ok(self.law.coefficient(speed)?.to_f32())
    }

    /// Integral of mu(|v_s + v_a cos theta|) over [from, to] (rad), composite Simpson.
    fn integral(&self, v_s: f32, v_a: f32, from: f32, to: f32) -> Result<f32, ModelError> {
        let h = (to - from) / SIMPSON_INTERVALS as f32;
        let mut sum = 0.0f32;
        for k in 0..=SIMPSON_INTERVALS {
            let weight = match k {
                0 => 1.0,
                _ if k == SIMPSON_INTERVALS => 1.0,
                _ if k % 2 == 1 => 4.0,
                _ => 2.0,
            };
            let theta = from + k as f32 * h;
            sum += weight * self.coefficient(v_s + v_a * libm::cosf(theta))?;
        }
        Ok(sum * h / 3.0)
    }
}

impl FrictionModel for ExpCoulombVibrated {
    /// < mu(|v|) sgn v > / mu(v_s) at |v_s| = the operating point's speed and v_a = amplitude
    /// x full-scale velocity: 1 without vibration, 0 for v_s = 0 with vibration. Error
    /// `OutOfDomain` for a negative amplitude or for v_s = 0 without vibration (the ratio is
    /// undefined without sliding).
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        if amplitude.is_negative() {
            return Err(ModelError::OutOfDomain {
                input: "amplitude",
                reason: "must be >= 0",
            });
        }
        let v_s = libm::fabsf(point.sliding_velocity.to_f32());
        let v_a = amplitude.to_f32() * self.full_scale_velocity;
        match (v_s > 0.0, v_a > 0.0) {
            (_, false) if v_s > 0.0 => return Ok(Q2_30::ONE),
            (false, false) => {
                return Err(ModelError::OutOfDomain {
                    input: "v",
                    reason: "no sliding: the friction ratio is undefined without vibration",
                });
            }
            (false, true) => return Ok(Q2_30::ZERO),
            _ => {}
        }
        let average = if v_s < v_a {
            let reversal = libm::acosf(-v_s / v_a);
            let forward = self.integral(v_s, v_a, 0.0, reversal)?;
            let backward = self.integral(v_s, v_a, reversal, PI)?;
            (forward - backward) / PI
        } else {
            self.integral(v_s, v_a, 0.0, PI)? / PI
        };
        let ratio = average / self.coefficient(v_s)?;
        Ok(Q2_30::from_f32_saturating(ratio.clamp(0.0, 1.999)).value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::Q16_16;

    /// Seed 002 Table 1 with the seed 003 stack at full scale (0.1195 m/s).
    fn table_1() -> ExpCoulombVibrated {
        ExpCoulombVibrated::new(0.42, 0.32, 0.01, 0.1195).expect("valid")
    }

    fn at(speed: f64) -> OperatingPoint {
        OperatingPoint {
            normal_force: Q16_16::from_int_const(15),
            sliding_velocity: Q8_24::from_f64_saturating(speed).value,
        }
    }

    fn amplitude(a: f64) -> Q1_31 {
        Q1_31::from_f64_saturating(a).value
    }

    /// An independent average: 2e5 samples of mu(|v|) sgn v over a period, f64.
    fn sampled(mu_s: f64, mu_d: f64, decay: f64, v_s: f64, v_a: f64) -> f64 {
        let mu = |v: f64| mu_d + (mu_s - mu_d) * (-decay * v.abs()).exp();
        let n = 200_000;
        let sum: f64 = (0..n)
            .map(|k| {
                let v = v_s + v_a * (core::f64::consts::TAU * (k as f64 + 0.5) / n as f64).cos();
                mu(v) * v.signum()
            })
            .sum();
        sum / n as f64 / mu(v_s)
    }

    #[test]
    fn without_decay_it_is_the_littmann_law() {
        let flat = ExpCoulombVibrated::new(0.3, 0.3, 0.0, 0.1).expect("valid");
        for (v_s, a) in [(0.038, 0.683), (0.01, 1.0), (0.05, 0.6), (0.09, 0.95)] {
            let ratio = flat.ratio(&at(v_s), amplitude(a)).expect("ratio").to_f64();
            let littmann = core::f64::consts::FRAC_2_PI * (v_s / (a * 0.1)).asin();
            assert!(
                (ratio - littmann).abs() < 2e-6,
                "{v_s} {a}: {ratio} vs {littmann}"
            );
        }
    }

    #[test]
    fn the_exponential_law_matches_a_sampled_average() {
        for (decay, v_s, a) in [(0.01, 0.09, 0.9), (0.01, 0.03, 0.5), (5.0, 0.05, 1.0)] {
            let model = ExpCoulombVibrated::new(0.42, 0.32, decay, 0.1195).expect("valid");
            let ratio = model.ratio(&at(v_s), amplitude(a)).expect("ratio").to_f64();
            let want = sampled(0.42, 0.32, decay, v_s, a * 0.1195);
            assert!(
                (ratio - want).abs() < 3e-5,
                "{decay} {v_s} {a}: {ratio} vs {want}"
            );
        }
    }

    #[test]
    fn limits_and_errors() {
        let model = table_1();
        assert_eq!(model.ratio(&at(0.05), Q1_31::ZERO), Ok(Q2_30::ONE));
        assert_eq!(model.ratio(&at(0.0), amplitude(0.5)), Ok(Q2_30::ZERO));
        assert!(model.ratio(&at(0.0), Q1_31::ZERO).is_err());
        assert!(model.ratio(&at(0.05), Q1_31::from_bits(-1)).is_err());
        // No reversal: the period mean of a convex decreasing mu, just above 1.
        let above = model
            .ratio(&at(0.2), amplitude(0.5))
            .expect("ratio")
            .to_f64();
        assert!((1.0..1.0 + 1e-4).contains(&above), "{above}");
        // More vibration, less friction.
        let ratios: [f64; 4] = core::array::from_fn(|k| {
            let a = 0.4 + 0.2 * k as f64;
            model
                .ratio(&at(0.05), amplitude(a))
                .expect("ratio")
                .to_f64()
        });
        assert!(ratios.windows(2).all(|w| w[1] < w[0]), "{ratios:?}");
        assert!(ExpCoulombVibrated::new(0.42, 0.32, 0.01, 0.0).is_err());
        assert!(ExpCoulombVibrated::new(0.42, 0.32, -1.0, 0.1).is_err());
    }
}
