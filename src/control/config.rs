//! The controller's settings in SI units, and the fixed-point configuration made from them.
//!
//! [`Settings`] is what a scene or a person writes (`f64`, SI); [`Config::new`] validates it
//! and precomputes every coefficient once (filter poles, lead gain, reciprocal-free step
//! sizes, the actuator's amplitude ceiling), so the control step only multiplies and adds.
//! A `Config` is `Copy`: the loop swaps it atomically between steps
//! (`Controller::reconfigure`).

use super::estimate::{EstimatorConfig, NaturalConfig};
use super::filter::{FilterError, LowPassCoef};
use super::limits::{ActuatorRatings, AmplitudeLimit, LimitsError};
use super::pi::{GainsError, PiGains};
use super::schedule::GainSchedule;
use super::shaper::{ShaperConfig, ShaperError};
use super::sliding::SlidingConfig;
use super::stage::StageConfig;
use super::supervisor::RampConfig;
use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};

/// Controller settings, SI units. Scenes and boards run [`super::controller_settings`] (the
/// tuning, `control/tuning.rs`); [`Settings::REFERENCE`] is the baseline it starts from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Control period, s (the loop runs at 1 / period; reference 100 us, 10 kHz).
    pub period_s: f64,
    /// -3 dB bandwidth of the normal-force filter, Hz.
    pub normal_bandwidth_hz: f64,
    /// -3 dB bandwidth of the tangential-force filter, Hz (also filters the prediction).
    pub tangential_bandwidth_hz: f64,
    /// -3 dB bandwidth of the sliding-velocity filter, Hz.
    pub velocity_bandwidth_hz: f64,
    /// Smallest normal force for which a friction coefficient is formed, N.
    pub min_normal_force_n: f64,
    /// Largest plausible |normal force|, N; beyond it the sensor is faulty.
    pub normal_force_range_n: f64,
    /// Largest plausible |tangential force|, N.
    pub tangential_force_range_n: f64,
    /// Largest plausible |sliding velocity|, m/s.
    pub velocity_range_m_s: f64,
    /// Speed above which the contact slides, m/s.
    pub sliding_on_m_s: f64,
    /// Speed below which it stops sliding, m/s (< `sliding_on_m_s`).
    pub sliding_off_m_s: f64,
    /// Time a sliding change must hold before it is accepted, s.
    pub sliding_debounce_s: f64,
    /// The scene's friction coefficient, the prior of the natural friction.
    pub natural_prior: f64,
    /// How many samples the prior is worth; 0: the first sample learned replaces it.
    pub natural_prior_weight: u32,
    /// Averaging window of the natural friction once learned, s.
    pub natural_window_s: f64,
    /// Least time the natural friction is learned (sliding, loaded, drive off) before a run's
    /// drive may start, s; 0 to start at once. Capped at the averaging window.
    pub natural_learn_s: f64,
    /// Estimated vibration amplitude below which the drive counts as off for learning,
    /// fraction of full scale.
    pub natural_max_drive: f64,
    /// Time constant of the transducer's vibration envelope, s (reference 0.8 ms).
    pub envelope_time_constant_s: f64,
    /// Time constant the lead gives the envelope, s (<= the envelope's).
    pub response_time_constant_s: f64,
    /// Time constant of the tangential load cell's own first-order lag (its amplifier), s;
    /// 0 for none. The prediction passes the same lag as the measurement
    /// (`tuning.rs` says why it is not lumped into the envelope).
    pub sensor_lag_s: f64,
    /// Time constant of the contact's own friction transient, s: a Dahl contact's friction
    /// relaxes over the slip length `mu W / k_t`, at the sliding speed in `mu W / (k_t v)`
    /// (physics-notes; `tuning.rs`); 0 for a rigid contact. The prediction passes it first.
    pub contact_lag_s: f64,
    /// Slew limit: time to change the command by full scale, s.
    pub slew_full_scale_s: f64,
    /// Soft start: time for the ceiling to rise by full scale, s.
    pub ramp_up_full_scale_s: f64,
    /// Ramp-down: time to fall from full scale to zero, s.
    pub ramp_down_full_scale_s: f64,
    /// Proportional gain of the correction PI right after a target change (ratio/ratio).
    pub kp_fast: f64,
    /// Integral gain of the correction PI right after a target change, 1/s.
    pub ki_fast_per_s: f64,
    /// Proportional gain of the correction PI in steady state (ratio per ratio).
    pub kp: f64,
    /// Integral gain of the correction PI in steady state, 1/s.
    pub ki_per_s: f64,
    /// How long the fast gains are held after the loop closes or the target changes, s
    /// (then they fade to the steady ones by the running-mean law, `schedule.rs`).
    pub boost_hold_s: f64,
    /// Bound of the PI's integral, ratio units.
    pub integral_limit: f64,
    /// The actuator's ratings, for the amplitude ceiling.
    pub actuator: ActuatorRatings,
    /// RMS noise of one normal-force sample, N: measured by the cell's `tare`
    /// (`sense::SensorChannel::noise`), the datasheet's until then. Only the tuning rule
    /// ([`super::tuned`]) reads it.
    pub normal_noise_n: f64,
    /// RMS noise of one tangential-force sample, N (as `normal_noise_n`).
    pub tangential_noise_n: f64,
    /// The model's declared relative mismatch: the plant's friction reduction may differ from
    /// the model's by this fraction (0.2: the acceptance's +-20 % in mu and k_t). Only the
    /// tuning rule reads it.
    pub model_mismatch: f64,
    /// The load the noise is referred to, N: the lightest load the rig runs at (where the
    /// cells' noise is largest against the forces). Only the tuning rule reads it.
    pub design_load_n: f64,
    /// The overshoot a target step may reach, fraction of the step, with a plant off the model
    /// by `model_mismatch`: the feedforward of each step is staged so that it cannot pass it
    /// (`control/stage.rs`); `None`: the whole step at once.
    pub step_overshoot: Option<f64>,
}

