//! `src/model/dahl/dahl_table_nodes.rs`: the nodes of the firmware's Dahl steady-state tables
//! (`sonolube::model::dahl_table`), from the independent f64 reference
//! ([`crate::reference::dahl_models::dahl_steady`]), as Rust source.
//!
//! R = F_avg / (mu W) for alpha = 1 depends on zeta and kappa x_a only (physics-notes §2), so
//! the reference is evaluated on a unit scene: mu = 1, W = 1 N, omega = 1 rad/s, v_a = 1 m/s
//! (x_a = 1 m), v = zeta m/s and k_t = kappa x_a N/m. The table's axes are
//! w = sqrt(1 - zeta) in [0, 1] and y = log2(kappa x_a) in [`LOG2_KXA_MIN`, `LOG2_KXA_MAX`].
//!
//! Besides the nodes, the file holds two helper tables the firmware needs off the reference:
//! - `LOG2_MANTISSA`: log2(1 + k / 256), k = 0..=256, Q4.28 (a maths table: the firmware's
//!   logarithms are a table lookup and one linear interpolation, not a series);
//! - `GUESS`: the start of the inverse's Newton iteration, w at which the finest table's
//!   interpolant (f64, the firmware's own Catmull-Rom on these nodes) reaches a ratio r at
//!   log2 tau = log2(kappa |v| / omega), over sqrt(1 - r) in [0, 1] and log2 tau in [`LOG2_KXA_MIN`,
//!   `LOG2_KXA_MAX`]. Found by bisection on the interpolant: a start only; the inverse's
//!   accuracy is that of its Newton steps on the forward table.
//!
//! `sonolube dahl-table` writes the file; `sonolube dahl-table --check` verifies that the
//! committed one is what this generates.

use std::f64::consts::PI;
use std::fmt::Write as _;

use sonolube::model::dahl_table::{GUESS_TAU, GUESS_U, LOG2_KXA_MAX, LOG2_KXA_MIN, SIDE_W, SIDE_Y};

use crate::reference::dahl_models::{DahlSteadyInput, dahl_steady};

/// Path of the generated file, relative to the repository root.
pub const PATH: &str = "src/model/dahl/dahl_table_nodes.rs";

/// The exact steady-state ratio at zeta <= 1 and kappa x_a > 0 (odd in zeta: reversed
/// sliding reverses the mean force). Errors: the reference's (message).
pub fn exact_ratio_zeta(zeta: f64, kxa: f64) -> Result<f64, String> {
    if zeta < 0.0 {
        return exact_ratio_zeta(-zeta, kxa).map(|r| -r);
    }
    if zeta == 0.0 {
        return Ok(0.0);
    }
    if zeta >= 1.0 {
        return Ok(1.0);
    }
    dahl_steady(&DahlSteadyInput {
        friction_coefficient: 1.0,
        normal_load: 1.0,
        tangential_stiffness: kxa,
        sliding_velocity: zeta,
        vibration_velocity: 1.0,
        frequency: 1.0 / (2.0 * PI),
        shape_exponent: 1.0,
    })
    .map_err(|e| e.to_string())?
    .friction_ratio
    .ok_or_else(|| "the ratio is undefined at zero sliding velocity".to_string())
}

/// The exact steady-state ratio at the table's coordinates w = sqrt(1 - zeta) in [0, 1] and
/// y = log2(kappa x_a). Errors: the reference's (message).
pub fn exact_ratio(w: f64, log2_kxa: f64) -> Result<f64, String> {
    exact_ratio_zeta(1.0 - w * w, log2_kxa.exp2())
}

/// y of node `j` (-1..=SIDE_Y: the ghosts included).
fn node_y(j: isize) -> f64 {
    f64::from(LOG2_KXA_MIN)
        + f64::from(LOG2_KXA_MAX - LOG2_KXA_MIN) * j as f64 / (SIDE_Y - 1) as f64
}

