//! Closed-loop performance metrics, computed online (no stored time series).
//!
//! The same accumulator runs in the host scene runner and in the firmware, so both report the
//! same numbers for the same scene. It is fed once per control step with the target friction,
//! the friction the loop is judged on (the plant's true friction in a simulation) and whether the
//! drive sat at its limit. A new *segment* starts whenever the target changes; for each segment
//! it records:
//!
//! - **settling time**: from the target change to the last step outside the band
//!   `|friction - target| <= band * |target|` (the band is 2 % in the scene criteria);
//! - **overshoot**: the largest excursion past the target in the direction of the step, in
//!   percent of the step size (0 for a segment without a step);
//! - **steady-state RMS error**: RMS of `(friction - target) / target` over the part of the
//!   segment that starts `steady_after_s` after the target change (the settling budget), in
//!   percent;
//! - **worst tracking error**: the largest `|friction - target| / |target|` over that same part;
//! - **time at the drive limit**.
//!
//! Arithmetic is `f32` (the Cortex-M4F has a single-precision FPU; this is not the control step).

/// What the metrics need to know about a run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MetricsConfig {
    /// Control period, in seconds (> 0).
    pub period_s: f32,
    /// Relative settling band (0.02 for +-2 %).
    pub band: f32,
    /// Time after a target change from which the segment counts as steady, in seconds.
    pub steady_after_s: f32,
}

/// Metrics of one segment (between two target changes).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SegmentMetrics {
    /// Time of the target change that started the segment, in seconds.
    pub start_s: f32,
    /// Duration of the segment, in seconds.
    pub duration_s: f32,
    /// Target during the segment (same unit as the friction fed in).
    pub target: f32,
    /// Size of the target step that started the segment (target minus the previous target).
    pub step: f32,
    /// Settling time, in seconds; `None` if the friction was still outside the band at the end.
    pub settling_s: Option<f32>,
    /// Overshoot in percent of the step size (0 without a step).
    pub overshoot_pct: f32,
    /// RMS relative error over the steady part, in percent (`None` if the segment is shorter
    /// than `steady_after_s`).
    pub steady_rms_pct: Option<f32>,
    /// Largest relative error over the steady part, in percent.
    pub steady_max_pct: Option<f32>,
    /// Time with the drive at its limit, in seconds.
    pub at_limit_s: f32,
}

/// Online accumulator of [`SegmentMetrics`], one segment at a time.
#[derive(Debug, Clone, Copy)]
pub struct Metrics {
    config: MetricsConfig,
    steps: u32,
    current: Option<Segment>,
}

#[derive(Debug, Clone, Copy)]
struct Segment {
    start_step: u32,
    target: f32,
    step: f32,
    last_outside_step: Option<u32>,
    overshoot: f32,
    steady_count: u32,
    steady_sum_sq: f32,
    steady_max: f32,
    at_limit_steps: u32,
}

impl Metrics {
    /// A new accumulator.
    pub const fn new(config: MetricsConfig) -> Self {
        Self {
            config,
            steps: 0,
            current: None,
        }
    }

    /// Feeds one control step. Returns the metrics of the segment that ended, if the target
    /// changed at this step. Non-finite values are treated as outside the band.
    pub fn record(&mut self, target: f32, friction: f32, at_limit: bool) -> Option<SegmentMetrics> {
        let mut ended = None;
        let changed = match &self.current {
            Some(segment) => segment.target != target,
            None => true,
        };
        if changed {
            let previous = self.current.map(|s| s.target);
            ended = self.finish();
            self.current = Some(Segment {
                start_step: self.steps,
                target,
                step: previous.map_or(0.0, |p| target - p),
                last_outside_step: None,
                overshoot: 0.0,
                steady_count: 0,
                steady_sum_sq: 0.0,
                steady_max: 0.0,
                at_limit_steps: 0,
            });
        }
        let steady_after_steps = self.steps_for(self.config.steady_after_s);
        let band = self.config.band;
        let now = self.steps;
        if let Some(segment) = &mut self.current {
            let error = friction - segment.target;
            let scale = libm::fabsf(segment.target);
            let relative = if scale > 0.0 { error / scale } else { error };
            // NaN compares false, so a non-finite value counts as outside the band.
            let inside = libm::fabsf(relative) <= band;
            if !inside {
                segment.last_outside_step = Some(now);
            }
            // Past the target in the direction of the step: positive `error * sign(step)`.
            if segment.step != 0.0 {
                let past = error * libm::copysignf(1.0, segment.step);
                if past > segment.overshoot {
                    segment.overshoot = past;
                }
            }
            if now - segment.start_step >= steady_after_steps && relative.is_finite() {
                segment.steady_count += 1;
                segment.steady_sum_sq += relative * relative;
                segment.steady_max = segment.steady_max.max(libm::fabsf(relative));
            }
            if at_limit {
                segment.at_limit_steps += 1;
            }
        }
        self.steps = self.steps.saturating_add(1);
        ended
    }

