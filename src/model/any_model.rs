//! A scene's model spec turned into a concrete friction model.
//!
//! [`AnyModel`] holds one of the concrete models of [`crate::model`], built from a
//! [`ModelSpec`] and the scene's hardware (full-scale amplitude, frequency, horn), and
//! dispatches [`FrictionModel`] to it. The plant builds one from the scene's plant spec; a
//! controller can build one from the controller spec the same way.

use crate::fx::{Q1_31, Q2_30};
#[cfg(feature = "cube")]
use crate::model::contact::ContactKind;
use crate::model::contact::ContactParams;
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::contact::EStarRule;
use crate::model::coulomb::{CoulombConstants, CoulombModel};
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::cube::{CubeOptions, CubeParams};
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::cube_model::CubeModel;
#[cfg(feature = "cube")]
use crate::model::cube_table::CubeTable;
#[cfg(feature = "dahl")]
use crate::model::dahl::DahlParams;
#[cfg(feature = "dahl")]
use crate::model::dahl_steady::DahlModel;
#[cfg(feature = "dahl")]
use crate::model::dahl_table::DahlTable;
#[cfg(feature = "exp-coulomb")]
use crate::model::exp_average::ExpCoulombVibrated;
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::horn::UPhase;
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::quadrature::SlipWindow;
use crate::model::{FrictionModel, Inversion, ModelError, OperatingPoint};
use crate::scene::{ModelKind, ModelSpec, RoughSurface, Scene};

/// Quadrature points of the cube models: the model's default (16 points, the controller's
/// cost budget, README of `crate::model`).
pub const CUBE_QUADRATURE_POINTS: usize = crate::model::cube::DEFAULT_QUADRATURE_POINTS;

/// Quadrature nodes per period of the Dahl steady state (the gap integral; the Coulomb part
/// is exact).
pub const DAHL_QUADRATURE_POINTS: u32 = 64;

/// One of the concrete friction models. The cube variant carries its quadrature tables (about
/// 1 KB), the tabulated cube its exact model and a fixed-capacity table of 17 x 17 Q2.30 nodes
/// (1,156 bytes, whatever the table size: [`crate::model::cube_table`]), which makes the enum
/// about 2.2 KB (a test pins it); there is no heap to box it into, and a plant or
/// controller holds one model.
///
/// ```
/// use sonolube::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
/// use sonolube::model::{AnyModel, FrictionModel, OperatingPoint};
///
/// // The reference scene's plant: a Dahl contact (mu 0.24, k_t 2e7 N/m) at 40 kHz.
/// let scene = sonolube::scene::find("reference").expect("built in");
/// let plant = AnyModel::new(scene, &scene.plant)?;
/// assert_eq!(plant.kind(), scene.plant.kind);
/// let point = OperatingPoint {
///     normal_force: Q16_16::from_f64(4.155)?,
///     sliding_velocity: Q8_24::from_f64(0.038)?,
/// };
/// assert_eq!(plant.ratio(&point, Q1_31::ZERO)?, Q2_30::ONE);
/// // The f64 reference (host-tests) gives 0.214808 at full amplitude.
/// let full = plant.ratio(&point, Q1_31::MAX)?.to_f64();
/// assert!((full - 0.214_808).abs() < 5e-4, "{full}");
///
/// // The load-ramp scene's plant: the elastic-plastic cube model (Al horn on SS, 40 N),
/// // 0.4806 in the reference at 0.005 m/s and full amplitude.
/// let horn = sonolube::scene::find("load-ramp").expect("built in");
/// let cube = AnyModel::new(horn, &horn.plant)?;
/// let point = OperatingPoint {
///     normal_force: Q16_16::from_f64(40.0)?,
///     sliding_velocity: Q8_24::from_f64(0.005)?,
/// };
/// let full = cube.ratio(&point, Q1_31::MAX)?.to_f64();
/// assert!((full - 0.4806).abs() < 2e-3, "{full}");
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum AnyModel {
    /// Littmann law on a Coulomb contact ([`ModelKind::Coulomb`]).
    Coulomb(CoulombModel),
    /// Exponential Coulomb law averaged over the vibration ([`ModelKind::ExpCoulomb`]).
    #[cfg(feature = "exp-coulomb")]
    ExpCoulomb(ExpCoulombVibrated),
    /// Dahl contact in its periodic steady state ([`ModelKind::Dahl`]).
    #[cfg(feature = "dahl")]
    Dahl(DahlModel),
    /// Cube model, elastic or elastic-plastic contact ([`ModelKind::CubeElastic`],
    /// [`ModelKind::CubeElasticPlastic`]). Not in a bare-metal build without the cargo feature
    /// `cube-exact`, whose cube scenes run their tables from flash alone.
    #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
    Cube(CubeModel),
    /// Cube model tabulated over (ln load, amplitude) and interpolated, with its exact model for
    /// loads outside the table (a model variant only: no scene kind names it;
    /// `crate::variant::select` chooses it).
    #[cfg(feature = "cube")]
    CubeTable(CubeTable),
    /// Dahl steady state interpolated in a table compiled into flash (a model variant only,
    /// chosen by `crate::variant::select`; [`crate::model::dahl_table`]).
    #[cfg(feature = "dahl")]
    DahlTable(DahlTable),
}

