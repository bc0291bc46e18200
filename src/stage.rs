//! The stages of one control period, for the benchmark's breakdown of a control step's cost
//! (issue 24, item 3: where a step's instructions go).
//!
//! The step's code calls [`StageMarks::enter`] where a stage begins. The control path runs
//! with the unit marks `()` (every call inlines to nothing: the firmware's step is the
//! unmarked code, and the marks touch no data, so a marked step computes bit for bit what an
//! unmarked one does); the QEMU benchmark (`board/qemu/src/bench.rs`) passes marks that read
//! the clock and charge the time since the last mark to the stage that was running.

/// A stage of the control period, in the order a step meets them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The simulation's script and bookkeeping around the firmware's step: the scene's target
    /// schedule applied as a `target` command, the period's readings taken in and the output
    /// kept (`sonolube_sim::ClosedLoop`; on a rig the protocol's commands arrive between
    /// periods and the board's task does the rest).
    Script,
    /// The resonance loop: the drive current's samples (phase and amplitude detection, the
    /// frequency tracker), and the search's and the lock's hold on the drive command.
    Resonance,
    /// The load cells' codes to newtons: format, fault checks, calibration.
    Sensing,
    /// The friction estimate: the filtered load, friction and speed, the coefficient.
    Estimator,
    /// Faults, the sliding detector, learning the natural friction, the supervisor's state
    /// machine, the ramps, the output record and the station's bookkeeping.
    Supervision,
    /// The model's operating point and its prediction F'/F at the applied drive.
    Model,
    /// The model's inverse: the drive amplitude for the commanded ratio.
    Inverse,
    /// The target's ratio, the prediction's lag filters, the PI with its gain schedule, and
    /// the net-force hold where the motor region drives.
    Feedback,
    /// The drive shaper: slew limit, soft-start ceiling, envelope estimate.
    Shaper,
}

impl Stage {
    /// Every stage, in [`Stage`]'s order.
    pub const ALL: [Stage; 9] = [
        Stage::Script,
        Stage::Resonance,
        Stage::Sensing,
        Stage::Estimator,
        Stage::Supervision,
        Stage::Model,
        Stage::Inverse,
        Stage::Feedback,
        Stage::Shaper,
    ];

    /// The stage's name in the benchmark's output and in docs/speed.md (one word).
    pub const fn name(self) -> &'static str {
        match self {
            Stage::Script => "script",
            Stage::Resonance => "resonance",
            Stage::Sensing => "sensing",
            Stage::Estimator => "estimator",
            Stage::Supervision => "supervision",
            Stage::Model => "model",
            Stage::Inverse => "inverse",
            Stage::Feedback => "feedback",
            Stage::Shaper => "shaper",
        }
    }

    /// The stage's index in [`Stage::ALL`].
    pub const fn index(self) -> usize {
        self as usize
    }
}

/// Where a control step's stages begin. The unit `()` marks nothing.
pub trait StageMarks {
    /// `stage` begins now (the one running until now ends).
    fn enter(&mut self, stage: Stage);
}

impl StageMarks for () {
    #[inline(always)]
    fn enter(&mut self, _stage: Stage) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_is_in_index_order_with_distinct_names() {
        for (i, stage) in Stage::ALL.iter().enumerate() {
            assert_eq!(stage.index(), i);
            assert!(!stage.name().contains(' '));
            for other in &Stage::ALL[..i] {
                assert_ne!(other.name(), stage.name());
            }
        }
    }
}