    /// Ends the current segment (at the end of a run) and returns its metrics.
    pub fn finish(&mut self) -> Option<SegmentMetrics> {
        let segment = self.current.take()?;
        let period = self.config.period_s;
        let length = self.steps - segment.start_step;
        let settling_s = match segment.last_outside_step {
            None => Some(0.0),
            Some(last) if last + 1 < self.steps => {
                Some((last + 1 - segment.start_step) as f32 * period)
            }
            Some(_) => None,
        };
        let overshoot_pct = if segment.step != 0.0 {
            100.0 * segment.overshoot / libm::fabsf(segment.step)
        } else {
            0.0
        };
        let (steady_rms_pct, steady_max_pct) = if segment.steady_count > 0 {
            (
                Some(100.0 * libm::sqrtf(segment.steady_sum_sq / segment.steady_count as f32)),
                Some(100.0 * segment.steady_max),
            )
        } else {
            (None, None)
        };
        Some(SegmentMetrics {
            start_s: segment.start_step as f32 * period,
            duration_s: length as f32 * period,
            target: segment.target,
            step: segment.step,
            settling_s,
            overshoot_pct,
            steady_rms_pct,
            steady_max_pct,
            at_limit_s: segment.at_limit_steps as f32 * period,
        })
    }

    fn steps_for(&self, seconds: f32) -> u32 {
        if self.config.period_s > 0.0 && seconds > 0.0 {
            libm::ceilf(seconds / self.config.period_s) as u32
        } else {
            0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CONFIG: MetricsConfig = MetricsConfig {
        period_s: 1e-4,
        band: 0.02,
        steady_after_s: 3e-3,
    };

    /// A first-order response from `from` to `to` with time constant `tau_s`.
    fn first_order(metrics: &mut Metrics, from: f32, to: f32, tau_s: f32, steps: u32) -> f32 {
        let mut value = from;
        let k = 1.0 - libm::expf(-CONFIG.period_s / tau_s);
        for _ in 0..steps {
            metrics.record(to, value, false);
            value += k * (to - value);
        }
        value
    }

    #[test]
    fn first_order_step_settles_at_the_analytic_time_without_overshoot() {
        let mut m = Metrics::new(CONFIG);
        for _ in 0..10 {
            assert!(m.record(1.0, 1.0, false).is_none());
        }
        first_order(&mut m, 1.0, 0.5, 0.8e-3, 200);
        let segment = m.finish().expect("a segment");
        // |0.5 e^(-t/tau)| <= 0.02 * 0.5  ->  t = tau ln 50 = 3.13 ms (sampled at 0.1 ms).
        let settling = segment.settling_s.expect("settled");
        assert!(
            (settling - 0.8e-3 * 50f32.ln()).abs() <= 1.0e-4,
            "{settling}"
        );
        assert_eq!(segment.overshoot_pct, 0.0);
        assert!((segment.step + 0.5).abs() < 1e-6);
        assert!(segment.steady_max_pct.unwrap() <= 100.0 * 0.5 * (-3.0f32 / 0.8).exp() / 0.5 + 0.5);
    }

    #[test]
    fn overshoot_is_measured_in_percent_of_the_step() {
        let mut m = Metrics::new(CONFIG);
        m.record(1.0, 1.0, false);
        // Step down to 0.5; the response dips to 0.45 (10 % of the 0.5 step) and comes back.
        for value in [0.8, 0.6, 0.45, 0.48, 0.5, 0.5] {
            m.record(0.5, value, false);
        }
        let segment = m.finish().unwrap();
        assert!(
            (segment.overshoot_pct - 10.0).abs() < 1e-3,
            "{}",
            segment.overshoot_pct
        );
    }

    #[test]
    fn segment_ends_when_the_target_changes_and_reports_time_at_limit() {
        let mut m = Metrics::new(CONFIG);
        for _ in 0..50 {
            m.record(1.0, 1.0, true);
        }
        let ended = m.record(2.0, 1.0, false).expect("segment ended");
        assert!((ended.at_limit_s - 50.0 * 1e-4).abs() < 1e-7);
        assert!((ended.duration_s - 50.0 * 1e-4).abs() < 1e-7);
        assert_eq!(ended.settling_s, Some(0.0));
        // 50 steps = 5 ms > 3 ms: the steady part exists and is exact.
        assert_eq!(ended.steady_rms_pct, Some(0.0));
    }

    #[test]
    fn never_settling_and_noise_are_reported() {
        let mut m = Metrics::new(CONFIG);
        m.record(1.0, 1.0, false);
        for k in 0..100 {
            m.record(0.5, if k % 2 == 0 { 0.6 } else { 0.4 }, false);
        }
        let segment = m.finish().unwrap();
        assert_eq!(segment.settling_s, None);
        // Error alternates +-20 %: RMS 20 %.
        assert!((segment.steady_rms_pct.unwrap() - 20.0).abs() < 1e-3);
        assert!((segment.steady_max_pct.unwrap() - 20.0).abs() < 1e-3);
    }

    #[test]
    fn non_finite_friction_counts_as_outside_and_does_not_poison_the_rms() {
        let mut m = Metrics::new(CONFIG);
        for k in 0..60 {
            m.record(1.0, if k == 59 { f32::NAN } else { 1.0 }, false);
        }
        let segment = m.finish().unwrap();
        assert_eq!(segment.settling_s, None);
        assert_eq!(segment.steady_rms_pct, Some(0.0));
    }
}
