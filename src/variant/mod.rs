//! Model variants for the speed-versus-accuracy trade (issue 7): every way the friction model
//! can be evaluated, what each costs and how accurate it is, and the choice of the cheapest
//! adequate one for a scene.
//!
//! A [`Variant`] is a fidelity level ([`Fidelity`]: the Littmann closed form, one exact Dahl
//! update, the Coulomb model, the Dahl steady state, the cube model with elastic or
//! elastic-plastic contact) in a numeric form ([`Form`]: the project's fixed point, `f32` with
//! `micromath`'s fast approximations, `f32` with `libm`, `f64` with `libm`) with its knobs (the
//! quadrature points of the Dahl and cube averages; for the cube models, the size of a table
//! of F'/F over (ln load, amplitude) interpolated instead of evaluating the quadrature,
//! [`crate::model::cube_table`]). [`CATALOGUE`] lists every variant the
//! measurement covers; [`Model`] and [`Kernel`] evaluate one.
//!
//! - The fixed-point forms are the models of [`crate::model`], built as the controller builds
//!   them ([`fixed`]); they are the only ones a scene can select ([`select`]): the controller's
//!   model interface is fixed point, and the project keeps floats out of the control step.
//! - The float forms ([`float_inplane`], [`float_cube`]) run the same algorithm (same closed
//!   forms, same quadrature rule and node count) with the same scene constants folded in `f64`
//!   at scene load, so that the difference between forms is the arithmetic and the maths
//!   library alone. They are measured to publish the trade, not used by the firmware.
//!
//! The measurement itself (errors against the independent `f64` reference, host timings, the
//! instruction counts from the QEMU benchmark build) is the host tool's `sonolube speed`
//! (`host-tests/src/speed`, driven by `scripts/speed-table`); it writes [`table`], the measured
//! data [`select`] chooses from. [`grid`] holds the operating points both sides use.

pub mod budget;
pub mod fixed;
pub mod float_cube;
pub mod float_inplane;
pub mod gauss;
pub mod grid;
pub mod model;
pub mod real;
pub mod select;
pub mod table;

pub use model::{Kernel, Model};
pub use select::{Parts, Reason, Selection, select};

/// What is modelled: the fidelity level of a variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fidelity {
    /// The Littmann law mu_i(zeta) alone (seed 001 eq 1): a kernel, input zeta.
    Littmann,
    /// One exact Dahl update f' = s + (f - s) e^(-kappa |dx|) (physics-notes §2): a kernel,
    /// inputs f, direction and travel.
    DahlUpdate,
    /// The Coulomb model's friction ratio |mu_i(v / v_a)| at an operating point (seed 003
    /// eqs 1-4): the controller's default model.
    Coulomb,
    /// The Dahl model's periodic steady state (seed 003 eqs 5-7, physics-notes §2), alpha = 1.
    DahlSteady,
    /// The cube model (seed 000 eq 15) on the purely elastic contact (seed 001 eqs 11-14).
    CubeElastic,
    /// The cube model on the elastic-plastic contact (seed 000 eqs 1-8).
    CubeElasticPlastic,
}

/// Which evaluations share an operating grid and a reference: the model families.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Family {
    /// Kernels: evaluated on their own input grids, not at a scene's operating points.
    Kernel,
    /// Vibration in the sliding plane, contact not re-evaluated: Coulomb and Dahl.
    InPlane,
    /// Vibration normal to the contact: the cube models (contact re-evaluated over the cycle).
    Cube,
}

impl Fidelity {
    /// The family the level belongs to.
    pub const fn family(self) -> Family {
        match self {
            Fidelity::Littmann | Fidelity::DahlUpdate => Family::Kernel,
            Fidelity::Coulomb | Fidelity::DahlSteady => Family::InPlane,
            Fidelity::CubeElastic | Fidelity::CubeElasticPlastic => Family::Cube,
        }
    }

    /// Short name, as in the variant names and the table.
    pub const fn name(self) -> &'static str {
        match self {
            Fidelity::Littmann => "Littmann closed form",
            Fidelity::DahlUpdate => "Dahl update",
            Fidelity::Coulomb => "Coulomb ratio",
            Fidelity::DahlSteady => "Dahl steady",
            Fidelity::CubeElastic => "cube el",
            Fidelity::CubeElasticPlastic => "cube ep",
        }
    }
}

