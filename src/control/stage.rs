//! The feedforward of a target step, staged so that a plant off the model by the declared
//! mismatch cannot overshoot it (issue 23).
//!
//! After a target change the model error at the new operating point is seen only through the
//! lags after the friction (the tangential cell and the force filter): the correction follows
//! it late, so a feedforward that jumps to the target carries a plant that reduces the friction
//! `1 + m` times as much as the model (`m` the declared mismatch) past the target by up to `m` of
//! the step. The controller's prediction passes those same lags (it is what the cells will show
//! of the model's friction), so it measures how much of the step the correction can already
//! answer for. Let `x` be the feedforward's progress through the step and `z` the filtered
//! prediction's, both as fractions of the step, and let the correction follow the observed
//! model error: the plant's friction is then `(1 + m) x - m z`, which stays within the
//! overshoot `o` for
//!
//! ```text
//! x <= ((1 + o) + m z) / (1 + m).
//! ```
//!
//! The staged feedforward takes the largest such `x`: at once `(1 + o) / (1 + m)` of the step
//! (0.875 at the reference's m 0.2, o 5 %), then following the prediction's progress, the whole
//! step once `z >= (m - o) / m` (0.75). In ratio units, with `r0` the filtered prediction when
//! the step began and `u = r_target - r0`:
//!
//! ```text
//! r_ff = r0 + (1 + o) / (1 + m) u + m / (1 + m) (p_f - r0),   not beyond r_target.
//! ```
//!
//! It needs no bound on how fast the envelope follows the feedforward: the lead can ask for the
//! staged amplitude within one control period (`tuning.rs`, `controller_settings`), where the
//! first-order lead it replaces had to be slowed to 0.344 ms on the reference to bound the same
//! overshoot. A plant off by less than `m` (the reference's own) reaches 87.5 % of the step
//! in the envelope's time and the rest as the prediction's lag allows.

use super::config::ConfigError;
use crate::fx::Q2_30;

/// The two coefficients of the staged step, Q2.30: `(1 + o) / (1 + m)` (the share of the step
/// taken at once, in (0, 1)) and `m / (1 + m)` (the share of the prediction's progress
/// added, in [0, 1/2)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StageConfig {
    lead: Q2_30,
    follow: Q2_30,
}

impl StageConfig {
    /// The staging for a declared mismatch `mismatch` (a fraction in [0, 1)) and an overshoot
    /// `overshoot` (a fraction of the step, >= 0). `Ok(None)` when no staging is needed
    /// (`overshoot >= mismatch`: the whole step at once cannot overshoot by more); error
    /// `OutOfRange` naming `step_overshoot` or `model_mismatch` for a NaN, infinite or
    /// out-of-range value.
    pub fn new(overshoot: f64, mismatch: f64) -> Result<Option<Self>, ConfigError> {
        if !(overshoot.is_finite() && overshoot >= 0.0) {
            return Err(ConfigError::OutOfRange {
                setting: "step_overshoot",
            });
        }
        let bad_mismatch = ConfigError::OutOfRange {
            setting: "model_mismatch",
        };
        if !(0.0..1.0).contains(&mismatch) {
            return Err(bad_mismatch);
        }
        if overshoot >= mismatch {
            return Ok(None);
        }
        // (1 + o) / (1 + m) in (1/2, 1) and m / (1 + m) in [0, 1/2): both fit Q2.30.
        let lead =
            Q2_30::from_f64((1.0 + overshoot) / (1.0 + mismatch)).map_err(|_| bad_mismatch)?;
        let follow = Q2_30::from_f64(mismatch / (1.0 + mismatch)).map_err(|_| bad_mismatch)?;
        Ok(Some(Self { lead, follow }))
    }

    /// `(1 + o) / (1 + m)`, Q2.30.
    pub const fn lead(&self) -> Q2_30 {
        self.lead
    }

