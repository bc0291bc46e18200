//! From the desired vibration amplitude to the drive command: envelope-lag compensation, the
//! slew limit and the ceilings.
//!
//! The transducer's vibration envelope follows the drive command with a first-order lag
//! (acceptance scene: `tau_env = 0.8 ms`, eight control periods). A plain step of the command
//! would take `4 tau_env = 3.2 ms` to come within 2 %, more than the whole settling budget.
//! The shaper keeps an estimate `a_env` of the envelope (the same lag, `alpha_env = 1 -
//! exp(-T / tau_env)`) and commands `u = a_env + g (a_desired - a_env)` with
//! `g = alpha_resp / alpha_env`, which makes the envelope follow the desired amplitude with
//! the faster time constant `tau_resp` (default 0.25 ms, `g = 2.8`): the lag's pole is
//! cancelled and replaced (a first-order lead). The overdrive this needs is bounded by the
//! slew limit and the ceilings; when they cut it, the estimate still follows the command
//! actually applied, so it stays right and the response is simply slower.
//!
//! Order of the limits: lead, then slew (`|u - u_prev| <= slew_step`), then the ceiling and
//! the floor 0. The ceiling comes last because it is a rating: it is never exceeded, even if
//! that means a step larger than the slew limit.

use super::SampleBlock;
use super::filter::{FilterError, LowPass, LowPassCoef};
use crate::fx::{Q1_31, Q8_24};

/// Configuration of the drive shaping.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ShaperConfig {
    envelope: LowPassCoef,
    lead_gain: Q8_24,
    slew_step: Q1_31,
    /// `2 s (1 - alpha_env) / alpha_env` (`s` the slew step), Q8.24 in [0, 128): the braking
    /// bound's coefficient ([`ShaperConfig::braking_excess`]).
    brake: Q8_24,
}

/// Why the shaping settings were refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ShaperError {
    /// A time constant or the period is not usable as a filter (see [`FilterError`]).
    Filter(FilterError),
    /// The slew time is not a finite positive number, or the lead gain is >= 128.
    OutOfRange,
}

impl ShaperConfig {
    /// Shaping for an envelope lag `envelope_tau_s`, a desired response time constant
    /// `response_tau_s` (equal to `envelope_tau_s` for no lead), and a slew limit of full
    /// scale in `slew_full_scale_s`, at the control period `period_s`. Configuration only.
    pub fn new(
        envelope_tau_s: f64,
        response_tau_s: f64,
        slew_full_scale_s: f64,
        period_s: f64,
    ) -> Result<Self, ShaperError> {
        let envelope = LowPassCoef::from_time_constant(envelope_tau_s, period_s)
            .map_err(ShaperError::Filter)?;
        let response = LowPassCoef::from_time_constant(response_tau_s, period_s)
            .map_err(ShaperError::Filter)?;
        if !(slew_full_scale_s.is_finite() && slew_full_scale_s > 0.0) {
            return Err(ShaperError::OutOfRange);
        }
        let gain = response.alpha().to_f64() / envelope.alpha().to_f64();
        let lead_gain = Q8_24::from_f64(gain).map_err(|_| ShaperError::OutOfRange)?;
        let step = (period_s / slew_full_scale_s).min(1.0);
        let slew_step = Q1_31::from_f64_saturating(step).value.max(Q1_31::ULP);
        // Below 128: beyond it the bound exceeds full scale for every gap above 2^-7 anyway
        // (sqrt(128 d) > 1), so the largest Q8.24 value is taken there.
        let alpha = envelope.alpha().to_f64();
        let brake =
            Q8_24::from_f64_saturating(2.0 * slew_step.to_f64() * (1.0 - alpha) / alpha).value;
        Ok(Self {
            envelope,
            lead_gain,
            slew_step,
            brake,
        })
    }

