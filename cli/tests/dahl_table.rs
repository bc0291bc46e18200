//! The Dahl steady-state tables (`sonolube::model::dahl_table`, issue 13) against the
//! independent f64 reference: the committed nodes are the reference's, and the fixed-point
//! interpolation and inverse meet their accuracy over the table and at its extremes.

use std::f64::consts::PI;

use sonolube::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
use sonolube::model::dahl::DahlParams;
use sonolube::model::dahl_table::{DahlGrid, DahlTable, GRID_33, GRID_65};
use sonolube::model::{FrictionModel, OperatingPoint, Reach};
use sonolube_host::dahl_table::{SIDES, exact_ratio, padded_nodes};
use sonolube_host::reference::dahl_models::{DahlSteadyInput, dahl_steady};

/// The unit scene of the generator: x_a,max = 1 m, omega = 1 rad/s, mu = 1, k_t = 1 N/m, so
/// at W = 1 N: v_a = a m/s, zeta = v / a, kappa x_a = a.
fn unit(grid: &'static DahlGrid) -> DahlTable {
    DahlTable::new(
        &DahlParams {
            friction_coefficient: 1.0,
            tangential_stiffness: 1.0,
            frequency_hz: 1.0 / (2.0 * PI),
            full_scale_amplitude_m: 1.0,
            shape_exponent: 1.0,
            quadrature_points: 64,
        },
        grid,
    )
    .unwrap()
}

/// Every 37th node of each committed table (and its ghosts' rule) is the reference's value,
/// rounded to Q2.30: the file is what the generator writes (`sonolube dahl-table --check`
/// compares all of it).
#[test]
fn committed_nodes_are_the_references() {
    let committed = std::fs::read_to_string(
        sonolube_cli::speed::repo_root().join(sonolube_host::dahl_table::PATH),
    )
    .unwrap();
    for side in SIDES {
        let stride = side + 2;
        let start = committed
            .find(&format!("pub static NODES_{side}"))
            .expect("table in the file");
        let body = &committed[start..];
        let body = &body[body.find('[').unwrap() + 1..];
        let body = &body[body.find('[').unwrap() + 1..body.find("];").unwrap()];
        let values: Vec<i64> = body
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(values.len(), stride * stride);
        let span = 16.0;
        for k in (0..side * side).step_by(37) {
            let (i, j) = (k / side, k % side);
            let want = exact_ratio(
                i as f64 / (side - 1) as f64,
                -8.0 + span * j as f64 / (side - 1) as f64,
            )
            .unwrap();
            let got = values[(i + 1) * stride + j + 1];
            assert_eq!(
                got,
                (want * f64::from(1u32 << 30)).round() as i64,
                "{side}: ({i}, {j})"
            );
        }
        let _ = padded_nodes; // the generator's ghosts are checked through the fixed point below
    }
}

/// Interpolation error of the fixed-point table against the reference, between the nodes,
/// over the whole table (x in (0, 1), ln kappa x_a in (-8, 8)) and over the in-plane scenes'
/// part of it (kappa x_a <= 50: every scene's full amplitude, load and velocity range).
#[test]
fn interpolation_error_over_the_table() {
    for (grid, whole_bound, scenes_bound) in [(&GRID_33, 2e-3, 1e-3), (&GRID_65, 1e-4, 1e-4)] {
        let (mut whole, mut scenes): (f64, f64) = (0.0, 0.0);
        let m = 47;
        for a in 0..m {
            for b in 0..m {
                let x = (a as f64 + 0.5) / m as f64;
                let y = -8.0 + 16.0 * (b as f64 + 0.43) / m as f64;
                let got = unit(grid)
                    .ratio_at(Q2_30::from_f64(x).unwrap(), Q8_24::from_f64(y).unwrap())
                    .unwrap()
                    .to_f64();
                let xq = Q2_30::from_f64(x).unwrap().to_f64();
                let yq = Q8_24::from_f64(y).unwrap().to_f64();
                let error = (got - exact_ratio(xq, yq).unwrap()).abs();
                whole = whole.max(error);
                if yq <= 50f64.ln() {
                    scenes = scenes.max(error);
                }
            }
        }
        eprintln!(
            "T={0}x{0}: max error {whole:.2e} over the table, {scenes:.2e} for kappa x_a <= 50",
            grid.side
        );
        assert!(whole <= whole_bound, "T={}: {whole:e}", grid.side);
        assert!(scenes <= scenes_bound, "T={}: {scenes:e}", grid.side);
    }
}

