//! The tabulated cube models (`sonolube::model::cube_table`) against the independent `f64`
//! reference: the interpolation error bound of each table size holds on a dense grid over
//! every horn scene's tabulated range (the margin beyond `load_range_n` included), and loads
//! outside the table get the exact model's accuracy.

use sonolube::fx::{Q1_31, Q8_24, Q16_16};
use sonolube::model::OperatingPoint;
use sonolube::scene::SCENES;
use sonolube::variant::grid::GridPoint;
use sonolube::variant::{CATALOGUE, Family, Model};
use sonolube_cli::speed::reference;

/// Loads and amplitudes of the dense grid (amplitudes k / 96: 1 in 3 is not a node of any
/// table, since 96 is not a power of two).
const LOADS: u32 = 17;
const AMPLITUDES: u32 = 96;

/// Bound on |F'/F - reference| per table side: the bilinear error measured against the exact
/// fixed-point model (model::cube_table's tests: 6.0e-3, 1.6e-3, 4.2e-4 at most) with
/// a margin; the fixed point's own error is about 1e-7.
fn bound(side: u8) -> f64 {
    match side {
        5 => 7e-3,
        9 => 2e-3,
        17 => 5e-4,
        _ => panic!("no bound for side {side}"),
    }
}

fn grid_point(load_n: f64, amplitude: Q1_31) -> GridPoint {
    GridPoint {
        point: OperatingPoint {
            normal_force: Q16_16::from_f64(load_n).unwrap(),
            sliding_velocity: Q8_24::from_f64(0.005).unwrap(),
        },
        amplitude,
    }
}

fn amplitude(k: u32) -> Q1_31 {
    Q1_31::from_bits(((u64::from(k) << 31) / u64::from(AMPLITUDES)).min(i32::MAX as u64) as i32)
}

#[test]
fn every_table_meets_its_bound_over_the_tabulated_range() {
    // The cube tables (the Dahl tables have their own test, `dahl_table.rs`).
    let tables: Vec<_> = CATALOGUE
        .iter()
        .filter(|v| v.table > 0 && v.fidelity.family() == Family::Cube)
        .collect();
    assert!(tables.len() >= 6);
    assert!(tables.iter().all(|v| v.table <= 17));
    let mut checked = 0;
    for scene in SCENES.iter().filter(|s| s.contents.normal_vibration) {
        // Inside the table: the stated range widened by e^0.12 (the table's margin is e^0.125).
        let (lo, hi) = (
            scene.contents.load_min_n * (-0.12f64).exp(),
            scene.contents.load_max_n * 0.12f64.exp(),
        );
        for level in [tables[0].fidelity, tables[tables.len() - 1].fidelity] {
            let points: Vec<(GridPoint, f64)> = (0..LOADS)
                .flat_map(|l| {
                    let load = lo * (hi / lo).powf(f64::from(l) / f64::from(LOADS - 1));
                    (0..=AMPLITUDES).map(move |k| grid_point(load, amplitude(k)))
                })
                .map(|at| (at, reference::ratio(scene, level, &at).unwrap()))
                .collect();
            let mut previous = f64::INFINITY;
            for variant in tables.iter().filter(|v| v.fidelity == level) {
                let model = Model::new(scene, variant).expect(variant.name);
                let mut worst: f64 = 0.0;
                for (at, want) in &points {
                    let got = model.ratio(at).expect(variant.name);
                    worst = worst.max((got - want).abs());
                }
                let b = bound(variant.table);
                assert!(
                    worst <= b,
                    "{} {}: {worst:e} > {b:e}",
                    scene.name,
                    variant.name
                );
                // A larger table is more accurate (bilinear: about 4x per doubling).
                assert!(worst < previous / 3.0, "{} {}", scene.name, variant.name);
                previous = worst;
                checked += 1;
            }
        }
    }
    assert!(checked >= 3 * tables.len() / 2, "{checked}");
}

#[test]
fn loads_outside_the_table_get_the_exact_accuracy() {
    let scene = SCENES.iter().find(|s| s.name == "horn-al-ss").unwrap();
    let variant = CATALOGUE
        .iter()
        .find(|v| v.name == "cube ep T=5x5")
        .unwrap();
    let model = Model::new(scene, variant).unwrap();
    for load in [20.0, 30.0, 300.0, 1000.0] {
        for k in [1, 17, 50, 96] {
            let at = grid_point(load, amplitude(k));
            let want = reference::ratio(scene, variant.fidelity, &at).unwrap();
            let got = model.ratio(&at).unwrap();
            // The exact fixed-point model's accuracy (1e-7), not the 5 x 5 table's (6e-3).
            assert!((got - want).abs() < 1e-6, "{load} N, {k}: {got} vs {want}");
        }
    }
}