    /// The most the command may pass the desired amplitude while the envelope is `gap` (Q1.31,
    /// at least 0) short of it, so that the slew limit can still bring the command back before the
    /// envelope passes the desired amplitude: `sqrt(h^2 + 2 s (1 - alpha) / alpha d) - h`, `h =
    /// d + s / 2`.
    ///
    /// Why: the lead's command is `a_env + g (a_des - a_env)`; with a large `g` (a slow envelope
    /// against a fast lead) it lies far above `a_des`, and coming down costs `n = (u - a_des) /
    /// s` steps at the slew step `s`, over which the envelope keeps rising by `alpha (u_j -
    /// a_env)` a step. With `w = u - a_des` and `d = a_des - a_env`, and the envelope taken as
    /// standing still (an upper bound), the rise over the `n + 1` steps `u, u - s, ..., a_des`
    /// is at most `alpha (w / s + 1) (w / 2 + d)`; it stays within `d` for `w^2 + (s + 2 d) w -
    /// 2 s d (1 / alpha - 1) <= 0`. Without the bound a 60 kHz, Q 200 transducer (g 7 with a
    /// lead of one period) overshot its 30 % step by 20 %.
    pub fn braking_excess(&self, gap: Q1_31) -> Q1_31 {
        // In units of 2^-23 (d, h < 2^24): 4 h^2 + 2 b d < 2^50 + 2^55, its root in units of
        // 2^-24, below 2^28, shifted to Q1.31 below 2^35: taken at most full scale.
        let d = (gap.to_bits().max(0) as u64) >> 8;
        let h = d + ((self.slew_step.to_bits().max(0) as u64) >> 9);
        let b = self.brake.to_bits().max(0) as u64;
        let root = u64::from(crate::fx::isqrt_u64(4 * h * h + 2 * b * d));
        let excess = ((root << 7) as i64 - ((h << 8) as i64)).clamp(0, i32::MAX as i64);
        Q1_31::from_bits(excess as i32)
    }

    /// The envelope model's coefficient `1 - exp(-T / tau_env)`.
    pub const fn envelope(&self) -> LowPassCoef {
        self.envelope
    }

    /// The lead gain `g`, Q8.24, >= 1 when the response is faster than the envelope.
    pub const fn lead_gain(&self) -> Q8_24 {
        self.lead_gain
    }

    /// Largest change of the command per step, Q1.31 fraction of full scale.
    pub const fn slew_step(&self) -> Q1_31 {
        self.slew_step
    }
}

/// The command of one step and which limit shaped it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Shaped {
    /// Drive command, Q1.31 fraction of full scale in [0, ceiling].
    pub amplitude: Q1_31,
    /// The slew limit cut the lead's command.
    pub slew_limited: bool,
    /// The ceiling cut the command.
    pub ceiling_limited: bool,
}

/// State of the drive shaping: the last command and the envelope estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveShaper {
    command: Q1_31,
    envelope: LowPass<31>,
    /// The envelope estimate before the last command was applied ([`Self::replace`]).
    before: LowPass<31>,
}

impl DriveShaper {
    /// Drive off, envelope at rest.
    pub const fn new() -> Self {
        Self {
            command: Q1_31::ZERO,
            envelope: LowPass::new(Q1_31::ZERO),
            before: LowPass::new(Q1_31::ZERO),
        }
    }

    /// Applies `amplitude` as it is (ramp-down, drive off, fault: no lead, no slew) and
    /// advances the envelope estimate with it. Negative values are taken as zero.
    pub fn apply(&mut self, config: &ShaperConfig, amplitude: Q1_31) {
        self.command = amplitude.max(Q1_31::ZERO);
        self.before = self.envelope;
        config.envelope.process(&mut self.envelope, self.command);
    }

    /// Replaces the last command by `amplitude`, the drive actually applied over that step
    /// (another owner drove the transducer: the resonance search), and advances the envelope
    /// estimate from where it was before that step with it. Negative values are taken as zero.
    pub fn replace(&mut self, config: &ShaperConfig, amplitude: Q1_31) {
        self.envelope = self.before;
        self.apply(config, amplitude);
    }

    /// The last command, Q1.31 fraction of full scale in [0, 1).
    pub const fn command(&self) -> Q1_31 {
        self.command
    }

    /// The estimated vibration envelope (the command through the transducer's lag), Q1.31
    /// fraction of full scale in [0, 1). Exactly zero once the drive has been off long enough.
    pub const fn envelope(&self) -> Q1_31 {
        self.envelope.output()
    }
}

/// One step's request to the shaper: the amplitude the loop wants and the ceiling it may not
/// pass, both Q1.31 fractions of full scale in [0, 1) (a negative ceiling counts as zero).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveRequest {
    /// The amplitude the loop wants.
    pub desired: Q1_31,
    /// The ceiling of this step (the limit, or the soft start's ramp).
    pub ceiling: Q1_31,
}

