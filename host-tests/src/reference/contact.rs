//! Rough-surface contact: elastic-plastic (seed 000 eqs 1-8) and purely elastic (their
//! omega_c -> infinity limit, equal to seed 001 eqs 13-14 as corrected in physics-notes §3),
//! and the cube tangential stiffness K_t = E* A_r^2 / d^3 (seed 000 eq 9).
//!
//! Every force and area term is a constant times E = e^(-lambda d / R_q), so
//! F_n = K_F E and A_r = K_A E exactly: d = (R_q / lambda) ln(K_F / F_n) and A_r = F_n / p_eff
//! with p_eff = K_F / K_A (physics-notes §3). Eqs 4 and 5 are dimensionless and scaled by
//! A_n E*; the bracket of eq 7 is 1 - (1 + X) e^(-X) (sign typo corrected). The brackets are
//! the incomplete gamma functions gamma(5/2, X) and gamma(2, X), evaluated by their series.

use std::f64::consts::PI;

use super::RefError;
use super::error::{positive, within};
use super::numerics::{GAMMA_5_2, gamma_lower_2, gamma_lower_5_2};

/// Rule for the combined modulus E*.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EStarRule {
    /// 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (seed 000, default; variant value `seed000`).
    #[default]
    Seed000,
    /// 1/E* = 1/E1 + 1/E2 (seed 001 eq 13 text; variant value `seed001`).
    Seed001,
}

/// Which contact model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactModel {
    /// Elastic-plastic, seed 000 eqs 1-8 (default; variant value `ep`).
    #[default]
    ElasticPlastic,
    /// Purely elastic: omega_c -> infinity in eqs 4 and 7 (= seed 001 eqs 13-14; value `el`).
    Elastic,
}

/// Material and surface parameters (seed 000 Table 2 gives R_q = 6 um, R_s = 1.7 um,
/// A_n = 1e-4 m^2, eta = 47e9 /m^2, c = 17, lambda = 3, Al 73 GPa / 0.33, SS 200 GPa / 0.29,
/// Y0 = 410 MPa).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactParameters {
    /// Standard deviation of asperity heights R_q in m (> 0).
    pub roughness_rq: f64,
    /// Asperity summit radius R_s in m (> 0).
    pub summit_radius: f64,
    /// Nominal contact area A_n in m^2 (> 0).
    pub nominal_area: f64,
    /// Areal asperity density eta in 1/m^2 (> 0).
    pub asperity_density: f64,
    /// Exponential height-distribution constant c (> 0; 17 in seed 000).
    pub distribution_c: f64,
    /// Exponential height-distribution constant lambda (> 0; 3 in seed 000).
    pub distribution_lambda: f64,
    /// Young's modulus of body 1 in Pa (> 0).
    pub young_1: f64,
    /// Poisson's ratio of body 1, in (-1, 0.5].
    pub poisson_1: f64,
    /// Young's modulus of body 2 in Pa (> 0).
    pub young_2: f64,
    /// Poisson's ratio of body 2, in (-1, 0.5].
    pub poisson_2: f64,
    /// Poisson's ratio of the softer material, in (-1, 0.5] (eq 1, C_nu and eq 5).
    pub poisson_soft: f64,
    /// Failure strength Y0 of the softer material in Pa (> 0; unused by the elastic model).
    pub yield_strength: f64,
}

/// Load-independent constants of a contact: F_n = `force_constant` E, areas = constant x E.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactConstants {
    /// Combined modulus E* in Pa.
    pub e_star: f64,
    /// Critical interference omega_c in m (eq 1; infinite for the elastic model).
    pub critical_interference: f64,
    /// X = lambda omega_c / R_q (dimensionless).
    pub x: f64,
    /// Elastic force constant in N (eq 4 times A_n E*, without e^(-lambda d/R_q)).
    pub elastic_force: f64,
    /// Plastic force constant in N (eq 5 times A_n E*, including e^(-X)).
    pub plastic_force: f64,
    /// Elastic area constant in m^2 (eq 7, corrected).
    pub elastic_area: f64,
    /// Plastic area constant in m^2 (eq 8, including e^(-X)).
    pub plastic_area: f64,
    /// ln K_F, K_F = elastic_force + plastic_force in N.
    pub ln_force_constant: f64,
}

