//! The commissioning sequence, one control period at a time (see the module documentation of
//! [`super`] for the steps and why each ends where it does).

use super::{
    CellZero, CommissionResult, Measured, NATURAL_SAMPLES, QUIET_TIME_CONSTANTS, Refusal,
    SETTLED_GROUPS, SETTLED_GROWTH, check,
};
use crate::fx::{Q1_31, Q16_16};
use crate::resonance::{
    LockState, ResonanceReport, RingDownSums, group_amplitude_lsb, group_amplitude_squared,
};

/// The step commissioning is in (or failed in).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Step {
    /// The resonance search.
    Resonance,
    /// The drive burst at the found resonance.
    Burst,
    /// The drive off, the current's decay recorded.
    RingDown,
    /// The drive off, waiting for the envelope to die out.
    Quiet,
    /// The drive off, mu0 averaged.
    Natural,
}

impl Step {
    /// The step's name in replies: `resonance`, `burst`, `ring-down`, `quiet`, `natural`.
    pub const fn name(self) -> &'static str {
        match self {
            Step::Resonance => "resonance",
            Step::Burst => "burst",
            Step::RingDown => "ring-down",
            Step::Quiet => "quiet",
            Step::Natural => "natural",
        }
    }
}

/// What the sequence asks of the station for one period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phase {
    /// Let the resonance search drive (its own amplitude).
    Search,
    /// Drive this amplitude (Q1.31 fraction of full scale) at the tracked frequency.
    Drive(Q1_31),
    /// Drive off; the resonance loop is to be pinned where it is (the ring-down starts: its
    /// samples must stay synchronous to the frequency of the burst).
    DriveOffPinned,
    /// Drive off.
    Off,
    /// Finished: the result (checked against its ranges) or why there is none.
    Done(Result<CommissionResult, Refusal>),
}

/// Longest any one step may take, s: one second (a search, a burst of Q = 5000 at 20 kHz,
/// 12 time constants, or a contact that never slides).
const STEP_LIMIT_S: f64 = 1.0;

/// The sequence's state: the step, the current-sense grouping and the measurements so far.
#[derive(Debug, Clone, PartialEq)]
pub struct Commissioning {
    step: Step,
    /// Control periods in the present step.
    periods: u32,
    step_limit: u32,
    period_s: f64,
    burst_amplitude: Q1_31,
    group: [u16; 4],
    group_len: usize,
    /// The last group's `4 A^2`, LSB^2 (burst).
    last_group: u64,
    settled_groups: u32,
    /// Sums over the settled burst periods of `f - f_ref` and `f d` (Hz; `d` the detuning)
    /// and of their squares and product, for f0's mean and standard error; `f_ref` is the
    /// first settled period's frequency (the sums then stay small).
    detuning: DetuningSums,
    /// The ring-down's fit, one group at a time.
    ring_down: RingDownSums,
    ring_down_closed: bool,
    /// Drive frequency over the ring-down, mHz.
    ring_down_frequency_mhz: u32,
    time_constant: Measured,
    resonance: Measured,
    quality: Measured,
    ring_down_points: u32,
    quiet_periods: u32,
    natural_sum: f64,
    natural_square_sum: f64,
    natural_count: u32,
    normal: CellZero,
    tangential: CellZero,
}

/// The inputs of one period the sequence reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodInputs {
    /// The resonance loop's report after this period's current samples.
    pub resonance: ResonanceReport,
    /// The sensed normal force, N.
    pub normal_force: Q16_16,
    /// The sensed tangential force, N.
    pub tangential_force: Q16_16,
    /// Sliding speed, m/s (signed).
    pub sliding_velocity_m_per_s: f32,
    /// Speed above which the contact slides, m/s (the controller's setting).
    pub sliding_on_m_s: f64,
    /// Least normal force for a coefficient, N (the controller's setting).
    pub min_normal_force_n: f64,
    /// A fault is latched (the sequence stops).
    pub fault: bool,
}

impl Commissioning {
    /// A sequence for a loop of `period_s` (> 0) whose burst drives `burst_amplitude`, with
    /// the cells' zeros as they stand.
    pub fn new(
        period_s: f64,
        burst_amplitude: Q1_31,
        normal: CellZero,
        tangential: CellZero,
    ) -> Self {
        let none = Measured {
            value: f64::NAN,
            standard_error: f64::NAN,
        };
        Self {
            step: Step::Resonance,
            periods: 0,
            step_limit: libm::ceil(STEP_LIMIT_S / period_s).clamp(1.0, 1e9) as u32,
            period_s,
            burst_amplitude,
            group: [0; 4],
            group_len: 0,
            last_group: 0,
            settled_groups: 0,
            detuning: DetuningSums::EMPTY,
            ring_down: RingDownSums::new(),
            ring_down_closed: false,
            ring_down_frequency_mhz: 0,
            time_constant: none,
            resonance: none,
            quality: none,
            ring_down_points: 0,
            quiet_periods: 0,
            natural_sum: 0.0,
            natural_square_sum: 0.0,
            natural_count: 0,
            normal,
            tangential,
        }
    }

