//! The exact `f64` model of each level at a scene's grid point, from the independent reference
//! ([`sonolube_host::reference`]: closed forms and converged adaptive quadrature, never the firmware's
//! code), with the scene's controller parameters and hardware as the variants use them
//! ([`sonolube::variant::fixed`]).

use std::f64::consts::TAU;

use sonolube::scene::{RoughSurface, Scene};
use sonolube::variant::Fidelity;
use sonolube::variant::grid::{DahlUpdateInput, GridPoint};

use sonolube_host::reference::contact::{ContactModel, ContactParameters, EStarRule};
use sonolube_host::reference::coulomb::{littmann_ratio, velocity_ratio};
use sonolube_host::reference::cube::{CubeInput, CubeOptions, SlipWindow, UPhase, cube_reduction};
use sonolube_host::reference::dahl_models::{DahlSteadyInput, dahl_steady};

/// The reference's contact parameters for a scene surface.
fn contact(surface: &RoughSurface) -> ContactParameters {
    ContactParameters {
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

/// F'/F of the exact model of `level` for `scene` at `at` (the point's exact values): the
/// friction ratio with vibration over without, in [0, 1] for every level and scene here.
/// Errors: a kernel level, a level the scene has no parameters for, or the reference's own
/// validation (message).
pub fn ratio(scene: &Scene<'_>, level: Fidelity, at: &GridPoint) -> Result<f64, String> {
    let (load, v, a) = (at.load_n(), at.velocity_m_per_s(), at.amplitude());
    let spec = &scene.controller;
    let frequency = scene.transducer.drive_hz;
    let full_scale = scene.actuator.full_scale_amplitude_m;
    let vibration_velocity = a * TAU * frequency * full_scale;
    match level {
        Fidelity::Coulomb => {
            let zeta = velocity_ratio(v, vibration_velocity).map_err(|e| e.to_string())?;
            Ok(zeta.map_or(1.0, |zeta| littmann_ratio(zeta).abs()))
        }
        Fidelity::DahlSteady => {
            let k_t = spec.k_t_n_per_m.ok_or("no k_t in the controller spec")?;
            dahl_steady(&DahlSteadyInput {
                friction_coefficient: spec.mu,
                normal_load: load,
                tangential_stiffness: k_t,
                sliding_velocity: v,
                vibration_velocity,
                frequency,
                shape_exponent: spec.dahl_alpha.unwrap_or(1.0),
            })
            .map_err(|e| e.to_string())?
            .friction_ratio
            .ok_or_else(|| "no sliding (v = 0): the friction ratio is undefined".into())
        }
        Fidelity::CubeElastic | Fidelity::CubeElasticPlastic => {
            let horn = scene.horn.ok_or("no horn")?;
            let surface = spec.surface.ok_or("no surface in the controller spec")?;
            let options = CubeOptions {
                e_star_rule: EStarRule::Seed000,
                contact_model: if level == Fidelity::CubeElastic {
                    ContactModel::Elastic
                } else {
                    ContactModel::ElasticPlastic
                },
                window: SlipWindow::SurfacesApart,
                u_phase: UPhase::InPhase,
            };
            cube_reduction(
                &CubeInput {
                    normal_force: load,
                    friction_coefficient: spec.mu,
                    longitudinal_amplitude: a * full_scale,
                    vertical_amplitude: a * horn.vertical_amplitude_m,
                    position: horn.contact_position_m,
                    horn_length: horn.length_m,
                    frequency,
                    contact: contact(&surface),
                },
                options,
            )
            .map(|out| out.friction_ratio)
            .map_err(|e| e.to_string())
        }
        Fidelity::Littmann | Fidelity::DahlUpdate => Err("a kernel has no scene reference".into()),
    }
}

/// The Littmann law at the exact zeta (reference closed form, half-angle form near 1).
pub fn littmann(zeta: f64) -> f64 {
    littmann_ratio(zeta)
}

/// The exact Dahl update f' = s + (f - s) e^-y (physics-notes §2's closed form, alpha = 1)
/// at the input's exact values, with `exp_m1` so that small travels keep their precision.
pub fn dahl_update(input: &DahlUpdateInput) -> f64 {
    let s = if input.forward { 1.0 } else { -1.0 };
    let (f, y) = (input.state.to_f64(), input.travel.to_f64());
    // s + (f - s) e^-y = f + (f - s) (e^-y - 1).
    f + (f - s) * (-y).exp_m1()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::scene::find;
    use sonolube::variant::grid::SceneGrid;

    #[test]
    fn references_match_the_known_values_of_the_scenes() {
        // load-ramp at 40 N, amplitude 1 - 2^-31: the cube values of the papers' reading
        // (0.4806 elastic-plastic, 0.4926 elastic with mu = 0.55: mu does not enter at the node).
        let ramp = find("load-ramp").unwrap();
        let grid = SceneGrid::new(ramp);
        let full = grid.get(23).unwrap();
        assert_eq!(full.load_n(), 40.0);
        let ep = ratio(ramp, Fidelity::CubeElasticPlastic, &full).unwrap();
        let el = ratio(ramp, Fidelity::CubeElastic, &full).unwrap();
        assert!((ep - 0.480_622_553).abs() < 1e-6, "{ep}");
        assert!((el - 0.492_557_153).abs() < 1e-6, "{el}");
        assert!(ratio(ramp, Fidelity::Littmann, &full).is_err());
        // reference scene: Coulomb vs Dahl at full amplitude (zeta = 0.318).
        let reference = find("reference").unwrap();
        let at = SceneGrid::new(reference).get(23).unwrap();
        let coulomb = ratio(reference, Fidelity::Coulomb, &at).unwrap();
        let zeta = at.velocity_m_per_s() / (at.amplitude() * TAU * 40e3 * 0.4756e-6);
        assert!((coulomb - 2.0 / std::f64::consts::PI * zeta.asin()).abs() < 1e-15);
        let dahl = ratio(reference, Fidelity::DahlSteady, &at).unwrap();
        assert!((dahl - 0.211_603).abs() < 1e-5, "{dahl}");
        let beam = find("beam-table").unwrap();
        let at = SceneGrid::new(beam).get(0).unwrap();
        assert!(ratio(beam, Fidelity::DahlSteady, &at).is_err());
        assert!(ratio(beam, Fidelity::CubeElastic, &at).is_err());
    }

    #[test]
    fn the_update_reference_is_the_closed_form() {
        let input = DahlUpdateInput {
            state: sonolube::fx::Q2_30::from_f64(-0.5).unwrap(),
            forward: true,
            travel: sonolube::fx::Q2_30::from_f64(0.25).unwrap(),
        };
        assert!((dahl_update(&input) - (1.0 - 1.5 * (-0.25f64).exp())).abs() < 1e-15);
        assert!((littmann(0.5) - 1.0 / 3.0).abs() < 1e-15);
    }
}
