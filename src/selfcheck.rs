//! Timing self-check of a periodic task.
//!
//! A [`PeriodMonitor`] is fed the timestamps (in timer ticks) at which a periodic task woke up.
//! It keeps the smallest and largest interval seen and counts intervals that exceeded the period
//! by more than the allowed lateness (overruns). The firmware uses it at boot to prove that the
//! executor, the time driver and the ticker work together before the drive is enabled.

/// Statistics of the intervals between the wake-ups of a periodic task.
///
/// All times are in timer ticks (`u64`, the unit of `embassy_time::Instant::as_ticks`), so the
/// monitor is independent of the tick rate. Counters saturate at `u32::MAX`; intervals are
/// computed with saturating subtraction, so a timestamp that goes backwards counts as an
/// interval of 0 ticks (and is reported through [`PeriodMonitor::backwards`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PeriodMonitor {
    period_ticks: u64,
    max_late_ticks: u64,
    first: Option<u64>,
    last: Option<u64>,
    intervals: u32,
    min_interval: u64,
    max_interval: u64,
    overruns: u32,
    backwards: u32,
}

/// Verdict of a [`PeriodMonitor`] after a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PeriodVerdict {
    /// Fewer intervals than required were seen.
    TooFewIntervals {
        /// Intervals seen.
        seen: u32,
        /// Intervals required.
        required: u32,
    },
    /// At least one interval exceeded the period plus the allowed lateness.
    Overrun {
        /// Number of late intervals.
        count: u32,
        /// Longest interval seen, in ticks.
        max_interval: u64,
    },
    /// A timestamp went backwards: the time source is not monotonic.
    NotMonotonic {
        /// Number of backwards steps.
        count: u32,
    },
    /// The mean interval differs from the period by more than the allowed lateness.
    MeanOff {
        /// Mean interval over the run, in ticks (rounded down).
        mean_interval: u64,
    },
    /// Every check passed.
    Pass,
}

impl PeriodMonitor {
    /// A monitor for a task with period `period_ticks` (> 0) that may be at most `max_late_ticks`
    /// late on any single wake-up.
    pub const fn new(period_ticks: u64, max_late_ticks: u64) -> Self {
        Self {
            period_ticks,
            max_late_ticks,
            first: None,
            last: None,
            intervals: 0,
            min_interval: u64::MAX,
            max_interval: 0,
            overruns: 0,
            backwards: 0,
        }
    }

    /// Records one wake-up at time `now_ticks`.
    pub fn record(&mut self, now_ticks: u64) {
        if let Some(last) = self.last {
            if now_ticks < last {
                self.backwards = self.backwards.saturating_add(1);
            }
            let interval = now_ticks.saturating_sub(last);
            self.intervals = self.intervals.saturating_add(1);
            self.min_interval = self.min_interval.min(interval);
            self.max_interval = self.max_interval.max(interval);
            if interval > self.period_ticks.saturating_add(self.max_late_ticks) {
                self.overruns = self.overruns.saturating_add(1);
            }
        }
        self.first.get_or_insert(now_ticks);
        self.last = Some(now_ticks);
    }

    /// Number of complete intervals recorded.
    pub const fn intervals(&self) -> u32 {
        self.intervals
    }

    /// Shortest interval seen, in ticks (`None` before the second wake-up).
    pub const fn min_interval(&self) -> Option<u64> {
        if self.intervals == 0 {
            None
        } else {
            Some(self.min_interval)
        }
    }

    /// Longest interval seen, in ticks (`None` before the second wake-up).
    pub const fn max_interval(&self) -> Option<u64> {
        if self.intervals == 0 {
            None
        } else {
            Some(self.max_interval)
        }
    }

    /// Number of intervals longer than the period plus the allowed lateness.
    pub const fn overruns(&self) -> u32 {
        self.overruns
    }

    /// Number of timestamps that were earlier than the one before.
    pub const fn backwards(&self) -> u32 {
        self.backwards
    }

    /// Judges the run: at least `required_intervals` intervals, no overrun, a monotonic time
    /// source, and a mean interval within the allowed lateness of the period.
    pub fn verdict(&self, required_intervals: u32) -> PeriodVerdict {
        if self.intervals < required_intervals || self.intervals == 0 {
            return PeriodVerdict::TooFewIntervals {
                seen: self.intervals,
                required: required_intervals,
            };
        }
        if self.backwards > 0 {
            return PeriodVerdict::NotMonotonic {
                count: self.backwards,
            };
        }
        if self.overruns > 0 {
            return PeriodVerdict::Overrun {
                count: self.overruns,
                max_interval: self.max_interval,
            };
        }
        let (Some(first), Some(last)) = (self.first, self.last) else {
            return PeriodVerdict::TooFewIntervals {
                seen: self.intervals,
                required: required_intervals,
            };
        };
        let mean_interval = (last - first) / u64::from(self.intervals);
        if mean_interval.abs_diff(self.period_ticks) > self.max_late_ticks {
            return PeriodVerdict::MeanOff { mean_interval };
        }
        PeriodVerdict::Pass
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_period_passes() {
        let mut m = PeriodMonitor::new(1000, 10);
        for k in 0..=100u64 {
            m.record(5 + k * 1000);
        }
        assert_eq!(m.intervals(), 100);
        assert_eq!(m.min_interval(), Some(1000));
        assert_eq!(m.max_interval(), Some(1000));
        assert_eq!(m.verdict(100), PeriodVerdict::Pass);
    }

    #[test]
    fn jitter_within_lateness_passes_but_one_late_wakeup_is_an_overrun() {
        let mut m = PeriodMonitor::new(1000, 10);
        let times = [0u64, 1005, 2000, 3010, 4000];
        for t in times {
            m.record(t);
        }
        assert_eq!(m.verdict(4), PeriodVerdict::Pass);
        m.record(5011);
        assert_eq!(
            m.verdict(4),
            PeriodVerdict::Overrun {
                count: 1,
                max_interval: 1011
            }
        );
    }

    #[test]
    fn too_few_intervals_is_reported() {
        let mut m = PeriodMonitor::new(1000, 10);
        assert_eq!(m.min_interval(), None);
        m.record(0);
        m.record(1000);
        assert_eq!(
            m.verdict(2),
            PeriodVerdict::TooFewIntervals {
                seen: 1,
                required: 2
            }
        );
    }

    #[test]
    fn backwards_time_is_not_monotonic_and_does_not_underflow() {
        let mut m = PeriodMonitor::new(1000, 10);
        m.record(2000);
        m.record(1000);
        m.record(2000);
        assert_eq!(m.backwards(), 1);
        assert_eq!(m.min_interval(), Some(0));
        assert_eq!(m.verdict(1), PeriodVerdict::NotMonotonic { count: 1 });
    }

    #[test]
    fn a_consistently_slow_clock_is_caught_by_the_mean() {
        // Every interval is 8 ticks long: within the per-interval lateness of 10, but the mean
        // is off by 8 > 5.
        let mut m = PeriodMonitor::new(1000, 5);
        for k in 0..=50u64 {
            m.record(k * 1008);
        }
        assert_eq!(m.overruns(), 50);
        let mut m = PeriodMonitor::new(1000, 10);
        for k in 0..=50u64 {
            m.record(k * 1008);
        }
        assert_eq!(m.verdict(50), PeriodVerdict::Pass);
        let mut m = PeriodMonitor::new(1000, 10);
        for k in 0..=50u64 {
            m.record(k * 985 + if k % 2 == 0 { 0 } else { 9 });
        }
        assert_eq!(m.verdict(50), PeriodVerdict::MeanOff { mean_interval: 985 });
    }
}