impl Settings {
    /// The baseline at the reference scene's loop (10 kHz loop, 40 kHz drive, 0.8 ms envelope
    /// lag), which the controller's unit tests run against the test plant (`closed_loop.rs`).
    /// The tuning every scene and board runs is [`super::controller_settings`]: this baseline
    /// with the scene's quantities and four departures, each with its reason at its constant in
    /// `control/tuning.rs` (both force filters [`super::FORCE_FILTER_HZ`], prior weight
    /// [`super::NATURAL_PRIOR_WEIGHT`], debounce [`super::SLIDING_DEBOUNCE_S`], steady gains
    /// [`super::STEADY_GAINS`]).
    pub const REFERENCE: Self = Self {
        period_s: 1e-4,
        normal_bandwidth_hz: 200.0,
        tangential_bandwidth_hz: 800.0,
        velocity_bandwidth_hz: 200.0,
        min_normal_force_n: 0.5,
        normal_force_range_n: 2_000.0,
        tangential_force_range_n: 2_000.0,
        velocity_range_m_s: 5.0,
        sliding_on_m_s: 1e-3,
        sliding_off_m_s: 0.5e-3,
        sliding_debounce_s: 2e-3,
        natural_prior: 0.3,
        natural_prior_weight: 4,
        natural_window_s: 0.2,
        natural_learn_s: 0.0,
        natural_max_drive: 1e-3,
        envelope_time_constant_s: 0.8e-3,
        response_time_constant_s: 0.25e-3,
        sensor_lag_s: 0.0,
        contact_lag_s: 0.0,
        slew_full_scale_s: 0.5e-3,
        ramp_up_full_scale_s: 5e-3,
        ramp_down_full_scale_s: 5e-3,
        kp_fast: 0.3,
        ki_fast_per_s: 4_000.0,
        kp: 0.0,
        ki_per_s: 150.0,
        boost_hold_s: 3e-3,
        integral_limit: 0.5,
        actuator: ActuatorRatings::SEED_003_40_KHZ,
        normal_noise_n: 0.05,
        tangential_noise_n: 0.01,
        model_mismatch: 0.2,
        design_load_n: 4.0,
        step_overshoot: None,
    };
}

impl Default for Settings {
    fn default() -> Self {
        Self::REFERENCE
    }
}

/// Why settings were refused; `setting` names the field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// A filter bandwidth or time constant is unusable.
    Filter {
        /// The field.
        setting: &'static str,
        /// Why.
        error: FilterError,
    },
    /// The drive shaping settings are unusable.
    Shaper(ShaperError),
    /// The actuator ratings are unusable.
    Limits(LimitsError),
    /// The PI gains are unusable.
    Gains(GainsError),
    /// A value is NaN, non-positive where it must be positive, or does not fit its format.
    OutOfRange {
        /// The field.
        setting: &'static str,
    },
}

/// Plausible ranges of the sensor readings (beyond them a sensor is faulty).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorRanges {
    /// Largest |F_n|, Q16.16 N.
    pub normal: Q16_16,
    /// Largest |F_t|, Q16.16 N.
    pub tangential: Q16_16,
    /// Largest |v|, Q8.24 m/s.
    pub velocity: Q8_24,
}

