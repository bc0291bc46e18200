//! Unit tests of the fixed-point contact model (physics-notes §3 numbers, guards, inverses).
use super::*;

fn constants(kind: ContactKind) -> ContactConstants {
    ContactConstants::new(
        &ContactParams::SEED_000_TABLE_2_AL_ON_SS,
        EStarRule::Seed000,
        kind,
    )
    .unwrap()
}

fn separation_um(c: &ContactConstants, load: f64) -> f64 {
    let state = c.state(ln_load_from_si(load).unwrap()).unwrap();
    state.separation_rq.to_f64() * 6.0
}

#[test]
fn seed000_separations_and_their_constant_gap() {
    // physics-notes §3: 24.93 um (elastic) and 18.11 um (elastic-plastic) at 40 N, gap 6.82 um.
    let (ep, el) = (
        constants(ContactKind::ElasticPlastic),
        constants(ContactKind::Elastic),
    );
    assert!((separation_um(&ep, 40.0) - 18.111_083).abs() < 2e-6);
    assert!((separation_um(&el, 40.0) - 24.931_257).abs() < 2e-6);
    for load in [40.0, 140.0, 240.0] {
        let gap = separation_um(&el, load) - separation_um(&ep, load);
        assert!((gap - 6.820_174).abs() < 2e-6, "{load} N: {gap}");
    }
    let scene = ep.scene();
    assert!((scene.mean_pressure / 602.273_813e6 - 1.0).abs() < 1e-8);
    assert!((scene.critical_interference / 4.287_352e-10 - 1.0).abs() < 1e-6);
}

#[test]
fn area_grows_sixfold_and_split_matches_the_shares() {
    let ep = constants(ContactKind::ElasticPlastic);
    let at = |load: f64| ep.state(ln_load_from_si(load).unwrap()).unwrap();
    let ratio = at(240.0).area_scaled().to_f64() / at(40.0).area_scaled().to_f64();
    // Two Q8.24 logarithms, 3e-8 each.
    assert!((ratio - 6.0).abs() < 6.0 * 7e-8, "{ratio}");
    let s = at(40.0);
    let split = ep.split(&s);
    let fe = split.elastic_force.unwrap().to_f64();
    assert!((fe / 40.0 / 6.126_848e-9 - 1.0).abs() < 1e-6, "{fe}");
    let total =
        split.elastic_area_ratio.unwrap().to_f64() + split.plastic_area_ratio.unwrap().to_f64();
    assert!((total / s.area_scaled().to_f64() - 1.0).abs() < 1e-7);
    let el = constants(ContactKind::Elastic);
    assert_eq!(el.split(&el.state(s.ln_load).unwrap()).plastic_force, None);
    // Linear A_r / A_n agrees with the wide one to 1 ulp of Q2.30.
    assert!((s.area_ratio().to_f64() - s.area_scaled().to_f64()).abs() < 1e-9);
}

#[test]
fn forward_map_inverts_the_load_map() {
    let ep = constants(ContactKind::ElasticPlastic);
    for load in [1e-3, 0.5, 40.0, 3000.0, 5e4] {
        let s = ep.state(ln_load_from_si(load).unwrap()).unwrap();
        let back = ep.state_at_separation(s.separation_rq).unwrap();
        // d / R_q is rounded to 6e-8: lambda 6e-8 / 2 in ln F_n.
        assert!(
            (back.load_scaled().to_f64() / load - 1.0).abs() < 1.5e-7,
            "{load} N: {}",
            back.load_scaled().to_f64() / load - 1.0
        );
    }
}

#[test]
fn guards_give_typed_errors() {
    let ep = constants(ContactKind::ElasticPlastic);
    assert!(matches!(
        ln_load(Q16_16::ZERO),
        Err(ModelError::OutOfDomain { input: "F_n", .. })
    ));
    assert!(ln_load_from_si(0.0).is_err() && ln_load_from_si(-1.0).is_err());
    assert_eq!(
        ln_load_from_si(f64::NAN),
        Err(ModelError::NonFinite { input: "F_n" })
    );
    // A_r > A_n above p_eff A_n = 6.0e4 N; d < 0 above K_F = 3.4e5 N.
    assert!(ep.state(ln_load_from_si(5.9e4).unwrap()).is_ok());
    assert!(matches!(
        ep.state(ln_load_from_si(6.1e4).unwrap()),
        Err(ModelError::OutOfDomain { input: "F_n", .. })
    ));
    assert!(ep.state(ln_load_from_si(4e5).unwrap()).is_err());
    assert!(ep.state_at_separation(Q8_24::ZERO).is_err());
    assert!(ep.state_at_separation(Q8_24::from_bits(1)).is_err()); // A_r > A_n
    assert!(ep.state_at_separation(Q8_24::MAX).is_err()); // F_n < e^-32 N
    // The Q16.16 path agrees with the SI path.
    let q = ln_load(Q16_16::from_int(40).unwrap()).unwrap();
    assert!((q.to_f64() - ln_load_from_si(40.0).unwrap().to_f64()).abs() < 2e-8);
}

#[test]
fn si_logarithm_is_accurate_over_twenty_decades() {
    let mut worst: f64 = 0.0;
    for i in 0..=4000 {
        let load = libm::exp(-13.0 + 26.0 * i as f64 / 4000.0) * 1.000_000_1;
        let got = ln_load_from_si(load).unwrap().to_f64();
        worst = worst.max((got - load.ln()).abs());
    }
    assert!(worst < 1.6e-8, "{worst:e}");
}
