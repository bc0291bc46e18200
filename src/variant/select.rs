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
//!    to 64 and its tables `T=49x73`) the errors are measured against the reference
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

use super::budget::{BOARD, Board, StepCost};
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
    /// Whole control steps with each fixed-point model variant, measured in QEMU
    /// ([`super::budget`]).
    pub steps: &'static [StepCost],
}

impl Measurements {
    /// Instructions per evaluation of the variant named `variant`.
    pub fn instructions(&self, variant: &str) -> Option<f32> {
        self.costs
            .iter()
            .find(|c| c.variant == variant)
            .map(|c| c.instructions)
    }

    /// The longest control step measured with the variant named `variant`, instructions.
    pub fn longest_step(&self, variant: &str) -> Option<u32> {
        self.steps
            .iter()
            .find(|c| c.variant == variant)
            .map(|c| c.longest)
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
    /// Refused: no variant that meets the accuracy budget (when none meets it, the most
    /// accurate; when nothing was measured, the scene's own model at its default knob) has a
    /// control step within the period budget. The variant named is the one of those whose
    /// longest step is the shortest. [`Selection::build`] refuses to build it.
    Overruns {
        /// Its measured maximum error, % (`None`: the scene's own model, not measured).
        error_pct: Option<f32>,
        /// The scene's accuracy budget, %.
        budget_pct: f32,
        /// Whether its error meets the accuracy budget.
        accurate: bool,
        /// The scene's controller model (for the own-model case).
        kind: ModelKind,
    },
}

/// The control period's budget and the chosen variant's control step ([`super::budget`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Period {
    /// The board the budget is for ([`super::budget::BOARD`]).
    pub board: &'static str,
    /// The scene's control rate, whole Hz.
    pub rate_hz: u32,
    /// Instructions in one control period at the scene's rate on that board.
    pub budget: u32,
    /// The chosen variant's longest measured control step, instructions (`None`: not
    /// measured, so not checked).
    pub step_longest: Option<u32>,
}

impl Period {
    /// Whether the step fits (an unmeasured step is not held against the scene).
    pub fn fits(&self) -> bool {
        self.step_longest.is_none_or(|step| step <= self.budget)
    }
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
    /// The period budget and the chosen variant's step.
    pub period: Period,
}

/// The variant for `scene` from the committed measurements ([`table::MEASURED`]), which were
/// taken on the built-in scenes: a scene is measured when a built-in scene with the same
/// measurement inputs was ([`measured_twin`]: the scene itself, or one that differs only in
/// what the errors do not depend on, such as its name, control rate or accuracy budget);
/// otherwise it keeps its own model ([`Reason::NotMeasured`]).
pub fn select(scene: &Scene<'_>) -> Selection {
    match measured_twin(scene, &table::MEASURED) {
        Some(name) => select_from(&Scene { name, ..*scene }, &table::MEASURED),
        None => not_measured(scene, &table::MEASURED, &BOARD),
    }
}

