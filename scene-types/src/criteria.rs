//! What a scene demands (accuracy, pass criteria) and what it contains.
//!
//! Errors of the criteria are measured on the friction quantity of the target kind, with the
//! plant's ground truth: the friction force for a force target, the friction coefficient
//! (friction / normal load) for a coefficient target, and the friction ratio (friction over
//! the plant's natural friction) against 1 - reduction for a reduction target. "% of target"
//! is relative to that quantity's target value.

/// The accuracy a scene needs.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Accuracy {
    /// Closed-loop friction accuracy, % of target, (0, 100]: the tightest band of the scene's
    /// criteria (the loader checks that they agree).
    pub friction_pct: f64,
    /// Error budget of the controller model's evaluation (a model variant's numerical error
    /// against the exact model), % of the natural friction, (0, friction_pct]: the figure
    /// the choice of the cheapest adequate model variant is made against.
    pub model_pct: f64,
}

/// What a scene contains, for choosing the cheapest adequate model variant.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Contents {
    /// Vibration along the sliding direction is present (a stack, seed 003 eq 2; a horn away
    /// from its node, seed 000 eq 16).
    pub tangential_vibration: bool,
    /// Vibration normal to the contact is present (a horn's Poisson motion, seed 000 eq 17).
    pub normal_vibration: bool,
    /// Lowest normal load of the scene, N (at most the load profile's minimum).
    pub load_min_n: f64,
    /// Highest normal load of the scene, N (at least the load profile's maximum).
    pub load_max_n: f64,
    /// Lowest sliding velocity, signed, m/s (at most the velocity profile's minimum).
    pub velocity_min_m_per_s: f64,
    /// Highest sliding velocity, signed, m/s (at least the velocity profile's maximum).
    pub velocity_max_m_per_s: f64,
}

/// A pass criterion for the closed-loop runner. Times are s from the scene start, windows lie
/// within the scene, limits are in (0, 100] %.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Criterion {
    /// After each target step, the error enters +-`band_pct` % of the new target within
    /// `within_s` and stays there until the next target change.
    Settle {
        /// Band, % of target.
        band_pct: f64,
        /// Time allowed after the step, s.
        within_s: f64,
    },
    /// After each target step, the excursion past the new target, % of the step size.
    Overshoot {
        /// Limit, %.
        max_pct: f64,
    },
    /// RMS of the error over `from_s ..= to_s`, % of target.
    SteadyRmsError {
        /// Limit, %.
        max_pct: f64,
        /// Window start, s.
        from_s: f64,
        /// Window end, s.
        to_s: f64,
    },
    /// Largest absolute error over `from_s ..= to_s`, % of target.
    TrackingError {
        /// Limit, %.
        max_pct: f64,
        /// Window start, s.
        from_s: f64,
        /// Window end, s.
        to_s: f64,
    },
    /// After each injected fault's onset, the supervisor is in fault and the drive command is
    /// zero within this many control periods, 1 ..= 100000.
    FaultReaction {
        /// Control periods allowed.
        within_periods: u32,
    },
}
