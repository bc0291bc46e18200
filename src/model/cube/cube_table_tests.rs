//! Unit tests of the tabulated cube model against the exact fixed-point model it is built from
//! (the bound against the independent f64 reference is `host-tests/tests/cube_table.rs`).

use super::*;
use crate::fx::Q8_24;
use crate::model::contact::ContactKind;
use crate::model::cube::CubeOptions;
use crate::model::cube::tests::test_1;

/// Tabulated load range of the tests: horn-al-ss's 40 to 240 N.
const RANGE: (f64, f64) = (40.0, 240.0);

fn exact(kind: ContactKind) -> CubeModel {
    let options = CubeOptions {
        contact_kind: kind,
        ..CubeOptions::default()
    };
    CubeModel::new(&test_1(0.0), &options).unwrap()
}

fn table(kind: ContactKind, side: usize) -> CubeTable {
    CubeTable::new(exact(kind), RANGE, side).unwrap()
}

fn at(load_n: f64) -> OperatingPoint {
    OperatingPoint {
        normal_force: Q16_16::from_f64(load_n).unwrap(),
        sliding_velocity: Q8_24::from_f64(0.005).unwrap(),
    }
}

/// Largest |table - exact| (F'/F) over a dense grid inside the range: 41 loads (geometric)
/// times 257 amplitudes, none of them on purpose at a node.
fn worst_error(table: &CubeTable) -> f64 {
    let exact = table.exact().expect("built with its exact model");
    let mut worst: f64 = 0.0;
    for l in 0..=40 {
        let load = RANGE.0 * libm::pow(RANGE.1 / RANGE.0, f64::from(l) / 40.0);
        let p = at(load);
        for k in 0..=256u32 {
            let a = Q1_31::from_bits(((u64::from(k) << 31) / 256).min(i32::MAX as u64) as i32);
            let got = table.ratio(&p, a).unwrap().to_f64();
            let want = exact.ratio(&p, a).unwrap().to_f64();
            worst = worst.max((got - want).abs());
        }
    }
    worst
}

#[test]
fn nodes_are_the_exact_model_exactly() {
    for kind in [ContactKind::Elastic, ContactKind::ElasticPlastic] {
        for side in [3, 5, 9, 17] {
            let t = table(kind, side);
            let (low, high) = t.ln_load_range();
            for row in 0..side {
                let ln = Q6_26::from_bits(low.to_bits() + row as i32 * t.ln_load_step);
                let prepared = t.exact().expect("exact").scene().prepare(ln).unwrap();
                for column in 0..side {
                    let a = t.node_amplitude(column);
                    let want = t
                        .exact()
                        .expect("exact")
                        .ratio_prepared(&prepared, a)
                        .unwrap();
                    assert_eq!(t.node(row, column), Some(want), "{side} {row} {column}");
                }
            }
            assert_eq!(
                high.to_bits(),
                low.to_bits() + (side as i32 - 1) * t.ln_load_step
            );
            assert_eq!(t.node(side, 0), None);
            // The interpolation itself returns a node exactly at the node: first row
            // (load fraction 0), each column's amplitude.
            for column in 0..side {
                let a = t.node_amplitude(column);
                let load = Cell {
                    index: 0,
                    fraction: 0,
                };
                let bits = t.interpolate(load, a.convert::<30>().unwrap().to_bits() as i64);
                assert_eq!(bits as i32, t.nodes[column], "{side} column {column}");
            }
        }
    }
}

#[test]
fn interpolation_error_shrinks_with_the_table_and_meets_its_bound() {
    // Bounds against the exact fixed-point model (N = 16), Al/SS test 1 over 40-240 N:
    // measured (elastic / elastic-plastic) 5.4e-3 / 6.0e-3, 1.4e-3 / 1.6e-3, 3.7e-4 / 4.2e-4
    // for 5, 9, 17 nodes (9.5e-5 / 1.1e-4 at 33, no longer offered): the bilinear error falls 4x per halving of the
    // step (the amplitude curvature dominates).
    for kind in [ContactKind::Elastic, ContactKind::ElasticPlastic] {
        let mut previous = f64::INFINITY;
        for (side, bound) in [(5, 7e-3), (9, 2e-3), (17, 5e-4)] {
            let worst = worst_error(&table(kind, side));
            assert!(worst <= bound, "{kind:?} {side}: {worst:e} > {bound:e}");
            assert!(worst < previous / 3.5, "{kind:?} {side}: {worst:e}");
            previous = worst;
        }
    }
}

