//! Scene-load constants of the rough contact, in f64 (seed 000 eqs 1-8; physics-notes §3).
//!
//! Computed once per scene, never in the control step. Eqs 4 and 5 are dimensionless and scaled
//! by A_n E*; the bracket of eq 4 is the lower incomplete gamma function gamma(5/2, X) and the
//! corrected bracket of eq 7 is gamma(2, X) = 1 - (1 + X) e^(-X) (sign typo), X = lambda
//! omega_c / R_q. For X ~ 2e-4 (Al/SS) the printed forms are differences of O(1) terms equal to
//! about 3e-10: they are evaluated by their series (physics-notes §3).

use core::f64::consts::PI;

use super::ModelError;

/// Rule for the combined modulus E*.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EStarRule {
    /// 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (seed 000 after eq 1; default).
    #[default]
    Seed000,
    /// 1/E* = 1/E1 + 1/E2 (seed 001 after eq 13; variant).
    Seed001,
}

/// Which contact model gives d(F_n) and A_r(F_n).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ContactKind {
    /// Elastic-plastic, seed 000 eqs 1-8 (default).
    #[default]
    ElasticPlastic,
    /// Purely elastic: omega_c -> infinity in eqs 4 and 7 (= corrected seed 001 eqs 13-14).
    Elastic,
}

/// Material and surface parameters in SI units (seed 000 Table 2 gives them for aluminium on
/// stainless steel: [`ContactParams::SEED_000_TABLE_2_AL_ON_SS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactParams {
    /// Standard deviation of asperity heights R_q in m (> 0).
    pub roughness_rq: f64,
    /// Asperity summit radius R_s in m (> 0).
    pub summit_radius: f64,
    /// Nominal contact area A_n in m^2 (> 0).
    pub nominal_area: f64,
    /// Areal asperity density eta in 1/m^2 (> 0).
    pub asperity_density: f64,
    /// Height-distribution constant c (> 0; 17 in seed 000 eq 2).
    pub distribution_c: f64,
    /// Height-distribution constant lambda (> 0; 3 in seed 000 eq 2), in (2^-30, 2^30).
    pub distribution_lambda: f64,
    /// Young's modulus of body 1 in Pa (> 0).
    pub young_1: f64,
    /// Poisson's ratio of body 1, in (-1, 0.5].
    pub poisson_1: f64,
    /// Young's modulus of body 2 in Pa (> 0).
    pub young_2: f64,
    /// Poisson's ratio of body 2, in (-1, 0.5].
    pub poisson_2: f64,
    /// Poisson's ratio of the softer material, in (-1, 0.5] (eq 1, C_nu, eq 5; elastic-plastic
    /// only, not read by the elastic model).
    pub poisson_soft: f64,
    /// Failure strength Y0 of the softer material in Pa (> 0; elastic-plastic only).
    pub yield_strength: f64,
}

impl ContactParams {
    /// Seed 000 (Dong & Dapino, elastic-plastic cube model) Table 2: aluminium (body 1, the
    /// softer) on stainless steel (body 2), SI units. The one definition of these numbers in
    /// the firmware core; the f64 reference in host-tests keeps its own copy
    /// (`sonolube_host::papers::AL_SS`) so that the two are written independently.
    pub const SEED_000_TABLE_2_AL_ON_SS: Self = Self {
        // R_q = 6 um, R_s = 1.7 um, A_n = 1e-4 m^2, eta = 47e9 /m^2.
        roughness_rq: 6e-6,
        summit_radius: 1.7e-6,
        nominal_area: 1e-4,
        asperity_density: 47e9,
        // Exponential height distribution (eq 2): c = 17, lambda = 3.
        distribution_c: 17.0,
        distribution_lambda: 3.0,
        // Al: E = 73 GPa, nu = 0.33; SS: E = 200 GPa, nu = 0.29.
        young_1: 73e9,
        poisson_1: 0.33,
        young_2: 200e9,
        poisson_2: 0.29,
        // Al is the softer material: its nu, and Y0 = 410 MPa.
        poisson_soft: 0.33,
        yield_strength: 410e6,
    };
}

