//! Tests of the assembled plant (`mod.rs`), on the built-in scenes.

use super::*;
use sonolube::scene::{LoadCell, ModelKind, ModelSpec, find};

/// A Coulomb contact (seed 003: mu = 0.2), whose ratio has a closed form to check against.
const COULOMB: ModelSpec = ModelSpec {
    kind: ModelKind::Coulomb,
    mu: 0.2,
    mu_static: None,
    decay_s_per_m: None,
    k_t_n_per_m: None,
    dahl_alpha: None,
    surface: None,
};

fn scene(name: &str) -> Scene<'static> {
    Scene {
        plant: COULOMB,
        ..*find(name).expect("built-in scene")
    }
}

fn quiet(cell: LoadCell) -> LoadCell {
    LoadCell {
        noise_rms_pct_fs: 0.0,
        offset_n: 0.0,
        gain_error: 0.0,
        ..cell
    }
}

#[test]
fn the_same_scene_and_inputs_give_the_same_run() {
    let scene = scene("reference");
    let mut a = Plant::from_scene(&scene).expect("plant");
    let mut b = Plant::from_scene(&scene).expect("plant");
    let mut seen_codes = [false; 4096];
    for k in 0..250u32 {
        let command = (k % 50) as f32 / 50.0;
        let (ra, rb) = (a.step(command, 40_000.0), b.step(command, 40_000.0));
        assert_eq!(ra, rb, "step {k}");
        assert_eq!(
            ra.truth.contact.friction_n.to_bits(),
            rb.truth.contact.friction_n.to_bits()
        );
        seen_codes[usize::try_from(ra.tangential_code.raw()).unwrap()] = true;
    }
    // The noise is live: many different codes, not a constant.
    assert!(seen_codes.iter().filter(|&&seen| seen).count() > 20);
    // Another seed gives another noise sequence.
    let mut c = Plant::from_scene(&Scene {
        noise_seed: 7,
        ..scene
    })
    .expect("plant");
    let differs = (0..50).any(|_| a.step(0.0, 40_000.0) != c.step(0.0, 40_000.0));
    assert!(differs);
}

#[test]
fn friction_follows_the_envelope_through_the_model() {
    let scene = scene("reference");
    let mut plant = Plant::from_scene(&scene).expect("plant");
    let tau = scene.transducer.envelope_time_constant_s() as f32;
    let v_full = scene.full_scale_vibration_velocity_m_per_s() as f32;
    for k in 1..=40u32 {
        let readings = plant.step(1.0, 40_000.0);
        let truth = readings.truth;
        let t = k as f32 * 1e-4;
        let envelope = 1.0 - libm::expf(-t / tau);
        assert!(
            (truth.vibration_amplitude - envelope).abs() < 1e-5,
            "step {k}"
        );
        // Littmann: F'/F = (2/pi) asin(v / v_a) while v < v_a (seed 003, physics-notes §1).
        let zeta = 0.038 / (envelope * v_full);
        let expected = if zeta >= 1.0 {
            1.0
        } else {
            core::f32::consts::FRAC_2_PI * libm::asinf(zeta)
        };
        assert!((truth.contact.ratio - expected).abs() < 2e-4, "step {k}");
        let natural = 0.2 * 4.155;
        assert!((truth.contact.natural_friction_n - natural).abs() < 1e-6);
        assert!((truth.contact.friction_n - expected * natural).abs() < 2e-4);
        let reduction_mpct = if k >= 50 { 50_000 } else { 0 };
        assert_eq!(truth.target, Some(Target::Reduction { reduction_mpct }));
    }
}

