//! The Coulomb model under a longitudinal vibration (seed 003 eqs 1-4; physics-notes §1): scene
//! constants, the period-averaged friction F_avg = mu W mu_i(v / v_a), and [`CoulombModel`], its
//! [`FrictionModel`] with a closed-form inverse (the Littmann law inverted).
//!
//! # Costs (Coulomb and Dahl models)
//!
//! Instructions executed on the Cortex-M4 instruction set, counted under QEMU `mps2-an386`
//! (`-accel tcg,one-insn-per-tb=on -d exec,nochain`: one trace line per instruction) for a
//! call through a non-inlined wrapper (call, return and result unpacking included), built for
//! `thumbv7em-none-eabihf` at `opt-level = "s"` with fat LTO. SMULL/UMULL are single-cycle on
//! the Cortex-M4F, so cycles are close to these counts.
//!
//! | call | instructions |
//! |---|---|
//! | [`super::littmann::mu_i`], mean over zeta in [-1, 1) (bench build, `docs/speed.md`) | 45 |
//! | [`super::dahl::update`] (exact, alpha = 1), Q2.30 travel (bench build, `docs/speed.md`) | 44 |
//! | [`super::wide::recip`] | 69 |
//! | [`CoulombModel`] `ratio` (v / v_a included) / closed-form `invert` | 360-410 / 810-850 |
//! | [`super::exp_coulomb::ExpCoulombConstants::friction`] | 206 |
//! | actuator stroke + current + voltage limit | 306 |
//! | [`super::dahl_steady::DahlModel`] `ratio`, N = 64 / N = 32 | 49k / 26k |
//!
//! The rows other than the first two were traced before `exp_neg` and the Littmann law were
//! made faster; `scripts/speed-table` measures the current costs of every variant
//! (`docs/speed.md`: Coulomb ratio 287, Dahl steady N = 64 37,608).
//!
//! The first two are the hot-path goals (80 and 60): `mu_i` meets it except on
//! 1/2 < |zeta| < 1, where `fx`'s `asin` takes its half-angle branch and a square root.

use crate::fx::{Q, Q1_31, Q2_30, Q8_24, sin};

use super::fx_error;
use super::littmann::{VelocityRatio, velocity_ratio};
use super::{FrictionModel, Inversion, ModelError, OperatingPoint, Reach};
use crate::fx::Scaled;
use crate::fx::wide;

/// Scene constants of the Coulomb model (seed 003 eqs 2-4), built once from SI values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CoulombConstants {
    mu: Q8_24,
    full_scale_velocity: Scaled,
    inv_full_scale_velocity: Scaled,
}

impl CoulombConstants {
    /// `friction_coefficient` mu (dimensionless, [0, 128)), `frequency_hz` f (> 0) and the
    /// scene's full-scale vibration amplitude `full_scale_amplitude_m` x_a,max in metres (> 0):
    /// amplitude 1.0 means v_a = 2 pi f x_a,max (seed 003 eq 2). f64, scene load only.
    ///
    /// Errors: `NonFinite`; `OutOfDomain` for mu < 0 or mu >= 128, f <= 0, x_a,max <= 0.
    pub fn new(
        friction_coefficient: f64,
        frequency_hz: f64,
        full_scale_amplitude_m: f64,
    ) -> Result<Self, ModelError> {
        let mu = friction_coefficient_q("mu", friction_coefficient)?;
        let frequency = crate::model::scaled_from_f64(frequency_hz, "f")?;
        let amplitude = crate::model::scaled_from_f64(full_scale_amplitude_m, "x_a")?;
        let full_scale_velocity = crate::model::scaled_from_f64(
            core::f64::consts::TAU * frequency.to_f64() * amplitude.to_f64(),
            "v_a",
        )?;
        Ok(Self {
            mu,
            full_scale_velocity,
            inv_full_scale_velocity: wide::recip(full_scale_velocity),
        })
    }

    /// Friction coefficient mu, Q8.24.
    pub fn friction_coefficient(&self) -> Q8_24 {
        self.mu
    }

    /// Vibration velocity amplitude v_a = amplitude * 2 pi f x_a,max in m/s for `amplitude`
    /// (Q1.31 fraction of full scale, [0, 1)); `None` for amplitude <= 0 (no vibration).
    pub fn vibration_velocity(&self, amplitude: Q1_31) -> Option<Scaled> {
        wide::from_q(amplitude).map(|a| wide::mul(a, self.full_scale_velocity))
    }