/// The name under which `measured` holds `scene`'s errors: the built-in scene of its name when
/// [`measured_as_built_in`], else the first built-in scene with the same measurement inputs
/// (a test scene that is the `reference` scene at another control rate has the `reference`
/// scene's errors: the grid and the models are the same). `None`: not measured.
pub fn measured_twin(scene: &Scene<'_>, measured: &Measurements) -> Option<&'static str> {
    let has_errors = |name: &str| measured.errors.iter().any(|e| e.scene == name);
    if let Some(built) = crate::scene::find(scene.name)
        && same_measurement_inputs(scene, built)
        && has_errors(built.name)
    {
        return Some(built.name);
    }
    crate::scene::compiled()
        .iter()
        .find(|built| same_measurement_inputs(scene, built) && has_errors(built.name))
        .map(|built| built.name)
}

/// Whether `scene` is, in everything the committed errors depend on, the built-in scene of its
/// name: its contents (the grid), its controller's parameters (the kind aside: the kind only
/// names the required level, whose errors the table holds), the drive frequency, the
/// full-scale amplitude and the horn. A scene file loaded at run time under a built-in name,
/// with other contents or parameters, was not measured. The budget (`accuracy`) is not a
/// measurement input: it is what the selection compares the errors with.
pub fn measured_as_built_in(scene: &Scene<'_>) -> bool {
    crate::scene::find(scene.name).is_some_and(|built| same_measurement_inputs(scene, built))
}

/// Whether the committed errors of `built` are `scene`'s too (see [`measured_as_built_in`]).
fn same_measurement_inputs(scene: &Scene<'_>, built: &Scene<'_>) -> bool {
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

/// A control rate to the nearest whole Hz (the loader keeps it in 1e3 ..= 1e5; `as`
/// saturates anything else).
fn whole_hz(rate_hz: f64) -> u32 {
    libm::round(rate_hz) as u32
}

/// The fixed-point variant the scene's own controller model is at its default knob
/// (`AnyModel::new`: Dahl N = 64, cube N = 16), whose control step was measured; `None` for a
/// model outside the catalogue (`exp-coulomb`).
pub fn default_variant(kind: ModelKind) -> Option<&'static Variant> {
    let (fidelity, points) = match kind {
        ModelKind::Coulomb => (Fidelity::Coulomb, 0),
        ModelKind::Dahl => (Fidelity::DahlSteady, 64),
        ModelKind::CubeElastic => (Fidelity::CubeElastic, 16),
        ModelKind::CubeElasticPlastic => (Fidelity::CubeElasticPlastic, 16),
        ModelKind::ExpCoulomb => return None,
    };
    super::lookup(fidelity, Form::Fixed, points)
}

/// The scene's own controller model, unmeasured against the reference; refused when its
/// measured control step does not fit the period.
fn not_measured(scene: &Scene<'_>, measured: &Measurements, board: &Board) -> Selection {
    let kind = scene.controller.kind;
    let period = Period {
        board: board.name,
        rate_hz: whole_hz(scene.control_rate_hz),
        budget: board.period_budget(scene.control_rate_hz),
        step_longest: default_variant(kind).and_then(|v| measured.longest_step(v.name)),
    };
    let reason = if period.fits() {
        Reason::NotMeasured { kind }
    } else {
        Reason::Overruns {
            error_pct: None,
            budget_pct: scene.accuracy.model_pct as f32,
            accurate: false,
            kind,
        }
    };
    Selection {
        variant: None,
        required: None,
        reason,
        parts: None,
        period,
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
    /// Longest control step, instructions.
    step: u32,
}

/// [`select`] from the measurements `measured` (tests give their own), for this build's board
/// ([`BOARD`]).
pub fn select_from(scene: &Scene<'_>, measured: &Measurements) -> Selection {
    select_for(scene, measured, &BOARD)
}

/// [`select_from`] for `board`'s period budget: the cheapest variant that meets the accuracy
/// budget and whose longest measured control step fits the period; refused
/// ([`Reason::Overruns`]) when some meet the accuracy and none of those fits, or when none
/// meets it and the most accurate does not fit either.
pub fn select_for(scene: &Scene<'_>, measured: &Measurements, board: &Board) -> Selection {
    let not_measured = not_measured(scene, measured, board);
    let period_budget = board.period_budget(scene.control_rate_hz);
    let fits = move |c: &Candidate| c.step <= period_budget;
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
                    step: measured.longest_step(v.name)?,
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
        .filter(fits)
        .map(|c| c.instructions)
        .min_by(f32::total_cmp);
    let cheapest = least.and_then(|least| {
        candidates()
            .filter(within)
            .filter(fits)
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
            let shortest_step = |a: &Candidate, b: &Candidate| a.step.cmp(&b.step);
            let by_error =
                |a: &Candidate, b: &Candidate| a.error.max_error.total_cmp(&b.error.max_error);
            // Accurate enough but too slow: refused, naming the accurate one nearest to fit.
            let accurate = candidates().filter(within).min_by(shortest_step);
            // None accurate enough: the most accurate of the required level that fits (else of
            // any level that fits); refused when nothing fits.
            let fitting = candidates()
                .filter(fits)
                .filter(most_accurate)
                .min_by(by_error)
                .or_else(|| candidates().filter(fits).min_by(by_error));
            let overruns = |c: Candidate| {
                (
                    c,
                    Reason::Overruns {
                        error_pct: Some(100.0 * c.error.max_error),
                        budget_pct: budget,
                        accurate: within(&c),
                        kind: scene.controller.kind,
                    },
                )
            };
            match (accurate, fitting) {
                (Some(c), _) => overruns(c),
                (None, Some(c)) => (
                    c,
                    Reason::NoneMeets {
                        error_pct: 100.0 * c.error.max_error,
                        budget_pct: budget,
                        instructions: c.instructions,
                        points: c.error.points,
                    },
                ),
                (None, None) => match candidates().min_by(by_error) {
                    Some(c) => overruns(c),
                    None => return not_measured,
                },
            }
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
        period: Period {
            board: board.name,
            rate_hz: whole_hz(scene.control_rate_hz),
            budget: period_budget,
            step_longest: Some(chosen.step),
        },
    }
}

impl Selection {
    /// Whether the scene is refused: no variant fits both the accuracy and the period.
    pub fn refused(&self) -> bool {
        matches!(self.reason, Reason::Overruns { .. })
    }

    /// The model the controller should use: the chosen variant built from the scene's
    /// controller parameters and hardware, or the scene's own model when nothing was measured.
    /// Errors: the model's own validation.
    /// Errors: [`ModelError::OutOfDomain`] on "control period" for a refused selection
    /// ([`Reason::Overruns`]: its line says which budget fails and by how much).
    pub fn build(&self, scene: &Scene<'_>) -> Result<AnyModel, ModelError> {
        if self.refused() {
            return Err(ModelError::OutOfDomain {
                input: "control period",
                reason: "no model variant meets the accuracy budget with a control step within the period budget (the selection line says by how much)",
            });
        }
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
            Reason::NotMeasured { kind } => write!(
                f,
                "model {kind:?} (the scene's own, default knob): not in the measured table"
            )?,
            Reason::Overruns {
                error_pct,
                budget_pct,
                accurate,
                kind,
            } => {
                match (self.variant, error_pct) {
                    (Some(v), Some(e)) => write!(
                        f,
                        "REFUSED: model {}, the {} measured against {against} (max error \
                         {e:.2e} %, budget {budget_pct} %)",
                        v.name,
                        if accurate {
                            "variant within the accuracy budget with the shortest control step"
                        } else {
                            "most accurate variant (NONE meets the accuracy budget)"
                        }
                    )?,
                    _ => write!(
                        f,
                        "REFUSED: model {kind:?} (the scene's own, default knob, not in the \
                         measured table)"
                    )?,
                }
                let p = self.period;
                let step = p.step_longest.unwrap_or(0);
                return write!(
                    f,
                    "; period budget {} instructions ({} at {} Hz): its control step, up to {} \
                     instructions, exceeds it by {} instructions",
                    Thousands(p.budget),
                    p.board,
                    Hz(p.rate_hz),
                    Thousands(step),
                    Thousands(step.saturating_sub(p.budget))
                );
            }
        }
        self.period.fmt(f)?;
        if let Some(parts) = self.parts {
            write!(f, "; {parts}")?;
        }
        Ok(())
    }
}

/// A count with thousands separators (`12,500`).
struct Thousands(u32);

impl fmt::Display for Thousands {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.0;
        if n >= 1_000_000 {
            write!(
                f,
                "{},{:03},{:03}",
                n / 1_000_000,
                n / 1000 % 1000,
                n % 1000
            )
        } else if n >= 1000 {
            write!(f, "{},{:03}", n / 1000, n % 1000)
        } else {
            write!(f, "{n}")
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Thousands {
    fn format(&self, f: defmt::Formatter) {
        let n = self.0;
        if n >= 1_000_000 {
            defmt::write!(
                f,
                "{=u32},{=u32:03},{=u32:03}",
                n / 1_000_000,
                n / 1000 % 1000,
                n % 1000
            )
        } else if n >= 1000 {
            defmt::write!(f, "{=u32},{=u32:03}", n / 1000, n % 1000)
        } else {
            defmt::write!(f, "{=u32}", n)
        }
    }
}

/// A control rate in whole hertz (the scene loader keeps it in 1e3 ..= 1e5).
struct Hz(u32);

impl fmt::Display for Hz {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Hz {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=u32}", self.0)
    }
}

impl fmt::Display for Period {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "; period budget {} instructions ({}), control step ",
            Thousands(self.budget),
            self.board
        )?;
        match self.step_longest {
            Some(step) => write!(f, "up to {} instructions", Thousands(step)),
            None => f.write_str("not measured"),
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Period {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "; period budget {} instructions ({=str}), control step ",
            Thousands(self.budget),
            self.board
        );
        match self.step_longest {
            Some(step) => defmt::write!(f, "up to {} instructions", Thousands(step)),
            None => defmt::write!(f, "not measured"),
        }
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
            Reason::NotMeasured { kind } => defmt::write!(
                f,
                "model {} (the scene's own, default knob): not in the measured table",
                kind
            ),
            Reason::Overruns {
                error_pct,
                budget_pct,
                accurate,
                kind,
            } => {
                match (self.variant, error_pct) {
                    (Some(v), Some(e)) => defmt::write!(
                        f,
                        "REFUSED: model {=str}, the {=str} measured against {=str} (max error {=f32} %, budget {=f32} %)",
                        v.name,
                        if accurate {
                            "variant within the accuracy budget with the shortest control step"
                        } else {
                            "most accurate variant (NONE meets the accuracy budget)"
                        },
                        against,
                        e,
                        budget_pct
                    ),
                    _ => defmt::write!(
                        f,
                        "REFUSED: model {} (the scene's own, default knob, not in the measured table)",
                        kind
                    ),
                }
                let p = self.period;
                let step = p.step_longest.unwrap_or(0);
                defmt::write!(
                    f,
                    "; period budget {} instructions ({=str} at {} Hz): its control step, up to {} instructions, exceeds it by {} instructions",
                    Thousands(p.budget),
                    p.board,
                    Hz(p.rate_hz),
                    Thousands(step),
                    Thousands(step.saturating_sub(p.budget))
                );
                return;
            }
        }
        defmt::write!(f, "{}", self.period);
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