impl AnyModel {
    /// The model of `spec` (the scene's controller or plant spec) with the scene's hardware:
    /// vibration amplitude at full command and drive frequency, and for the cube models the
    /// horn (A = the actuator's full-scale amplitude, B, x, L). The project's default variants
    /// are used: seed 000's E* rule, the surfaces-apart slip window, in-phase u, 16 points.
    ///
    /// Errors: the model's own validation, or `OutOfDomain` for a spec that lacks what its
    /// kind needs (the scene loader never lets one through).
    pub fn new(scene: &Scene<'_>, spec: &ModelSpec) -> Result<Self, ModelError> {
        let frequency_hz = scene.transducer.drive_hz;
        let amplitude_m = scene.actuator.full_scale_amplitude_m;
        match spec.kind {
            ModelKind::Coulomb => Ok(AnyModel::Coulomb(CoulombModel {
                constants: CoulombConstants::new(spec.mu, frequency_hz, amplitude_m)?,
            })),
            #[cfg(feature = "exp-coulomb")]
            ModelKind::ExpCoulomb => Ok(AnyModel::ExpCoulomb(ExpCoulombVibrated::new(
                spec.mu_static.ok_or(missing("mu_s"))?,
                spec.mu,
                spec.decay_s_per_m.ok_or(missing("alpha_dc"))?,
                core::f64::consts::TAU * frequency_hz * amplitude_m,
            )?)),
            #[cfg(feature = "dahl")]
            ModelKind::Dahl => Ok(AnyModel::Dahl(DahlModel::new(&DahlParams {
                friction_coefficient: spec.mu,
                tangential_stiffness: spec.k_t_n_per_m.ok_or(missing("k_t"))?,
                frequency_hz,
                full_scale_amplitude_m: amplitude_m,
                shape_exponent: spec.dahl_alpha.unwrap_or(1.0),
                quadrature_points: DAHL_QUADRATURE_POINTS,
            })?)),
            #[cfg(all(
                feature = "cube",
                not(any(feature = "cube-exact", not(target_os = "none")))
            ))]
            ModelKind::CubeElastic | ModelKind::CubeElasticPlastic => {
                Err(ModelError::OutOfDomain {
                    input: "model",
                    reason: "the exact cube model is not in this build (cargo feature `cube-exact`): only the compiled scenes' tables in flash",
                })
            }
            #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
            ModelKind::CubeElastic | ModelKind::CubeElasticPlastic => {
                let horn = scene.horn.ok_or(missing("horn"))?;
                let surface = spec.surface.ok_or(missing("surface"))?;
                let params = CubeParams {
                    contact: contact_params(&surface),
                    friction_coefficient: spec.mu,
                    longitudinal_amplitude: amplitude_m,
                    vertical_amplitude: horn.vertical_amplitude_m,
                    position: horn.contact_position_m,
                    horn_length: horn.length_m,
                    frequency: frequency_hz,
                };
                let options = CubeOptions {
                    e_star_rule: EStarRule::Seed000,
                    contact_kind: if spec.kind == ModelKind::CubeElastic {
                        ContactKind::Elastic
                    } else {
                        ContactKind::ElasticPlastic
                    },
                    window: SlipWindow::SurfacesApart,
                    u_phase: UPhase::InPhase,
                    quadrature_points: CUBE_QUADRATURE_POINTS,
                };
                Ok(AnyModel::Cube(CubeModel::new(&params, &options)?))
            }
            #[allow(unreachable_patterns)]
            kind => Err(not_compiled(kind)),
        }
    }

    /// Which kind of model this is.
    pub fn kind(&self) -> ModelKind {
        match self {
            AnyModel::Coulomb(_) => ModelKind::Coulomb,
            #[cfg(feature = "exp-coulomb")]
            AnyModel::ExpCoulomb(_) => ModelKind::ExpCoulomb,
            #[cfg(feature = "dahl")]
            AnyModel::Dahl(_) | AnyModel::DahlTable(_) => ModelKind::Dahl,
            #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
            AnyModel::Cube(model) => cube_kind(model.scene().contact().scene().kind),
            #[cfg(feature = "cube")]
            AnyModel::CubeTable(table) => cube_kind(table.contact_kind()),
        }
    }
}