/// Contact state at one separation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState {
    /// Load-independent constants.
    pub constants: ContactConstants,
    /// Separation (cube height) d in m.
    pub separation: f64,
    /// Normal force F_n = F_e + F_p in N.
    pub normal_force: f64,
    /// Elastic part F_e in N.
    pub elastic_force: f64,
    /// Plastic part F_p in N.
    pub plastic_force: f64,
    /// Elastic real contact area A_e in m^2.
    pub elastic_area: f64,
    /// Plastic real contact area A_p in m^2.
    pub plastic_area: f64,
    /// Real contact area A_r = A_e + A_p in m^2.
    pub real_area: f64,
    /// Tangential cube stiffness K_t = E* A_r^2 / d^3 in N/m (seed 000 eq 9).
    pub tangential_stiffness: f64,
}

impl ContactState {
    /// Mean real contact pressure p_eff = F_n / A_r in Pa (load independent; reported as
    /// `p_c`).
    pub fn mean_pressure(&self) -> f64 {
        self.normal_force / self.real_area
    }
}

/// Validates the parameters and returns the load-independent constants.
pub fn contact_constants(
    p: &ContactParameters,
    rule: EStarRule,
    model: ContactModel,
) -> Result<ContactConstants, RefError> {
    let rq = positive("Rq", p.roughness_rq)?;
    let rs = positive("Rs", p.summit_radius)?;
    let an = positive("An", p.nominal_area)?;
    let eta = positive("eta", p.asperity_density)?;
    let c = positive("c", p.distribution_c)?;
    let lam = positive("lam", p.distribution_lambda)?;
    let e1 = positive("E1", p.young_1)?;
    let e2 = positive("E2", p.young_2)?;
    let poisson = "Poisson's ratio must be in (-1, 0.5]";
    let nu1 = within("nu1", p.poisson_1, -1.0 + f64::EPSILON, 0.5, poisson)?;
    let nu2 = within("nu2", p.poisson_2, -1.0 + f64::EPSILON, 0.5, poisson)?;
    let e_star = match rule {
        EStarRule::Seed000 => 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2),
        EStarRule::Seed001 => 1.0 / (1.0 / e1 + 1.0 / e2),
    };
    let beta = eta * rq * rs; // roughness parameter (seed 000 after eq 4)
    let area_scale = c * PI * beta * an / (lam * lam);
    // Eq 4 prefactor times A_n E*: 4 c beta (R_q/R_s)^(1/2) / (3 lambda^(5/2)).
    let elastic_prefactor = an * e_star * 4.0 * c * beta * (rq / rs).sqrt() / (3.0 * lam.powf(2.5));
    let constants = match model {
        ContactModel::Elastic => ContactConstants {
            e_star,
            critical_interference: f64::INFINITY,
            x: f64::INFINITY,
            elastic_force: elastic_prefactor * GAMMA_5_2,
            plastic_force: 0.0,
            elastic_area: area_scale,
            plastic_area: 0.0,
            ln_force_constant: (elastic_prefactor * GAMMA_5_2).ln(),
        },
        ContactModel::ElasticPlastic => {
            let nu = within("nu_soft", p.poisson_soft, -1.0 + f64::EPSILON, 0.5, poisson)?;
            let y0 = positive("Y0", p.yield_strength)?;
            let hardness_c = 1.234 + 1.256 * nu; // C_nu (seed 000 after eq 1)
            let plastic_pressure = hardness_c * (1.0 - nu * nu) * y0;
            let root = hardness_c * PI * (1.0 - nu * nu) * y0 / (2.0 * e_star);
            let omega_c = root * root * rs; // eq 1
            let x = lam * omega_c / rq;
            let exp_x = (-x).exp();
            // Eq 5 times A_n E*: the E* of its denominator cancels.
            let plastic_force =
                an * c * PI * beta * plastic_pressure / (lam * lam) * (2.0 + x) * exp_x;
            let elastic_force = elastic_prefactor * gamma_lower_5_2(x);
            ContactConstants {
                e_star,
                critical_interference: omega_c,
                x,
                elastic_force,
                plastic_force,
                elastic_area: area_scale * gamma_lower_2(x),
                plastic_area: area_scale * (2.0 + x) * exp_x,
                ln_force_constant: (elastic_force + plastic_force).ln(),
            }
        }
    };
    let all_finite = [
        constants.e_star,
        constants.elastic_force,
        constants.plastic_force,
        constants.elastic_area,
        constants.plastic_area,
        constants.ln_force_constant,
    ]
    .iter()
    .all(|value| value.is_finite());
    if !all_finite || constants.elastic_force + constants.plastic_force <= 0.0 {
        return Err(RefError::ModelValidity(
            "contact constants overflow or vanish for these material/surface parameters".into(),
        ));
    }
    Ok(constants)
}

