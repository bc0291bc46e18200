//! The quantity a run is judged in, from the target's kind and the plant's ground truth
//! (`sonolube::scene` criteria docs): friction force for a force target, friction coefficient
//! (friction / normal load) for a coefficient target, friction ratio (friction / natural
//! friction) against `1 - reduction` for a reduction target. Friction is taken as a
//! magnitude (the plant signs it like the sliding velocity; the controller uses `|F_t|`).
//! A net-force target (issue 27) is judged signed: the horn's force on the block along +x,
//! which is minus the plant's signed tangential force (the force the block drags the horn
//! and the cell with, signed like the sliding velocity for friction).

use crate::plant::GroundTruth;
use sonolube::protocol::Target;

/// What a target holds, hence what the criteria measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Quantity {
    /// Friction ratio F'/F (force over natural friction), dimensionless.
    Ratio,
    /// Friction coefficient (friction over normal load), dimensionless.
    Coefficient,
    /// Friction force, N.
    Force,
    /// Net tangential force of the horn on the block along +x, N, signed.
    NetForce,
}

impl Quantity {
    /// The quantity a target of this kind holds.
    pub const fn of(target: &Target) -> Self {
        match target {
            Target::Force { .. } => Quantity::Force,
            Target::Coef { .. } => Quantity::Coefficient,
            Target::Reduction { .. } => Quantity::Ratio,
            Target::NetForce { .. } => Quantity::NetForce,
        }
    }

    /// Short name for tables and CSV headers: `ratio`, `coef`, `force_n`, `net_force_n`.
    pub const fn name(self) -> &'static str {
        match self {
            Quantity::Ratio => "ratio",
            Quantity::Coefficient => "coef",
            Quantity::Force => "force_n",
            Quantity::NetForce => "net_force_n",
        }
    }
}

/// A target and the plant's value in the target's quantity at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Judged {
    /// The quantity.
    pub quantity: Quantity,
    /// The target's value: `1 - reduction`, the coefficient, or the force in N; > 0 but for
    /// the net force (N along +x, either sign).
    pub target: f32,
    /// The plant's true value; NaN where it is undefined (no natural friction, no load).
    pub actual: f32,
}

impl Judged {
    /// `target` judged against `truth`.
    pub fn new(target: &Target, truth: &GroundTruth) -> Self {
        let friction = libm::fabsf(truth.contact.friction_n);
        let per = |denominator: f32| {
            if denominator > 0.0 {
                friction / denominator
            } else {
                f32::NAN
            }
        };
        let quantity = Quantity::of(target);
        let actual = match quantity {
            Quantity::Ratio => per(truth.contact.natural_friction_n),
            Quantity::Coefficient => per(truth.normal_load_n),
            Quantity::Force => friction,
            Quantity::NetForce => -truth.contact.friction_n,
        };
        Self {
            quantity,
            target: target_value(target),
            actual,
        }
    }

    /// `(actual - target) / |target|`, signed; NaN if `actual` is.
    pub fn relative_error(&self) -> f32 {
        (self.actual - self.target) / libm::fabsf(self.target)
    }
}

/// The value of `target` in its quantity: `1 - reduction`, the coefficient, the force in N.
pub fn target_value(target: &Target) -> f32 {
    match *target {
        // Scaled integers below 2^24 (the protocol's ranges for coef and reduction, forces up
        // to 16.7 kN) convert exactly, and one division rounds correctly.
        Target::Reduction { reduction_mpct } => {
            100_000u32.saturating_sub(reduction_mpct) as f32 / 100_000.0
        }
        Target::Coef { coef_ppm } => coef_ppm as f32 / 1e6,
        Target::Force { force_mn } => force_mn as f32 / 1e3,
        Target::NetForce { force_mn } => force_mn as f32 / 1e3,
    }
}

/// The friction force `target` asks of the plant now, N: `(1 - reduction)` x the true natural
/// friction, the coefficient x the true normal load, or the force.
pub fn target_friction_n(target: &Target, truth: &GroundTruth) -> f32 {
    let value = target_value(target);
    match Quantity::of(target) {
        Quantity::Ratio => value * truth.contact.natural_friction_n,
        Quantity::Coefficient => value * truth.normal_load_n,
        Quantity::Force => value,
        // The tangential force the net-force target asks for, as a magnitude like the
        // others (the horn's force on the block is minus the cell's reading).
        Quantity::NetForce => libm::fabsf(value),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plant::Plant;
    use sonolube::scene::find;

    #[test]
    fn each_kind_is_judged_in_its_own_quantity() {
        let scene = find("reference").expect("built in");
        let mut plant = Plant::from_scene(scene).expect("plant");
        let truth = plant.step(0.0, 40_000.0).truth;
        // Drive off: the plant shows its natural friction, mu 0.24 x 4.155 N.
        let natural = 0.24 * 4.155;
        assert!((truth.contact.friction_n - natural).abs() < 1e-5);
        let half = Target::Reduction {
            reduction_mpct: 50_000,
        };
        let judged = Judged::new(&half, &truth);
        assert_eq!(judged.quantity, Quantity::Ratio);
        assert_eq!(judged.target, 0.5);
        assert!((judged.actual - 1.0).abs() < 1e-6);
        assert!((judged.relative_error() - 1.0).abs() < 1e-5);
        assert!((target_friction_n(&half, &truth) - natural / 2.0).abs() < 1e-5);
        let coef = Target::Coef { coef_ppm: 120_000 };
        let judged = Judged::new(&coef, &truth);
        assert!((judged.actual - 0.24).abs() < 1e-6);
        assert!((judged.relative_error() - 1.0).abs() < 1e-4);
        assert!((target_friction_n(&coef, &truth) - 0.12 * 4.155).abs() < 1e-5);
        let force = Target::Force { force_mn: 500 };
        let judged = Judged::new(&force, &truth);
        assert_eq!(judged.quantity.name(), "force_n");
        assert!((judged.actual - natural).abs() < 1e-5);
        assert_eq!(target_friction_n(&force, &truth), 0.5);
        // The net force is the horn's force on the block: sliding at +x with the drive
        // off, that is friction towards -x.
        assert!(truth.sliding_velocity_m_per_s > 0.0);
        let net = Target::NetForce { force_mn: -500 };
        let judged = Judged::new(&net, &truth);
        assert_eq!(judged.quantity.name(), "net_force_n");
        assert_eq!(judged.target, -0.5);
        assert!((judged.actual + natural).abs() < 1e-5);
        assert!((judged.relative_error() + (natural - 0.5) / 0.5).abs() < 1e-4);
    }

    #[test]
    fn an_undefined_value_is_nan() {
        let scene = find("reference").expect("built in");
        let mut plant = Plant::from_scene(scene).expect("plant");
        let mut truth = plant.step(0.0, 40_000.0).truth;
        truth.normal_load_n = 0.0;
        truth.contact.natural_friction_n = 0.0;
        let coef = Judged::new(&Target::Coef { coef_ppm: 1 }, &truth);
        assert!(coef.actual.is_nan() && coef.relative_error().is_nan());
        let ratio = Judged::new(&Target::Reduction { reduction_mpct: 0 }, &truth);
        assert!(ratio.actual.is_nan());
    }
}
