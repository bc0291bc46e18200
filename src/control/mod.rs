//! Friction control: hold a target friction by the drive amplitude of the ultrasonic
//! lubrication (physics-notes §1-6).
//!
//! One [`Controller::step`] per control period (10 kHz in the reference scene) turns the two
//! load cells and the sliding velocity into a drive amplitude:
//!
//! ```text
//!  F_n, F_t, v ──> estimate ──> mu, F_n, v ──┬──> target ratio r_t (target.rs)
//!  (Q16.16, Q8.24)  (filters, guard)         │
//!                                            │  measured ratio r_m = mu / mu0
//!  model.ratio(point, a_env) ─> r̂ ─> cell lag ─> same filter as F_t ─> r̂_f
//!  PI error e = (r̂_f - c) - r_m ──> PI (fast→slow gains) ──> correction c
//!  model.invert(point, r_t + c) ──> feedforward amplitude ──> actuator ceiling
//!   ──> lead (envelope-lag compensation) ──> slew ──> ceiling ──> drive command u
//!  supervisor: idle / ramp-up / running / ramp-down / fault, a reason on every transition
//! ```
//!
//! # Formats, units and ranges
//!
//! | quantity | type | unit | range |
//! |---|---|---|---|
//! | normal and tangential force, force ranges, `F_n_min` | Q16.16 | N | ±32768, 15 µN steps |
//! | sliding velocity, sliding thresholds | Q8.24 | m/s | ±128 |
//! | friction coefficients `mu`, `mu0`, coef target | Q2.30 | 1 | [0, 2) |
//! | friction ratio `F'/F` (target, measured, command), PI error, correction, integral | Q2.30 | 1 | [0, 2), signed ±2 |
//! | amplitudes (command, feedforward, envelope estimate, ceilings, ramp and slew steps) | Q1.31 | fraction of full scale | [0, 1) |
//! | force target | Q18.14 ([`ForceQ`]) | N | up to 131072 N |
//! | filter coefficient `alpha` | Q1.31 | 1 | [2^-20, 1) |
//! | filter state | `i64` | input lsb × 2^31 | |
//! | `kp`, lead gain `g` | Q8.24 | 1 | [0, 128) |
//! | `ki T`, gain-schedule decay | Q2.30 | 1 | [0, 1] |
//! | reciprocals `1/F_n`, `1/mu0` | [`Reciprocal`]: Q2.30 mantissa and exponent | | any positive value |
//!
//! Everything per step is integer arithmetic, rounded to nearest, saturating where a range can
//! be exceeded; there is no division (reciprocals by Newton-Raphson), no float and no loop.
//! Configuration ([`Settings`] → [`Config`]) is `f64`, once.
//!
//! # Estimate (estimate.rs, sliding.rs)
//!
//! First-order low-passes (filter.rs, exactly -3 dB at the stated frequency): **both forces
//! 250 Hz** ([`FORCE_FILTER_HZ`]: equal filters make `F_t / F_n` follow a load change exactly;
//! the prediction passes the same filter) and **velocity 1 kHz** ([`VELOCITY_FILTER_HZ`]).
//! `mu = |F_t| / F_n`, with `F_n` guarded at `F_n_min` (0.5 N): below it the contact counts as
//! unloaded. `mu0` starts at the scene's `mu`, worth no sample ([`NATURAL_PRIOR_WEIGHT`]: the
//! first sample replaces it), and is learned (running mean, then a 0.2 s window) only while
//! sliding with the drive off, e.g. before a start or while the target is natural friction; a
//! run's drive starts only after 3 ms of it ([`NATURAL_LEARN_S`]). Sliding: hysteresis 1 /
//! 0.5 mm/s and a 1 ms debounce ([`SLIDING_DEBOUNCE_S`]).
//!
//! The tuning every scene and board runs is [`controller_settings`] (why each value:
//! `tuning.rs`). It starts from [`Settings::REFERENCE`], a baseline with a 200 Hz normal and an
//! 800 Hz tangential filter, a 200 Hz speed filter, prior weight 4, a 2 ms debounce, no wait
//! for mu0, no cell lag in the prediction and steady gains kp 0 / ki 150 /s;
//! the controller's unit tests against the test plant (and "Numbers" below) run that baseline.
//!
//! # Feedforward, reference and PI (pi.rs, schedule.rs)
//!
//! The feedforward is the model inversion: `a = invert(point, r_t + c)` at the measured
//! (filtered) `F_n` and `|v|`. The PI corrects the model error `c` in ratio units, so its loop
//! gain does not depend on the slope of the model (the Littmann law has a dead zone and an
//! infinite slope at its edge, where an amplitude-domain PI would be useless or unstable).
//!
//! The PI does not compare the measurement with the target but with what the model predicts the
//! cells read *now*: `r̂ = model.ratio(point, a_env)` at the estimated actual envelope (the
//! transducer's time constant), passed through the tangential cell's own lag and the
//! tangential filter, as the measurement is, minus the present correction. At steady state that is the
//! target (`r̂ = r_t + c`), so `e = r_t - r_m` there and the integral removes every static
//! error; during a transient, the envelope lag, the filter lag, the slew limit, the soft start
//! and the saturations are all inside the prediction, so the error is only the model mismatch
//! and the integral does not wind up over the feedforward's own transient. A target change moves
//! nothing in the feedback path (bumpless); gain changes re-base the integral (bumpless).
//! Clamping anti-windup freezes the integral when the drive is at its floor or ceiling in the
//! direction the error pushes (the model's natural friction or full drive, the actuator limit,
//! the soft start), and the integral is bounded to ±0.5 regardless.
//!
//! Tuning by pole placement. For a static mismatch `d`, `e_k = -(d + c_(k-1))`, so the
//! correction obeys `c_k = (1 - kp - kiT) c_(k-1) + kp c_(k-2)` + drive: poles
//! `z^2 - (1 - kp - kiT) z - kp = 0`. **Fast gains `kp` 0.3, `ki` 4000 /s** (`kiT` 0.4): poles
//! 0.72 and -0.42, a 0.3 ms time constant, the scale of the response the mismatch is seen
//! through (0.25 ms; the force filters' lag is in the prediction too); faster overcorrects,
//! because the mismatch seen mid-transient belongs to another amplitude (with ±20 % mismatch
//! `d` itself changes with `c` by a factor 0.8 to 1.25, the margin this leaves). That is the
//! baseline; the scenes and boards run the fast `ki` the tuning rule computes ([`tuned`]: the
//! Kalman gain `m / (sigma_r sqrt(tau_L T))` of the observed model error against the cells'
//! measured noise, capped at `ki T = 1 - m - kp` so that the correction's dominant pole stays
//! non-negative for a declared mismatch `m`; 5000 /s for the reference). **Slow gains `kp`
//! 0.1, `ki` 300 /s** ([`STEADY_GAINS`]): poles 0.973 and -0.103, 3.6 ms, fast enough to follow
//! a model error that moves with the operating point. The gains start fast when the loop
//! closes or the target changes, are held for three observation lags (`tau_L`, the envelope's
//! response, the contact's relaxation, the cell and the force filter: [`observation_lag_s`])
//! and then fade by the running-mean law `ki(t) = 1 / (t + 1 / ki_fast)` to the slow set
//! (`schedule.rs`): the model error of a new operating point is found quickly, then averaged.
//! The derivation: docs/control-and-scenes.md, "Tuning from the rig's physics".
//!
//! # Drive shaping and limits (shaper.rs, limits.rs)
//!
//! The envelope lag (0.8 ms, pole 0.8825) is cancelled by a lead that places the response pole at
//! **`tau_resp` = 0.25 ms** (0.6703, gain `g` = 2.8): a step of amplitude settles to 2 % in about
//! 1 ms instead of 3.2 ms, and steps up to 1/g of full scale need no more than full drive. Then
//! the slew limit (full scale in 0.5 ms) and the ceiling `min(V_max / V_fs, I_max / (2 pi f C
//! V_fs))` from the actuator ratings. Soft start: full scale in 5 ms; ramp-down: 5 ms.
//!
//! # Supervisor (supervisor.rs, reason.rs)
//!
//! Idle, ramp-up, running, ramp-down and a latched fault, with a [`Reason`] (stable code and
//! name, table in reason.rs) on every transition. A sensor fault (reported, or a reading beyond
//! the sensor's range) or a model error puts the drive at zero in the same step. Losing sliding
//! or load ramps down to zero and restarts when the contact returns. Commands return
//! [`ControlError`], which maps to the protocol's codes 21-23 (and 6 for a bad target).
//!
//! # Numbers
//!
//! The controller on the test plant (settling, overshoot, noise, load ramp) and its cost on the
//! Cortex-M4, with the commands that measure them: `docs/control-and-scenes.md`, "The
//! controller on the test plant".

