//! Model specifications: which friction model, with which parameters, for the controller and
//! for the plant.

/// A friction model, in the project's order of fidelity (lowest first; [`ModelKind::fidelity`]).
/// A scene's plant always uses a model of higher fidelity than its controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModelKind {
    /// Littmann velocity-ratio law on a rigid Coulomb contact (seed 003 eqs 1-4,
    /// physics-notes §1). Uses `mu` only.
    Coulomb,
    /// Exponential (Stribeck-like) Coulomb law averaged over the vibration (seed 002 eq 10).
    /// Uses `mu` (= mu_d), `mu_static`, `decay_s_per_m`.
    ExpCoulomb,
    /// Dahl compliant contact under vibration, periodic steady state (seed 003 eqs 5-7,
    /// physics-notes §2). Uses `mu`, `k_t_n_per_m`, `dahl_alpha`.
    Dahl,
    /// Cube model on a purely elastic rough contact (seed 001 eqs 11-14 as corrected in
    /// physics-notes §3). Uses `mu` and `surface`, and the scene's horn.
    CubeElastic,
    /// Cube model on the elastic-plastic rough contact (seed 000 eqs 1-17, physics-notes §3-4).
    /// Uses `mu` and `surface`, and the scene's horn.
    CubeElasticPlastic,
}

impl ModelKind {
    /// Rank in the fidelity order, 0 (Coulomb) ..= 4 (elastic-plastic cube).
    pub const fn fidelity(self) -> u8 {
        match self {
            ModelKind::Coulomb => 0,
            ModelKind::ExpCoulomb => 1,
            ModelKind::Dahl => 2,
            ModelKind::CubeElastic => 3,
            ModelKind::CubeElasticPlastic => 4,
        }
    }
}

/// Rough-surface and material parameters of the cube models (seed 000 Table 2 gives
/// R_q = 6 um, R_s = 1.7 um, A_n = 1e-4 m^2, eta = 47e9 /m^2, c = 17, lambda = 3,
/// Al 73 GPa / 0.33, SS 200 GPa / 0.29, Y0 = 410 MPa).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RoughSurface {
    /// Standard deviation of asperity heights R_q, m, (0, 1e-3].
    pub rq_m: f64,
    /// Asperity summit radius R_s, m, (0, 1e-3].
    pub rs_m: f64,
    /// Nominal contact area A_n, m^2, (0, 1].
    pub nominal_area_m2: f64,
    /// Areal asperity density eta, 1/m^2, (0, 1e15].
    pub asperity_density_per_m2: f64,
    /// Exponential height-distribution constant c (dimensionless), (0, 1e3].
    pub distribution_c: f64,
    /// Exponential height-distribution constant lambda (dimensionless), (0, 100].
    pub distribution_lambda: f64,
    /// Young's modulus of body 1 (the horn), Pa, (0, 1e13].
    pub young_1_pa: f64,
    /// Poisson's ratio of body 1, (-1, 0.5].
    pub poisson_1: f64,
    /// Young's modulus of body 2 (the block), Pa, (0, 1e13].
    pub young_2_pa: f64,
    /// Poisson's ratio of body 2, (-1, 0.5].
    pub poisson_2: f64,
    /// Poisson's ratio of the softer material (seed 000 eq 1), (-1, 0.5].
    pub poisson_soft: f64,
    /// Failure strength Y0 of the softer material, Pa, (0, 1e11].
    pub yield_strength_pa: f64,
}

/// A friction model and its own parameters. Which parameters a kind needs is listed on
/// [`ModelKind`]; the others may be given (a controller's belief about the contact, used if a
/// later choice of model needs them) and are then validated the same way.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ModelSpec {
    /// Which model.
    pub kind: ModelKind,
    /// Kinetic (dynamic) friction coefficient mu, (0, 2] (mu_d of the exponential law).
    pub mu: f64,
    /// Static coefficient mu_s of the exponential law, [mu, 2].
    pub mu_static: Option<f64>,
    /// Exponential decay coefficient alpha_dc, s/m, [0, 1e3] (seed 002 Table 1: 0.01).
    pub decay_s_per_m: Option<f64>,
    /// Tangential contact stiffness k_t, N/m, (0, 1e13] (seed 003: 0.056 N/um = 5.6e4).
    pub k_t_n_per_m: Option<f64>,
    /// Dahl shape exponent alpha, (0, 4] (seed 003 takes 1; filled in as 1 for Dahl).
    pub dahl_alpha: Option<f64>,
    /// Rough contact of the cube models.
    pub surface: Option<RoughSurface>,
}

impl ModelSpec {
    /// Natural (undriven) friction coefficient at sliding speed `speed_m_per_s` (>= 0):
    /// mu_d + (mu_s - mu_d) e^(-alpha_dc |v|) for the exponential law (seed 002 eq 10), `mu`
    /// for every other model.
    pub fn natural_coefficient(&self, speed_m_per_s: f64) -> f64 {
        match (self.kind, self.mu_static, self.decay_s_per_m) {
            (ModelKind::ExpCoulomb, Some(mu_s), Some(decay)) => {
                self.mu + (mu_s - self.mu) * libm::exp(-decay * libm::fabs(speed_m_per_s))
            }
            _ => self.mu,
        }
    }
}

/// Plant parameters over controller parameters, derived from the two specs by the loader:
/// the model error that feedback has to remove besides the difference of model kinds.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Mismatch {
    /// mu_plant / mu_controller, > 0 (1.2 is a plant with 20 % more friction).
    pub mu_ratio: f64,
    /// k_t plant / k_t controller, > 0, when both specs give k_t.
    pub k_t_ratio: Option<f64>,
    /// R_q plant / R_q controller, > 0, when both specs give a surface.
    pub rq_ratio: Option<f64>,
}