/// The load-independent constants of a contact (f64, SI units): every force is
/// `constant * e^(-lambda d / R_q)` and so is every area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneContact {
    /// Model variant.
    pub kind: ContactKind,
    /// Combined modulus E* in Pa.
    pub e_star: f64,
    /// Critical interference omega_c in m (eq 1; infinite for the elastic model).
    pub critical_interference: f64,
    /// X = lambda omega_c / R_q (infinite for the elastic model).
    pub interference_ratio: f64,
    /// Elastic force constant F_e e^(lambda d / R_q) in N (eq 4 times A_n E*).
    pub elastic_force: f64,
    /// Plastic force constant in N (eq 5 times A_n E*, e^(-X) included; 0 when elastic).
    pub plastic_force: f64,
    /// Elastic area constant in m^2 (eq 7, corrected).
    pub elastic_area: f64,
    /// Plastic area constant in m^2 (eq 8, e^(-X) included; 0 when elastic).
    pub plastic_area: f64,
    /// ln(K_F / 1 N), K_F = elastic_force + plastic_force.
    pub ln_force_constant: f64,
    /// Mean real contact pressure p_eff = F_n / A_r in Pa (602 MPa elastic-plastic, 36.5 GPa
    /// elastic for Al/SS, physics-notes §3).
    pub mean_pressure: f64,
    /// ln(p_eff A_n / 1 N): the load at which A_r = A_n.
    pub ln_full_area_load: f64,
    /// R_q in m.
    pub roughness_rq: f64,
    /// A_n in m^2.
    pub nominal_area: f64,
    /// lambda.
    pub distribution_lambda: f64,
}

/// `value` if finite, else `NonFinite`.
pub(crate) fn finite(input: &'static str, value: f64) -> Result<f64, ModelError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ModelError::NonFinite { input })
    }
}

/// `value` if finite and > 0.
pub(crate) fn positive(input: &'static str, value: f64) -> Result<f64, ModelError> {
    if finite(input, value)? > 0.0 {
        Ok(value)
    } else {
        Err(ModelError::OutOfDomain {
            input,
            reason: "must be > 0",
        })
    }
}

/// `value` if finite and >= 0.
pub(crate) fn non_negative(input: &'static str, value: f64) -> Result<f64, ModelError> {
    if finite(input, value)? >= 0.0 {
        Ok(value)
    } else {
        Err(ModelError::OutOfDomain {
            input,
            reason: "must be >= 0",
        })
    }
}

/// A Poisson ratio in (-1, 0.5].
pub(crate) fn poisson(input: &'static str, value: f64) -> Result<f64, ModelError> {
    if finite(input, value)? > -1.0 && value <= 0.5 {
        Ok(value)
    } else {
        Err(ModelError::OutOfDomain {
            input,
            reason: "a Poisson ratio must be in (-1, 0.5]",
        })
    }
}

/// Gamma(5/2) = 3 sqrt(pi) / 4: the bracket of eq 4 as X -> infinity.
const GAMMA_5_2: f64 = 1.329_340_388_179_137;

/// Lower incomplete gamma function gamma(s, x) for s > 0, x >= 0: the series
/// x^s e^(-x) sum_k x^k / (s (s+1) ... (s+k)) below x = 1 (where the closed forms cancel),
/// the closed forms above (s = 2 and s = 5/2 only, the two the contact needs).
pub(crate) fn lower_gamma(s: f64, x: f64) -> f64 {
    if x <= 1.0 {
        let mut term = 1.0 / s;
        let mut sum = term;
        let mut k = 1.0;
        while term > 1e-18 * sum && k < 200.0 {
            term *= x / (s + k);
            sum += term;
            k += 1.0;
        }
        libm::pow(x, s) * libm::exp(-x) * sum
    } else if s == 2.0 {
        1.0 - (1.0 + x) * libm::exp(-x)
    } else {
        let root = libm::sqrt(x);
        GAMMA_5_2 * libm::erf(root) - root * (x + 1.5) * libm::exp(-x)
    }
}

