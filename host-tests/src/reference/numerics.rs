//! Numerical building blocks of the reference: converged quadrature, bisection and the few
//! special functions the papers need, each written to keep full double precision where a naive
//! formula would cancel (physics-notes §1 and §3).

use std::f64::consts::PI;
use std::sync::OnceLock;

use super::RefError;

/// Number of Gauss-Legendre nodes of the basic rule used by [`integrate`].
const GL_ORDER: usize = 20;

/// Nodes and weights of the `GL_ORDER`-point Gauss-Legendre rule on [-1, 1], computed once by
/// Newton iteration on the Legendre polynomial (three-term recurrence), converged to 1 ulp.
fn gauss_legendre() -> &'static [(f64, f64); GL_ORDER] {
    static RULE: OnceLock<[(f64, f64); GL_ORDER]> = OnceLock::new();
    RULE.get_or_init(|| {
        let n = GL_ORDER as f64;
        let mut rule = [(0.0, 0.0); GL_ORDER];
        for (i, slot) in rule.iter_mut().enumerate() {
            // Tricomi's initial guess for the i-th root (descending order).
            let mut x = (PI * (i as f64 + 0.75) / (n + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0_f64, x);
                for k in 2..=GL_ORDER {
                    let k = k as f64;
                    let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                derivative = n * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / derivative;
                x -= step;
                if step.abs() <= 1e-17 {
                    break;
                }
            }
            *slot = (x, 2.0 / ((1.0 - x * x) * derivative * derivative));
        }
        rule
    })
}

/// Fixed `GL_ORDER`-point Gauss-Legendre estimate of the integral of `f` over [a, b].
fn gauss_fixed(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64) -> f64 {
    let half = 0.5 * (b - a);
    let mid = 0.5 * (b + a);
    gauss_legendre()
        .iter()
        .map(|&(x, w)| w * f(mid + half * x))
        .sum::<f64>()
        * half
}

/// Largest number of subintervals [`integrate`] may visit before it reports non-convergence.
const INTERVAL_BUDGET: usize = 400_000;

/// Adaptive Gauss-Legendre quadrature of `f` over `[a, b]` (a <= b).
///
/// An interval is accepted when its 20-point estimate and the sum of the estimates on its two
/// halves differ by less than its share of `abs_tol` (or by less than a few ulps of the value,
/// the rounding floor). The error of an accepted interval is then far below that difference
/// (the rule has degree 39), so the result is converged to `abs_tol` for smooth integrands and
/// resolves boundary layers by local bisection. Non-finite integrand values or an exhausted
/// budget give [`RefError::NotConverged`].
pub fn integrate(
    mut f: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    abs_tol: f64,
) -> Result<f64, RefError> {
    if b <= a {
        return Ok(0.0);
    }
    let mut visited = 0usize;
    let mut total = 0.0;
    // Explicit stack: (left, right, estimate on the interval, tolerance share).
    let whole = gauss_fixed(&mut f, a, b);
    let mut stack = vec![(a, b, whole, abs_tol)];
    while let Some((lo, hi, coarse, tol)) = stack.pop() {
        visited += 1;
        if visited > INTERVAL_BUDGET || !coarse.is_finite() {
            return Err(RefError::NotConverged("adaptive Gauss-Legendre quadrature"));
        }
        let mid = 0.5 * (lo + hi);
        let left = gauss_fixed(&mut f, lo, mid);
        let right = gauss_fixed(&mut f, mid, hi);
        let fine = left + right;
        let floor = 64.0 * f64::EPSILON * (left.abs() + right.abs());
        if (fine - coarse).abs() <= tol.max(floor) || mid <= lo || mid >= hi {
            total += fine;
        } else {
            stack.push((lo, mid, left, 0.5 * tol));
            stack.push((mid, hi, right, 0.5 * tol));
        }
    }
    if total.is_finite() {
        Ok(total)
    } else {
        Err(RefError::NotConverged("adaptive Gauss-Legendre quadrature"))
    }
}