    /// The step in progress.
    pub fn step(&self) -> Step {
        self.step
    }

    /// The current-sense codes of the last period (12-bit, mid-scale zero), one per PWM period
    /// a quarter turn apart, grouped by four.
    pub fn push_current(&mut self, codes: &[u16]) {
        for &code in codes {
            if let Some(slot) = self.group.get_mut(self.group_len) {
                *slot = code;
                self.group_len += 1;
            }
            if self.group_len == 4 {
                self.group_len = 0;
                self.finish_group(group_amplitude_squared(self.group));
            }
        }
    }

    fn finish_group(&mut self, amplitude_squared: u64) {
        match self.step {
            Step::Burst => {
                let (now, before) = (
                    group_amplitude_lsb(amplitude_squared),
                    group_amplitude_lsb(self.last_group),
                );
                self.last_group = amplitude_squared;
                if before > 0.0 && libm::fabs(now - before) <= before * SETTLED_GROWTH {
                    self.settled_groups += 1;
                } else {
                    self.settled_groups = 0;
                    self.detuning = DetuningSums::EMPTY;
                }
            }
            Step::RingDown if !self.ring_down_closed => {
                self.ring_down_closed =
                    !self.ring_down.push(group_amplitude_lsb(amplitude_squared));
            }
            _ => {}
        }
    }

    /// One control period: what the station is to drive, or the end.
    pub fn control(&mut self, inputs: &PeriodInputs) -> Phase {
        if inputs.fault {
            return Phase::Done(Err(Refusal::new(self.step, "fault latched", f64::NAN)));
        }
        self.periods += 1;
        if self.periods > self.step_limit {
            let reason = match self.step {
                Step::Resonance => "resonance search did not lock",
                Step::Burst => "burst did not settle",
                Step::RingDown => "ring-down did not end",
                Step::Quiet => "quiet period did not end",
                Step::Natural => "not sliding with load",
            };
            let value = match self.step {
                Step::Natural => f64::from(self.natural_count),
                _ => f64::from(self.periods),
            };
            return Phase::Done(Err(Refusal::new(self.step, reason, value)));
        }
        match self.step {
            Step::Resonance => match inputs.resonance.state {
                LockState::Locked => {
                    self.enter(Step::Burst);
                    Phase::Drive(self.burst_amplitude)
                }
                LockState::Lost(_) => Phase::Done(Err(Refusal::new(
                    Step::Resonance,
                    "resonance search failed",
                    f64::NAN,
                ))),
                _ => Phase::Search,
            },
            Step::Burst => {
                if self.settled_groups > 0
                    && let Some(detuning) = inputs.resonance.detuning
                {
                    self.detuning
                        .add(inputs.resonance.frequency.millihertz(), detuning.to_bits());
                }
                if self.settled_groups >= SETTLED_GROUPS && self.detuning.count >= 2 {
                    self.ring_down_frequency_mhz = inputs.resonance.frequency.millihertz();
                    self.enter(Step::RingDown);
                    Phase::DriveOffPinned
                } else {
                    Phase::Drive(self.burst_amplitude)
                }
            }
            Step::RingDown => {
                if !self.ring_down_closed {
                    return Phase::Off;
                }
                match self.fit() {
                    Ok(()) => {
                        let quiet = QUIET_TIME_CONSTANTS * self.time_constant.value / self.period_s;
                        self.quiet_periods = libm::ceil(quiet).clamp(1.0, 1e9) as u32;
                        self.enter(Step::Quiet);
                        Phase::Off
                    }
                    Err(refusal) => Phase::Done(Err(refusal)),
                }
            }
            Step::Quiet => {
                if self.periods >= self.quiet_periods {
                    self.enter(Step::Natural);
                }
                Phase::Off
            }
            Step::Natural => {
                let normal_n = inputs.normal_force.to_f64();
                let sliding =
                    libm::fabs(f64::from(inputs.sliding_velocity_m_per_s)) >= inputs.sliding_on_m_s;
                if sliding && normal_n >= inputs.min_normal_force_n {
                    let coefficient = libm::fabs(inputs.tangential_force.to_f64()) / normal_n;
                    self.natural_sum += coefficient;
                    self.natural_square_sum += coefficient * coefficient;
                    self.natural_count += 1;
                }
                if self.natural_count >= NATURAL_SAMPLES {
                    Phase::Done(self.result())
                } else {
                    Phase::Off
                }
            }
        }
    }

