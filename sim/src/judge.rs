//! Judging a run online: per-segment metrics ([`crate::metrics`]), the scene's criteria, the
//! reaction to each injected fault, the tracking error while the normal load ramps.
//!
//! A *target step* is a change of the target at a point of the scene's target table that is
//! not a ramp, after the start (the first point sets the initial target; the start-up, with
//! its sliding debounce and soft start, is not a step response). `Settle` and `Overshoot`
//! are judged on the segments that target steps start; `SteadyRmsError` and `TrackingError`
//! on their time windows (sampled at the control instants within half a period of the
//! window); `FaultReaction` from each fault's onset sample to the first control step that is
//! in fault with a zero drive command, counting that step (reacting on the first faulty sample
//! takes one period). Sums are `f64` (soft float on the Cortex-M4F: this is not the control
//! step), the rest `f32` like [`crate::metrics`].

use heapless::Vec;

use super::quantity::Quantity;
use super::summary::{
    FaultReaction, Measured, Observation, Origin, RampTracking, RunSummary, StepSegment, Verdict,
};
use crate::metrics::{Metrics, MetricsConfig, SegmentMetrics};
use sonolube::protocol::SupervisorState;
use sonolube::scene::{Criterion, Scene};

/// Largest number of stored step segments (the target table holds at most 64 points).
pub const MAX_SEGMENTS: usize = 64;
/// Largest number of criteria a scene may have for the runner.
pub const MAX_CRITERIA: usize = 16;
/// Largest number of injected faults a scene may have for the runner.
pub const MAX_FAULTS: usize = 16;
/// Band of the summary's settling times without a `Settle` criterion: +-2 % (the issue's).
pub const DEFAULT_BAND: f32 = 0.02;
/// Start of a segment's steady part without a `Settle` criterion, s after its start: room for
/// the start-up (sliding debounce and soft start, up to 7 ms) and a settling budget (3 ms).
pub const DEFAULT_STEADY_AFTER_S: f32 = 0.01;

/// RMS and largest relative error over a set of instants, %.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct ErrorStats {
    sum_sq: f64,
    count: u32,
    largest: f32,
    undefined: u32,
}

impl ErrorStats {
    fn add(&mut self, relative: f32) {
        if relative.is_finite() {
            self.sum_sq += f64::from(relative) * f64::from(relative);
            self.count += 1;
            self.largest = self.largest.max(libm::fabsf(relative));
        } else {
            self.undefined += 1;
        }
    }

    fn rms_pct(&self) -> Measured {
        self.measured(|s| 100.0 * libm::sqrt(s.sum_sq / f64::from(s.count)) as f32)
    }

    fn largest_pct(&self) -> Measured {
        self.measured(|s| 100.0 * s.largest)
    }

    fn measured(&self, value: impl Fn(&Self) -> f32) -> Measured {
        match (self.undefined, self.count) {
            (0, 0) => Measured::Nothing,
            (0, _) => Measured::Percent(value(self)),
            _ => Measured::Undefined,
        }
    }
}

/// Per-criterion state.
#[derive(Debug, Clone, Copy)]
enum Track {
    Settle {
        metrics: Metrics,
        judged: u32,
        worst_s: f32,
        unsettled: bool,
    },
    Overshoot {
        judged: u32,
        worst_pct: f32,
    },
    Window {
        from_s: f32,
        to_s: f32,
        stats: ErrorStats,
    },
    Faults,
}

/// The overshoot of a target step that changes the target's kind (a reduction to a
/// coefficient, say), in newtons of friction: the step is the change of the friction the
/// targets ask of the plant, the excursion the plant's friction past the new target in the
/// step's direction.
#[derive(Debug, Clone, Copy)]
struct CrossStep {
    /// Target friction after the step minus before it, N.
    step_n: f32,
    /// Largest excursion past the target in the step's direction so far, N (>= 0).
    worst_past_n: f32,
}

impl CrossStep {
    fn add(&mut self, (target_n, actual_n): (f32, f32)) {
        let past = (actual_n - target_n) * libm::copysignf(1.0, self.step_n);
        if past > self.worst_past_n {
            self.worst_past_n = past;
        }
    }

    /// In percent of the step (0 for a step of no size).
    fn overshoot_pct(&self) -> f32 {
        if self.step_n != 0.0 {
            100.0 * self.worst_past_n / libm::fabsf(self.step_n)
        } else {
            0.0
        }
    }
}

/// The online judge of one run.
#[derive(Debug, Clone)]
pub struct Judge {
    period_s: f32,
    metrics: Metrics,
    segments: Vec<StepSegment, MAX_SEGMENTS>,
    current: Option<(Origin, Quantity, bool)>,
    last: Option<(Quantity, f32)>,
    /// The target friction at the last step, N.
    last_friction_target_n: Option<f32>,
    /// The current segment's overshoot in newtons, when its step changed the target's kind.
    cross: Option<CrossStep>,
    criteria: Vec<(Criterion, Track), MAX_CRITERIA>,
    faults: Vec<FaultReaction, MAX_FAULTS>,
    at_limit_steps: u32,
    ramp: ErrorStats,
    steps: u32,
}

