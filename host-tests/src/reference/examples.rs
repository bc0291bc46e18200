//! A valid example input set for every model, taken from the papers' parameters (seed 000
//! Tables 1-2 for contact and cube, seed 003 Tables 1-2 for Coulomb, Dahl and actuator, seed 002
//! Table 1 for the exponential law). Useful as a template for the command-line tool and as the
//! seed of the fuzzing tests.

use std::collections::BTreeMap;

use super::RefError;

/// Seed 000 Table 2, aluminium on stainless steel (SI units): the f64 reference's own copy,
/// [`crate::papers::AL_SS`].
const CONTACT_AL_SS: &[(&str, f64)] = crate::papers::AL_SS;

/// A valid input map for `model` (SI units), or [`RefError::UnknownModel`].
#[rustfmt::skip]
pub fn example_inputs(model: &str) -> Result<BTreeMap<String, f64>, RefError> {
    let own: &[(&str, f64)] = match model {
        "littmann_mu_i" => &[("zeta", 0.5564)],
        "coulomb_avg_friction" => &[("mu", 0.2), ("W", 0.54), ("v", 0.038), ("x_a", 0.2718e-6), ("f", 40e3)],
        "coulomb_sampled_avg_sign" => &[("v", 0.038), ("v_a", 0.0683), ("f", 40e3), ("dt", 1e-7), ("Tw", 1e-3)],
        "dahl_steady" => &[("mu", 0.2), ("W", 0.54), ("k_t", 5.6e4), ("v", 0.038), ("v_a", 0.0683), ("f", 40e3), ("alpha", 1.0)],
        "dahl_window" => &[("mu", 0.2), ("W", 0.54), ("k_t", 5.6e4), ("v", 0.038), ("v_a", 0.0683), ("f", 40e3), ("Tw", 1e-3), ("f0", 1.0)],
        "dahl_delta_transient" => &[("F_t0", 21.6), ("K_t", 4.42e10), ("v_rel", 0.005), ("t", 1e-7), ("delta0", 0.0)],
        "contact_ep" | "contact_el" => &[("F_n", 40.0)],
        "contact_ep_of_d" => &[("d", 18e-6)],
        "cube_reduction" => &[("F_n", 40.0), ("mu", 0.54), ("A", 11.46e-6), ("B", 1.1e-6), ("x", 0.0), ("L", 0.127), ("f", 20e3)],
        "horn_kinematics" => &[("x", 0.01), ("t", 1e-5), ("A", 11.46e-6), ("B", 1.1e-6), ("f", 20e3), ("L", 0.127)],
        "B_from_A" => &[("A", 11.46e-6), ("D", 25.4e-3), ("nu", 0.33), ("L", 0.127)],
        "exp_coulomb_law" => &[("mu_s", 0.42), ("mu_d", 0.32), ("alpha_dc", 0.01), ("Vs", 0.11), ("F_N", 15.0)],
        // Seed 003 Table 1: the f64 reference's own copy, independent of the firmware's
        // `sonolube::model::actuator::ActuatorParams::SEED_003_TABLE_1`.
        "actuator" => &[("V", 3.0), ("f", 40e3), ("n", 62.0), ("d33", 730e-12), ("C", 300e-9), ("K_stack", 3.14e8),
                        ("K_bolt", 3.7e7), ("V_max", 15.466), ("I_max", 1.75)],
        // Seed 001 §3.2: the block held at point -1 (1 in left of the centreline), 120 N.
        "motor_force" => &[("F_n", 120.0), ("mu", 0.55), ("A", 11.46e-6), ("B", 1.1e-6), ("x", -0.0254), ("L", 0.127),
                           ("f", 20e3), ("Rq", 6e-6), ("lam", 3.0), ("v_b", 0.0)],
        other => return Err(RefError::UnknownModel(other.to_string())),
    };
    let contact = model.starts_with("contact") || model == "cube_reduction";
    let shared: &[(&str, f64)] = if contact { CONTACT_AL_SS } else { &[] };
    Ok(shared.iter().chain(own).map(|&(key, value)| (key.to_string(), value)).collect())
}