/// The shaper: one step's request through the lead, the slew limit and the ceiling into this
/// step's command, which also advances the envelope estimate.
impl SampleBlock<DriveRequest> for ShaperConfig {
    type State = DriveShaper;
    type Output = Shaped;

    fn process(&self, shaper: &mut DriveShaper, request: DriveRequest) -> Shaped {
        let envelope = shaper.envelope.output().to_bits() as i64;
        // (desired - envelope) in (-2^31, 2^31) times g < 2^31: below 2^62.
        let push = (request.desired.to_bits() as i64 - envelope) * self.lead_gain.to_bits() as i64;
        let lead = envelope + ((push + (1 << 23)) >> 24);
        // No more overdrive than the slew limit can take back before the envelope passes the
        // desired amplitude ([`ShaperConfig::braking_excess`]), either way.
        let desired = request.desired.to_bits() as i64;
        let gap = Q1_31::from_bits((desired - envelope).abs().min(i32::MAX as i64) as i32);
        let excess = self.braking_excess(gap).to_bits() as i64;
        let lead = lead
            .min(desired.max(envelope) + excess)
            .max(desired.min(envelope) - excess);
        let previous = shaper.command.to_bits() as i64;
        let step = self.slew_step.to_bits() as i64;
        // max/min, not clamp: no panic path in the binary.
        let slewed = lead.min(previous + step).max(previous - step);
        let ceiling_bits = request.ceiling.to_bits().max(0) as i64;
        let bounded = slewed.min(ceiling_bits).max(0);
        let shaped = Shaped {
            amplitude: Q1_31::from_bits(bounded as i32), // in [0, ceiling]
            slew_limited: slewed != lead,
            ceiling_limited: slewed > ceiling_bits,
        };
        shaper.apply(self, shaped.amplitude);
        shaped
    }
}

impl Default for DriveShaper {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const T: f64 = 1e-4;

    fn a(x: f64) -> Q1_31 {
        Q1_31::from_f64(x).unwrap()
    }

    #[test]
    fn lead_makes_the_envelope_follow_the_faster_time_constant() {
        // A slow slew limit would hide the lead; allow full scale in one step here.
        let cfg = ShaperConfig::new(0.8e-3, 0.25e-3, 1e-4, T).unwrap();
        assert!((cfg.lead_gain().to_f64() - 2.805).abs() < 1e-3);
        let mut shaper = DriveShaper::new();
        let mut true_envelope = 0.0f64;
        let alpha_env = 1.0 - (-T / 0.8e-3f64).exp();
        for n in 1..=30 {
            let shaped = cfg.process(
                &mut shaper,
                DriveRequest {
                    desired: a(0.3),
                    ceiling: Q1_31::MAX,
                },
            );
            true_envelope += alpha_env * (shaped.amplitude.to_f64() - true_envelope);
            let want = 0.3 * (1.0 - (-(n as f64) * T / 0.25e-3).exp());
            assert!(
                (true_envelope - want).abs() < 1e-6,
                "step {n}: {true_envelope} vs {want}"
            );
            assert!((shaper.envelope().to_f64() - true_envelope).abs() < 1e-8);
        }
    }

    #[test]
    fn a_replaced_command_advances_the_envelope_from_before_it() {
        let config = ShaperConfig::new(0.8e-3, 0.25e-3, 0.5e-3, 1e-4).unwrap();
        let mut told = DriveShaper::new();
        let mut applied = DriveShaper::new();
        for k in 0..30 {
            let search = a(if k < 20 { 0.1 } else { 0.0 });
            config.process(
                &mut told,
                DriveRequest {
                    desired: a(0.6),
                    ceiling: a(0.9),
                },
            );
            told.replace(&config, search);
            applied.apply(&config, search);
            assert_eq!(told, applied, "step {k}");
        }
        assert!(told.envelope().to_f64() > 0.02 && told.command() == Q1_31::ZERO);
    }