    /// `m / (1 + m)`, Q2.30.
    pub const fn follow(&self) -> Q2_30 {
        self.follow
    }

    /// This step's feedforward target ratio for the target ratio `target`, given the filtered
    /// prediction before this step (`before`, the step's start when one is pending) and after
    /// it (`predicted`), all Q2.30. Returns `target` once the step is complete (and from then
    /// on until [`StepStage::restart`]). Any input bits are fine: the bound lies between the
    /// step's start and `target`, nothing overflows.
    pub fn staged(
        &self,
        stage: &mut StepStage,
        target: Q2_30,
        before: Q2_30,
        predicted: Q2_30,
    ) -> Q2_30 {
        if stage.pending {
            stage.pending = false;
            stage.start = Some(before);
        }
        let Some(start) = stage.start else {
            return target;
        };
        let r0 = start.to_bits() as i64;
        let u = target.to_bits() as i64 - r0;
        let progress = predicted.to_bits() as i64 - r0;
        // |u|, |progress| < 2^32 and the coefficients < 2^30: the products fit i64.
        let lead = (self.lead.to_bits() as i64 * u + (1 << 29)) >> 30;
        let follow = (self.follow.to_bits() as i64 * progress + (1 << 29)) >> 30;
        let bound = r0 + lead + follow;
        let done = if u < 0 {
            bound <= target.to_bits() as i64
        } else {
            bound >= target.to_bits() as i64
        };
        if done {
            stage.start = None;
            return target;
        }
        // Not done: the bound lies strictly between r0 - |u| and target, inside Q2.30.
        Q2_30::from_bits(bound as i32)
    }
}

/// The staging's state: whether a step is to begin at the next loop step, and the filtered
/// prediction where the present one began (`None`: no step in progress).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StepStage {
    pending: bool,
    start: Option<Q2_30>,
}

impl StepStage {
    /// No step in progress.
    pub const fn new() -> Self {
        Self {
            pending: false,
            start: None,
        }
    }

    /// A step begins at the next loop step (the target changed, or the loop closed).
    pub fn restart(&mut self) {
        self.pending = true;
        self.start = None;
    }

