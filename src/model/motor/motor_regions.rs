//! Seed 001 Table 1: where on the horn's bottom face the transition region (friction
//! reduction, the cube model) and the motor-effect regions (the net drive, `super::motor`) were
//! measured, and the model choice by the block's position.

use super::ModelError;

/// Seed 001 Table 1, in metres from the horn centre: the transition region (measured), by horn
/// material. The motor regions reach from its edges to +-1.5 in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredRegions {
    /// Transition region [low, high] in m.
    pub transition: (f64, f64),
    /// Outer ends of the motor regions [left, right] in m.
    pub motor_outer: (f64, f64),
}

const INCH: f64 = 0.0254;

/// Aluminium horn (seed 001 Table 1): transition -0.25 to +0.25 in, motor to +-1.5 in.
pub const ALUMINIUM_HORN_REGIONS: MeasuredRegions = MeasuredRegions {
    transition: (-0.25 * INCH, 0.25 * INCH),
    motor_outer: (-1.5 * INCH, 1.5 * INCH),
};

/// Stainless-steel horn (seed 001 Table 1): transition +0.1 to +0.2 in, motor to +-1.5 in.
pub const STAINLESS_HORN_REGIONS: MeasuredRegions = MeasuredRegions {
    transition: (0.1 * INCH, 0.2 * INCH),
    motor_outer: (-1.5 * INCH, 1.5 * INCH),
};

/// Young's moduli of the two horns Table 1 measured (seed 000 Table 2: Al 73 GPa, SS 200 GPa),
/// and how far a scene's horn may be from one to be taken as that horn: +-15 %, wider than the
/// spread of the grades (Al alloys 69-79 GPa, stainless 190-203 GPa) and far from the other.
const ALUMINIUM_YOUNG_PA: f64 = 73e9;
const STAINLESS_YOUNG_PA: f64 = 200e9;
const SAME_MATERIAL: f64 = 0.15;

impl MeasuredRegions {
    /// Table 1's regions for a horn of Young's modulus `young_pa` (body 1 of the scene's rough
    /// surface): the aluminium horn's or the stainless-steel horn's. `None` for any other
    /// material: Table 1 measured no regions for it, and they are not guessed.
    pub fn for_horn_modulus(young_pa: f64) -> Option<Self> {
        let near = |reference: f64| libm::fabs(young_pa / reference - 1.0) <= SAME_MATERIAL;
        if near(ALUMINIUM_YOUNG_PA) {
            Some(ALUMINIUM_HORN_REGIONS)
        } else if near(STAINLESS_YOUNG_PA) {
            Some(STAINLESS_HORN_REGIONS)
        } else {
            None
        }
    }
}

/// Which of seed 001's regions a position lies in, and so which model describes the block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HornRegion {
    /// Inside the measured transition region: friction reduction, the cube model.
    Transition,
    /// In a motor-effect region: the net drive force, this module's model.
    Motor,
    /// Beyond the measured motor regions (Table 1 stops at +-1.5 in): the motor model is
    /// still evaluated (it runs to the horn's ends) but no measurement backs it.
    BeyondMeasured,
}

impl MeasuredRegions {
    /// Whether `x` (m from the centre) lies in the measured transition region (inclusive).
    pub fn in_transition(&self, x: f64) -> bool {
        self.transition.0 <= x && x <= self.transition.1
    }

    /// The region of position `x` (m from the centre): the model choice by where the block is.
    /// A non-finite `x` is [`ModelError::NonFinite`].
    pub fn region(&self, x: f64) -> Result<HornRegion, ModelError> {
        if !x.is_finite() {
            return Err(ModelError::NonFinite { input: "x" });
        }
        Ok(classify(x, self.transition, self.motor_outer))
    }
}

/// The region of position `x` given the transition region `[low, high]` and the motor regions'
/// outer ends `[left, right]`, in any one unit of position (metres here; the station's horn
/// phase counts, `sonolube::station`), ends included.
pub fn classify<T: PartialOrd>(x: T, transition: (T, T), motor_outer: (T, T)) -> HornRegion {
    if transition.0 <= x && x <= transition.1 {
        HornRegion::Transition
    } else if motor_outer.0 <= x && x <= motor_outer.1 {
        HornRegion::Motor
    } else {
        HornRegion::BeyondMeasured
    }
}
