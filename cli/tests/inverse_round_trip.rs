//! Every fixed-point inverse the controller can run (the Coulomb ratio, the Dahl tables, the
//! cube model and its tables) by its behaviour (issue 24 item 6): over every shipped scene's
//! operating grid, the target is the exact f64 model's ratio at a grid point, the inverse gives
//! an amplitude, and the exact f64 model's ratio at that amplitude is the target again:
//! `ratio(invert(r)) = r` against the independent reference, not against the variant's own
//! forward model (which a shared bug would satisfy). The controller's call, `invert_from`
//! (from the last step's amplitude), is held to the same bound from starts near the answer,
//! far from it and at both ends of the range.
//!
//! The bound of a variant is its stated accuracy as a forward model (the inverse lands on its
//! own forward value, which is that far from the reference) plus 2e-6 for the inverse's
//! residual and the amplitude's Q1.31 rounding:
//! - Coulomb ratio: 1e-6 (closed form);
//! - Dahl steady T=49x73: 1e-4 (`cli/tests/dahl_table.rs`);
//! - cube N=16: 1e-5 (converged quadrature, its Newton inverse's tolerance);
//! - cube T=SxS: bilinear tables, 8e-3 (S = 5), 2e-3 (9), 6e-4 (17): `docs/speed.md`'s max
//!   errors with margin.

use sonolube::fx::{Q1_31, Q2_30};
use sonolube::model::{FrictionModel, Reach};
use sonolube::scene::SCENES;
use sonolube::variant::fixed::{fixed_model, variant_buildable};
use sonolube::variant::grid::{GridPoint, SceneGrid};
use sonolube::variant::{CATALOGUE, Fidelity, Form, Variant};
use sonolube_cli::speed::reference;

/// The accuracy a variant's forward model is held to (module docs), or `None` for a variant
/// whose inverse is not tested here (the float forms, the exact Dahl steady state's bisection).
fn bound(variant: &Variant) -> Option<f64> {
    if variant.form != Form::Fixed {
        return None;
    }
    match (variant.fidelity, variant.table) {
        (Fidelity::Coulomb, _) => Some(1e-6),
        (Fidelity::DahlSteady, 49) => Some(1e-4),
        (Fidelity::CubeElastic | Fidelity::CubeElasticPlastic, 0) if variant.points == 16 => {
            Some(1e-5)
        }
        (Fidelity::CubeElastic | Fidelity::CubeElasticPlastic, 5) => Some(8e-3),
        (Fidelity::CubeElastic | Fidelity::CubeElasticPlastic, 9) => Some(2e-3),
        (Fidelity::CubeElastic | Fidelity::CubeElasticPlastic, 17) => Some(6e-4),
        _ => None,
    }
}

#[test]
fn every_inverse_returns_to_its_target_on_the_reference() {
    let mut tested = 0;
    let mut report = Vec::new();
    for variant in CATALOGUE {
        let Some(bound) = bound(variant) else {
            continue;
        };
        let mut worst: f64 = 0.0;
        let mut points = 0;
        for scene in SCENES {
            if !variant_buildable(scene, variant) {
                continue;
            }
            let model = fixed_model(scene, variant).unwrap();
            let level = variant.fidelity;
            let exact = |p: &GridPoint, a: Q1_31| {
                reference::ratio(
                    scene,
                    level,
                    &GridPoint {
                        point: p.point,
                        amplitude: a,
                    },
                )
                .unwrap()
            };
            for p in SceneGrid::new(scene).points() {
                let target = Q2_30::from_f64(exact(&p, p.amplitude)).unwrap();
                let in_plane = matches!(level, Fidelity::Coulomb | Fidelity::DahlSteady);
                if target >= Q2_30::ONE || (in_plane && p.velocity_m_per_s() == 0.0) {
                    // No reversal at this amplitude, or no sliding (the in-plane ratio is 0 at
                    // every amplitude: the inverse refuses, unit-tested with each model).
                    continue;
                }
                let t = target.to_f64();
                // The cold inverse, and the controller's call: from a start nearby (last
                // step's amplitude, a little off), from one far off, and from the ends.
                let near = Q1_31::from_f64(p.amplitude.to_f64() * 0.995).unwrap();
                let far = Q1_31::from_f64(p.amplitude.to_f64() * 0.3).unwrap();
                for inv in [
                    model.invert(&p.point, target),
                    model.invert_from(&p.point, target, near),
                    model.invert_from(&p.point, target, far),
                    model.invert_from(&p.point, target, Q1_31::ZERO),
                    model.invert_from(&p.point, target, Q1_31::MAX),
                ] {
                    let inv = inv.unwrap();
                    let error = match inv.reach {
                        Reach::Reached => (exact(&p, inv.amplitude) - t).abs(),
                        // The variant's own floor may sit above a reachable target by its error.
                        Reach::BelowMinimum => {
                            (model.ratio(&p.point, Q1_31::MAX).unwrap().to_f64() - t).max(0.0)
                        }
                        Reach::AboveNatural => {
                            panic!(
                                "{} on {}: {t} reported above natural",
                                variant.name, scene.name
                            )
                        }
                    };
                    assert!(
                        error <= bound + 2e-6,
                        "{} on {} at W {} N, v {} m/s: target {t}, {inv:?}, off by {error:.2e} \
                     (bound {bound:.0e})",
                        variant.name,
                        scene.name,
                        p.load_n(),
                        p.velocity_m_per_s()
                    );
                    worst = worst.max(error);
                }
                points += 1;
            }
        }
        if points > 0 {
            tested += 1;
            report.push(format!(
                "{}: {points} targets, worst {worst:.1e} (bound {bound:.0e})",
                variant.name
            ));
        }
    }
    eprintln!("{}", report.join("\n"));
    // Coulomb, the Dahl table, two cube levels at N = 16 and three tables each.
    assert!(tested >= 10, "{report:?}");
}