/// The arithmetic a variant runs in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Form {
    /// The project's fixed point (`crate::fx` Q formats, `crate::model`).
    Fixed,
    /// `f32` with `micromath`'s approximations of asin, exp, ln, sin, cos and sqrt.
    F32Micromath,
    /// `f32` with `libm` (correctly rounded or nearly so).
    F32Libm,
    /// `f64` with `libm`: the float reference form (software floating point on a Cortex-M4F).
    F64,
}

impl Form {
    /// Suffix of variant names in this form (empty for fixed point).
    pub const fn suffix(self) -> &'static str {
        match self {
            Form::Fixed => "",
            Form::F32Micromath => " f32 micromath",
            Form::F32Libm => " f32 libm",
            Form::F64 => " f64",
        }
    }

    /// Description for reports.
    pub const fn describe(self) -> &'static str {
        match self {
            Form::Fixed => "fixed point",
            Form::F32Micromath => "f32 micromath",
            Form::F32Libm => "f32 libm",
            Form::F64 => "f64 libm",
        }
    }
}

/// One way to evaluate the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Variant {
    /// Unique name, the first column of the table: the fidelity's name, ` N=<points>` when it
    /// has a quadrature, then the form's suffix (`cube ep N=16`, `Coulomb ratio f32 libm`).
    pub name: &'static str,
    /// What is modelled.
    pub fidelity: Fidelity,
    /// The arithmetic.
    pub form: Form,
    /// Quadrature points per average (Dahl: nodes per period, even, 4..=4096; cube: points of
    /// the Gauss-Legendre rule over the slip half-period, 1..=64); 0 where there is none. For
    /// a table variant, the quadrature its nodes are computed with.
    pub points: u16,
    /// Nodes per axis of a table: for the cube models, of F'/F over (ln load, amplitude) built
    /// at scene start and interpolated bilinearly ([`crate::model::cube_table`]: 5, 9 or 17);
    /// for the Dahl steady state, of F_avg / (mu W) over (mu_i(zeta), ln kappa x_a) compiled
    /// into flash from the f64 reference and interpolated bicubically
    /// ([`crate::model::dahl_table`]: 49 nodes in w by 73 in log2 kappa x_a, alpha = 1). Fixed point only; 0 for a variant
    /// that evaluates its model directly.
    pub table: u8,
}

#[cfg(feature = "defmt")]
impl defmt::Format for Variant {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=str}", self.name)
    }
}

macro_rules! variants {
    ($($name:literal => $fidelity:ident, $form:ident, $points:literal $(, T $table:literal)?;)*) => {
        &[$(Variant {
            name: $name,
            fidelity: Fidelity::$fidelity,
            form: Form::$form,
            points: $points,
            table: 0 $(+ $table)?,
        }),*]
    };
}

