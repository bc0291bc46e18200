//! Test doubles for the controller: two small friction models, a first-order plant with
//! load-cell noise, and a seeded random generator. Test-only.

use super::io::Inputs;
use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16, sin};
use crate::model::{FrictionModel, Inversion, ModelError, OperatingPoint, Reach};

/// `F'/F = 1 - slope a`, floored at 0; inverted by the trait's default bisection.
pub struct LinearModel {
    pub slope: Q2_30,
}

impl FrictionModel for LinearModel {
    fn ratio(&self, _point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        let reduction: Q2_30 = self.slope.saturating_mul_to::<30, 31>(amplitude).value;
        Ok(Q2_30::ONE.saturating_sub(reduction).value.max(Q2_30::ZERO))
    }
}

/// The Littmann law (physics-notes §1) with the vibration velocity amplitude proportional to
/// the drive: `F'/F = 2/pi asin(v / (a v_max))` when `a v_max > v`, else 1. Closed-form
/// inverse `a = v / (v_max sin(pi r / 2))`.
pub struct LittmannModel {
    /// Vibration velocity amplitude at full drive, m/s, Q8.24.
    pub velocity_max: Q8_24,
}

impl LittmannModel {
    pub fn new(velocity_max_m_s: f64) -> Self {
        Self {
            velocity_max: Q8_24::from_f64(velocity_max_m_s).unwrap(),
        }
    }
}

impl FrictionModel for LittmannModel {
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        let overflow = ModelError::Overflow { quantity: "zeta" };
        let vibration: Q8_24 = self
            .velocity_max
            .saturating_mul_to::<24, 31>(amplitude)
            .value;
        let v = point.sliding_velocity.saturating_abs().value;
        if vibration <= v {
            return Ok(Q2_30::ONE);
        }
        let zeta: Q2_30 = v
            .checked_div_to::<30, 24>(vibration)
            .map_err(|_| overflow)?;
        let angle = zeta.asin().map_err(|_| overflow)?;
        angle.checked_mul(Q2_30::FRAC_2_PI).map_err(|_| overflow)
    }

    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        if target >= Q2_30::ONE {
            return Ok(Inversion {
                amplitude: Q1_31::ZERO,
                ratio: Q2_30::ONE,
                reach: Reach::AboveNatural,
            });
        }
        let full = self.ratio(point, Q1_31::MAX)?;
        if target <= full {
            return Ok(Inversion {
                amplitude: Q1_31::MAX,
                ratio: full,
                reach: Reach::BelowMinimum,
            });
        }
        // A quarter turn is 2^30 in the phase: r in Q2.30 is the phase of (pi/2) r.
        let zeta = sin(target.to_bits() as u32);
        let vibration: Q8_24 = self.velocity_max.saturating_mul_to::<24, 31>(zeta).value;
        let v = point.sliding_velocity.saturating_abs().value;
        let amplitude: Q1_31 = v.checked_div_to::<31, 24>(vibration).unwrap_or(Q1_31::MAX);
        Ok(Inversion {
            amplitude,
            ratio: self.ratio(point, amplitude)?,
            reach: Reach::Reached,
        })
    }
}

/// xorshift64* (Vigna), seeded: reproducible noise without a dependency.
pub struct XorShift(u64);

impl XorShift {
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (core::f64::consts::TAU * u2).cos()
    }
}

/// The test plant: a Littmann contact whose vibration envelope lags the command (first order,
/// exact discretisation), read by two load cells with Gaussian noise of a given RMS.
pub struct Plant {
    pub mu: f64,
    pub velocity_max: f64,
    pub sliding_velocity: f64,
    pub normal_force: f64,
    pub envelope: f64,
    envelope_alpha: f64,
    pub normal_noise_n: f64,
    pub tangential_noise_n: f64,
    rng: XorShift,
}

impl Plant {
    pub fn new(mu: f64, velocity_max: f64, tau_env_s: f64, period_s: f64, seed: u64) -> Self {
        Self {
            mu,
            velocity_max,
            sliding_velocity: 0.038,
            normal_force: 40.0,
            envelope: 0.0,
            envelope_alpha: 1.0 - (-period_s / tau_env_s).exp(),
            normal_noise_n: 0.0,
            tangential_noise_n: 0.0,
            rng: XorShift::new(seed),
        }
    }

    /// The true friction ratio at the present envelope.
    pub fn ratio(&self) -> f64 {
        let vibration = self.envelope * self.velocity_max;
        let v = self.sliding_velocity.abs();
        if vibration <= v {
            1.0
        } else {
            (v / vibration).asin() * core::f64::consts::FRAC_2_PI
        }
    }

    /// The true friction force, N (opposing the sliding: negative for positive velocity).
    pub fn friction(&self) -> f64 {
        -self.mu * self.normal_force * self.ratio() * self.sliding_velocity.signum()
    }

    /// This sample's sensor readings.
    pub fn measure(&mut self) -> Inputs {
        let normal = self.normal_force + self.normal_noise_n * self.rng.normal();
        let tangential = self.friction() + self.tangential_noise_n * self.rng.normal();
        Inputs {
            normal_force: Q16_16::from_f64(normal).unwrap(),
            tangential_force: Q16_16::from_f64(tangential).unwrap(),
            sliding_velocity: Q8_24::from_f64(self.sliding_velocity).unwrap(),
            sensor_fault: None,
        }
    }

    /// Applies the drive command for one period.
    pub fn advance(&mut self, command: crate::drive::Amplitude) {
        self.envelope += self.envelope_alpha * (command.to_f64() - self.envelope);
    }
}