impl Judge {
    /// A judge for `scene`. `None` if it has more than [`MAX_CRITERIA`] criteria or
    /// [`MAX_FAULTS`] faults.
    pub fn new(scene: &Scene<'_>) -> Option<Self> {
        let period_s = scene.control_period_s() as f32;
        let config = |band_pct: f64, within_s: f64| MetricsConfig {
            period_s,
            band: (band_pct / 100.0) as f32,
            steady_after_s: within_s as f32,
        };
        let first_settle = scene.criteria.iter().find_map(|c| match *c {
            Criterion::Settle { band_pct, within_s } => Some(config(band_pct, within_s)),
            _ => None,
        });
        let summary = first_settle.unwrap_or(MetricsConfig {
            period_s,
            band: DEFAULT_BAND,
            steady_after_s: DEFAULT_STEADY_AFTER_S,
        });
        let mut criteria = Vec::new();
        for criterion in scene.criteria {
            let track = match *criterion {
                Criterion::Settle { band_pct, within_s } => Track::Settle {
                    metrics: Metrics::new(config(band_pct, within_s)),
                    judged: 0,
                    worst_s: 0.0,
                    unsettled: false,
                },
                Criterion::Overshoot { .. } => Track::Overshoot {
                    judged: 0,
                    worst_pct: 0.0,
                },
                Criterion::SteadyRmsError { from_s, to_s, .. }
                | Criterion::TrackingError { from_s, to_s, .. } => Track::Window {
                    from_s: from_s as f32 - period_s / 2.0,
                    to_s: to_s as f32 + period_s / 2.0,
                    stats: ErrorStats::default(),
                },
                Criterion::FaultReaction { .. } => Track::Faults,
            };
            criteria.push((*criterion, track)).ok()?;
        }
        let mut faults = Vec::new();
        for fault in scene.faults {
            // The plant's grid: the first control instant at or after the onset.
            let onset = libm::ceil(fault.at_s / scene.control_period_s() - 1e-6);
            let onset_step = onset.max(0.0) as u32;
            faults
                .push(FaultReaction {
                    onset_step,
                    periods: None,
                })
                .ok()?;
        }
        Some(Self {
            period_s,
            metrics: Metrics::new(summary),
            segments: Vec::new(),
            current: None,
            last: None,
            last_friction_target_n: None,
            cross: None,
            criteria,
            faults,
            at_limit_steps: 0,
            ramp: ErrorStats::default(),
            steps: 0,
        })
    }

    /// Takes one control step.
    pub fn observe(&mut self, o: &Observation) {
        self.steps = self.steps.saturating_add(1);
        self.at_limit_steps += u32::from(o.at_limit);
        for fault in &mut self.faults {
            let faulted = o.state == SupervisorState::Fault && o.drive_zero;
            if fault.periods.is_none() && o.step >= fault.onset_step && faulted {
                fault.periods = Some(o.step - fault.onset_step + 1);
            }
        }
        let Some(judged) = o.judged else {
            return;
        };
        let relative = judged.relative_error();
        if o.load_ramping {
            self.ramp.add(relative);
        }
        let origin = match (self.last, o.target_step) {
            (None, _) => Origin::Start,
            (Some(_), true) => Origin::Step,
            (Some(_), false) => Origin::Ramp,
        };
        let same_quantity = self.last.is_none_or(|(q, _)| q == judged.quantity);
        // A new segment exactly when `Metrics` starts one: the target value changed.
        let new_segment = self.last.is_none_or(|(_, t)| t != judged.target);
        let ended = self
            .metrics
            .record(judged.target, judged.actual, o.at_limit);
        let current = self.current;
        if let Some(ended) = ended {
            self.close(ended, current);
        }
        let is_step = matches!(current, Some((Origin::Step, _, _)));
        for (_, track) in &mut self.criteria {
            match track {
                Track::Settle { metrics, .. } => {
                    let ended = metrics.record(judged.target, judged.actual, o.at_limit);
                    if let Some(ended) = ended.filter(|_| is_step) {
                        settle(track, &ended);
                    }
                }
                Track::Window {
                    from_s,
                    to_s,
                    stats,
                } if o.time_s >= *from_s && o.time_s <= *to_s => stats.add(relative),
                _ => {}
            }
        }
        if new_segment {
            self.current = Some((origin, judged.quantity, same_quantity));
            self.cross = match (
                origin,
                same_quantity,
                self.last_friction_target_n,
                o.friction_n,
            ) {
                (Origin::Step, false, Some(before), Some((after, _))) => Some(CrossStep {
                    step_n: after - before,
                    worst_past_n: 0.0,
                }),
                _ => None,
            };
        }
        if let (Some(cross), Some(friction)) = (&mut self.cross, o.friction_n) {
            cross.add(friction);
        }
        self.last = Some((judged.quantity, judged.target));
        self.last_friction_target_n = o.friction_n.map(|(target, _)| target);
    }