    #[test]
    fn slew_and_ceiling_limit_the_command() {
        let cfg = ShaperConfig::new(0.8e-3, 0.25e-3, 0.5e-3, T).unwrap(); // 0.2 per step
        let mut shaper = DriveShaper::new();
        let s = cfg.process(
            &mut shaper,
            DriveRequest {
                desired: a(0.9),
                ceiling: a(0.5),
            },
        );
        assert!(s.slew_limited && !s.ceiling_limited);
        assert!((s.amplitude.to_f64() - 0.2).abs() < 1e-9);
        let s = cfg.process(
            &mut shaper,
            DriveRequest {
                desired: a(0.9),
                ceiling: a(0.5),
            },
        );
        assert!((s.amplitude.to_f64() - 0.4).abs() < 1e-9);
        let s = cfg.process(
            &mut shaper,
            DriveRequest {
                desired: a(0.9),
                ceiling: a(0.5),
            },
        );
        assert!(s.ceiling_limited && s.amplitude == a(0.5));
        // A ceiling dropped below the command applies at once, beyond the slew limit.
        let s = cfg.process(
            &mut shaper,
            DriveRequest {
                desired: a(0.9),
                ceiling: a(0.1),
            },
        );
        assert_eq!(s.amplitude, a(0.1));
        // Drive off: the envelope estimate decays to exactly zero.
        for _ in 0..2_000 {
            shaper.apply(&cfg, Q1_31::ZERO);
        }
        assert_eq!(shaper.envelope(), Q1_31::ZERO);
    }

    #[test]
    fn the_overdrive_stops_where_the_slew_limit_can_still_take_it_back() {
        // 60 kHz, Q 200 (tau_env 1.06 ms), a lead of one period (g 7.0), full scale slewed
        // in 0.5 ms: the step to 0.3 must not carry the envelope past 0.3. Without the
        // braking bound the command sat at full scale and came down 0.2 a step too late: the
        // envelope reached 0.325.
        let cfg = ShaperConfig::new(1.061e-3, 1e-4, 0.5e-3, T).unwrap();
        assert!(
            (cfg.lead_gain().to_f64() - 6.99).abs() < 0.05,
            "{:?}",
            cfg.lead_gain()
        );
        let mut shaper = DriveShaper::new();
        let mut peak = 0.0f64;
        for _ in 0..100 {
            cfg.process(
                &mut shaper,
                DriveRequest {
                    desired: a(0.3),
                    ceiling: a(0.999),
                },
            );
            peak = peak.max(shaper.envelope().to_f64());
        }
        assert!(peak <= 0.3 + 1e-6, "{peak}");
        assert!((shaper.envelope().to_f64() - 0.3).abs() < 1e-4);
        // The bound: sqrt(h^2 + 2 s (1 - alpha) / alpha d) - h, h = d + s / 2; 0 with no
        // gap, and never negative.
        let alpha = cfg.envelope().alpha().to_f64();
        let (d, s) = (0.1, 0.2);
        let h = d + s / 2.0;
        let want = (h * h + 2.0 * s * (1.0 - alpha) / alpha * d).sqrt() - h;
        let got = cfg.braking_excess(a(d)).to_f64();
        assert!((got - want).abs() < 1e-5, "{got} {want}");
        assert_eq!(cfg.braking_excess(Q1_31::ZERO), Q1_31::ZERO);
        assert_eq!(cfg.braking_excess(Q1_31::from_bits(-5)), Q1_31::ZERO);
        assert!(cfg.braking_excess(Q1_31::MAX).to_f64() > 0.0);
    }

    #[test]
    fn settings_are_validated() {
        assert!(ShaperConfig::new(0.0, 0.25e-3, 1e-3, T).is_err());
        assert!(ShaperConfig::new(0.8e-3, 0.25e-3, 0.0, T).is_err());
        assert_eq!(
            ShaperConfig::new(10.0, 1e-6, 1e-3, T),
            Err(ShaperError::OutOfRange)
        );
    }

    proptest! {
        #[test]
        fn any_requests_stay_in_zero_to_ceiling(
            steps in proptest::collection::vec((any::<i32>(), any::<i32>()), 1..100)
        ) {
            let cfg = ShaperConfig::new(0.8e-3, 0.1e-3, 0.2e-3, T).unwrap();
            let mut shaper = DriveShaper::new();
            for (desired, ceiling) in steps {
                let s = cfg.process(&mut shaper, DriveRequest { desired: Q1_31::from_bits(desired), ceiling: Q1_31::from_bits(ceiling) });
                prop_assert!(!s.amplitude.is_negative());
                prop_assert!(s.amplitude.to_bits() <= ceiling.max(0));
                prop_assert!(!shaper.envelope().is_negative());
            }
        }
    }
}
