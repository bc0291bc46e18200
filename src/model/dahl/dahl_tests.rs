//! The beyond-Coulomb branch of the exact Dahl update (|f| > 1: a seed 000 transient started
//! from |delta0| > F_t0 / K_t) against the f64 reference, on a dense grid (issue 18).
//!
//! Bound, in units of Q2.30 (2^-30): the weight e^-y is `exp_neg`'s correctly rounded value
//! (<= 0.75 ulp), multiplied by |f - s| <= 3, and `lerp` rounds once (0.5): 2.75 ulp. The
//! rounding of both steps is to nearest, so the signed errors average out: the mean over the
//! grid is a small fraction of an ulp, where a weight rounded down would pull every result
//! toward s by half an ulp of the weight times |f - s| (a mean of about -1 ulp here).

use super::dahl::update;
use crate::fx::{Q2_30, Q8_24};
use std::vec::Vec;

const ULP: f64 = 1.0 / (1u64 << 30) as f64;

/// Signed errors (ulp) of `update` against `s + (f - s) e^-y` at the quantized y.
fn errors() -> Vec<f64> {
    let mut errors = Vec::new();
    // f beyond the Coulomb level on both sides, both directions of travel: |f - s| from 0 to 3.
    let states = (1..=97).flat_map(|i| {
        let x = 1.0 + i as f64 / 97.0 * 0.999_999;
        [x, -x]
    });
    for f in states {
        let fq = Q2_30::from_f64(f).unwrap();
        for forward in [true, false] {
            let s = if forward { 1.0 } else { -1.0 };
            // Travels below 2 in Q2.30 (the table and polynomial path), larger ones in Q8.24
            // (the reduction by k ln2).
            for j in 0..=211 {
                let y = 1e-6 + 1.999 * (j as f64 / 211.0).powi(2);
                let yq = Q2_30::from_f64(y).unwrap();
                let got = update(fq, forward, yq).unwrap().to_f64();
                let want = s + (fq.to_f64() - s) * (-yq.to_f64()).exp();
                errors.push((got - want) / ULP);
            }
            for y in [2.0, 2.7, 3.3, 5.0, 7.1, 11.0, 20.0] {
                let yq = Q8_24::from_f64(y).unwrap();
                let got = update(fq, forward, yq).unwrap().to_f64();
                let want = s + (fq.to_f64() - s) * (-yq.to_f64()).exp();
                errors.push((got - want) / ULP);
            }
        }
    }
    errors
}

#[test]
fn beyond_coulomb_update_is_within_2_75_ulp_and_unbiased() {
    let errors = errors();
    let worst = errors.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    eprintln!(
        "beyond-Coulomb Dahl update: {} cases, worst {worst:.3} ulp, mean {mean:.3} ulp",
        errors.len()
    );
    assert!(worst <= 2.75, "worst {worst} ulp");
    assert!(mean.abs() <= 0.25, "mean {mean} ulp");
}

#[test]
fn beyond_coulomb_states_relax_monotonically_toward_s() {
    // Each step moves f toward s and never past it, at every travel, from either side.
    for (f0, forward) in [(1.999, false), (-2.0, true), (1.5, true), (-1.25, false)] {
        let s = if forward { 1.0 } else { -1.0 };
        let mut f = Q2_30::from_f64(f0).unwrap();
        let step = Q2_30::from_f64(0.01).unwrap();
        for _ in 0..2_000 {
            let next = update(f, forward, step).unwrap();
            let (d_old, d_new) = ((f.to_f64() - s).abs(), (next.to_f64() - s).abs());
            assert!(d_new <= d_old, "{f0} {forward}: {f:?} -> {next:?}");
            assert!(
                (next.to_f64() - s) * (f.to_f64() - s) >= 0.0,
                "{f0}: crossed s"
            );
            f = next;
        }
        // 2000 steps of 0.01 is e^-20 (6e-9 ulp of the start): f ends where one more step
        // would move it by less than half an ulp, 0.5 / (1 - e^-0.01) = 50.3 ulp from s, and
        // rounding to nearest holds it there (no drift past s).
        let left = (f.to_f64() - s).abs() / ULP;
        let stall = 0.5 / (1.0 - (-step.to_f64()).exp());
        assert!(left <= stall + 1.0, "{f0}: {left} ulp from s");
    }
}