#[test]
fn extremes_of_amplitude_and_load() {
    let t = table(ContactKind::ElasticPlastic, 17);
    let exact = t.exact().expect("built with its exact model");
    let (low, high) = t.ln_load_range();
    for load in [
        RANGE.0,
        RANGE.1,
        t.node_load_n(0) * 1.0001,
        t.node_load_n(16) / 1.0001,
    ] {
        let p = at(load);
        assert_eq!(t.covers(p.normal_force), Ok(true), "{load}");
        // Amplitude 0: no vibration, F'/F = 1 exactly (every node of column 0 is 1).
        assert_eq!(t.ratio(&p, Q1_31::ZERO), Ok(Q2_30::ONE));
        let full = t.ratio(&p, Q1_31::MAX).unwrap();
        let want = exact.ratio(&p, Q1_31::MAX).unwrap();
        assert!(
            (full.to_f64() - want.to_f64()).abs() < 5e-5,
            "{load}: {full:?} {want:?}"
        );
    }
    assert!(low.to_f64() < libm::log(RANGE.0) - 0.12 && high.to_f64() > libm::log(RANGE.1) + 0.12);
    // A negative amplitude is an error, not a clamp.
    assert!(t.ratio(&at(100.0), Q1_31::from_bits(-(1 << 20))).is_err());
    // Zero load: ln 0, an error from both paths.
    let zero = OperatingPoint {
        normal_force: Q16_16::ZERO,
        ..at(1.0)
    };
    assert!(t.ratio(&zero, Q1_31::MAX).is_err());
    assert!(t.invert(&zero, Q2_30::from_f64(0.7).unwrap()).is_err());
    assert!(t.covers(Q16_16::ZERO).is_err());
}

#[test]
fn loads_outside_the_range_fall_back_to_the_exact_model() {
    let t = table(ContactKind::ElasticPlastic, 9);
    let exact = t.exact().expect("built with its exact model");
    for load in [1.0, RANGE.0 / 1.2, RANGE.1 * 1.2, 20_000.0] {
        let p = at(load);
        assert_eq!(t.covers(p.normal_force), Ok(false), "{load}");
        for a in [Q1_31::ZERO, Q1_31::from_f64(0.3).unwrap(), Q1_31::MAX] {
            assert_eq!(t.ratio(&p, a), exact.ratio(&p, a), "{load}");
        }
        let target = Q2_30::from_f64(0.7).unwrap();
        assert_eq!(t.invert(&p, target), exact.invert(&p, target), "{load}");
        let hint = Q1_31::from_f64(0.4).unwrap();
        assert_eq!(
            t.invert_from(&p, target, hint),
            exact.invert_from(&p, target, hint),
            "{load}"
        );
    }
    // Inside the range the table answers, and differs from the exact model off the nodes.
    let p = at(100.0);
    let a = Q1_31::from_f64(0.3).unwrap();
    assert_ne!(t.ratio(&p, a), exact.ratio(&p, a));
}