    fn close(&mut self, mut metrics: SegmentMetrics, current: Option<(Origin, Quantity, bool)>) {
        let Some((origin, quantity, same_quantity)) = current else {
            return;
        };
        // `Metrics` counts from the first observation, whose sample is at one period.
        metrics.start_s += self.period_s;
        // A step between two kinds of target: its size and excursion in newtons of friction.
        let cross = if same_quantity { None } else { self.cross };
        if let Some(cross) = cross {
            metrics.overshoot_pct = cross.overshoot_pct();
        }
        if origin == Origin::Step && (same_quantity || cross.is_some()) {
            for (_, track) in &mut self.criteria {
                if let Track::Overshoot { judged, worst_pct } = track {
                    *judged += 1;
                    *worst_pct = worst_pct.max(metrics.overshoot_pct);
                }
            }
        }
        if origin != Origin::Ramp {
            let segment = StepSegment {
                metrics,
                origin,
                quantity,
                same_quantity,
            };
            // Full only past 64 target points, which the loader refuses.
            let _ = self.segments.push(segment);
        }
    }

    /// The summary so far (the open segments are closed on a copy).
    pub fn summary(&self) -> RunSummary {
        let mut judge = self.clone();
        let current = judge.current;
        let is_step = matches!(current, Some((Origin::Step, _, _)));
        if let Some(ended) = judge.metrics.finish() {
            judge.close(ended, current);
        }
        let mut verdicts = Vec::new();
        for (criterion, track) in &mut judge.criteria {
            if let Track::Settle { metrics, .. } = track
                && let Some(ended) = metrics.finish().filter(|_| is_step)
            {
                settle(track, &ended);
            }
            let measured = measure(criterion, track, &judge.faults);
            // Cannot overflow: both vectors hold MAX_CRITERIA.
            let _ = verdicts.push(Verdict {
                criterion: *criterion,
                measured,
                passed: passes(criterion, measured),
            });
        }
        RunSummary {
            steps: judge.steps,
            segments: judge.segments,
            time_at_limit_s: judge.at_limit_steps as f32 * judge.period_s,
            load_ramp: RampTracking {
                rms: judge.ramp.rms_pct(),
                largest: judge.ramp.largest_pct(),
            },
            faults: judge.faults,
            verdicts,
        }
    }
}

fn settle(track: &mut Track, ended: &SegmentMetrics) {
    if let Track::Settle {
        judged,
        worst_s,
        unsettled,
        ..
    } = track
    {
        *judged += 1;
        match ended.settling_s {
            Some(settling) => *worst_s = worst_s.max(settling),
            None => *unsettled = true,
        }
    }
}

fn measure(criterion: &Criterion, track: &Track, faults: &[FaultReaction]) -> Measured {
    match *track {
        Track::Settle { judged: 0, .. } | Track::Overshoot { judged: 0, .. } => Measured::Nothing,
        Track::Settle {
            unsettled: true, ..
        } => Measured::Never,
        Track::Settle { worst_s, .. } => Measured::Seconds(worst_s),
        Track::Overshoot { worst_pct, .. } => Measured::Percent(worst_pct),
        Track::Window { stats, .. } => match criterion {
            Criterion::TrackingError { .. } => stats.largest_pct(),
            _ => stats.rms_pct(),
        },
        Track::Faults => {
            let worst = faults.iter().map(|f| f.periods).max_by_key(|p| match p {
                // `None` (never) ranks above every count.
                Some(periods) => u64::from(*periods),
                None => u64::MAX,
            });
            match worst {
                None => Measured::Nothing,
                Some(None) => Measured::Never,
                Some(Some(periods)) => Measured::Periods(periods),
            }
        }
    }
}

fn passes(criterion: &Criterion, measured: Measured) -> bool {
    // Times are whole periods in f32: allow their rounding.
    const TIME_SLACK_S: f32 = 1e-7;
    match (*criterion, measured) {
        (Criterion::Settle { within_s, .. }, Measured::Seconds(s)) => {
            s <= within_s as f32 + TIME_SLACK_S
        }
        (Criterion::Overshoot { max_pct }, Measured::Percent(p))
        | (Criterion::SteadyRmsError { max_pct, .. }, Measured::Percent(p))
        | (Criterion::TrackingError { max_pct, .. }, Measured::Percent(p)) => p <= max_pct as f32,
        (Criterion::FaultReaction { within_periods }, Measured::Periods(n)) => n <= within_periods,
        _ => false,
    }
}

#[cfg(test)]
#[path = "judge_tests.rs"]
mod tests;
