//! Unit checks of the numerical building blocks against independent methods and known values.

use std::f64::consts::PI;

use super::numerics::{
    GAMMA_5_2, acos_stable, bisect, erf, gamma_lower_2, gamma_lower_5_2, integrate,
    lower_gamma_series, one_minus_cos, sin_minus_identity, sin_minus_phi_cos,
};

/// Composite Simpson rule with `n` (even) intervals: an independent quadrature.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|k| f(a + h * k as f64) * if k % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + inner + f(b)) * h / 3.0
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

#[test]
fn gamma_5_2_series_matches_quadrature_at_small_x() {
    // gamma(5/2, X) = integral_0^sqrt(X) 2 s^4 e^(-s^2) ds (t = s^2 removes the t^1.5 cusp).
    for x in [1e-8, 2.143_676e-4, 1e-2, 0.3, 1.0, 4.0] {
        let root = f64::sqrt(x);
        let quadrature = simpson(|s| 2.0 * s.powi(4) * (-s * s).exp(), 0.0, root, 4000);
        assert!(close(gamma_lower_5_2(x), quadrature, 1e-12), "X = {x}");
    }
    // Leading term 0.4 X^2.5 (physics-notes §3).
    let x = 2e-4;
    assert!(close(gamma_lower_5_2(x), 0.4 * x.powf(2.5), 2e-4));
}

#[test]
fn gamma_series_matches_printed_forms_where_they_do_not_cancel() {
    for x in [0.5, 1.0, 3.0, 10.0, 30.0, 39.9, 40.1, 80.0] {
        let root = f64::sqrt(x);
        let printed_eq4 = 0.75 * PI.sqrt() * erf(root) - (x * root + 1.5 * root) * (-x).exp();
        assert!(
            close(gamma_lower_5_2(x), printed_eq4, 1e-13),
            "eq 4 at X = {x}"
        );
        let printed_eq7 = 1.0 - (1.0 + x) * (-x).exp();
        assert!(
            close(gamma_lower_2(x), printed_eq7, 1e-13),
            "eq 7 at X = {x}"
        );
    }
    assert!(close(gamma_lower_5_2(700.0), GAMMA_5_2, 1e-15));
    assert!(close(
        lower_gamma_series(1.0, 2.0),
        1.0 - (-2.0f64).exp(),
        1e-14
    ));
}

#[test]
fn gamma_2_series_matches_quadrature_at_small_x() {
    for x in [1e-9, 2.143_676e-4, 0.1, 2.0] {
        let quadrature = simpson(|t| t * (-t).exp(), 0.0, x, 2000);
        assert!(close(gamma_lower_2(x), quadrature, 1e-12), "X = {x}");
    }
}

#[test]
fn erf_known_values() {
    assert!(close(erf(1.0), 0.842_700_792_949_714_9, 1e-15));
    assert!(close(erf(0.5), 0.520_499_877_813_046_5, 1e-15));
    assert!(close(erf(-2.0), -0.995_322_265_018_952_7, 1e-15));
    assert_eq!(erf(0.0), 0.0);
    assert_eq!(erf(10.0), 1.0);
}

#[test]
fn series_helpers_match_direct_forms_where_safe() {
    for phi in [0.3, 0.45, 0.499, 0.501, 1.0, 2.0, PI] {
        let direct = phi.sin() - phi * phi.cos();
        assert!(close(sin_minus_phi_cos(phi), direct, 1e-13), "phi = {phi}");
    }
    assert!(close(sin_minus_phi_cos(1e-4), 1e-12 / 3.0, 1e-8));
    for h in [-0.7, -0.3, 0.2, 0.49, 0.51, 3.0] {
        let h: f64 = h;
        assert!(close(sin_minus_identity(h), h.sin() - h, 1e-13), "h = {h}");
        assert!(close(one_minus_cos(h), 1.0 - h.cos(), 1e-13), "h = {h}");
    }
    for z in [-0.9, -0.5, 0.0, 0.3, 0.9] {
        let z: f64 = z;
        assert!(close(acos_stable(z), z.acos(), 1e-15), "z = {z}");
    }
    // Near 1: acos(1 - e) = sqrt(2 e) (1 + e/12 + ...).
    let e = 1e-12;
    assert!(close(
        acos_stable(1.0 - e),
        (2.0 * e).sqrt() * (1.0 + e / 12.0),
        1e-3
    ));
    assert_eq!(acos_stable(1.0), 0.0);
    assert_eq!(acos_stable(-1.0), PI);
}

#[test]
fn adaptive_quadrature_with_graded_breaks_resolves_narrow_layers() {
    // A boundary layer of width 1e-6 in [0, 1], split where (t/w)^2 = 1, 4, 16, 64, 256 as the
    // Dahl stretches are (a lone fixed rule on [0, 1] would not see it at all).
    let width = 1e-6;
    let exact = width * 0.5 * PI.sqrt();
    let mut total = 0.0;
    let mut start = 0.0;
    for end in [
        width,
        2.0 * width,
        4.0 * width,
        8.0 * width,
        16.0 * width,
        1.0,
    ] {
        total += integrate(|t| (-(t / width).powi(2)).exp(), start, end, 1e-18).unwrap();
        start = end;
    }
    assert!(close(total, exact, 1e-13));
    let smooth = integrate(f64::cos, 0.0, 1.0, 1e-16).unwrap();
    assert!(close(smooth, 1f64.sin(), 1e-15));
    assert!(integrate(|_| f64::NAN, 0.0, 1.0, 1e-12).is_err());
}

#[test]
fn bisection_reaches_one_ulp() {
    let root = bisect(|x| x * x - 2.0, 0.0, 2.0);
    assert!((root - 2f64.sqrt()).abs() <= 2.0 * f64::EPSILON);
    let decreasing = bisect(|x| 1.0 - x, 0.0, 3.0);
    assert!((decreasing - 1.0).abs() <= 2.0 * f64::EPSILON);
}
