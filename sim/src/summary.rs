//! What the judge reports: the observation it takes per step, and the run's summary with a
//! verdict per criterion.

use heapless::Vec;

use super::judge::{MAX_CRITERIA, MAX_FAULTS, MAX_SEGMENTS};
use super::quantity::{Judged, Quantity};
use crate::metrics::SegmentMetrics;
use sonolube::protocol::SupervisorState;
use sonolube::scene::Criterion;

/// One control step as the judge sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Control step, 1 for the first (its sample is taken at one period).
    pub step: u32,
    /// Time of the step's sample, s.
    pub time_s: f32,
    /// The target and the plant's value in its quantity; `None` without a target.
    pub judged: Option<Judged>,
    /// The friction force the target asks of the plant and the plant's true friction, N
    /// (magnitudes); `None` without a target. The one quantity every target shares: a step
    /// that changes the target's kind is judged for overshoot in it.
    pub friction_n: Option<(f32, f32)>,
    /// A target step (not a ramp, not the first point) takes effect at this step.
    pub target_step: bool,
    /// The drive command is at the actuator's ceiling.
    pub at_limit: bool,
    /// The normal-load profile is ramping at this instant.
    pub load_ramping: bool,
    /// Supervisor state after the step.
    pub state: SupervisorState,
    /// The drive command after the step is zero.
    pub drive_zero: bool,
}

/// Why a segment started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Origin {
    /// The first target, at the start.
    Start,
    /// A target step.
    Step,
    /// A ramp of the target moved it (not stored).
    Ramp,
}

/// A segment started by the first target or a target step.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StepSegment {
    /// Metrics of the segment, times in s from the scene start.
    pub metrics: SegmentMetrics,
    /// What started it.
    pub origin: Origin,
    /// The quantity its target and errors are in.
    pub quantity: Quantity,
    /// Whether the previous target was of the same quantity. When it was not, the segment's
    /// `overshoot_pct` is measured in newtons of friction (the target friction before and
    /// after the step, and the plant's friction against the new target): the one quantity
    /// both targets share.
    pub same_quantity: bool,
}

/// How an injected fault was handled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultReaction {
    /// Control step of the first faulty sample.
    pub onset_step: u32,
    /// Control periods from the onset sample to fault with zero drive, the reacting step
    /// included (1: the step that read the first faulty sample); `None`: never.
    pub periods: Option<u32>,
}

/// A measured value of a criterion.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Measured {
    /// A time, s.
    Seconds(f32),
    /// A percentage.
    Percent(f32),
    /// A number of control periods.
    Periods(u32),
    /// The event never happened (no settling, no reaction to a fault).
    Never,
    /// The value was undefined at some instant (no load, or no natural friction).
    Undefined,
    /// Nothing to measure (no target step, an empty window, no fault).
    Nothing,
}

/// A criterion of the scene, what was measured and whether it passed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Verdict {
    /// The criterion.
    pub criterion: Criterion,
    /// The worst value over the run (largest settling time, overshoot, error, reaction).
    pub measured: Measured,
    /// Whether the measured value meets the criterion (never for `Never`, `Undefined`,
    /// `Nothing`).
    pub passed: bool,
}

/// The error while the normal load ramps, %.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RampTracking {
    /// RMS relative error, %.
    pub rms: Measured,
    /// Largest relative error, %.
    pub largest: Measured,
}

/// What a run achieved: step segments, time at the limit, fault reactions, verdicts.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// Control steps judged.
    pub steps: u32,
    /// Segments of the first target and of each target step, in order.
    pub segments: Vec<StepSegment, MAX_SEGMENTS>,
    /// Time with the drive command at the actuator's ceiling, s.
    pub time_at_limit_s: f32,
    /// Error while the normal load ramps (`Nothing` if it never does).
    pub load_ramp: RampTracking,
    /// Each injected fault, in the scene's order.
    pub faults: Vec<FaultReaction, MAX_FAULTS>,
    /// Each criterion of the scene, in its order.
    pub verdicts: Vec<Verdict, MAX_CRITERIA>,
}

impl RunSummary {
    /// Whether every criterion passed.
    pub fn passed(&self) -> bool {
        self.verdicts.iter().all(|verdict| verdict.passed)
    }
}