    /// Whether a step is pending or in progress.
    pub const fn active(&self) -> bool {
        self.pending || self.start.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(x: f64) -> Q2_30 {
        Q2_30::from_f64(x).unwrap()
    }

    /// The peak overshoot, fraction of the step, of a plant whose friction moves `1 + m` times
    /// as much as the model's, `(1 + m) x - m z`, when the correction follows the model error
    /// through a first-order lag `tau_s` (`z` the model's friction through it) and the
    /// feedforward `x` is either staged or the whole step at once, stepped at `period_s`.
    fn peak(staged: bool, m: f64, o: f64, tau_s: f64, period_s: f64) -> f64 {
        let config = StageConfig::new(o, m).unwrap().unwrap();
        let mut stage = StepStage::new();
        stage.restart();
        let alpha = 1.0 - (-period_s / tau_s).exp();
        // A step of the ratio from 1 to 0.5.
        let (r0, target) = (1.0, 0.5);
        let mut p = r0;
        let mut worst: f64 = 0.0;
        for _ in 0..200 {
            let before = p;
            let r = if staged {
                config
                    .staged(&mut stage, q(target), q(before), q(p))
                    .to_f64()
            } else {
                target
            };
            // The model's friction follows the feedforward at once; the observed one lags.
            p += alpha * (r - p);
            let x = (r0 - r) / (r0 - target);
            let z = (r0 - p) / (r0 - target);
            worst = worst.max((1.0 + m) * x - m * z - 1.0);
        }
        worst
    }

    #[test]
    fn the_staged_step_keeps_a_mismatched_plant_within_the_overshoot() {
        // The reference: m 0.2, o 5 %, 0.716 ms of lag after the friction, 10 kHz. The whole
        // step at once overshoots by nearly m; the staged one by at most o.
        let at_once = peak(false, 0.2, 0.05, 0.716e-3, 1e-4);
        assert!(at_once > 0.15, "{at_once}");
        let staged = peak(true, 0.2, 0.05, 0.716e-3, 1e-4);
        assert!(staged <= 0.05 + 1e-6, "{staged}");
        assert!(staged > 0.04, "{staged}");
        // Another mismatch and lag.
        assert!(peak(true, 0.4, 0.02, 2e-3, 1e-4) <= 0.02 + 1e-6);
    }

    #[test]
    fn the_stage_takes_its_share_at_once_and_the_whole_step_once_the_prediction_follows() {
        let config = StageConfig::new(0.05, 0.2).unwrap().unwrap();
        assert!((config.lead().to_f64() - 0.875).abs() < 1e-9);
        assert!((config.follow().to_f64() - 0.2 / 1.2).abs() < 1e-9);
        let mut stage = StepStage::new();
        // No step: the target as it is.
        assert_eq!(config.staged(&mut stage, q(0.5), q(1.0), q(1.0)), q(0.5));
        stage.restart();
        assert!(stage.active());
        // From 1 to 0.5 with the prediction still at 1: 0.875 of the step.
        let first = config.staged(&mut stage, q(0.5), q(1.0), q(1.0));
        assert!((first.to_f64() - 0.5625).abs() < 1e-8, "{first:?}");
        // The prediction has covered 0.6 of the step (z 0.6): x = (1.05 + 0.12) / 1.2.
        let later = config.staged(&mut stage, q(0.5), q(0.7), q(0.7));
        assert!((later.to_f64() - (1.0 - 0.5 * 1.17 / 1.2)).abs() < 1e-8);
        // At z 0.75 the whole step; the stage ends and stays ended.
        assert_eq!(
            config.staged(&mut stage, q(0.5), q(0.625), q(0.625)),
            q(0.5)
        );
        assert!(!stage.active());
        assert_eq!(config.staged(&mut stage, q(0.5), q(1.0), q(1.0)), q(0.5));
        // Upwards (less reduction) the same, mirrored.
        stage.restart();
        let up = config.staged(&mut stage, q(0.9), q(0.5), q(0.5));
        assert!((up.to_f64() - (0.5 + 0.875 * 0.4)).abs() < 1e-8);
        // A step of nothing ends at once.
        stage.restart();
        assert_eq!(config.staged(&mut stage, q(0.5), q(0.5), q(0.5)), q(0.5));
        assert!(!stage.active());
    }

    #[test]
    fn staging_settings_are_checked() {
        assert_eq!(StageConfig::new(0.05, 0.05), Ok(None));
        assert_eq!(StageConfig::new(0.3, 0.2), Ok(None));
        assert!(StageConfig::new(f64::NAN, 0.2).is_err());
        assert!(StageConfig::new(-0.1, 0.2).is_err());
        assert!(StageConfig::new(0.05, 1.0).is_err());
        assert!(StageConfig::new(f64::INFINITY, 0.2).is_err());
    }

    #[test]
    fn any_bits_stay_between_the_start_and_the_target() {
        let config = StageConfig::new(0.0, 0.9).unwrap().unwrap();
        for (t, b, p) in [
            (i32::MIN, i32::MAX, i32::MIN),
            (i32::MAX, i32::MIN, i32::MAX),
            (0, i32::MAX, 0),
            (i32::MIN, 0, i32::MAX),
        ] {
            let mut stage = StepStage::new();
            stage.restart();
            let r = config.staged(
                &mut stage,
                Q2_30::from_bits(t),
                Q2_30::from_bits(b),
                Q2_30::from_bits(p),
            );
            let (lo, hi) = (t.min(b), t.max(b));
            assert!(r.to_bits() >= lo && r.to_bits() <= hi, "{t} {b} {p}: {r:?}");
        }
    }
}