    /// Period-averaged Coulomb friction (seed 003 eq 4 averaged, physics-notes §1) at the load
    /// `normal_force` (W in newtons, any format `Q<FW>`, >= 0), sliding velocity `v` (m/s, any
    /// format, any sign) and `amplitude` (Q1.31 fraction of full scale, [0, 1)).
    ///
    /// Errors: `OutOfDomain` for W < 0, amplitude < 0, or v = 0 without vibration; `Overflow`
    /// when mu W does not fit `Q<FW>` (pick a format with room for mu W).
    pub fn average<const FW: u32, const FV: u32>(
        &self,
        normal_force: Q<FW>,
        v: Q<FV>,
        amplitude: Q1_31,
    ) -> Result<CoulombAverage<FW>, ModelError> {
        if normal_force.is_negative() {
            return Err(negative("W"));
        }
        if amplitude.is_negative() {
            return Err(negative("amplitude"));
        }
        let vibration_velocity = self.vibration_velocity(amplitude);
        let ratio = velocity_ratio(v, vibration_velocity)?;
        let mu_i = ratio.mu_i()?;
        let level: Q<FW> = normal_force
            .checked_mul_to(self.mu)
            .map_err(fx_error("mu W"))?;
        let without = if v.is_positive() {
            level
        } else if v.is_negative() {
            level.checked_neg().map_err(fx_error("mu W"))?
        } else {
            Q::<FW>::ZERO
        };
        Ok(CoulombAverage {
            vibration_velocity,
            velocity_ratio: ratio,
            mu_i,
            friction_without_vibration: without,
            average_friction: level.checked_mul_to(mu_i).map_err(fx_error("F_avg"))?,
        })
    }
}

/// Result of [`CoulombConstants::average`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CoulombAverage<const FW: u32> {
    /// v_a in m/s; `None` without vibration.
    pub vibration_velocity: Option<Scaled>,
    /// zeta = v / v_a.
    pub velocity_ratio: VelocityRatio,
    /// mu_i(zeta) = F_avg / (mu W), Q2.30 in [-1, 1].
    pub mu_i: Q2_30,
    /// mu W sgn(v) in newtons, in the load's format (0 at v = 0).
    pub friction_without_vibration: Q<FW>,
    /// F_avg = mu W mu_i(zeta) in newtons, in the load's format.
    pub average_friction: Q<FW>,
}

impl<const FW: u32> CoulombAverage<FW> {
    /// Relative reduction 1 - |mu_i| = (2/pi) acos(|zeta|), Q2.30 in [0, 1] (times 100: the
    /// percent reduction of seed 003 Tables 2-3).
    pub fn reduction(&self) -> Q2_30 {
        Q2_30::from_bits(Q2_30::ONE.to_bits() - self.mu_i.to_bits().abs())
    }
}

/// A friction coefficient in Q8.24 from f64 (scene load).
pub(crate) fn friction_coefficient_q(input: &'static str, x: f64) -> Result<Q8_24, ModelError> {
    if !x.is_finite() {
        return Err(ModelError::NonFinite { input });
    }
    if !(0.0..128.0).contains(&x) {
        return Err(ModelError::OutOfDomain {
            input,
            reason: "friction coefficient must be in [0, 128)",
        });
    }
    Q8_24::from_f64(x).map_err(fx_error(input))
}

fn negative(input: &'static str) -> ModelError {
    ModelError::OutOfDomain {
        input,
        reason: "must be >= 0",
    }
}

/// The Coulomb model as a [`FrictionModel`]: ratio F'/F = |mu_i(v / v_a)|, v_a = amplitude *
/// 2 pi f x_a,max; 1 without vibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CoulombModel {
    /// The scene's constants.
    pub constants: CoulombConstants,
}