/// Every variant the measurement covers, kernels first, then by fidelity, knob and form.
/// The names are checked against their fields by a test.
pub const CATALOGUE: &[Variant] = variants! {
    "Littmann closed form" => Littmann, Fixed, 0;
    "Littmann closed form f32 micromath" => Littmann, F32Micromath, 0;
    "Littmann closed form f32 libm" => Littmann, F32Libm, 0;
    "Littmann closed form f64" => Littmann, F64, 0;
    "Dahl update" => DahlUpdate, Fixed, 0;
    "Dahl update f32 micromath" => DahlUpdate, F32Micromath, 0;
    "Dahl update f32 libm" => DahlUpdate, F32Libm, 0;
    "Dahl update f64" => DahlUpdate, F64, 0;
    "Coulomb ratio" => Coulomb, Fixed, 0;
    "Coulomb ratio f32 micromath" => Coulomb, F32Micromath, 0;
    "Coulomb ratio f32 libm" => Coulomb, F32Libm, 0;
    "Coulomb ratio f64" => Coulomb, F64, 0;
    "Dahl steady N=16" => DahlSteady, Fixed, 16;
    "Dahl steady N=16 f32 micromath" => DahlSteady, F32Micromath, 16;
    "Dahl steady N=16 f32 libm" => DahlSteady, F32Libm, 16;
    "Dahl steady N=16 f64" => DahlSteady, F64, 16;
    "Dahl steady N=32" => DahlSteady, Fixed, 32;
    "Dahl steady N=32 f32 micromath" => DahlSteady, F32Micromath, 32;
    "Dahl steady N=32 f32 libm" => DahlSteady, F32Libm, 32;
    "Dahl steady N=32 f64" => DahlSteady, F64, 32;
    "Dahl steady N=64" => DahlSteady, Fixed, 64;
    "Dahl steady N=64 f32 micromath" => DahlSteady, F32Micromath, 64;
    "Dahl steady N=64 f32 libm" => DahlSteady, F32Libm, 64;
    "Dahl steady N=64 f64" => DahlSteady, F64, 64;
    "Dahl steady T=49x73" => DahlSteady, Fixed, 64, T 49;
    "cube el N=4" => CubeElastic, Fixed, 4;
    "cube el N=4 f32 micromath" => CubeElastic, F32Micromath, 4;
    "cube el N=4 f32 libm" => CubeElastic, F32Libm, 4;
    "cube el N=4 f64" => CubeElastic, F64, 4;
    "cube el N=8" => CubeElastic, Fixed, 8;
    "cube el N=8 f32 micromath" => CubeElastic, F32Micromath, 8;
    "cube el N=8 f32 libm" => CubeElastic, F32Libm, 8;
    "cube el N=8 f64" => CubeElastic, F64, 8;
    "cube el N=16" => CubeElastic, Fixed, 16;
    "cube el N=16 f32 micromath" => CubeElastic, F32Micromath, 16;
    "cube el N=16 f32 libm" => CubeElastic, F32Libm, 16;
    "cube el N=16 f64" => CubeElastic, F64, 16;
    "cube el N=32" => CubeElastic, Fixed, 32;
    "cube el N=32 f32 micromath" => CubeElastic, F32Micromath, 32;
    "cube el N=32 f32 libm" => CubeElastic, F32Libm, 32;
    "cube el N=32 f64" => CubeElastic, F64, 32;
    "cube el T=5x5" => CubeElastic, Fixed, 16, T 5;
    "cube el T=9x9" => CubeElastic, Fixed, 16, T 9;
    "cube el T=17x17" => CubeElastic, Fixed, 16, T 17;
    "cube ep N=4" => CubeElasticPlastic, Fixed, 4;
    "cube ep N=4 f32 micromath" => CubeElasticPlastic, F32Micromath, 4;
    "cube ep N=4 f32 libm" => CubeElasticPlastic, F32Libm, 4;
    "cube ep N=4 f64" => CubeElasticPlastic, F64, 4;
    "cube ep N=8" => CubeElasticPlastic, Fixed, 8;
    "cube ep N=8 f32 micromath" => CubeElasticPlastic, F32Micromath, 8;
    "cube ep N=8 f32 libm" => CubeElasticPlastic, F32Libm, 8;
    "cube ep N=8 f64" => CubeElasticPlastic, F64, 8;
    "cube ep N=16" => CubeElasticPlastic, Fixed, 16;
    "cube ep N=16 f32 micromath" => CubeElasticPlastic, F32Micromath, 16;
    "cube ep N=16 f32 libm" => CubeElasticPlastic, F32Libm, 16;
    "cube ep N=16 f64" => CubeElasticPlastic, F64, 16;
    "cube ep N=32" => CubeElasticPlastic, Fixed, 32;
    "cube ep N=32 f32 micromath" => CubeElasticPlastic, F32Micromath, 32;
    "cube ep N=32 f32 libm" => CubeElasticPlastic, F32Libm, 32;
    "cube ep N=32 f64" => CubeElasticPlastic, F64, 32;
    "cube ep T=5x5" => CubeElasticPlastic, Fixed, 16, T 5;
    "cube ep T=9x9" => CubeElasticPlastic, Fixed, 16, T 9;
    "cube ep T=17x17" => CubeElasticPlastic, Fixed, 16, T 17;
};

/// The variant named `name`, if catalogued.
pub fn find(name: &str) -> Option<&'static Variant> {
    CATALOGUE.iter().find(|variant| variant.name == name)
}

/// The variant of `fidelity` in `form` with `points` quadrature points evaluated directly (no
/// table), if catalogued.
pub fn lookup(fidelity: Fidelity, form: Form, points: u16) -> Option<&'static Variant> {
    CATALOGUE
        .iter()
        .find(|v| v.fidelity == fidelity && v.form == form && v.points == points && v.table == 0)
}

/// The table variant of `fidelity` with `side` nodes per axis, if catalogued.
pub fn lookup_table(fidelity: Fidelity, side: u8) -> Option<&'static Variant> {
    CATALOGUE
        .iter()
        .find(|v| v.fidelity == fidelity && v.table == side && side > 0)
}

