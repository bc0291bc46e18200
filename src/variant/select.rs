//! Choosing a scene's model variant from the measured table (issue 7, "Use").
//!
//! A scene states the accuracy it needs (`accuracy.model_pct`, % of the natural friction) and
//! what it contains (`contents`: vibration components, load and velocity ranges). [`select`]
//! decides what has to be modelled, then picks the cheapest fixed-point variant whose measured
//! maximum error over the scene's grid ([`super::grid`]) meets the budget:
//!
//! 1. **No normal vibration: no contact re-evaluation.** Without out-of-plane motion the contact
//!    (separation, real area) does not change over the cycle, so no cube model: the in-plane
//!    family (Coulomb, Dahl). The reference is the scene's physics, not the model its file
//!    names (issue 13): with a finite contact stiffness (`k_t_n_per_m`) the Dahl steady state
//!    with the scene's k_t and alpha, so a stiff contact keeps the Coulomb ratio only where the
//!    ratio is within budget of Dahl; without k_t (a rigid contact) the Coulomb ratio.
//! 2. **Normal vibration: the contact is re-evaluated**, and the complete contact is the
//!    elastic-plastic one. The elastic contact (no plastic terms) is a candidate like any other:
//!    it is chosen when its measured error against the elastic-plastic reference over the
//!    scene's load range meets the budget (and it is not dearer).
//! 3. Among the candidates (fixed point, the required level or a reduced one in the same family,
//!    every quadrature knob and table size: the Coulomb ratio, the Dahl steady state at N = 16
//!    to 64 and its tables `T=65x65`, `T=129x129`) the errors are measured against the reference
//!    level's exact `f64` model, and the reason line names that reference; the cheapest in Cortex-M4 instructions that meets the budget
//!    wins, costs within [`COST_RESOLUTION`] of it counting as ties, which go to the lower level
//!    (fewer parts), then to the more accurate (the table sizes cost the same per evaluation). When none meets it, the most accurate variant of the
//!    required level is taken and the reason says so.
//!
//! Only fixed-point variants are candidates: the controller's model interface
//! ([`crate::model::FrictionModel`]) is fixed point and the project keeps floats out of the
//! control step; the float forms are measured to publish the trade. A scene that is not in the
//! table (a file loaded at run time, also one that takes a built-in scene's name but differs
//! from it in what was measured) or whose controller model is not catalogued keeps its own
//! model at the default knob, and the reason says that too.
//!
//! [`crate::station::Station::new`] builds every scene's controller model from [`select`]
//! ([`Selection::build`]), on the host and in the firmware alike, and the boards and
//! `sonolube scene` print the [`Selection`] (its `Display` and `defmt` forms) at scene start.

use core::fmt;

use super::fixed::{buildable, fixed_model, variant_buildable};
use super::{CATALOGUE, Family, Fidelity, Form, Variant, table};
use crate::model::AnyModel;
use crate::model::ModelError;
use crate::scene::{ModelKind, ModelSpec, Scene};

/// Instructions per evaluation below which two measured costs are not told apart: the QEMU
/// counts' SysTick rounding is up to 0.3 instructions per call for the cheap variants
/// (`board/qemu/src/bench.rs`).
pub const COST_RESOLUTION: f32 = 1.0;

/// Measured cost of one variant: instructions per evaluation on the Cortex-M4 instruction set
/// (QEMU, `-icount shift=0`, averaged over the variant's grid points).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cost {
    /// Variant name ([`super::CATALOGUE`]).
    pub variant: &'static str,
    /// Instructions per evaluation.
    pub instructions: f32,
}

/// Measured error of one variant against one level's exact `f64` model over one scene's grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneError {
    /// Scene name.
    pub scene: &'static str,
    /// Variant name.
    pub variant: &'static str,
    /// The level whose exact model is the reference.
    pub reference: Fidelity,
    /// Largest |F'/F - reference| over the grid (fraction of the natural friction), rounded
    /// up to three significant digits (so small numerical changes elsewhere rarely move it, and
    /// it never understates the measurement).
    pub max_error: f32,
    /// Grid points.
    pub points: u16,
}