impl FrictionModel for CoulombModel {
    /// |mu_i(v / v_a)|, Q2.30 in [0, 1]: exactly 1 for amplitude 0 or |v| >= v_a, 0 for v = 0
    /// with vibration on. Error `OutOfDomain` for a negative amplitude, or v = 0 without
    /// vibration (static friction: the ratio is undefined).
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        if amplitude.is_negative() {
            return Err(negative("amplitude"));
        }
        let v_a = self.constants.vibration_velocity(amplitude);
        let mu_i = velocity_ratio(point.sliding_velocity, v_a)?.mu_i()?;
        Ok(Q2_30::from_bits(mu_i.to_bits().abs()))
    }

    /// Closed form: zeta = sin(pi r / 2) (r = target), v_a = |v| / zeta, amplitude = v_a /
    /// v_a,max (seed 001 eq 1 inverted). `AboveNatural` (amplitude 0) for r >= 1;
    /// `BelowMinimum` (full amplitude) when the amplitude would reach full scale, including
    /// r <= 0 (zeta = 0 needs v_a = infinity). Error `OutOfDomain` for v = 0 (ratio undefined
    /// without vibration). Cost: one `sin`, one reciprocal, two products, plus one
    /// [`Self::ratio`] to report the ratio actually reached (about 830 instructions, module
    /// docs).
    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        let v = point.sliding_velocity;
        let Some(speed) = wide::from_q(v.saturating_abs().value) else {
            return Err(ModelError::OutOfDomain {
                input: "v",
                reason: "no sliding: the friction ratio is undefined without vibration",
            });
        };
        if target >= Q2_30::ONE {
            return Ok(Inversion {
                amplitude: Q1_31::ZERO,
                ratio: Q2_30::ONE,
                reach: Reach::AboveNatural,
            });
        }
        // sin(pi r / 2): r in Q2.30 is r quarter turns, i.e. r 2^30 in 2^32-per-turn phase.
        let zeta = if target.is_positive() {
            wide::from_q(sin(target.to_bits() as u32))
        } else {
            None
        };
        let amplitude = zeta.map(|z| {
            let needed = wide::mul(speed, wide::recip(z));
            wide::to_q::<31>(wide::mul(needed, self.constants.inv_full_scale_velocity))
        });
        match amplitude {
            Some(a) if !a.saturated && a.value < Q1_31::MAX => Ok(Inversion {
                amplitude: a.value,
                ratio: self.ratio(point, a.value)?,
                reach: Reach::Reached,
            }),
            _ => Ok(Inversion {
                amplitude: Q1_31::MAX,
                ratio: self.ratio(point, Q1_31::MAX)?,
                reach: Reach::BelowMinimum,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q8_24, Q16_16};
    use core::f64::consts::{FRAC_2_PI, TAU};

    /// Seed 003 §4.1 with the printed v_a = 0.0683 m/s at 40 kHz (x_a = 0.2718 um), as the
    /// amplitude 0.5 of a 0.5436 um full scale.
    fn seed003() -> CoulombConstants {
        CoulombConstants::new(0.2, 40e3, 2.0 * 0.0683 / (TAU * 40e3)).unwrap()
    }

    fn half() -> Q1_31 {
        Q1_31::from_f64(0.5).unwrap()
    }

    #[test]
    fn seed_003_exact_reductions() {
        let c = seed003();
        let w = Q16_16::from_f64(0.540).unwrap();
        for (v, want_pct) in [(0.038, 62.438_825_297_721), (0.068, 5.969_040_014_305)] {
            let v = Q8_24::from_f64(v).unwrap();
            let avg = c.average(w, v, half()).unwrap();
            let pct = 100.0 * avg.reduction().to_f64();
            // Against the closed form at the Q8.24 velocity, and (looser: the quantisation of
            // v moves zeta by 4e-7, 3e-4 points at zeta = 0.9956) at the SI velocity.
            let exact = 200.0 / core::f64::consts::PI * (v.to_f64() / 0.0683).acos();
            assert!((pct - exact).abs() < 1e-6, "{pct} vs {exact}");
            assert!((pct - want_pct).abs() < 5e-4, "{pct} vs {want_pct}");
            let level = 0.2 * w.to_f64();
            assert!((avg.friction_without_vibration.to_f64() - level).abs() < 2e-5);
            let f_avg = level * (1.0 - pct / 100.0);
            assert!((avg.average_friction.to_f64() - f_avg).abs() < 2e-5);
        }
        let v_a = c.vibration_velocity(half()).unwrap().to_f64();
        assert!((v_a / 0.0683 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn errors_and_limits() {
        let c = seed003();
        let w = Q16_16::from_f64(1.0).unwrap();
        let v = Q8_24::from_f64(-0.01).unwrap();
        assert!(c.average(Q16_16::from_bits(-1), v, half()).is_err());
        assert!(c.average(w, v, Q1_31::from_bits(-1)).is_err());
        assert!(c.average(w, Q8_24::ZERO, Q1_31::ZERO).is_err());
        let still = c.average(w, v, Q1_31::ZERO).unwrap();
        assert_eq!(still.mu_i.to_f64(), -1.0);
        assert_eq!(still.average_friction, still.friction_without_vibration);
        let stopped = c.average(w, Q8_24::ZERO, half()).unwrap();
        assert_eq!(
            (stopped.mu_i, stopped.reduction()),
            (Q2_30::ZERO, Q2_30::ONE)
        );
        // mu W beyond the load's format is an error, not a wrap.
        let c3 = CoulombConstants::new(3.0, 40e3, 1e-6).unwrap();
        assert!(matches!(
            c3.average(Q16_16::from_int(20_000).unwrap(), v, half()),
            Err(ModelError::Overflow { .. })
        ));
        assert!(CoulombConstants::new(-0.1, 40e3, 1e-6).is_err());
        assert!(CoulombConstants::new(0.1, 0.0, 1e-6).is_err());
        assert!(CoulombConstants::new(0.1, 40e3, f64::NAN).is_err());
    }

    fn model() -> CoulombModel {
        CoulombModel {
            constants: seed003(),
        }
    }

    fn point(v: f64) -> OperatingPoint {
        OperatingPoint {
            normal_force: Q16_16::from_f64(0.54).unwrap(),
            sliding_velocity: Q8_24::from_f64(v).unwrap(),
        }
    }

    #[test]
    fn ratio_is_monotone_and_matches_the_closed_form() {
        let m = model();
        let p = point(0.038);
        let mut last = Q2_30::ONE;
        for k in 0..=1000 {
            let a = Q1_31::from_bits((k as i64 * i32::MAX as i64 / 1000) as i32);
            let r = m.ratio(&p, a).unwrap();
            assert!(r <= last, "not monotone at {k}");
            last = r;
            let v_a = 2.0 * 0.0683 * a.to_f64();
            let v = p.sliding_velocity.to_f64();
            let want = if v_a <= v {
                1.0
            } else {
                FRAC_2_PI * (v / v_a).asin()
            };
            assert!((r.to_f64() - want).abs() < 1e-8, "{k}: {r:?} vs {want}");
        }
        assert_eq!(m.ratio(&point(0.0), half()), Ok(Q2_30::ZERO));
        assert!(m.ratio(&point(0.0), Q1_31::ZERO).is_err());
    }

    #[test]
    fn closed_form_inverse_round_trips_and_reports_reach() {
        let m = model();
        let p = point(-0.038);
        for k in 1..100 {
            let target = Q2_30::from_f64(0.37 + 0.006 * k as f64).unwrap();
            let inv = m.invert(&p, target).unwrap();
            assert_eq!(inv.reach, Reach::Reached, "{target:?}");
            assert!((inv.ratio.to_f64() - target.to_f64()).abs() < 1e-6);
            // The default bisection lands on the same amplitude.
            let bisected = super::super::invert(&m, &p, target, 24).unwrap();
            let gap = (bisected.amplitude.to_f64() - inv.amplitude.to_f64()).abs();
            assert!(gap < 1e-6, "closed form vs bisection: {gap}");
        }
        let high = m.invert(&p, Q2_30::ONE).unwrap();
        assert_eq!(
            (high.amplitude, high.reach),
            (Q1_31::ZERO, Reach::AboveNatural)
        );
        // Full amplitude gives zeta = 0.278, mu_i = 0.179: lower targets are out of reach.
        for target in [Q2_30::ZERO, Q2_30::from_f64(0.1).unwrap()] {
            let low = m.invert(&p, target).unwrap();
            assert_eq!(
                (low.amplitude, low.reach),
                (Q1_31::MAX, Reach::BelowMinimum)
            );
            assert!(
                (low.ratio.to_f64() - FRAC_2_PI * (0.038f64 / (2.0 * 0.0683)).asin()).abs() < 1e-6
            );
        }
        assert!(
            m.invert(&point(0.0), Q2_30::from_f64(0.5).unwrap())
                .is_err()
        );
    }
}