mod block;
mod config;
mod controller;
mod error;
mod error_text;
mod estimate;
mod filter;
mod io;
mod limits;
mod net_force;
mod pi;
mod reason;
mod recip;
mod schedule;
mod shaper;
mod sliding;
mod stage;
mod supervisor;
mod target;
mod tuning;

#[cfg(test)]
mod closed_loop;
#[cfg(test)]
mod controller_tests;
#[cfg(test)]
mod pi_tests;
#[cfg(test)]
mod property_tests;
#[cfg(test)]
mod testkit;

pub use block::SampleBlock;
pub use config::{Config, ConfigError, SensorRanges, Settings, gain_schedule};
pub use controller::{Controller, ControllerState};
pub use error::ControlError;
pub use estimate::{
    EstimatorConfig, FrictionEstimate, FrictionEstimator, MIN_NATURAL_COEF, NaturalConfig,
    NaturalFriction,
};
pub use filter::{FilterError, LowPass, LowPassCoef};
pub use io::{Inputs, Output, Saturation};
pub use limits::{ActuatorRatings, AmplitudeLimit, Binding, LimitsError};
pub use net_force::{HoldStep, NET_FORCE_MAX_MN, NetForceHold, NetForceTarget};
pub use pi::{Clamp, GainsError, Pi, PiCandidate, PiGains};
pub use reason::{ExternalFault, Reason, Sensor, SensorFault, SensorFaultKind};
pub use recip::Reciprocal;
pub use schedule::{Boost, GainSchedule};
pub use shaper::{DriveRequest, DriveShaper, Shaped, ShaperConfig, ShaperError};
pub use sliding::{SlidingConfig, SlidingDetector};
pub use stage::{StageConfig, StepStage};
pub use supervisor::{Contact, RampConfig, Supervisor};
pub use target::{ForceQ, PreparedTarget};
pub use tuning::{
    DECLARED_MODEL_MISMATCH, FORCE_FILTER_HZ, HOLD_LAG_MULTIPLE, MAX_STAGED_LEAD_GAIN,
    NATURAL_LEARN_S, NATURAL_PRIOR_WEIGHT, SLIDING_DEBOUNCE_S, STEADY_GAINS, VELOCITY_FILTER_HZ,
    contact_lag_s, controller_settings, declared_mismatch, drive_lead_s, learning_samples,
    low_pass_variance_share, natural_learning_error, noise_limited_ki_per_s, noise_rms_error,
    observation_lag_s, overshoot_criterion, ratio_noise, sampled_ki_cap_per_s,
    soft_start_full_scale_s, staged_response_time_constant_s, steady_noise_rms_error,
    steady_noise_share, tuned,
};