/// The validated fixed-point configuration (`Copy`: swapped atomically between steps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Config {
    pub(super) period_s: f64,
    pub(super) estimator: EstimatorConfig,
    pub(super) ranges: SensorRanges,
    pub(super) sliding: SlidingConfig,
    pub(super) natural: NaturalConfig,
    /// The natural friction's weight (prior plus samples learned) from which a run may
    /// start: `prior_weight` plus the samples of `natural_learn_s`, at most the window.
    pub(super) natural_ready: u32,
    pub(super) natural_max_drive: Q1_31,
    pub(super) shaper: ShaperConfig,
    /// The tangential cell's lag, applied to the prediction; `None` without one.
    pub(super) sensor_lag: Option<LowPassCoef>,
    /// The contact's relaxation lag, applied to the prediction; `None` without one.
    pub(super) contact_lag: Option<LowPassCoef>,
    pub(super) ramp: RampConfig,
    pub(super) gains: GainSchedule,
    /// The staging of a target step's feedforward; `None`: the whole step at once.
    pub(super) stage: Option<StageConfig>,
    pub(super) limit: AmplitudeLimit,
    /// The ratings `limit` was computed from, kept for [`Config::at_drive_frequency`].
    pub(super) actuator: ActuatorRatings,
}

/// The PI's gain schedule of `settings`: the fast set held for `boost_hold_s`, fading to the
/// steady set. Errors: `Gains` for unusable gains or hold, `OutOfRange` for the period.
pub fn gain_schedule(settings: &Settings) -> Result<GainSchedule, ConfigError> {
    let s = settings;
    let period = positive(s.period_s, "period_s")?;
    GainSchedule::new(
        PiGains::new(s.kp_fast, s.ki_fast_per_s, period, s.integral_limit)
            .map_err(ConfigError::Gains)?,
        PiGains::new(s.kp, s.ki_per_s, period, s.integral_limit).map_err(ConfigError::Gains)?,
        s.boost_hold_s,
        period,
    )
    .map_err(ConfigError::Gains)
}

/// A positive finite value, or the error naming `setting`.
fn positive(value: f64, setting: &'static str) -> Result<f64, ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ConfigError::OutOfRange { setting })
    }
}

/// The prediction's contact-lag stage for a lag of `contact_lag_s` at `period`: none for a
/// lag whose step decays below 2^-31 within one period (tau < T / (31 ln 2)), the identity at
/// the prediction's Q2.30 resolution: no stage, no cost.
fn contact_lag_stage(contact_lag_s: f64, period: f64) -> Result<Option<LowPassCoef>, ConfigError> {
    if contact_lag_s == 0.0
        || (contact_lag_s > 0.0 && contact_lag_s * 31.0 * core::f64::consts::LN_2 < period)
    {
        Ok(None)
    } else {
        LowPassCoef::from_time_constant(contact_lag_s, period)
            .map(Some)
            .map_err(|error| ConfigError::Filter {
                setting: "contact_lag_s",
                error,
            })
    }
}

/// Steps of `duration_s`, rounded, at least one, saturating.
fn steps(duration_s: f64, period_s: f64) -> u32 {
    libm::round(duration_s / period_s).clamp(1.0, u32::MAX as f64) as u32
}