/// The committed measurements ([`table::MEASURED`], written by `sonolube speed`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurements {
    /// Costs of every catalogued variant measured in QEMU.
    pub costs: &'static [Cost],
    /// Errors of the fixed-point model variants per scene and reference level.
    pub errors: &'static [SceneError],
}

impl Measurements {
    /// Instructions per evaluation of the variant named `variant`.
    pub fn instructions(&self, variant: &str) -> Option<f32> {
        self.costs
            .iter()
            .find(|c| c.variant == variant)
            .map(|c| c.instructions)
    }

    /// Error of `variant` against `reference` over `scene`'s grid.
    pub fn error(&self, scene: &str, variant: &str, reference: Fidelity) -> Option<&SceneError> {
        self.errors
            .iter()
            .find(|e| e.scene == scene && e.variant == variant && e.reference == reference)
    }
}

/// What the scene needs modelled, and what was skipped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Parts {
    /// No normal vibration: the contact is not re-evaluated (no cube model).
    InPlane {
        /// The scene's controller asks for the Dahl compliance: whether it was skipped
        /// (Coulomb met the budget against the Dahl model) and the best measured maximum
        /// error of the Coulomb ratio against it, %. `None` when the scene asks for Coulomb.
        compliance: Option<Reduction>,
    },
    /// Normal vibration: the contact is re-evaluated (cube model).
    Cube {
        /// Whether the plastic terms were skipped (elastic contact chosen) and the best measured
        /// maximum error of the elastic contact against the elastic-plastic model, %.
        plastic: Reduction,
        /// The scene's load range, N.
        load_range_n: (f32, f32),
    },
}

/// A part the scene might do without.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reduction {
    /// The part was left out.
    pub skipped: bool,
    /// Best measured maximum error without it, % of the natural friction (`None`: the reduced
    /// level was not measured for this scene).
    pub error_pct: Option<f32>,
}

/// Why the variant was chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reason {
    /// The cheapest measured candidate whose maximum error meets the budget.
    Meets {
        /// Its measured maximum error, % of the natural friction.
        error_pct: f32,
        /// The scene's budget, `accuracy.model_pct`.
        budget_pct: f32,
        /// Its instructions per evaluation.
        instructions: f32,
        /// Grid points the error is the maximum over.
        points: u16,
        /// Candidates measured for the scene.
        candidates: u8,
    },
    /// No candidate meets the budget: the most accurate variant of the required level.
    NoneMeets {
        /// Its measured maximum error, %.
        error_pct: f32,
        /// The scene's budget, %.
        budget_pct: f32,
        /// Its instructions per evaluation.
        instructions: f32,
        /// Grid points.
        points: u16,
    },
    /// The scene is not in the committed table, or its controller model is not catalogued:
    /// the scene's own controller model at the default knob, unmeasured.
    NotMeasured {
        /// The scene's controller model.
        kind: ModelKind,
    },
}

/// The model variant a scene runs, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Selection {
    /// The chosen variant; `None` for the scene's own model ([`Reason::NotMeasured`]).
    pub variant: Option<&'static Variant>,
    /// The level the errors are measured against (`None` when not measured).
    pub required: Option<Fidelity>,
    /// Why.
    pub reason: Reason,
    /// What is modelled and what was skipped (`None` when not measured).
    pub parts: Option<Parts>,
}

/// The variant for `scene` from the committed measurements ([`table::MEASURED`]), which were
/// taken on the built-in scenes: a scene that differs from the built-in scene of its name in
/// anything the measurement depends on ([`measured_as_built_in`]) is not measured and keeps
/// its own model ([`Reason::NotMeasured`]).
pub fn select(scene: &Scene<'_>) -> Selection {
    if !measured_as_built_in(scene) {
        return not_measured(scene);
    }
    select_from(scene, &table::MEASURED)
}