/// Root of a continuous function with `g(lo)` and `g(hi)` of opposite signs (or zero), by
/// bisection until the bracket cannot shrink in f64 (about 1 ulp). Returns the midpoint.
pub fn bisect(mut g: impl FnMut(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let g_lo = g(lo);
    if g_lo == 0.0 {
        return lo;
    }
    let lo_negative = g_lo < 0.0;
    for _ in 0..2200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo.min(hi) || mid >= lo.max(hi) {
            break;
        }
        let value = g(mid);
        if value == 0.0 {
            return mid;
        }
        if (value < 0.0) == lo_negative {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `acos(z)` for z in [-1, 1] as `2 atan2(sqrt(1 - z), sqrt(1 + z))`: accurate to a few ulps
/// also near z = +-1, where `acos` has an infinite slope (physics-notes §1 half-angle advice).
pub fn acos_stable(z: f64) -> f64 {
    let z = z.clamp(-1.0, 1.0);
    2.0 * (1.0 - z).sqrt().atan2((1.0 + z).sqrt())
}

/// `sin(h) - h` without cancellation: Taylor series below |h| = 0.5, direct above.
pub fn sin_minus_identity(h: f64) -> f64 {
    if h.abs() >= 0.5 {
        return h.sin() - h;
    }
    // -h^3/3! + h^5/5! - ...
    let h2 = h * h;
    let mut term = -h * h2 / 6.0;
    let mut sum = term;
    let mut k = 3.0;
    while term.abs() > 1e-18 * sum.abs() {
        term *= -h2 / ((2.0 * k - 2.0) * (2.0 * k - 1.0));
        sum += term;
        k += 1.0;
    }
    sum
}

/// `1 - cos(h)` without cancellation, as `2 sin^2(h / 2)`.
pub fn one_minus_cos(h: f64) -> f64 {
    let s = (0.5 * h).sin();
    2.0 * s * s
}

/// `sin(phi) - phi cos(phi)` for phi in [0, pi]: the travel of one monotone half of the Dahl
/// drive (see `dahl`), which behaves like phi^3 / 3 at small phi. Series
/// `sum_k (-1)^(k+1) 2k phi^(2k+1) / (2k+1)!` below phi = 0.5, direct above.
pub fn sin_minus_phi_cos(phi: f64) -> f64 {
    if phi >= 0.5 {
        return phi.sin() - phi * phi.cos();
    }
    let p2 = phi * phi;
    // k = 1 term: 2 phi^3 / 3!
    let mut power_over_factorial = phi * p2 / 6.0; // phi^(2k+1) / (2k+1)!
    let mut sum = 2.0 * power_over_factorial;
    let mut k = 1.0_f64;
    loop {
        k += 1.0;
        power_over_factorial *= -p2 / ((2.0 * k) * (2.0 * k + 1.0));
        let term = 2.0 * k * power_over_factorial;
        sum += term;
        if term.abs() <= 1e-18 * sum.abs() {
            break;
        }
    }
    sum
}

/// Lower incomplete gamma function gamma(s, x) = integral_0^x t^(s-1) e^(-t) dt, for s > 0 and
/// x >= 0, by the positive-term series `x^s e^(-x) sum_k x^k / (s (s+1) ... (s+k))`, which has
/// no cancellation (physics-notes §3: the bracket of seed 000 eq 4 is gamma(5/2, X) and that
/// of the corrected eq 7 is gamma(2, X)). Valid for x <= 600 (series sum stays finite).
pub fn lower_gamma_series(s: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let mut term = 1.0 / s;
    let mut sum = term;
    let mut k = 0.0;
    while k < 5000.0 {
        k += 1.0;
        term *= x / (s + k);
        sum += term;
        if term <= 1e-18 * sum {
            break;
        }
    }
    (s * x.ln() - x + sum.ln()).exp()
}

/// Gamma(5/2) = 3 sqrt(pi) / 4.
pub const GAMMA_5_2: f64 = 1.329_340_388_179_137;

/// gamma(5/2, X): the bracket of seed 000 eq 4 (physics-notes §3). Series up to X = 40;
/// above, Gamma(5/2) - (X^1.5 + 1.5 X^0.5) e^(-X), the dropped erfc term being < 1e-18.
pub fn gamma_lower_5_2(x: f64) -> f64 {
    if x <= 40.0 {
        lower_gamma_series(2.5, x)
    } else {
        GAMMA_5_2 - (x * x.sqrt() + 1.5 * x.sqrt()) * (-x).exp()
    }
}

/// gamma(2, X) = 1 - (1 + X) e^(-X): the bracket of seed 000 eq 7 with its sign typo corrected
/// (physics-notes §3). Series up to X = 40 (it is about X^2 / 2 at small X), direct above.
pub fn gamma_lower_2(x: f64) -> f64 {
    if x <= 40.0 {
        lower_gamma_series(2.0, x)
    } else {
        1.0 - (1.0 + x) * (-x).exp()
    }
}

/// Error function, as gamma(1/2, x^2) / sqrt(pi) (used only by the cross-checks that evaluate
/// the printed form of seed 000 eq 4 where it does not cancel).
pub fn erf(x: f64) -> f64 {
    let x2 = x * x;
    let magnitude = if x2 > 40.0 {
        1.0
    } else {
        lower_gamma_series(0.5, x2) / PI.sqrt()
    };
    magnitude.copysign(x)
}
