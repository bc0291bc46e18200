//! Readers for the string-keyed inputs and variants of [`super::eval_named`]: every key read is
//! remembered, so that unknown keys can be reported instead of silently ignored.

use std::collections::{BTreeMap, BTreeSet};

use super::RefError;
use super::contact::{ContactParameters, ContactState, EStarRule};
use super::cube::UPhase;
use super::error::finite;
use super::named::Outputs;

/// Reads inputs by key, remembering which were read so that leftovers can be reported.
pub(crate) struct Inputs<'a> {
    pub model: &'static str,
    pub map: &'a BTreeMap<String, f64>,
    pub read: BTreeSet<&'static str>,
}

impl Inputs<'_> {
    pub(crate) fn get(&mut self, key: &'static str) -> Result<f64, RefError> {
        self.read.insert(key);
        let value = *self.map.get(key).ok_or(RefError::MissingInput {
            model: self.model,
            key,
        })?;
        finite(key, value)
    }

    pub(crate) fn get_or(&mut self, key: &'static str, default: f64) -> Result<f64, RefError> {
        if self.map.contains_key(key) {
            self.get(key)
        } else {
            self.read.insert(key);
            Ok(default)
        }
    }

    pub(crate) fn finish(self) -> Result<(), RefError> {
        match self
            .map
            .keys()
            .find(|key| !self.read.contains(key.as_str()))
        {
            Some(key) => Err(RefError::UnknownInput {
                model: self.model,
                key: key.clone(),
            }),
            None => Ok(()),
        }
    }
}

/// Reads variant choices; keys a model does not declare are errors.
pub(crate) struct Variants<'a> {
    pub model: &'static str,
    pub map: &'a BTreeMap<String, String>,
    pub read: BTreeSet<&'static str>,
}

impl Variants<'_> {
    /// The value of `key` among `choices` (first = default when absent).
    pub(crate) fn choose<T: Copy>(
        &mut self,
        key: &'static str,
        choices: &[(&str, T)],
        allowed: &'static str,
    ) -> Result<T, RefError> {
        self.read.insert(key);
        let Some(text) = self.map.get(key) else {
            return Ok(choices[0].1);
        };
        choices
            .iter()
            .find(|(name, _)| name == text)
            .map(|&(_, value)| value)
            .ok_or_else(|| RefError::UnknownVariantValue {
                key,
                value: text.clone(),
                allowed,
            })
    }

    /// `quadrature_points`: a whole number N >= 1. The reference accepts and validates it but
    /// always uses its converged adaptive integral instead of an N-point rule.
    pub(crate) fn quadrature_points(&mut self) -> Result<(), RefError> {
        self.read.insert("quadrature_points");
        match self.map.get("quadrature_points") {
            Some(text) if !matches!(text.trim().parse::<u32>(), Ok(n) if n >= 1) => {
                Err(RefError::UnknownVariantValue {
                    key: "quadrature_points",
                    value: text.clone(),
                    allowed: "a whole number >= 1",
                })
            }
            _ => Ok(()),
        }
    }

    pub(crate) fn e_star_rule(&mut self) -> Result<EStarRule, RefError> {
        self.choose(
            "E_star_rule",
            &[
                ("seed000", EStarRule::Seed000),
                ("seed001", EStarRule::Seed001),
            ],
            "seed000 (default), seed001",
        )
    }

    pub(crate) fn u_phase(&mut self) -> Result<UPhase, RefError> {
        self.choose(
            "u_phase",
            &[
                ("inphase", UPhase::InPhase),
                ("quadrature", UPhase::Quadrature),
            ],
            "inphase (default), quadrature",
        )
    }

    pub(crate) fn finish(self) -> Result<(), RefError> {
        match self
            .map
            .keys()
            .find(|key| !self.read.contains(key.as_str()))
        {
            Some(key) => Err(RefError::UnknownVariantKey {
                model: self.model,
                key: key.clone(),
            }),
            None => Ok(()),
        }
    }
}

/// Contact parameters from the input map; `nu_soft` and `Y0` are optional (NaN, never read)
/// for the purely elastic model.
pub(crate) fn contact_parameters(
    inputs: &mut Inputs<'_>,
    elastic_only: bool,
) -> Result<ContactParameters, RefError> {
    let mut soft = |key| {
        if elastic_only {
            inputs.get_or(key, f64::NAN)
        } else {
            inputs.get(key)
        }
    };
    let poisson_soft = soft("nu_soft")?;
    let yield_strength = soft("Y0")?;
    Ok(ContactParameters {
        roughness_rq: inputs.get("Rq")?,
        summit_radius: inputs.get("Rs")?,
        nominal_area: inputs.get("An")?,
        asperity_density: inputs.get("eta")?,
        distribution_c: inputs.get("c")?,
        distribution_lambda: inputs.get("lam")?,
        young_1: inputs.get("E1")?,
        poisson_1: inputs.get("nu1")?,
        young_2: inputs.get("E2")?,
        poisson_2: inputs.get("nu2")?,
        poisson_soft,
        yield_strength,
    })
}

pub(crate) fn contact_outputs(
    state: &ContactState,
    plastic_detail: bool,
    nominal_area: f64,
) -> Outputs {
    let mut out = Outputs::from([
        ("E_star", state.constants.e_star),
        ("d", state.separation),
        ("A_r", state.real_area),
        ("K_t", state.tangential_stiffness),
        ("ln_KF", state.constants.ln_force_constant),
    ]);
    if plastic_detail {
        out.extend([
            ("omega_c", state.constants.critical_interference),
            ("X", state.constants.x),
            ("p_c", state.mean_pressure()),
            ("A_e", state.elastic_area),
            ("A_p", state.plastic_area),
            ("F_e", state.elastic_force),
            ("F_p", state.plastic_force),
            ("A_r_over_An", state.real_area / nominal_area),
        ]);
    }
    out
}