impl Variant {
    /// The `f64` variant of the same fidelity and quadrature, evaluated directly: the
    /// denominator of the host time ratio (for a table variant, the `f64` form of the exact
    /// model its table is built from).
    pub fn f64_twin(&self) -> Option<&'static Variant> {
        lookup(self.fidelity, Form::F64, self.points)
    }

    /// The form for reports: the numeric form, and whether the model is tabulated.
    pub const fn form_name(&self) -> &'static str {
        if self.table > 0 {
            "fixed point table"
        } else {
            self.form.describe()
        }
    }
}

/// Names of the control-step measurements of the QEMU benchmark build, one per fidelity level
/// the controller can run, with the scene each is timed on, the fidelity, and the table side
/// (nodes per axis; 0: the fidelity's model at the knob `crate::model::AnyModel::new` uses,
/// Dahl N = 64, cube N = 16; otherwise the table variant of that side, [`lookup_table`]). The
/// first is the default fidelity (the `reference` scene's Coulomb controller).
pub const CONTROL_STEPS: &[(&str, &str, Fidelity, u8)] = &[
    ("control step", "reference", Fidelity::Coulomb, 0),
    (
        "control step Dahl steady N=64",
        "reference",
        Fidelity::DahlSteady,
        0,
    ),
    (
        "control step Dahl steady T=49x73",
        "compliant",
        Fidelity::DahlSteady,
        49,
    ),
    (
        "control step cube el N=16",
        "load-ramp",
        Fidelity::CubeElastic,
        0,
    ),
    (
        "control step cube ep N=16",
        "load-ramp",
        Fidelity::CubeElasticPlastic,
        0,
    ),
    (
        "control step cube ep T=17x17",
        "load-ramp",
        Fidelity::CubeElasticPlastic,
        17,
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_say_what_the_variant_is() {
        for (i, v) in CATALOGUE.iter().enumerate() {
            // A table's knob names both sides: the Dahl table's second axis (log2 kappa x_a,
            // SIDE_Y nodes) is not its first (w, SIDE_W); the cube tables are square.
            let knob = if v.table > 0 && v.fidelity == Fidelity::DahlSteady {
                assert_eq!(v.table as usize, crate::model::dahl_table::SIDE_W);
                format!(" T={}x{}", v.table, crate::model::dahl_table::SIDE_Y)
            } else if v.table > 0 {
                format!(" T={}x{}", v.table, v.table)
            } else if v.points > 0 {
                format!(" N={}", v.points)
            } else {
                String::new()
            };
            let want = format!("{}{}{}", v.fidelity.name(), knob, v.form.suffix());
            assert_eq!(v.name, want);
            assert!(CATALOGUE[..i].iter().all(|w| w.name != v.name));
            assert_eq!(find(v.name), Some(v));
            if v.table > 0 {
                assert_eq!(lookup_table(v.fidelity, v.table), Some(v));
                assert_eq!(v.form, Form::Fixed, "{}: tables are fixed point", v.name);
            } else {
                assert_eq!(lookup(v.fidelity, v.form, v.points), Some(v));
            }
        }
        // The named rows exist.
        for name in ["Littmann closed form", "Dahl update", "cube ep N=16"] {
            assert_eq!(find(name).map(|v| v.form), Some(Form::Fixed), "{name}");
        }
        assert!(find("cube ep N=17").is_none());
        assert!(lookup_table(Fidelity::CubeElasticPlastic, 0).is_none());
    }

    #[test]
    fn every_variant_has_its_f64_twin_and_every_fidelity_every_form() {
        for v in CATALOGUE {
            let twin = v.f64_twin().expect(v.name);
            assert_eq!((twin.fidelity, twin.points), (v.fidelity, v.points));
            assert_eq!(twin.table, 0);
            if v.table > 0 {
                // Tables exist in fixed point only: the controller's form (a float table
                // would measure the same interpolation in other arithmetic), for the model
                // levels only.
                assert_ne!(v.fidelity.family(), Family::Kernel, "{}", v.name);
                continue;
            }
            for form in [Form::Fixed, Form::F32Micromath, Form::F32Libm, Form::F64] {
                assert!(lookup(v.fidelity, form, v.points).is_some(), "{}", v.name);
            }
        }
    }
}
