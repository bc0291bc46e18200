//! Reference of the motor-effect force (seed 001 §2, §3.2; physics-notes §8), in f64, written
//! from the physics rather than from the fixed-point code: the period average of the
//! instantaneous friction force, integrated over theta in [0, 2 pi) piece by piece between the
//! roots of the relative velocity (found by sampling and bisection, not by acos).
//!
//! - Kinematics (seed 000 eqs 16-17, x from the node): horn face velocity along x
//!   du/dt = A omega sin(pi x / L) P'(theta), vertical displacement v = B cos(pi x/L) cos theta;
//!   P' = cos theta for the elliptical locus (u = A sin theta sin(pi x/L): `quadrature`, the
//!   default here), -sin theta for the straight stroke printed in eqs 16-17 (`inphase`).
//! - Normal contact: the rough-contact law of seed 000 (every term proportional to
//!   e^(-lambda d / R_q), physics-notes §3) at the instantaneous gap d + v, the mean gap set so
//!   that the mean normal force is F_n: N = F_n e^(-lambda v / R_q) / <e^(-lambda v / R_q)>.
//! - Tangential: mu N sgn(du/dt - v_b) on the block (zero when the relative velocity is zero).
//! - Output: F_t = < mu N sgn(du/dt - v_b) > and phi = F_t / (mu F_n), computed as the ratio of
//!   the two period integrals of e^(-lambda v / R_q) (phi involves no load).

use std::f64::consts::PI;

use super::RefError;
use super::cube::UPhase;
use super::error::{finite, non_negative, positive, within};
use super::numerics::{bisect, integrate};

/// Inputs of [`motor_force`], SI units.
#[derive(Debug, Clone, Copy)]
pub struct MotorInput {
    /// mu (> 0).
    pub friction_coefficient: f64,
    /// F_n in N (>= 0).
    pub normal_force: f64,
    /// A in m (>= 0).
    pub longitudinal_amplitude: f64,
    /// B in m (>= 0).
    pub vertical_amplitude: f64,
    /// x in m from the horn centre, |x| <= L/2.
    pub position: f64,
    /// L in m (> 0).
    pub horn_length: f64,
    /// f in Hz (> 0).
    pub frequency: f64,
    /// R_q in m (> 0).
    pub roughness_rq: f64,
    /// lambda (> 0).
    pub distribution_lambda: f64,
    /// Block velocity v_b along +x, m/s.
    pub block_velocity: f64,
}

/// Outputs of [`motor_force`].
#[derive(Debug, Clone, Copy)]
pub struct MotorOutput {
    /// Net tangential force on the block along +x, N.
    pub net_force: f64,
    /// phi = F_t / (mu F_n) in [-1, 1].
    pub drive_ratio: f64,
    /// k = lambda B cos(pi x / L) / R_q.
    pub decay: f64,
    /// Peak face speed along x, A omega |sin(pi x / L)|, m/s.
    pub face_speed: f64,
}

/// Samples per period for locating the roots of the relative velocity (there are at most two).
const ROOT_SAMPLES: usize = 4096;