/// Validates `p` and computes the scene's contact constants.
pub(crate) fn scene_contact(
    p: &ContactParams,
    rule: EStarRule,
    kind: ContactKind,
) -> Result<SceneContact, ModelError> {
    let rq = positive("Rq", p.roughness_rq)?;
    let rs = positive("Rs", p.summit_radius)?;
    let an = positive("An", p.nominal_area)?;
    let eta = positive("eta", p.asperity_density)?;
    let c = positive("c", p.distribution_c)?;
    let lam = positive("lam", p.distribution_lambda)?;
    let e1 = positive("E1", p.young_1)?;
    let e2 = positive("E2", p.young_2)?;
    let nu1 = poisson("nu1", p.poisson_1)?;
    let nu2 = poisson("nu2", p.poisson_2)?;
    let e_star = match rule {
        EStarRule::Seed000 => 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2),
        EStarRule::Seed001 => 1.0 / (1.0 / e1 + 1.0 / e2),
    };
    let beta = eta * rq * rs; // roughness parameter (seed 000 after eq 4)
    let area_scale = c * PI * beta * an / (lam * lam); // eqs 7-8 prefactor
    // Eq 4 prefactor times A_n E*: 4 c beta (R_q / R_s)^(1/2) / (3 lambda^(5/2)).
    let elastic_scale =
        an * e_star * 4.0 * c * beta * libm::sqrt(rq / rs) / (3.0 * libm::pow(lam, 2.5));
    let (omega_c, x, fe, fp, ae, ap) = match kind {
        ContactKind::Elastic => (
            f64::INFINITY,
            f64::INFINITY,
            elastic_scale * GAMMA_5_2,
            0.0,
            area_scale,
            0.0,
        ),
        ContactKind::ElasticPlastic => {
            let nu = poisson("nu_soft", p.poisson_soft)?;
            let y0 = positive("Y0", p.yield_strength)?;
            let hardness = 1.234 + 1.256 * nu; // C_nu (seed 000 after eq 1)
            let root = hardness * PI * (1.0 - nu * nu) * y0 / (2.0 * e_star);
            let omega_c = root * root * rs; // eq 1
            let x = lam * omega_c / rq;
            let tail = (2.0 + x) * libm::exp(-x);
            // Eq 5 times A_n E* (the E* of its denominator cancels).
            let plastic = an * c * PI * beta * hardness * (1.0 - nu * nu) * y0 / (lam * lam);
            (
                omega_c,
                x,
                elastic_scale * lower_gamma(2.5, x),
                plastic * tail,
                area_scale * lower_gamma(2.0, x),
                area_scale * tail,
            )
        }
    };
    let force_constant = fe + fp;
    let area_constant = ae + ap;
    let ln_force_constant = libm::log(force_constant);
    let ln_full_area_load = ln_force_constant - libm::log(area_constant) + libm::log(an);
    let ok = [e_star, fe, fp, ae, ap, ln_force_constant, ln_full_area_load]
        .iter()
        .all(|v| v.is_finite())
        && force_constant > 0.0
        && area_constant > 0.0;
    if !ok {
        return Err(ModelError::Overflow {
            quantity: "contact constants (K_F, K_A) for these materials",
        });
    }
    Ok(SceneContact {
        kind,
        e_star,
        critical_interference: omega_c,
        interference_ratio: x,
        elastic_force: fe,
        plastic_force: fp,
        elastic_area: ae,
        plastic_area: ap,
        ln_force_constant,
        mean_pressure: force_constant / area_constant,
        ln_full_area_load,
        roughness_rq: rq,
        nominal_area: an,
        distribution_lambda: lam,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn incomplete_gamma_series_and_closed_forms_agree() {
        // Near x = 1 both branches are accurate: compare them.
        for &x in &[0.9, 0.99, 1.0] {
            let closed2 = 1.0 - (1.0 + x) * libm::exp(-x);
            assert!((lower_gamma(2.0, x) / closed2 - 1.0).abs() < 1e-14);
            let r = libm::sqrt(x);
            let closed52 = GAMMA_5_2 * libm::erf(r) - r * (x + 1.5) * libm::exp(-x);
            assert!((lower_gamma(2.5, x) / closed52 - 1.0).abs() < 1e-13);
        }
        // Small x: gamma(s, x) ~ x^s / s.
        let x = 2e-4;
        assert!((lower_gamma(2.0, x) / (x * x / 2.0) - 1.0).abs() < 2e-4);
        assert!((lower_gamma(2.5, x) / (libm::pow(x, 2.5) / 2.5) - 1.0).abs() < 2e-4);
        assert!((lower_gamma(2.5, 60.0) / GAMMA_5_2 - 1.0).abs() < 1e-15);
    }

    #[test]
    fn validation_names_the_input() {
        let p = ContactParams::SEED_000_TABLE_2_AL_ON_SS;
        let ep = (EStarRule::Seed000, ContactKind::ElasticPlastic);
        assert!(scene_contact(&p, ep.0, ep.1).is_ok());
        let bad = ContactParams {
            poisson_2: 0.6,
            ..p
        };
        assert!(matches!(
            scene_contact(&bad, ep.0, ep.1),
            Err(ModelError::OutOfDomain { input: "nu2", .. })
        ));
        let nan = ContactParams {
            yield_strength: f64::NAN,
            ..p
        };
        assert_eq!(
            scene_contact(&nan, ep.0, ep.1),
            Err(ModelError::NonFinite { input: "Y0" })
        );
        // The elastic model never reads nu_soft or Y0.
        assert!(scene_contact(&nan, EStarRule::Seed001, ContactKind::Elastic).is_ok());
    }
}