/// The extremes: the corners and edges of the table, and beyond its stiff end (the
/// extrapolation towards the Coulomb limit), at the scene level (W, v, amplitude) against the
/// reference's own scene-level steady state.
#[test]
fn extremes_against_the_reference() {
    // Seed 003: mu 0.2, 40 kHz, x_a,max 0.4756 um (the reference scene's stack).
    let x_fs = 0.4756e-6;
    let at = |k_t: f64, w: f64, v: f64, a: f64, grid: &'static DahlGrid| {
        let table = DahlTable::new(
            &DahlParams {
                friction_coefficient: 0.2,
                tangential_stiffness: k_t,
                frequency_hz: 40e3,
                full_scale_amplitude_m: x_fs,
                shape_exponent: 1.0,
                quadrature_points: 64,
            },
            grid,
        )
        .unwrap();
        let point = OperatingPoint {
            normal_force: Q16_16::from_f64(w).unwrap(),
            sliding_velocity: Q8_24::from_f64(v).unwrap(),
        };
        let amplitude = Q1_31::from_f64(a).unwrap();
        let got = table.ratio(&point, amplitude).unwrap().to_f64();
        let want = dahl_steady(&DahlSteadyInput {
            friction_coefficient: 0.2,
            normal_load: point.normal_force.to_f64(),
            tangential_stiffness: k_t,
            sliding_velocity: point.sliding_velocity.to_f64(),
            vibration_velocity: amplitude.to_f64() * 2.0 * PI * 40e3 * x_fs,
            frequency: 40e3,
            shape_exponent: 1.0,
        })
        .unwrap()
        .friction_ratio
        .expect("defined at a nonzero sliding velocity");
        (got, want)
    };
    for (k_t, w, v, a, bound) in [
        // compliant (seed 003's k_t): kappa x_a 0.016 to 0.25, zeta down to 0.32
        (5.6e4, 0.54, 0.038, 0.999, 1e-4),
        (5.6e4, 7.905, 0.038, 0.999, 1e-4),
        (5.6e4, 7.905, 0.038, 0.33, 1e-4),  // zeta just below 1
        (5.6e4, 4.155, 0.001, 0.999, 1e-4), // zeta 0.008: x near 0
        // the soft end of the table: kappa x_a = e^-7.7
        (5.6e4, 30.0, 0.0004, 0.999, 1e-4),
        // Mindlin stiffness of the stack scenes: kappa x_a up to 24
        (2.5e7, 2.0, 0.01, 0.999, 1e-4),
        (2.5e7, 4.155, 0.038, 0.5, 1e-4),
        // stiff: beyond the table's top (kappa x_a 6e4 to 2e5), the extrapolation
        (1e10, 4.155, 0.038, 0.999, 1e-3),
        (1e10, 4.155, 0.038, 0.5, 1e-3),
        (3e10, 0.54, 0.001, 0.999, 1e-4),
    ] {
        let (got, want) = at(k_t, w, v, a, &GRID_65);
        assert!(
            (got - want).abs() <= bound,
            "k_t {k_t} W {w} v {v} a {a}: table {got}, reference {want}"
        );
    }
    // Below the soft end: refused, not clamped.
    let table = unit(&GRID_65);
    let tiny = OperatingPoint {
        normal_force: Q16_16::ONE,
        sliding_velocity: Q8_24::from_f64(1e-5).unwrap(),
    };
    assert!(table.ratio(&tiny, Q1_31::from_f64(1e-4).unwrap()).is_err());
}

/// The inverse against the reference: the reference's ratio at the returned amplitude is the
/// target, for the compliant and the stack scenes' operating points.
#[test]
fn inverse_meets_the_target_on_the_reference() {
    let x_fs = 0.4756e-6;
    for (k_t, w, v) in [
        (5.6e4, 4.155, 0.038),
        (5.6e4, 0.54, 0.038),
        (2.5e7, 4.155, 0.038),
    ] {
        let table = DahlTable::new(
            &DahlParams {
                friction_coefficient: 0.2,
                tangential_stiffness: k_t,
                frequency_hz: 40e3,
                full_scale_amplitude_m: x_fs,
                shape_exponent: 1.0,
                quadrature_points: 64,
            },
            &GRID_65,
        )
        .unwrap();
        let point = OperatingPoint {
            normal_force: Q16_16::from_f64(w).unwrap(),
            sliding_velocity: Q8_24::from_f64(v).unwrap(),
        };
        for target in [0.55, 0.7, 0.8, 0.9, 0.99] {
            let inv = table
                .invert(&point, Q2_30::from_f64(target).unwrap())
                .unwrap();
            if inv.reach != Reach::Reached {
                continue;
            }
            let want = dahl_steady(&DahlSteadyInput {
                friction_coefficient: 0.2,
                normal_load: w,
                tangential_stiffness: k_t,
                sliding_velocity: point.sliding_velocity.to_f64(),
                vibration_velocity: inv.amplitude.to_f64() * 2.0 * PI * 40e3 * x_fs,
                frequency: 40e3,
                shape_exponent: 1.0,
            })
            .unwrap()
            .friction_ratio
            .expect("defined at a nonzero sliding velocity");
            assert!(
                (want - target).abs() <= 1e-4,
                "k_t {k_t} W {w}: target {target}, reference at the inverse {want}"
            );
        }
    }
}

/// Issue 13's new user: a copy of `reference` with a 2 N load and a 0.02 m/s slide, a scene the
/// committed table never measured. The host measures its candidates against the Dahl steady
/// state with its k_t when it loads it, and picks a measured variant (not "the scene's own").
#[test]
fn a_users_scene_file_is_measured_when_loaded() {
    use sonolube::scene::{Contents, Scene, find};
    use sonolube::variant::select::{Reason, measured_as_built_in};
    use sonolube::variant::{Fidelity, select};
    let reference = find("reference").unwrap();
    let mine = Scene {
        name: "my-reference",
        contents: Contents {
            load_min_n: 2.0,
            load_max_n: 2.0,
            velocity_min_m_per_s: 0.02,
            velocity_max_m_per_s: 0.02,
            ..reference.contents
        },
        ..*reference
    };
    assert!(!measured_as_built_in(&mine));
    assert!(matches!(select(&mine).reason, Reason::NotMeasured { .. }));
    let s = sonolube_cli::speed::table_rs::select_on_host(&mine).unwrap();
    assert_eq!(s.required, Some(Fidelity::DahlSteady));
    let variant = s.variant.expect("a measured choice");
    assert!(matches!(s.reason, Reason::Meets { .. }), "{s}");
    let line = format!("{s}");
    assert!(line.contains("against the Dahl steady state"), "{line}");
    assert!(
        line.starts_with(&format!("model {}", variant.name)),
        "{line}"
    );
    // A built-in scene gets the firmware's own choice.
    assert_eq!(
        sonolube_cli::speed::table_rs::select_on_host(reference).unwrap(),
        select(reference)
    );
}