impl Config {
    /// Validates `settings` and precomputes the fixed-point configuration (`f64`, once).
    pub fn new(settings: &Settings) -> Result<Self, ConfigError> {
        let s = settings;
        let period = positive(s.period_s, "period_s")?;
        let rate = 1.0 / period;
        let filter = |hz: f64, setting| {
            LowPassCoef::from_bandwidth(hz, rate)
                .map_err(|error| ConfigError::Filter { setting, error })
        };
        let q16 = |x: f64, setting| {
            Q16_16::from_f64(positive(x, setting)?).map_err(|_| ConfigError::OutOfRange { setting })
        };
        let q24 = |x: f64, setting| {
            Q8_24::from_f64(positive(x, setting)?).map_err(|_| ConfigError::OutOfRange { setting })
        };
        let fraction = |x: f64, setting| {
            if x.is_finite() && x >= 0.0 {
                Ok(Q1_31::from_f64_saturating(x).value)
            } else {
                Err(ConfigError::OutOfRange { setting })
            }
        };
        let step = |duration: f64, setting| {
            let step = period / positive(duration, setting)?;
            Ok::<_, ConfigError>(Q1_31::from_f64_saturating(step).value.max(Q1_31::ULP))
        };
        if !(s.sliding_off_m_s >= 0.0 && s.sliding_off_m_s < s.sliding_on_m_s) {
            return Err(ConfigError::OutOfRange {
                setting: "sliding_off_m_s",
            });
        }
        let prior = positive(s.natural_prior, "natural_prior")?;
        let prior = Q2_30::from_f64(prior).map_err(|_| ConfigError::OutOfRange {
            setting: "natural_prior",
        })?;
        let prior_weight = s.natural_prior_weight;
        let window =
            steps(positive(s.natural_window_s, "natural_window_s")?, period).max(prior_weight);
        let learn = s.natural_learn_s;
        if !(learn.is_finite() && learn >= 0.0) {
            return Err(ConfigError::OutOfRange {
                setting: "natural_learn_s",
            });
        }
        let learn_steps = libm::round(learn / period).min(u32::MAX as f64) as u32;
        let natural_ready = prior_weight.saturating_add(learn_steps).min(window);
        let debounce = s.sliding_debounce_s;
        if !(debounce.is_finite() && debounce >= 0.0) {
            return Err(ConfigError::OutOfRange {
                setting: "sliding_debounce_s",
            });
        }
        Ok(Self {
            period_s: period,
            estimator: EstimatorConfig {
                normal: filter(s.normal_bandwidth_hz, "normal_bandwidth_hz")?,
                tangential: filter(s.tangential_bandwidth_hz, "tangential_bandwidth_hz")?,
                velocity: filter(s.velocity_bandwidth_hz, "velocity_bandwidth_hz")?,
                min_normal_force: q16(s.min_normal_force_n, "min_normal_force_n")?,
            },
            ranges: SensorRanges {
                normal: q16(s.normal_force_range_n, "normal_force_range_n")?,
                tangential: q16(s.tangential_force_range_n, "tangential_force_range_n")?,
                velocity: q24(s.velocity_range_m_s, "velocity_range_m_s")?,
            },
            sliding: SlidingConfig {
                on: q24(s.sliding_on_m_s, "sliding_on_m_s")?,
                off: Q8_24::from_f64_saturating(s.sliding_off_m_s).value,
                debounce_steps: libm::round(debounce / period).min(u32::MAX as f64) as u32,
            },
            natural: NaturalConfig {
                prior,
                prior_weight,
                window,
            },
            natural_ready,
            natural_max_drive: fraction(s.natural_max_drive, "natural_max_drive")?,
            shaper: ShaperConfig::new(
                s.envelope_time_constant_s,
                s.response_time_constant_s,
                s.slew_full_scale_s,
                period,
            )
            .map_err(ConfigError::Shaper)?,
            contact_lag: contact_lag_stage(s.contact_lag_s, period)?,
            sensor_lag: if s.sensor_lag_s == 0.0 {
                None
            } else {
                let lag = LowPassCoef::from_time_constant(s.sensor_lag_s, period);
                Some(lag.map_err(|error| ConfigError::Filter {
                    setting: "sensor_lag_s",
                    error,
                })?)
            },
            ramp: RampConfig {
                up_step: step(s.ramp_up_full_scale_s, "ramp_up_full_scale_s")?,
                down_step: step(s.ramp_down_full_scale_s, "ramp_down_full_scale_s")?,
            },
            gains: gain_schedule(s)?,
            stage: match s.step_overshoot {
                Some(overshoot) => StageConfig::new(overshoot, s.model_mismatch)?,
                None => None,
            },
            limit: AmplitudeLimit::new(&s.actuator).map_err(ConfigError::Limits)?,
            actuator: s.actuator,
        })
    }

    /// This configuration on `settings` that differ from the ones it was built from only in
    /// what commissioning measures (`crate::station::commissioned_settings`): the envelope and
    /// lead time constants (`shaper`, [`ShaperConfig::new`] of them, computed before), the
    /// contact lag, the natural coefficient's prior, the drive frequency (the ceiling) and the
    /// gains (`gains`, [`gain_schedule`] of `settings`, computed before). Equal to
    /// [`Config::new`] of `settings` under that condition, at a fraction of its cost (the
    /// force and speed filters, the sensor lag, the ranges and ramps are kept), so that the
    /// station can put a `commission` result into the loop within control periods. Errors: as
    /// [`Config::new`] for the values it recomputes.
    pub fn commissioned(
        &self,
        settings: &Settings,
        gains: GainSchedule,
        shaper: ShaperConfig,
    ) -> Result<Self, ConfigError> {
        let s = settings;
        let prior = positive(s.natural_prior, "natural_prior")?;
        let prior = Q2_30::from_f64(prior).map_err(|_| ConfigError::OutOfRange {
            setting: "natural_prior",
        })?;
        Ok(Self {
            natural: NaturalConfig {
                prior,
                ..self.natural
            },
            shaper,
            contact_lag: contact_lag_stage(s.contact_lag_s, self.period_s)?,
            gains,
            limit: AmplitudeLimit::new(&s.actuator).map_err(ConfigError::Limits)?,
            actuator: s.actuator,
            ..*self
        })
    }

