//! Building a variant's model for a scene: what the controller would run (fixed point, as
//! [`crate::model::AnyModel`]) and the parameters the float forms share with it.
//!
//! Every form takes the scene's *controller* parameters (its belief about mu, k_t and the
//! surface: the mismatch with the plant is the feedback's business, not the model's) and the
//! scene's hardware (drive frequency, full-scale amplitude, horn), with the project's default
//! readings (seed 000's E* rule, the surfaces-apart slip window, an in-phase u). Only the
//! fidelity level and the quadrature knob come from the variant, so a variant of another level
//! than the scene's own controller model can be built whenever the controller spec carries its
//! parameters (the scene schema allows a spec to carry parameters its kind does not use).

use super::float_cube::FloatCubeParams;
use super::{Fidelity, Variant};
use crate::model::AnyModel;
use crate::model::ModelError;
use crate::model::any_model::contact_params;
use crate::model::contact::ContactKind;
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::contact::EStarRule;
use crate::model::coulomb::{CoulombConstants, CoulombModel};
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::cube::{CubeOptions, CubeParams};
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::cube_model::CubeModel;
#[cfg(feature = "cube")]
use crate::model::cube_table::CubeTable;
use crate::model::dahl::DahlParams;
#[cfg(feature = "dahl")]
use crate::model::dahl_steady::DahlModel;
#[cfg(feature = "dahl")]
use crate::model::dahl_table::{DahlGrid, DahlTable};
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::horn::UPhase;
#[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
use crate::model::quadrature::SlipWindow;
use crate::scene::{ModelKind, Scene};

/// What a scene's controller spec lacks for a fidelity level.
fn missing(input: &'static str) -> ModelError {
    ModelError::OutOfDomain {
        input,
        reason: "the scene's controller spec lacks what this fidelity needs",
    }
}

/// Whether the scene's controller spec and hardware carry every parameter of `fidelity`
/// (kernels need none), and this build holds the level's model family
/// ([`crate::scene::in_build`]).
pub fn buildable(scene: &Scene<'_>, fidelity: Fidelity) -> bool {
    match fidelity {
        Fidelity::Littmann | Fidelity::DahlUpdate | Fidelity::Coulomb => true,
        Fidelity::DahlSteady => {
            crate::scene::in_build(ModelKind::Dahl) && scene.controller.k_t_n_per_m.is_some()
        }
        Fidelity::CubeElastic | Fidelity::CubeElasticPlastic => {
            crate::scene::in_build(ModelKind::CubeElasticPlastic)
                && scene.horn.is_some()
                && scene.controller.surface.is_some()
        }
    }
}

/// Whether `variant` can be built for `scene`: [`buildable`] for its level, and for a Dahl
/// table alpha = 1 (the tables in flash are for alpha = 1 only) and a table of that size in
/// this build ([`crate::model::dahl_table::DahlGrid::of_side`]).
pub fn variant_buildable(scene: &Scene<'_>, variant: &Variant) -> bool {
    let dahl_table = variant.fidelity == Fidelity::DahlSteady && variant.table > 0;
    buildable(scene, variant.fidelity)
        && !(dahl_table
            && (scene.controller.dahl_alpha.unwrap_or(1.0) != 1.0
                || crate::model::dahl_table::DahlGrid::of_side(usize::from(variant.table))
                    .is_none()))
}

/// Dahl parameters of the scene's controller at `points` nodes per period.
pub fn dahl_params(scene: &Scene<'_>, points: u32) -> Result<DahlParams, ModelError> {
    let spec = &scene.controller;
    Ok(DahlParams {
        friction_coefficient: spec.mu,
        tangential_stiffness: spec.k_t_n_per_m.ok_or(missing("k_t"))?,
        frequency_hz: scene.transducer.drive_hz,
        full_scale_amplitude_m: scene.actuator.full_scale_amplitude_m,
        shape_exponent: spec.dahl_alpha.unwrap_or(1.0),
        quadrature_points: points,
    })
}

/// The contact model of a cube fidelity (elastic-plastic for anything else).
pub fn contact_kind(fidelity: Fidelity) -> ContactKind {
    if fidelity == Fidelity::CubeElastic {
        ContactKind::Elastic
    } else {
        ContactKind::ElasticPlastic
    }
}

