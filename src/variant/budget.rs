//! The control period's instruction budget (issue 24, item 4): what a board can run per
//! control step, and what a whole control step costs with each model variant.
//!
//! **A board's instructions per second** ([`Board`]). The budget of one control period is the
//! board's instruction rate over the scene's `control_rate_hz` ([`Board::period_budget`]),
//! rounded down.
//! - `qemu` (machine `mps2-an386`): QEMU runs the firmware under `-icount shift=2`
//!   (`scripts/qemu-run`), 4 ns of virtual time per guest instruction: 250 M instructions/s,
//!   10 instructions per 40-ns cycle of the board's 25 MHz SysTick clock (the figure the
//!   firmware prints with its `control step` line, `board/qemu/src/report.rs`).
//! - `nucleo-g474re` (STM32G474 at 170 MHz): 125 M instructions/s, 0.735 instructions per
//!   cycle (1.36 cycles per instruction: the middle of the 1.1 to 1.5 that docs/speed.md states
//!   for fixed-point code running from flash with 4 wait states; the 12,500 instructions per
//!   10 kHz period of docs/dahl.md and docs/running.md). Not measured on a G474 (the DWT cycle
//!   counter reads 0 under QEMU): a stated figure.
//!
//! The firmware is built for one board: the core's cargo feature `board-g474` selects the
//! G474's figure (the G474 firmware enables it), any other build (the host, the `qemu` board,
//! the tests) the `qemu` board's, so `sonolube scene` chooses as the firmware it is compared
//! with in QEMU does.
//!
//! **A control step's cost with a variant** ([`StepCost`]): `ClosedLoop::control_phase`
//! (target, sensing, estimate, model and its inverse, controller, drive command) timed in QEMU
//! around every step of a scene run with the controller model set to the variant
//! ([`step_scene`]: `reference` for the in-plane variants, `load-ramp` for the cube ones), by
//! the benchmark build (`board/qemu/src/bench.rs`, `bench step NAME` lines), committed in
//! [`super::table`] by `scripts/speed-table`. A variant fits a period when its **longest**
//! measured step is within the period budget: an overrun is one step too long, not an average.

use super::{Family, Form, Variant};

/// A board's instruction rate, for the period budget.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Board {
    /// The board's package name without `sonolube-` (`qemu`, `nucleo-g474re`).
    pub name: &'static str,
    /// Instructions per second (Cortex-M4 instruction set).
    pub instructions_per_s: u64,
}

/// The `qemu` board under `scripts/qemu-run`'s default `-icount shift=2`: 250 M instructions/s.
pub const QEMU: Board = Board {
    name: "qemu",
    instructions_per_s: 250_000_000,
};

/// The NUCLEO-G474RE at 170 MHz and 1.36 cycles per instruction: 125 M instructions/s.
pub const G474: Board = Board {
    name: "nucleo-g474re",
    instructions_per_s: 125_000_000,
};

/// The board this build chooses for (cargo feature `board-g474`: the G474; else `qemu`).
pub const BOARD: Board = if cfg!(feature = "board-g474") {
    G474
} else {
    QEMU
};

impl Board {
    /// Instructions in one control period at `control_rate_hz` (rounded down; 0 for a rate
    /// that is not finite and positive, which the scene loader never lets through).
    pub fn period_budget(&self, control_rate_hz: f64) -> u32 {
        if !(control_rate_hz.is_finite() && control_rate_hz > 0.0) {
            return 0;
        }
        let budget = libm::floor(self.instructions_per_s as f64 / control_rate_hz);
        // At most 250 M: fits u32.
        budget.min(u32::MAX as f64) as u32
    }
}

/// The measured cost of a whole control step with one variant (QEMU, `-icount shift=0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepCost {
    /// Variant name ([`super::CATALOGUE`]).
    pub variant: &'static str,
    /// Mean instructions per control step.
    pub mean: f32,
    /// Longest control step, instructions.
    pub longest: u32,
}

/// The scene a variant's control step is timed on (`None`: not a controller model, or not
/// fixed point): `reference` for the in-plane variants, `load-ramp` for the cube ones.
pub fn step_scene(variant: &Variant) -> Option<&'static str> {
    if variant.form != Form::Fixed {
        return None;
    }
    match variant.fidelity.family() {
        Family::InPlane => Some("reference"),
        Family::Cube => Some("load-ramp"),
        Family::Kernel => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variant::CATALOGUE;

    #[test]
    fn the_period_budget_is_the_rate_over_the_control_rate() {
        assert_eq!(QEMU.period_budget(10_000.0), 25_000);
        assert_eq!(G474.period_budget(10_000.0), 12_500);
        assert_eq!(QEMU.period_budget(100_000.0), 2_500);
        assert_eq!(G474.period_budget(3_000.0), 41_666);
        assert_eq!(QEMU.period_budget(0.0), 0);
        assert_eq!(QEMU.period_budget(f64::NAN), 0);
        #[cfg(not(feature = "board-g474"))]
        assert_eq!(BOARD, QEMU, "the host builds for the qemu board");
    }

    #[test]
    fn every_fixed_point_model_variant_has_a_step_scene() {
        for v in CATALOGUE {
            let model = v.form == Form::Fixed && v.fidelity.family() != Family::Kernel;
            assert_eq!(step_scene(v).is_some(), model, "{}", v.name);
        }
    }
}