#[test]
fn quiet_cells_read_the_true_forces() {
    let scene = Scene {
        normal_cell: quiet(find("reference").expect("built in").normal_cell),
        tangential_cell: quiet(find("reference").expect("built in").tangential_cell),
        ..scene("reference")
    };
    let mut plant = Plant::from_scene(&scene).expect("plant");
    let readings = plant.step(0.0, 40_000.0);
    // 4.155 N on 10 N full scale: 2048 + 0.4155 x 2048 = 2898.9; 0.831 N on 2 N: 2898.9.
    assert_eq!(readings.normal_code, AdcCode::new(2899));
    assert_eq!(readings.tangential_code, AdcCode::new(2899));
    // Driven, the friction falls and the cell follows within its 2 kHz bandwidth.
    let mut last = readings;
    for _ in 0..100 {
        last = plant.step(0.6, 40_000.0);
    }
    let cell = LoadCellSim::new(&scene.tangential_cell, 1.0, 0.0);
    let expected = cell.convert(last.truth.contact.friction_n);
    assert!(
        last.tangential_code.raw().abs_diff(i32::from(expected)) <= 1,
        "{last:?}"
    );
    assert!(last.tangential_code < AdcCode::new(2600));
    assert_eq!(last.sliding_velocity_m_per_s, 0.038);
}

#[test]
fn a_disconnected_cell_reads_the_rail_from_the_onset() {
    let scene = scene("sensor-fault");
    let mut plant = Plant::from_scene(&scene).expect("plant");
    // Onset at 15 ms: sample 150.
    for k in 1..=200u32 {
        let readings = plant.step(0.5, 40_000.0);
        let faulted = k >= 150;
        assert_eq!(
            readings.tangential_code == AdcCode::new(4095),
            faulted,
            "step {k}"
        );
        assert_eq!(
            readings.truth.tangential_fault.is_some(),
            faulted,
            "step {k}"
        );
        assert!(
            readings.normal_code > AdcCode::new(2700) && readings.normal_code < AdcCode::new(3100)
        );
    }
}

#[test]
fn a_spike_lasts_one_sample_and_a_stuck_cell_freezes() {
    let mut plant = Plant::from_scene(&scene("sensor-spike")).expect("plant");
    let codes: [AdcCode; 130] = core::array::from_fn(|_| plant.step(0.5, 40_000.0).tangential_code);
    // +1.5 N on 2 N full scale is +1536 codes, at sample 120 only (index 119).
    assert!(
        codes[119].raw() > codes[118].raw() + 1300,
        "{:?} after {:?}",
        codes[119],
        codes[118]
    );
    assert!(codes[120].raw() < codes[118].raw() + 100);
    let mut plant = Plant::from_scene(&scene("sensor-stuck")).expect("plant");
    let codes: [AdcCode; 200] = core::array::from_fn(|_| plant.step(0.5, 40_000.0).normal_code);
    // Frozen from sample 120 at the code of sample 119, while the noise moved it before.
    assert!(codes[119..].iter().all(|&code| code == codes[118]));
    assert!(codes[..118].windows(2).any(|w| w[0] != w[1]));
}

#[test]
fn substeps_refine_without_changing_the_envelope() {
    let one = Scene {
        plant_substeps: 1,
        ..scene("reference")
    };
    let sixteen = Scene {
        plant_substeps: 16,
        ..one
    };
    let (mut coarse, mut fine) = (
        Plant::from_scene(&one).expect("plant"),
        Plant::from_scene(&sixteen).expect("plant"),
    );
    for _ in 0..20 {
        let (a, b) = (coarse.step(0.8, 40_050.0), fine.step(0.8, 40_050.0));
        assert!((a.truth.vibration_amplitude - b.truth.vibration_amplitude).abs() < 1e-5);
    }
    assert_eq!(coarse.steps(), 20);
    assert!((coarse.time_s() - 0.002).abs() < 1e-9);
}

#[test]
fn a_hand_built_scene_with_bad_values_is_refused() {
    let bad = Scene {
        plant_substeps: 0,
        ..scene("reference")
    };
    assert_eq!(
        Plant::from_scene(&bad).err(),
        Some(PlantError::InvalidScene {
            field: "plant_substeps"
        })
    );
    let no_horn = Scene {
        plant: ModelSpec {
            kind: ModelKind::CubeElasticPlastic,
            ..COULOMB
        },
        ..scene("reference")
    };
    assert!(matches!(
        Plant::from_scene(&no_horn),
        Err(PlantError::Model(_))
    ));
}