#[test]
fn ratio_is_monotone_in_amplitude_and_inversion_round_trips() {
    for side in [3, 9, 17] {
        let t = table(ContactKind::ElasticPlastic, side);
        for load in [40.0, 57.3, 100.0, 239.9] {
            let p = at(load);
            let mut previous = Q2_30::ONE;
            for k in 0..=1024u32 {
                let a = Q1_31::from_bits(((u64::from(k) << 31) / 1024).min(i32::MAX as u64) as i32);
                let r = t.ratio(&p, a).unwrap();
                assert!(r <= previous, "{side} {load} {k}: {r:?} > {previous:?}");
                previous = r;
            }
            let floor = t.ratio(&p, Q1_31::MAX).unwrap();
            for target in [0.999_9, 0.9, 0.75, 0.6, 0.5, floor.to_f64() + 1e-6] {
                let target = Q2_30::from_f64(target).unwrap();
                let inv = t.invert(&p, target).unwrap();
                assert_eq!(inv.reach, Reach::Reached, "{side} {load} {target:?}");
                // Inside the table the hint changes nothing.
                assert_eq!(t.invert_from(&p, target, Q1_31::MAX), Ok(inv));
                // The returned ratio is the table's at the returned amplitude ...
                assert_eq!(t.ratio(&p, inv.amplitude), Ok(inv.ratio));
                // ... and within 2^-24 of the target (the interpolant's own inverse).
                let gap = (inv.ratio.to_f64() - target.to_f64()).abs();
                assert!(gap <= 1.0 / (1 << 24) as f64, "{side} {load}: {gap:e}");
                // Against the exact model's inverse: the interpolation error moved along the
                // slope (F'/F falls by at least 0.3 per unit amplitude here): a few times the
                // table's ratio error.
                let exact = t.exact().expect("exact").invert(&p, target).unwrap();
                let shift = (inv.amplitude.to_f64() - exact.amplitude.to_f64()).abs();
                let limit = match side {
                    3 => 5e-2,
                    9 => 1e-2,
                    _ => 3e-3,
                };
                assert!(shift < limit, "{side} {load}: {inv:?} vs {exact:?}");
            }
            let above = t.invert(&p, Q2_30::ONE).unwrap();
            assert_eq!(
                (above.reach, above.amplitude, above.ratio),
                (Reach::AboveNatural, Q1_31::ZERO, Q2_30::ONE)
            );
            let below = t.invert(&p, Q2_30::from_f64(0.1).unwrap()).unwrap();
            assert_eq!(
                (below.reach, below.amplitude, below.ratio),
                (Reach::BelowMinimum, Q1_31::MAX, floor)
            );
        }
    }
}

#[test]
fn bad_sides_ranges_and_untabulable_scenes_are_errors() {
    let e = || exact(ContactKind::ElasticPlastic);
    for side in [0, 1, 2, 4, 16, 33, 34, 65] {
        assert!(CubeTable::new(e(), RANGE, side).is_err(), "{side}");
    }
    for range in [
        (240.0, 40.0),
        (0.0, 40.0),
        (-1.0, 40.0),
        (f64::NAN, 40.0),
        (40.0, f64::INFINITY),
        (1e-20, 40.0),
        (40.0, 1e15),
    ] {
        assert!(CubeTable::new(e(), range, 9).is_err(), "{range:?}");
    }
    // A single load is a valid range: the margin gives the axis its width.
    let single = CubeTable::new(e(), (120.0, 120.0), 9).unwrap();
    assert_eq!(single.covers(Q16_16::from_int(120).unwrap()), Ok(true));
    assert_eq!(single.covers(Q16_16::from_int(140).unwrap()), Ok(false));
    // Off the node with an in-phase u the ratio is not monotone: refused.
    let off = CubeModel::new(&test_1(0.02), &CubeOptions::default()).unwrap();
    assert!(CubeTable::new(off, RANGE, 9).is_err());
}

/// Where F'/F is flat over several nodes (a horn that barely vibrates: 1.1 pm, so that the
/// ratio moves by a few Q2.30 ulps over the whole amplitude range), a target equal to the
/// plateau's value is reached at the plateau's first node: the smallest amplitude that
/// reaches it, not the largest.
#[test]
fn a_target_on_a_plateau_is_reached_at_its_smallest_amplitude() {
    let params = crate::model::cube::CubeParams {
        longitudinal_amplitude: 11.46e-6 * 1e-7,
        vertical_amplitude: 1.1e-6 * 1e-7,
        ..test_1(0.0)
    };
    let exact = CubeModel::new(&params, &CubeOptions::default()).unwrap();
    let table = CubeTable::new(exact, RANGE, 17).unwrap();
    let p = at(100.0);
    let ratios: Vec<Q2_30> = (0..17)
        .map(|j| table.ratio(&p, table.node_amplitude(j)).unwrap())
        .collect();
    let (natural, floor) = (ratios[0], ratios[16]);
    let mut plateaus = 0;
    for j in 1..16 {
        let value = ratios[j];
        if ratios[j - 1] > value && ratios[j + 1] == value && value > floor && value < natural {
            plateaus += 1;
            let inversion = table.invert(&p, value).unwrap();
            assert_eq!(
                (inversion.reach, inversion.amplitude, inversion.ratio),
                (Reach::Reached, table.node_amplitude(j), value),
                "plateau from node {j}: {ratios:?}"
            );
        }
    }
    // The case exists at this load (not a test that passes by finding no plateau).
    assert!(plateaus >= 1, "{ratios:?}");
}

