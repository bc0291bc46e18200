//! The time tables of a scene: breakpoints of its profiles and points of its target table
//! (evaluated by `sonolube::scene::interpolate` and `sonolube::scene::target_at`).

use crate::Target;

/// A breakpoint of a piecewise-linear profile.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Breakpoint {
    /// Time, s from the scene start, in [0, duration]; strictly increasing, the first at 0.
    pub t_s: f64,
    /// Value in the profile's unit (N for loads, m/s for velocities).
    pub value: f64,
}

/// A point of the target table.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TargetPoint {
    /// Time, s from the scene start, in [0, duration]; strictly increasing, the first at 0.
    pub at_s: f64,
    /// The target from this time on, within the `target` command's ranges.
    pub target: Target,
    /// `true`: reached by a linear ramp from the previous point (same kind of target);
    /// `false`: a step at `at_s`. The first point is always a step.
    pub ramp: bool,
}