/// The nodes with their ghosts, (SIDE_W + 2)(SIDE_Y + 2) values, w-major, as f64. The ghosts
/// are the reference's values one step beyond each edge (beyond w = 1, zeta < 0: the ratio is
/// odd in zeta), except below w = 0 (zeta > 1 has no continuation of R in w: linear
/// extrapolation). The reference runs on two threads (about 60 us a node).
pub fn padded_nodes() -> Result<Vec<f64>, String> {
    let stride = SIDE_Y + 2;
    let mut n = vec![0.0; (SIDE_W + 2) * stride];
    // Padded rows 1..=SIDE_W + 1: w = 0 .. 1 + 1 / (SIDE_W - 1); columns 0..stride.
    let rows: Vec<Result<Vec<f64>, String>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..2)
            .map(|part| {
                scope.spawn(move || {
                    (0..=SIDE_W)
                        .filter(|i| i % 2 == part)
                        .map(|i| {
                            let w = i as f64 / (SIDE_W - 1) as f64;
                            (0..stride)
                                .map(|j| exact_ratio(w, node_y(j as isize - 1)))
                                .collect()
                        })
                        .collect::<Vec<Result<Vec<f64>, String>>>()
                })
            })
            .collect();
        let parts: Vec<Vec<Result<Vec<f64>, String>>> = handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| vec![Err("thread".into())]))
            .collect();
        (0..=SIDE_W)
            .map(|i| {
                parts[i % 2]
                    .get(i / 2)
                    .cloned()
                    .unwrap_or(Err("row".into()))
            })
            .collect()
    });
    for (i, row) in rows.into_iter().enumerate() {
        for (j, value) in row?.into_iter().enumerate() {
            n[(i + 1) * stride + j] = value;
        }
    }
    for j in 0..stride {
        n[j] = 2.0 * n[stride + j] - n[2 * stride + j];
    }
    Ok(n)
}

/// Catmull-Rom weights at t in [0, 1].
fn weights(t: f64) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        (-t3 + 2.0 * t2 - t) / 2.0,
        (3.0 * t3 - 5.0 * t2 + 2.0) / 2.0,
        (-3.0 * t3 + 4.0 * t2 + t) / 2.0,
        (t3 - t2) / 2.0,
    ]
}

/// The f64 twin of the firmware's interpolant on padded nodes `n`, at w in [0, 1] and y
/// clamped to the table (the stiff extrapolation beyond its top included), for the inverse's
/// start table.
pub fn interpolant(n: &[f64], w: f64, y: f64) -> f64 {
    let stride = SIDE_Y + 2;
    let span = f64::from(LOG2_KXA_MAX - LOG2_KXA_MIN);
    let at = |w: f64, y: f64| {
        let pw = (w * (SIDE_W - 1) as f64).clamp(0.0, (SIDE_W - 1) as f64 - 1e-12);
        let py = ((y - f64::from(LOG2_KXA_MIN)) / span * (SIDE_Y - 1) as f64)
            .clamp(0.0, (SIDE_Y - 1) as f64);
        let (i, j) = (pw.floor() as usize, (py.floor() as usize).min(SIDE_Y - 2));
        let (wx, wy) = (weights(pw - i as f64), weights(py - j as f64));
        let mut r = 0.0;
        for (a, wa) in wx.iter().enumerate() {
            for (b, wb) in wy.iter().enumerate() {
                r += wa * wb * n[(i + a) * stride + j + b];
            }
        }
        r
    };
    let top = f64::from(LOG2_KXA_MAX);
    if y <= top {
        return at(w, y);
    }
    let coulomb = |w: f64| 2.0 / PI * (1.0 - w * w).asin();
    let x = coulomb(w);
    // As the firmware: by similarity in kappa x_a w^3 near the onset, else 1 / kappa x_a.
    let w1 = w * ((y - top) / 3.0).exp2();
    if w < 0.25 && w1 < 1.0 {
        return x + (at(w1, top) - coulomb(w1)) * w / w1;
    }
    x + (at(w, top) - x) * (top - y).exp2()
}