/// A table given the nodes `new` computed is `new`'s table; a wrong node count or a row that
/// rises with the amplitude is refused, as `new` refuses one.
#[test]
fn a_table_from_given_nodes_is_the_built_one_and_checks_them() {
    let built = table(ContactKind::ElasticPlastic, 9);
    let nodes = built.nodes().to_vec();
    assert_eq!(nodes.len(), 81);
    let given = CubeTable::with_nodes(exact(ContactKind::ElasticPlastic), RANGE, 9, &nodes);
    assert_eq!(given.as_ref(), Ok(&built));
    let short = CubeTable::with_nodes(exact(ContactKind::ElasticPlastic), RANGE, 9, &nodes[1..]);
    assert!(matches!(
        short,
        Err(ModelError::OutOfDomain {
            input: "table nodes",
            ..
        })
    ));
    let mut rising = nodes.clone();
    rising[9 + 4] = rising[9 + 3] + 1;
    let refused = CubeTable::with_nodes(exact(ContactKind::ElasticPlastic), RANGE, 9, &rising);
    assert!(matches!(
        refused,
        Err(ModelError::OutOfDomain { input: "x", .. })
    ));
}

/// A table from flash alone (the nodes and the contact kind, no exact model: a bare-metal build
/// without `cube-exact`) answers inside the range exactly as the table it was taken from, and
/// refuses a load outside it instead of evaluating or clamping.
#[test]
fn a_table_from_flash_alone_is_the_built_one_inside_and_refuses_outside() {
    for kind in [ContactKind::Elastic, ContactKind::ElasticPlastic] {
        let built = table(kind, 17);
        let flash = CubeTable::from_flash(kind, RANGE, 17, built.nodes()).unwrap();
        assert_eq!(flash.exact(), None);
        assert_eq!(flash.contact_kind(), kind);
        assert_eq!(flash.nodes(), built.nodes());
        assert_eq!(flash.ln_load_range(), built.ln_load_range());
        let target = Q2_30::from_f64(0.7).unwrap();
        let hint = Q1_31::from_f64(0.4).unwrap();
        for load in [RANGE.0 / 1.1, RANGE.0, 100.0, RANGE.1, RANGE.1 * 1.1] {
            let p = at(load);
            assert_eq!(flash.covers(p.normal_force), Ok(true), "{load}");
            for k in 0..=16 {
                let a = Q1_31::from_f64(f64::from(k) / 16.0 * 0.999_999).unwrap();
                assert_eq!(flash.ratio(&p, a), built.ratio(&p, a), "{load} {k}");
            }
            assert_eq!(flash.invert(&p, target), built.invert(&p, target), "{load}");
            assert_eq!(
                flash.invert_from(&p, target, hint),
                built.invert_from(&p, target, hint),
                "{load}"
            );
        }
        let refused = |result: Result<(), ModelError>| {
            matches!(
                result,
                Err(ModelError::OutOfDomain {
                    input: "normal force",
                    ..
                })
            )
        };
        for load in [1.0, RANGE.0 / 1.2, RANGE.1 * 1.2, 20_000.0] {
            let p = at(load);
            assert_eq!(flash.covers(p.normal_force), Ok(false), "{load}");
            // The table it came from answers there (its exact model); this one refuses.
            assert!(built.ratio(&p, Q1_31::MAX).is_ok(), "{load}");
            assert!(refused(flash.ratio(&p, Q1_31::MAX).map(drop)), "{load}");
            assert!(refused(flash.invert(&p, target).map(drop)), "{load}");
            assert!(
                refused(flash.invert_from(&p, target, hint).map(drop)),
                "{load}"
            );
        }
    }
    // The nodes are checked as `with_nodes` checks them.
    let nodes = table(ContactKind::ElasticPlastic, 9).nodes().to_vec();
    assert!(CubeTable::from_flash(ContactKind::ElasticPlastic, RANGE, 9, &nodes[1..]).is_err());
    assert!(CubeTable::from_flash(ContactKind::ElasticPlastic, RANGE, 17, &nodes).is_err());
    assert!(CubeTable::from_flash(ContactKind::ElasticPlastic, RANGE, 6, &nodes).is_err());
}