impl FrictionModel for AnyModel {
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        match self {
            AnyModel::Coulomb(model) => model.ratio(point, amplitude),
            #[cfg(feature = "exp-coulomb")]
            AnyModel::ExpCoulomb(model) => model.ratio(point, amplitude),
            #[cfg(feature = "dahl")]
            AnyModel::Dahl(model) => model.ratio(point, amplitude),
            #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
            AnyModel::Cube(model) => model.ratio(point, amplitude),
            #[cfg(feature = "cube")]
            AnyModel::CubeTable(model) => model.ratio(point, amplitude),
            #[cfg(feature = "dahl")]
            AnyModel::DahlTable(model) => model.ratio(point, amplitude),
        }
    }

    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        match self {
            AnyModel::Coulomb(model) => model.invert(point, target),
            #[cfg(feature = "exp-coulomb")]
            AnyModel::ExpCoulomb(model) => model.invert(point, target),
            #[cfg(feature = "dahl")]
            AnyModel::Dahl(model) => model.invert(point, target),
            #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
            AnyModel::Cube(model) => model.invert(point, target),
            #[cfg(feature = "cube")]
            AnyModel::CubeTable(model) => model.invert(point, target),
            #[cfg(feature = "dahl")]
            AnyModel::DahlTable(model) => model.invert(point, target),
        }
    }

    fn invert_from(
        &self,
        point: &OperatingPoint,
        target: Q2_30,
        start: Q1_31,
    ) -> Result<Inversion, ModelError> {
        match self {
            AnyModel::Coulomb(model) => model.invert_from(point, target, start),
            #[cfg(feature = "exp-coulomb")]
            AnyModel::ExpCoulomb(model) => model.invert_from(point, target, start),
            #[cfg(feature = "dahl")]
            AnyModel::Dahl(model) => model.invert_from(point, target, start),
            #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
            AnyModel::Cube(model) => model.invert_from(point, target, start),
            #[cfg(feature = "cube")]
            AnyModel::CubeTable(model) => model.invert_from(point, target, start),
            #[cfg(feature = "dahl")]
            AnyModel::DahlTable(model) => model.invert_from(point, target, start),
        }
    }

    fn load_enters_as_coulomb_force(&self) -> bool {
        match self {
            AnyModel::Coulomb(model) => model.load_enters_as_coulomb_force(),
            #[cfg(feature = "exp-coulomb")]
            AnyModel::ExpCoulomb(model) => model.load_enters_as_coulomb_force(),
            #[cfg(feature = "dahl")]
            AnyModel::Dahl(model) => model.load_enters_as_coulomb_force(),
            #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
            AnyModel::Cube(model) => model.load_enters_as_coulomb_force(),
            #[cfg(feature = "cube")]
            AnyModel::CubeTable(model) => model.load_enters_as_coulomb_force(),
            #[cfg(feature = "dahl")]
            AnyModel::DahlTable(model) => model.load_enters_as_coulomb_force(),
        }
    }
}

/// The scene kind of a cube model, from its contact.
#[cfg(feature = "cube")]
fn cube_kind(contact: ContactKind) -> ModelKind {
    match contact {
        ContactKind::Elastic => ModelKind::CubeElastic,
        ContactKind::ElasticPlastic => ModelKind::CubeElasticPlastic,
    }
}

/// The error for a model whose family this build leaves out (the cargo features `dahl`,
/// `cube` and `exp-coulomb` of the core; the built-in scenes of such a build never name one).
pub fn not_compiled(kind: ModelKind) -> ModelError {
    ModelError::OutOfDomain {
        input: "model",
        reason: match kind {
            ModelKind::Dahl => "the Dahl family is not in this build (cargo feature `dahl`)",
            ModelKind::ExpCoulomb => {
                "the exponential Coulomb law is not in this build (cargo feature `exp-coulomb`)"
            }
            ModelKind::CubeElastic | ModelKind::CubeElasticPlastic => {
                "the cube family is not in this build (cargo feature `cube`)"
            }
            ModelKind::Coulomb => "the Coulomb model is in every build",
        },
    }
}