/// Builds the state at separation d from E = e^(-lambda d / R_q), checking validity.
fn state_at(
    constants: ContactConstants,
    separation: f64,
    exp_factor: f64,
    nominal_area: f64,
) -> Result<ContactState, RefError> {
    if separation.is_nan() || separation <= 0.0 {
        return Err(RefError::ModelValidity(format!(
            "separation d = {separation:e} m <= 0: the load exceeds K_F = e^{:.4} N, beyond the \
             exponential contact model",
            constants.ln_force_constant
        )));
    }
    let elastic_area = constants.elastic_area * exp_factor;
    let plastic_area = constants.plastic_area * exp_factor;
    let real_area = elastic_area + plastic_area;
    if real_area > nominal_area {
        return Err(RefError::ModelValidity(format!(
            "real contact area {real_area:e} m^2 exceeds the nominal area {nominal_area:e} m^2"
        )));
    }
    let elastic_force = constants.elastic_force * exp_factor;
    let plastic_force = constants.plastic_force * exp_factor;
    Ok(ContactState {
        constants,
        separation,
        normal_force: elastic_force + plastic_force,
        elastic_force,
        plastic_force,
        elastic_area,
        plastic_area,
        real_area,
        tangential_stiffness: constants.e_star * real_area * real_area
            / (separation * separation * separation),
    })
}

/// Contact state under the normal force F_n in N (> 0): d = (R_q/lambda) ln(K_F / F_n).
pub fn contact_from_force(
    normal_force: f64,
    p: &ContactParameters,
    rule: EStarRule,
    model: ContactModel,
) -> Result<ContactState, RefError> {
    let normal_force = positive("F_n", normal_force)?;
    let constants = contact_constants(p, rule, model)?;
    let rq_over_lambda = p.roughness_rq / p.distribution_lambda;
    let separation = rq_over_lambda * (constants.ln_force_constant - normal_force.ln());
    // E = F_n / K_F exactly; written through the logarithm so that K_F never overflows.
    let exp_factor = (normal_force.ln() - constants.ln_force_constant).exp();
    state_at(constants, separation, exp_factor, p.nominal_area)
}

/// Contact state at the separation d in m (> 0): the forward map F_n(d) of seed 000 eqs 3-8.
pub fn contact_from_separation(
    separation: f64,
    p: &ContactParameters,
    rule: EStarRule,
    model: ContactModel,
) -> Result<ContactState, RefError> {
    let separation = positive("d", separation)?;
    let constants = contact_constants(p, rule, model)?;
    let exp_factor = (-p.distribution_lambda * separation / p.roughness_rq).exp();
    state_at(constants, separation, exp_factor, p.nominal_area)
}