    fn enter(&mut self, step: Step) {
        self.step = step;
        self.periods = 0;
        self.group_len = 0;
    }

    /// tau from the ring-down, then f0 from the burst's detuning with the measured Q.
    fn fit(&mut self) -> Result<(), Refusal> {
        let f_hz = f64::from(self.ring_down_frequency_mhz) / 1e3;
        let fit = self.ring_down.fit(4.0 / f_hz).map_err(|e| {
            let value = match e {
                crate::resonance::RingDownError::TooSmall(lsb) => lsb,
                crate::resonance::RingDownError::TooShort(n) => f64::from(n),
                _ => f64::NAN,
            };
            Refusal::new(Step::RingDown, e.reason(), value)
        })?;
        self.time_constant = Measured {
            value: fit.time_constant_s,
            standard_error: fit.time_constant_se_s,
        };
        self.ring_down_points = fit.points;
        // Q from the drive frequency first (within a fraction of a bandwidth of f0), then f0
        // from the detuning with that Q, then Q again from f0.
        let tau = fit.time_constant_s;
        let first_q = core::f64::consts::PI * f_hz * tau;
        self.resonance = self.detuning.resonance(first_q);
        let mean = self.resonance.value;
        let q = core::f64::consts::PI * mean * tau;
        let relative = libm::hypot(
            fit.time_constant_se_s / tau,
            self.resonance.standard_error / mean,
        );
        self.quality = Measured {
            value: q,
            standard_error: q * relative,
        };
        Ok(())
    }

    fn result(&self) -> Result<CommissionResult, Refusal> {
        let n = f64::from(self.natural_count);
        let mean = self.natural_sum / n;
        let variance = libm::fmax(self.natural_square_sum / n - mean * mean, 0.0) * n / (n - 1.0);
        let result = CommissionResult {
            resonance_hz: self.resonance,
            time_constant_s: self.time_constant,
            quality_factor: self.quality,
            natural_coefficient: Measured {
                value: mean,
                standard_error: libm::sqrt(variance / n),
            },
            ring_down_points: self.ring_down_points,
            normal: self.normal,
            tangential: self.tangential,
        };
        check(&result)?;
        Ok(result)
    }
}

/// The sums behind f0: per settled burst period `y = f (1 - d / 2Q)` with `f` the drive
/// frequency and `d` the detuning; kept as sums of `a = f - f_ref` and `b = f d` so that Q can
/// come later (`y - f_ref = a - b / 2Q`).
#[derive(Debug, Clone, Copy, PartialEq)]
struct DetuningSums {
    count: u32,
    reference_mhz: u32,
    sum_a: f64,
    sum_b: f64,
    sum_aa: f64,
    sum_bb: f64,
    sum_ab: f64,
}

impl DetuningSums {
    const EMPTY: Self = Self {
        count: 0,
        reference_mhz: 0,
        sum_a: 0.0,
        sum_b: 0.0,
        sum_aa: 0.0,
        sum_bb: 0.0,
        sum_ab: 0.0,
    };

    /// One period: drive frequency in mHz, detuning Q8.24 bits (half-bandwidths).
    fn add(&mut self, frequency_mhz: u32, detuning_bits: i32) {
        if self.count == 0 {
            self.reference_mhz = frequency_mhz;
        }
        let f = f64::from(frequency_mhz) / 1e3;
        let a = (f64::from(frequency_mhz) - f64::from(self.reference_mhz)) / 1e3;
        let b = f * f64::from(detuning_bits) / f64::from(1u32 << 24);
        self.sum_a += a;
        self.sum_b += b;
        self.sum_aa += a * a;
        self.sum_bb += b * b;
        self.sum_ab += a * b;
        self.count += 1;
    }

    /// f0 and the standard error of its mean, with the quality factor `q`.
    fn resonance(&self, q: f64) -> Measured {
        let n = f64::from(self.count);
        let k = 1.0 / (2.0 * q);
        let mean = (self.sum_a - k * self.sum_b) / n;
        let centred = |sum_xy: f64, sum_x: f64, sum_y: f64| sum_xy - sum_x * sum_y / n;
        let variance = (centred(self.sum_aa, self.sum_a, self.sum_a)
            + k * k * centred(self.sum_bb, self.sum_b, self.sum_b)
            - 2.0 * k * centred(self.sum_ab, self.sum_a, self.sum_b))
            / (n - 1.0);
        Measured {
            value: f64::from(self.reference_mhz) / 1e3 + mean,
            standard_error: libm::sqrt(libm::fmax(variance, 0.0) / n),
        }
    }
}