/// Cube parameters of the scene's controller and horn, for `fidelity`'s contact, N points.
pub fn cube_params(
    scene: &Scene<'_>,
    fidelity: Fidelity,
    points: usize,
) -> Result<FloatCubeParams, ModelError> {
    let horn = scene.horn.ok_or(missing("horn"))?;
    let surface = scene.controller.surface.ok_or(missing("surface"))?;
    Ok(FloatCubeParams {
        contact: contact_params(&surface),
        contact_kind: contact_kind(fidelity),
        friction_coefficient: scene.controller.mu,
        longitudinal_amplitude: scene.actuator.full_scale_amplitude_m,
        vertical_amplitude: horn.vertical_amplitude_m,
        position: horn.contact_position_m,
        horn_length: horn.length_m,
        points,
    })
}

/// The fixed-point model of a model-level `variant` (Coulomb, Dahl steady, cube, tabulated
/// cube over the scene's `contents.load_range_n`) for `scene`, as the controller runs it.
/// Errors: a kernel variant (`OutOfDomain` on "variant"), the spec lacking the level's
/// parameters, or the model's own validation.
pub fn fixed_model(scene: &Scene<'_>, variant: &Variant) -> Result<AnyModel, ModelError> {
    let frequency_hz = scene.transducer.drive_hz;
    let amplitude_m = scene.actuator.full_scale_amplitude_m;
    match variant.fidelity {
        Fidelity::Littmann | Fidelity::DahlUpdate => Err(ModelError::OutOfDomain {
            input: "variant",
            reason: "a kernel, not a friction model",
        }),
        Fidelity::Coulomb => Ok(AnyModel::Coulomb(CoulombModel {
            constants: CoulombConstants::new(scene.controller.mu, frequency_hz, amplitude_m)?,
        })),
        #[cfg(feature = "dahl")]
        Fidelity::DahlSteady if variant.table > 0 => {
            let grid =
                DahlGrid::of_side(usize::from(variant.table)).ok_or(ModelError::OutOfDomain {
                    input: "variant",
                    reason: "no Dahl table of this size",
                })?;
            Ok(AnyModel::DahlTable(DahlTable::new(
                &dahl_params(scene, u32::from(variant.points))?,
                grid,
            )?))
        }
        #[cfg(feature = "dahl")]
        Fidelity::DahlSteady => Ok(AnyModel::Dahl(DahlModel::new(&dahl_params(
            scene,
            u32::from(variant.points),
        )?)?)),
        #[cfg(not(feature = "dahl"))]
        Fidelity::DahlSteady => Err(crate::model::any_model::not_compiled(ModelKind::Dahl)),
        #[cfg(not(feature = "cube"))]
        Fidelity::CubeElastic | Fidelity::CubeElasticPlastic => Err(
            crate::model::any_model::not_compiled(ModelKind::CubeElasticPlastic),
        ),
        // A bare-metal build without the exact cube model (cargo feature `cube-exact`): the
        // compiled scenes' tables from flash alone, no f64 contact setup at scene start.
        #[cfg(all(
            feature = "cube",
            not(any(feature = "cube-exact", not(target_os = "none")))
        ))]
        Fidelity::CubeElastic | Fidelity::CubeElasticPlastic => {
            let nodes = crate::scene::cube_table_nodes(scene, variant.name)
                .filter(|_| variant.table > 0)
                .ok_or(ModelError::OutOfDomain {
                    input: "variant",
                    reason: "the exact cube model is not in this build (cargo feature `cube-exact`): only the compiled scenes' tables in flash",
                })?;
            let range = (scene.contents.load_min_n, scene.contents.load_max_n);
            Ok(AnyModel::CubeTable(CubeTable::from_flash(
                contact_kind(variant.fidelity),
                range,
                usize::from(variant.table),
                nodes,
            )?))
        }
        #[cfg(all(feature = "cube", any(feature = "cube-exact", not(target_os = "none"))))]
        Fidelity::CubeElastic | Fidelity::CubeElasticPlastic => {
            let p = cube_params(scene, variant.fidelity, usize::from(variant.points))?;
            let params = CubeParams {
                contact: p.contact,
                friction_coefficient: p.friction_coefficient,
                longitudinal_amplitude: p.longitudinal_amplitude,
                vertical_amplitude: p.vertical_amplitude,
                position: p.position,
                horn_length: p.horn_length,
                frequency: frequency_hz,
            };
            let options = CubeOptions {
                e_star_rule: EStarRule::Seed000,
                contact_kind: p.contact_kind,
                window: SlipWindow::SurfacesApart,
                u_phase: UPhase::InPhase,
                quadrature_points: p.points,
            };
            let exact = CubeModel::new(&params, &options)?;
            if variant.table == 0 {
                return Ok(AnyModel::Cube(exact));
            }
            // The table covers the load range the scene states it contains (widened by the
            // table's margin); loads outside it run `exact`. A compiled scene's table is in
            // flash (the build script built it, `crate::scene::cube_table_nodes`); a scene
            // loaded at run time builds it here.
            let range = (scene.contents.load_min_n, scene.contents.load_max_n);
            let side = usize::from(variant.table);
            let table = match crate::scene::cube_table_nodes(scene, variant.name) {
                Some(nodes) => CubeTable::with_nodes(exact, range, side, nodes)?,
                None => CubeTable::new(exact, range, side)?,
            };
            Ok(AnyModel::CubeTable(table))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
    use crate::model::{FrictionModel, OperatingPoint};
    use crate::scene::{ModelKind, ModelSpec, find};
    use crate::variant::find as variant;

    fn point(load: f64, v: f64) -> OperatingPoint {
        OperatingPoint {
            normal_force: Q16_16::from_f64(load).unwrap(),
            sliding_velocity: Q8_24::from_f64(v).unwrap(),
        }
    }

    /// At the scene's own kind and the default knobs, the variant's model is exactly the one
    /// `AnyModel::new` builds for the controller.
    #[test]
    fn default_knobs_give_the_controllers_own_model() {
        let reference = find("reference").unwrap();
        let own = AnyModel::new(reference, &reference.controller).unwrap();
        let built = fixed_model(reference, variant("Coulomb ratio").unwrap()).unwrap();
        assert_eq!(own, built);
        let horn = find("load-ramp").unwrap();
        let own = AnyModel::new(horn, &horn.controller).unwrap();
        assert_eq!(
            own,
            fixed_model(horn, variant("cube el N=16").unwrap()).unwrap()
        );
        let dahl_scene = Scene {
            controller: ModelSpec {
                kind: ModelKind::Dahl,
                ..reference.controller
            },
            ..*reference
        };
        let own = AnyModel::new(&dahl_scene, &dahl_scene.controller).unwrap();
        assert_eq!(
            own,
            fixed_model(reference, variant("Dahl steady N=64").unwrap()).unwrap()
        );
    }

    #[test]
    fn knobs_and_levels_change_the_model_and_missing_parameters_are_errors() {
        let horn = find("load-ramp").unwrap();
        let at = point(40.0, 0.005);
        let full = Q1_31::MAX;
        let ep16 = fixed_model(horn, variant("cube ep N=16").unwrap()).unwrap();
        let ep4 = fixed_model(horn, variant("cube ep N=4").unwrap()).unwrap();
        let el16 = fixed_model(horn, variant("cube el N=16").unwrap()).unwrap();
        let (r16, r4, el) = (
            ep16.ratio(&at, full).unwrap(),
            ep4.ratio(&at, full).unwrap(),
            el16.ratio(&at, full).unwrap(),
        );
        assert!((r16.to_f64() - 0.4806).abs() < 1e-3, "{r16:?}");
        assert_ne!(r16, r4);
        assert!(el > r16, "elastic {el:?} vs elastic-plastic {r16:?}");
        assert!(fixed_model(horn, variant("Littmann closed form").unwrap()).is_err());
        let beam = find("beam-table").unwrap();
        assert!(!buildable(beam, Fidelity::DahlSteady));
        assert!(fixed_model(beam, variant("Dahl steady N=16").unwrap()).is_err());
        assert!(!buildable(beam, Fidelity::CubeElasticPlastic));
        assert!(fixed_model(beam, variant("cube ep N=16").unwrap()).is_err());
        assert_eq!(
            fixed_model(beam, variant("Coulomb ratio").unwrap())
                .unwrap()
                .ratio(&point(15.0, 0.09), Q1_31::ZERO),
            Ok(Q2_30::ONE)
        );
    }
}