/// Whether `scene` is, in everything the committed errors depend on, the built-in scene of its
/// name: its contents (the grid), its controller's parameters (the kind aside: the kind only
/// names the required level, whose errors the table holds), the drive frequency, the
/// full-scale amplitude and the horn. A scene file loaded at run time under a built-in name,
/// with other contents or parameters, was not measured. The budget (`accuracy`) is not a
/// measurement input: it is what the selection compares the errors with.
pub fn measured_as_built_in(scene: &Scene<'_>) -> bool {
    let Some(built) = crate::scene::find(scene.name) else {
        return false;
    };
    let controller = ModelSpec {
        kind: built.controller.kind,
        ..scene.controller
    };
    controller == built.controller
        && scene.contents == built.contents
        && scene.horn == built.horn
        && scene.transducer.drive_hz == built.transducer.drive_hz
        && scene.actuator.full_scale_amplitude_m == built.actuator.full_scale_amplitude_m
}

/// The scene's own controller model, unmeasured.
fn not_measured(scene: &Scene<'_>) -> Selection {
    Selection {
        variant: None,
        required: None,
        reason: Reason::NotMeasured {
            kind: scene.controller.kind,
        },
        parts: None,
    }
}

/// The family and the reference level of `scene`: the most faithful model of its contact the
/// project has, from its physics (issue 13), not from the model its file names. Normal
/// vibration: the elastic-plastic cube model. In-plane vibration with a finite contact
/// stiffness (`k_t_n_per_m` in `[controller]`): the Dahl steady state with the scene's k_t
/// and alpha. In-plane without k_t: the rigid contact's Coulomb ratio. `None` when the scene's
/// controller model is outside the catalogue (`exp-coulomb`) or lacks the reference level's
/// parameters.
pub fn required_fidelity(scene: &Scene<'_>) -> Option<(Family, Fidelity)> {
    if scene.controller.kind == ModelKind::ExpCoulomb {
        return None;
    }
    let required = if scene.contents.normal_vibration {
        Fidelity::CubeElasticPlastic
    } else if scene.controller.k_t_n_per_m.is_some() {
        Fidelity::DahlSteady
    } else {
        Fidelity::Coulomb
    };
    buildable(scene, required).then_some((required.family(), required))
}

/// The reference level in words, for the reason line.
pub const fn reference_name(level: Fidelity) -> &'static str {
    match level {
        Fidelity::DahlSteady => "the Dahl steady state (the scene's k_t and alpha)",
        Fidelity::CubeElasticPlastic => "the elastic-plastic cube model",
        Fidelity::CubeElastic => "the elastic cube model",
        Fidelity::Coulomb => "the Coulomb ratio (rigid contact: no k_t)",
        Fidelity::Littmann | Fidelity::DahlUpdate => "a kernel",
    }
}

/// A candidate with its measurements.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    variant: &'static Variant,
    instructions: f32,
    error: SceneError,
}