    /// This configuration with the drive at `drive_frequency_hz`: the amplitude ceiling is
    /// recomputed, since the current rating binds at `a = I_max / (2 pi f C V_fs)`; everything
    /// else is kept. Configuration only (`f64`), between two steps. Errors: the frequency is not
    /// finite and positive, or the ratings leave no headroom there
    /// ([`ConfigError::Limits`]).
    pub fn at_drive_frequency(&self, drive_frequency_hz: f64) -> Result<Self, ConfigError> {
        let actuator = ActuatorRatings {
            drive_frequency_hz,
            ..self.actuator
        };
        Ok(Self {
            limit: AmplitudeLimit::new(&actuator).map_err(ConfigError::Limits)?,
            actuator,
            ..*self
        })
    }

    /// The actuator ratings the ceiling is computed from (at the present drive frequency).
    pub const fn actuator(&self) -> ActuatorRatings {
        self.actuator
    }

    /// The control period, s.
    pub const fn period_s(&self) -> f64 {
        self.period_s
    }

    /// The PI gain schedule.
    pub const fn gains(&self) -> GainSchedule {
        self.gains
    }

    /// The actuator's amplitude ceiling.
    pub const fn limit(&self) -> AmplitudeLimit {
        self.limit
    }

    /// The estimator's filters and load guard.
    pub const fn estimator(&self) -> EstimatorConfig {
        self.estimator
    }

    /// The drive shaping (envelope model, lead gain, slew step).
    pub const fn shaper(&self) -> ShaperConfig {
        self.shaper
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_settings_make_a_config() {
        let c = Config::new(&Settings::REFERENCE).unwrap();
        // The period the config reports is the one it was built for (10 kHz).
        assert_eq!(c.period_s(), Settings::REFERENCE.period_s);
        assert_eq!(c.period_s(), 1e-4);
        assert_eq!(c.sliding.debounce_steps, 20);
        assert_eq!(c.natural.window, 2_000);
        assert!((c.ramp.up_step.to_f64() - 0.02).abs() < 1e-9);
        assert!((c.shaper.slew_step().to_f64() - 0.2).abs() < 1e-9);
        assert!((c.estimator.tangential.bandwidth_hz(10_000.0) - 800.0).abs() < 0.1);
        assert_eq!(c.limit.max_amplitude, Q1_31::MAX);
        assert!((c.gains.fast().ki_step().to_f64() - 0.4).abs() < 1e-9);
        assert!((c.gains.slow().ki_step().to_f64() - 0.015).abs() < 1e-9);
    }

    #[test]
    fn each_bad_setting_is_named() {
        let r = Settings::REFERENCE;
        let cases: [(Settings, ConfigError); 6] = [
            (
                Settings { period_s: 0.0, ..r },
                ConfigError::OutOfRange {
                    setting: "period_s",
                },
            ),
            (
                Settings {
                    tangential_bandwidth_hz: 6_000.0,
                    ..r
                },
                ConfigError::Filter {
                    setting: "tangential_bandwidth_hz",
                    error: FilterError::AboveNyquist,
                },
            ),
            (
                Settings {
                    sliding_off_m_s: 2e-3,
                    ..r
                },
                ConfigError::OutOfRange {
                    setting: "sliding_off_m_s",
                },
            ),
            (
                Settings {
                    natural_prior: 3.0,
                    ..r
                },
                ConfigError::OutOfRange {
                    setting: "natural_prior",
                },
            ),
            (
                Settings {
                    ki_fast_per_s: 1e5,
                    ..r
                },
                ConfigError::Gains(GainsError::OutOfRange),
            ),
            (
                Settings {
                    min_normal_force_n: f64::NAN,
                    ..r
                },
                ConfigError::OutOfRange {
                    setting: "min_normal_force_n",
                },
            ),
        ];
        for (settings, error) in cases {
            assert_eq!(Config::new(&settings), Err(error));
        }
    }
}