#[cfg(any(
    feature = "dahl",
    all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))),
    feature = "exp-coulomb"
))]
fn missing(input: &'static str) -> ModelError {
    ModelError::OutOfDomain {
        input,
        reason: "the scene's spec lacks what this model needs",
    }
}

/// The contact parameters of a scene's rough surface (same fields, the model's names).
pub fn contact_params(surface: &RoughSurface) -> ContactParams {
    ContactParams {
        roughness_rq: surface.rq_m,
        summit_radius: surface.rs_m,
        nominal_area: surface.nominal_area_m2,
        asperity_density: surface.asperity_density_per_m2,
        distribution_c: surface.distribution_c,
        distribution_lambda: surface.distribution_lambda,
        young_1: surface.young_1_pa,
        poisson_1: surface.poisson_1,
        young_2: surface.young_2_pa,
        poisson_2: surface.poisson_2,
        poisson_soft: surface.poisson_soft,
        yield_strength: surface.yield_strength_pa,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q8_24, Q16_16};
    use crate::scene::{SCENES, find};

    fn point(load_n: f64, speed: f64) -> OperatingPoint {
        OperatingPoint {
            normal_force: Q16_16::from_f64_saturating(load_n).value,
            sliding_velocity: Q8_24::from_f64_saturating(speed).value,
        }
    }

    #[test]
    fn every_scene_spec_builds_its_kind_and_vibration_lowers_friction() {
        for scene in SCENES {
            let at = point(
                scene.normal_load_n[0].value,
                scene.contents.velocity_max_m_per_s,
            );
            for spec in [&scene.controller, &scene.plant] {
                let model = AnyModel::new(scene, spec).expect(scene.name);
                assert_eq!(model.kind(), spec.kind, "{}", scene.name);
                assert_eq!(
                    model.ratio(&at, Q1_31::ZERO),
                    Ok(Q2_30::ONE),
                    "{}",
                    scene.name
                );
                let full = model.ratio(&at, Q1_31::MAX).expect(scene.name);
                assert!(full < Q2_30::ONE, "{}: {full:?}", scene.name);
            }
        }
    }

    #[test]
    fn plant_models_agree_with_the_f64_reference() {
        // Values of the host's f64 reference (host-tests/src/reference) at the scenes' first
        // operating point with full amplitude: dahl_steady (mu 0.24, W 4.155 N, k_t 2e7 N/m,
        // v 0.038 m/s, v_a 0.11953 m/s) 0.214808; cube_reduction elastic-plastic (Al/SS,
        // 40 N, A 11.46 um, B 1.1 um, x = 0) 0.4806.
        let reference = find("reference").expect("built in");
        let dahl = AnyModel::new(reference, &reference.plant).expect("dahl");
        let ratio = dahl.ratio(&point(4.155, 0.038), Q1_31::MAX).expect("ratio");
        assert!((ratio.to_f64() - 0.214_808).abs() < 5e-4, "{ratio:?}");
        let horn = find("load-ramp").expect("built in");
        let cube = AnyModel::new(horn, &horn.plant).expect("cube");
        let ratio = cube.ratio(&point(40.0, 0.005), Q1_31::MAX).expect("ratio");
        assert!((ratio.to_f64() - 0.4806).abs() < 2e-3, "{ratio:?}");
    }

    /// What a plant or controller holds by value: the table's fixed capacity is the bulk.
    #[cfg(feature = "cube")]
    #[test]
    fn size() {
        let size = core::mem::size_of::<AnyModel>();
        let table = core::mem::size_of::<CubeTable>();
        assert!(table >= 4 * crate::model::cube_table::MAX_NODES, "{table}");
        assert!(size <= table + 64, "{size} vs {table}");
        assert!(size <= 2304, "{size}");
    }

    #[test]
    fn a_spec_missing_its_parameters_is_an_error() {
        let reference = find("reference").expect("built in");
        let no_stiffness = ModelSpec {
            k_t_n_per_m: None,
            ..reference.plant
        };
        assert!(AnyModel::new(reference, &no_stiffness).is_err());
        let cube = ModelSpec {
            kind: ModelKind::CubeElastic,
            ..reference.plant
        };
        assert!(AnyModel::new(reference, &cube).is_err());
    }
}