/// [`select`] from the measurements `measured` (tests give their own).
pub fn select_from(scene: &Scene<'_>, measured: &Measurements) -> Selection {
    let not_measured = not_measured(scene);
    let Some((family, required)) = required_fidelity(scene) else {
        return not_measured;
    };
    let candidates = || {
        CATALOGUE
            .iter()
            .filter(move |v| {
                v.form == Form::Fixed
                    && v.fidelity.family() == family
                    && v.fidelity <= required
                    && variant_buildable(scene, v)
            })
            .filter_map(move |v| {
                Some(Candidate {
                    variant: v,
                    instructions: measured.instructions(v.name)?,
                    error: *measured.error(scene.name, v.name, required)?,
                })
            })
    };
    let budget = scene.accuracy.model_pct as f32;
    let within = |c: &Candidate| 100.0 * c.error.max_error <= budget;
    // Costs within the counts' resolution of the cheapest are equal (the table sizes cost the
    // same per evaluation, up to the SysTick rounding): among them, the lower level, then the
    // more accurate.
    let least = candidates()
        .filter(within)
        .map(|c| c.instructions)
        .min_by(f32::total_cmp);
    let cheapest = least.and_then(|least| {
        candidates()
            .filter(within)
            .filter(|c| c.instructions <= least + COST_RESOLUTION)
            .min_by(|a, b| {
                a.variant
                    .fidelity
                    .cmp(&b.variant.fidelity)
                    .then(a.error.max_error.total_cmp(&b.error.max_error))
                    .then(a.instructions.total_cmp(&b.instructions))
            })
    });
    let count = candidates().count();
    if count == 0 {
        return not_measured;
    }
    let most_accurate = |c: &Candidate| c.variant.fidelity == required;
    let (chosen, reason) = match cheapest {
        Some(c) => (
            c,
            Reason::Meets {
                error_pct: 100.0 * c.error.max_error,
                budget_pct: budget,
                instructions: c.instructions,
                points: c.error.points,
                candidates: count.min(255) as u8,
            },
        ),
        None => {
            let pick = candidates()
                .filter(most_accurate)
                .min_by(|a, b| a.error.max_error.total_cmp(&b.error.max_error))
                .or_else(|| {
                    candidates().min_by(|a, b| a.error.max_error.total_cmp(&b.error.max_error))
                });
            let Some(c) = pick else {
                return not_measured;
            };
            (
                c,
                Reason::NoneMeets {
                    error_pct: 100.0 * c.error.max_error,
                    budget_pct: budget,
                    instructions: c.instructions,
                    points: c.error.points,
                },
            )
        }
    };
    let best_of = |level: Fidelity| {
        candidates()
            .filter(|c| c.variant.fidelity == level)
            .map(|c| 100.0 * c.error.max_error)
            .min_by(f32::total_cmp)
    };
    let parts = match family {
        Family::Cube => Parts::Cube {
            plastic: Reduction {
                skipped: chosen.variant.fidelity == Fidelity::CubeElastic,
                error_pct: best_of(Fidelity::CubeElastic),
            },
            load_range_n: (
                scene.contents.load_min_n as f32,
                scene.contents.load_max_n as f32,
            ),
        },
        _ => Parts::InPlane {
            compliance: (required == Fidelity::DahlSteady).then(|| Reduction {
                skipped: chosen.variant.fidelity == Fidelity::Coulomb,
                error_pct: best_of(Fidelity::Coulomb),
            }),
        },
    };
    Selection {
        variant: Some(chosen.variant),
        required: Some(required),
        reason,
        parts: Some(parts),
    }
}

impl Selection {
    /// The model the controller should use: the chosen variant built from the scene's
    /// controller parameters and hardware, or the scene's own model when nothing was measured.
    /// Errors: the model's own validation.
    pub fn build(&self, scene: &Scene<'_>) -> Result<AnyModel, ModelError> {
        match self.variant {
            Some(variant) => fixed_model(scene, variant),
            None => AnyModel::new(scene, &scene.controller),
        }
    }
}

/// `Some(x)` as `x`, `None` as "not measured", for the reason line.
struct Pct(Option<f32>);

/// Instructions per evaluation to the nearest whole one, as the `Display` form prints them
/// (`as` saturates: a negative or NaN count, which the table never holds, prints 0).
#[cfg(feature = "defmt")]
fn whole(instructions: f32) -> u32 {
    (instructions + 0.5) as u32
}

#[cfg(feature = "defmt")]
impl defmt::Format for Pct {
    fn format(&self, f: defmt::Formatter) {
        match self.0 {
            Some(x) => defmt::write!(f, "{=f32} %", x),
            None => defmt::write!(f, "not measured"),
        }
    }
}

impl fmt::Display for Pct {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(x) => write!(f, "{x:.3} %"),
            None => f.write_str("not measured"),
        }
    }
}