/// The inverse's start table: `GUESS_U` x `GUESS_TAU` values of w, Q0.16 (clamped below
/// 2^16), over u = sqrt(1 - r) (rows) and log2 tau (columns, one per binary order).
pub fn guess(n: &[f64]) -> Vec<u16> {
    let mut out = Vec::with_capacity(GUESS_U * GUESS_TAU);
    for k in 0..GUESS_U {
        let u = k as f64 / (GUESS_U - 1) as f64;
        let r = 1.0 - u * u;
        for l in 0..GUESS_TAU {
            let lt = f64::from(LOG2_KXA_MIN) + l as f64;
            // R falls from 1 at w = 0 to 0 at w = 1 along the curve y = log2 tau - log2 zeta.
            let curve = |w: f64| {
                let zeta = 1.0 - w * w;
                if zeta <= 0.0 {
                    return 0.0;
                }
                interpolant(n, w, lt - zeta.log2())
            };
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if curve(mid) > r {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let w = 0.5 * (lo + hi);
            out.push((w * 65536.0).round().min(65535.0) as u16);
        }
    }
    out
}

fn q(x: f64, frac: u32) -> i32 {
    let scaled = (x * f64::from(1u32 << frac)).round();
    assert!(scaled.abs() < 2f64.powi(31), "{x} does not fit Q.{frac}");
    scaled as i32
}

fn array<T: ToString>(out: &mut String, name: &str, ty: &str, doc: &str, values: &[T]) {
    let _ = writeln!(out, "/// {doc}");
    let _ = writeln!(out, "#[rustfmt::skip]");
    let _ = writeln!(out, "pub static {name}: [{ty}; {}] = [", values.len());
    for chunk in values.chunks(8) {
        let line: Vec<String> = chunk.iter().map(T::to_string).collect();
        let _ = writeln!(out, "    {},", line.join(", "));
    }
    let _ = writeln!(out, "];");
}

/// The file's text. Errors: the reference's (message).
pub fn render() -> Result<String, String> {
    let mut out = String::new();
    out.push_str(
        "//! Nodes of the Dahl steady-state tables (`super::dahl_table`): F_avg / (mu W) for\n\
         //! alpha = 1 over w = sqrt(1 - zeta) and y = log2(kappa x_a), Q1.15 of R - 1/2, w-major, one ghost\n\
         //! node on every side; the inverse's start table; and log2 of the mantissas.\n\
         //!\n\
         //! Generated by `sonolube dahl-table` (`host-tests/src/dahl_table.rs`) from the independent\n\
         //! f64 reference (`host-tests/src/reference/dahl.rs`); do not edit.\n\n",
    );
    let padded = padded_nodes()?;
    let nodes: Vec<i16> = padded
        .iter()
        .map(|&x| {
            let q = ((x - 0.5) * 32768.0).round();
            assert!((-32768.0..32768.0).contains(&q), "node {x} beyond Q1.15");
            q as i16
        })
        .collect();
    array(
        &mut out,
        "NODES",
        "i16",
        &format!(
            "{SIDE_W} x {SIDE_Y} nodes and their ghosts: R - 1/2 in Q1.15 (R = n / 2^15 + 1/2)."
        ),
        &nodes,
    );
    array(
        &mut out,
        "GUESS",
        "u16",
        &format!(
            "Start of the inverse: w (Q0.16) at sqrt(1 - r) = k / {} (rows) and log2 tau = \
             {LOG2_KXA_MIN} + l (columns), from the interpolant of `NODES`.",
            GUESS_U - 1
        ),
        &guess(&padded),
    );
    let log2: Vec<i32> = (0..=256)
        .map(|k| q((1.0 + k as f64 / 256.0).log2(), 28))
        .collect();
    array(
        &mut out,
        "LOG2_MANTISSA",
        "i32",
        "log2(1 + k / 256), k = 0..=256, Q4.28.",
        &log2,
    );
    Ok(out)
}