fn sign(value: f64) -> f64 {
    if value > 0.0 {
        1.0
    } else if value < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The period-averaged net tangential force; see the module docs. Errors: non-finite inputs,
/// mu <= 0, F_n < 0, negative amplitudes, L, f, R_q or lambda <= 0, |x| > L/2.
pub fn motor_force(input: &MotorInput, phase: UPhase) -> Result<MotorOutput, RefError> {
    let mu = positive("mu", input.friction_coefficient)?;
    let load = non_negative("F_n", input.normal_force)?;
    let a = non_negative("A", input.longitudinal_amplitude)?;
    let b = non_negative("B", input.vertical_amplitude)?;
    let length = positive("L", input.horn_length)?;
    let x = within(
        "x",
        input.position,
        -0.5 * length,
        0.5 * length,
        "|x| must be <= L/2",
    )?;
    let f = positive("f", input.frequency)?;
    let rq = positive("Rq", input.roughness_rq)?;
    let lambda = positive("lam", input.distribution_lambda)?;
    let v_b = finite("v_b", input.block_velocity)?;
    let omega = 2.0 * PI * f;
    let (sin_shape, cos_shape) = ((PI * x / length).sin(), (PI * x / length).cos());
    let face = a * omega * sin_shape; // signed peak face velocity
    let vertical = b * cos_shape;
    let weight = |theta: f64| (-lambda * vertical * theta.cos() / rq).exp();
    let relative = |theta: f64| {
        let shape = match phase {
            UPhase::Quadrature => theta.cos(),
            UPhase::InPhase => -theta.sin(),
        };
        face * shape - v_b
    };
    // Breakpoints: 0, the roots of the relative velocity, 2 pi.
    let mut breaks = vec![0.0];
    let step = 2.0 * PI / ROOT_SAMPLES as f64;
    for i in 0..ROOT_SAMPLES {
        let (lo, hi) = (i as f64 * step, (i + 1) as f64 * step);
        let (r_lo, r_hi) = (relative(lo), relative(hi));
        if r_lo != 0.0 && r_hi != 0.0 && (r_lo > 0.0) != (r_hi > 0.0) {
            breaks.push(bisect(relative, lo, hi));
        } else if r_hi == 0.0 && i + 1 < ROOT_SAMPLES {
            breaks.push(hi);
        }
    }
    breaks.push(2.0 * PI);
    let tolerance = 1e-15;
    let mut signed = 0.0;
    let mut total = 0.0;
    for pair in breaks.windows(2) {
        let (lo, hi) = (pair[0], pair[1]);
        let piece = integrate(weight, lo, hi, tolerance)?;
        signed += sign(relative(0.5 * (lo + hi))) * piece;
        total += piece;
    }
    let drive_ratio = signed / total;
    Ok(MotorOutput {
        net_force: mu * load * drive_ratio,
        drive_ratio,
        decay: lambda * vertical / rq,
        face_speed: face.abs(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seed(x: f64, v_b: f64) -> MotorInput {
        MotorInput {
            friction_coefficient: 0.55,
            normal_force: 120.0,
            longitudinal_amplitude: 11.46e-6,
            vertical_amplitude: 1.1e-6,
            position: x,
            horn_length: 0.127,
            frequency: 20e3,
            roughness_rq: 6e-6,
            distribution_lambda: 3.0,
            block_velocity: v_b,
        }
    }

    /// I0 and the modified Struve L0 by their series: for a held block on the ellipse,
    /// phi = -sgn(x) L0(k) / I0(k) (the integral of e^(-k cos) sgn(cos) over a period).
    fn closed_form(k: f64) -> f64 {
        let h = 0.5 * k;
        let (mut i0, mut ti) = (1.0, 1.0);
        let mut tl = h / (0.25 * PI);
        let mut l0 = tl;
        for m in 1..60 {
            let m = m as f64;
            ti *= h * h / (m * m);
            i0 += ti;
            tl *= h * h / ((m + 0.5) * (m + 0.5));
            l0 += tl;
        }
        l0 / i0
    }

    #[test]
    fn held_block_matches_the_struve_closed_form() {
        for &x in &[-0.0381, -0.0254, -0.003, 0.003, 0.0254, 0.05] {
            let o = motor_force(&seed(x, 0.0), UPhase::Quadrature).unwrap();
            let want = -x.signum() * closed_form(o.decay);
            assert!(
                (o.drive_ratio - want).abs() < 1e-13,
                "{x}: {} {want}",
                o.drive_ratio
            );
            assert!((o.net_force - 0.55 * 120.0 * want).abs() < 1e-11);
        }
    }

    #[test]
    fn limits() {
        // Node: no tangential motion; horn end: no vertical motion; straight stroke: symmetric.
        let node = motor_force(&seed(0.0, 0.0), UPhase::Quadrature).unwrap();
        assert_eq!(node.net_force, 0.0);
        let end = motor_force(&seed(0.0635, 0.0), UPhase::Quadrature).unwrap();
        assert!(end.drive_ratio.abs() < 1e-14);
        let line = motor_force(&seed(0.02, 0.0), UPhase::InPhase).unwrap();
        assert!(line.drive_ratio.abs() < 1e-14);
        // A block outrunning the face: plain friction against its motion.
        let fast = motor_force(&seed(0.001, 1.0), UPhase::Quadrature).unwrap();
        assert_eq!(fast.drive_ratio, -1.0);
        // Unloaded: apart over the whole cycle.
        let unloaded = motor_force(
            &MotorInput {
                normal_force: 0.0,
                ..seed(0.02, 0.0)
            },
            UPhase::Quadrature,
        )
        .unwrap();
        assert_eq!(unloaded.net_force, 0.0);
        assert!(motor_force(&seed(0.07, 0.0), UPhase::Quadrature).is_err());
    }
}