impl fmt::Display for Parts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Parts::InPlane { compliance: None } => {
                f.write_str("no normal vibration: contact not re-evaluated, no cube model")
            }
            Parts::InPlane {
                compliance: Some(r),
            } => write!(
                f,
                "no normal vibration: contact not re-evaluated; Dahl compliance {} (Coulomb ratio: {})",
                if r.skipped { "skipped" } else { "kept" },
                Pct(r.error_pct)
            ),
            Parts::Cube {
                plastic,
                load_range_n: (lo, hi),
            } => {
                write!(
                    f,
                    "normal vibration: contact re-evaluated; plastic terms {} (elastic contact ",
                    if plastic.skipped { "skipped" } else { "kept" },
                )?;
                if hi > lo {
                    write!(f, "over {lo} to {hi} N")?;
                } else {
                    write!(f, "at {lo} N")?;
                }
                write!(f, ": {})", Pct(plastic.error_pct))
            }
        }
    }
}

impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.variant.map_or("(own model)", |v| v.name);
        let against = self.required.map_or("-", reference_name);
        match self.reason {
            Reason::Meets {
                error_pct,
                budget_pct,
                instructions,
                points,
                candidates,
            } => write!(
                f,
                "model {name}: the cheapest within budget of {candidates} measured against \
                 {against}, {instructions:.0} instructions, max error {error_pct:.2e} % <= \
                 {budget_pct} % of natural friction over {points} points",
            )?,
            Reason::NoneMeets {
                error_pct,
                budget_pct,
                instructions,
                points,
            } => write!(
                f,
                "model {name}: NO variant meets the budget {budget_pct} % against {against}; \
                 most accurate, {instructions:.0} instructions, max error {error_pct:.2e} % over \
                 {points} points",
            )?,
            Reason::NotMeasured { kind } => {
                return write!(
                    f,
                    "model {kind:?} (the scene's own, default knob): not in the measured table"
                );
            }
        }
        if let Some(parts) = self.parts {
            write!(f, "; {parts}")?;
        }
        Ok(())
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Selection {
    fn format(&self, f: defmt::Formatter) {
        let name = self.variant.map_or("(own model)", |v| v.name);
        let against = self.required.map_or("-", reference_name);
        match self.reason {
            Reason::Meets {
                error_pct,
                budget_pct,
                instructions,
                points,
                candidates,
            } => defmt::write!(
                f,
                "model {=str}: the cheapest within budget of {=u8} measured against {=str}, {=u32} instructions, max error {=f32} % <= {=f32} % of natural friction over {=u16} points",
                name,
                candidates,
                against,
                whole(instructions),
                error_pct,
                budget_pct,
                points
            ),
            Reason::NoneMeets {
                error_pct,
                budget_pct,
                instructions,
                points,
            } => defmt::write!(
                f,
                "model {=str}: NO variant meets the budget {=f32} % against {=str}; most accurate, {=u32} instructions, max error {=f32} % over {=u16} points",
                name,
                budget_pct,
                against,
                whole(instructions),
                error_pct,
                points
            ),
            Reason::NotMeasured { kind } => {
                defmt::write!(
                    f,
                    "model {} (the scene's own, default knob): not in the measured table",
                    kind
                );
                return;
            }
        }
        match self.parts {
            Some(Parts::InPlane { compliance: None }) => defmt::write!(
                f,
                "; no normal vibration: contact not re-evaluated, no cube model"
            ),
            Some(Parts::InPlane {
                compliance: Some(r),
            }) => defmt::write!(
                f,
                "; no normal vibration: contact not re-evaluated; Dahl compliance {=str} (Coulomb ratio: {})",
                if r.skipped { "skipped" } else { "kept" },
                Pct(r.error_pct)
            ),
            Some(Parts::Cube {
                plastic,
                load_range_n: (lo, hi),
            }) => {
                defmt::write!(
                    f,
                    "; normal vibration: contact re-evaluated; plastic terms {=str} (elastic contact ",
                    if plastic.skipped { "skipped" } else { "kept" },
                );
                if hi > lo {
                    defmt::write!(f, "over {=f32} to {=f32} N", lo, hi);
                } else {
                    defmt::write!(f, "at {=f32} N", lo);
                }
                defmt::write!(f, ": {})", Pct(plastic.error_pct));
            }
            None => {}
        }
    }
}

#[cfg(test)]
#[path = "select_tests.rs"]
mod tests;
