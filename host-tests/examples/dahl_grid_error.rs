//! The error of a Dahl steady-state table of a given shape before it is built (how
//! `src/model/dahl/dahl_table.rs` was sized, `docs/dahl.md`): the f64 Catmull-Rom bicubic on
//! `SW` x `SY` reference nodes over w = sqrt(1 - zeta) in [0, 1] and log2(kappa x_a) in
//! [`YMIN`, `YMAX`], against the f64 reference at three points per cell in each direction.
//! Ghost nodes linear, or with `EXACT=1` the reference's own values one step beyond the edges
//! (w = 1 by the ratio's odd symmetry in zeta; w = 0 stays linear), as the firmware's table.
//!
//!     cargo run --release -p sonolube-host --example dahl_grid_error -- 49 73 -16 8
//!     EXACT=1 cargo run --release -p sonolube-host --example dahl_grid_error -- 49 73 -16 8

use sonolube_host::dahl_table::exact_ratio;

fn weights(t: f64) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        (-t3 + 2.0 * t2 - t) / 2.0,
        (3.0 * t3 - 5.0 * t2 + 2.0) / 2.0,
        (-3.0 * t3 + 4.0 * t2 + t) / 2.0,
        (t3 - t2) / 2.0,
    ]
}

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("SW SY YMIN YMAX as numbers"))
        .collect();
    let [sw, sy, ymin, ymax] = args[..] else {
        eprintln!("usage: dahl_grid_error SW SY YMIN YMAX");
        std::process::exit(2);
    };
    let (sw, sy) = (sw as usize, sy as usize);
    let exact = std::env::var_os("EXACT").is_some();
    // Beyond w = 1 zeta < 0: `exact_ratio` answers by the odd symmetry.
    let reference = |w: f64, y: f64| exact_ratio(w, y).expect("the reference converges");
    let y_of = |j: f64| ymin + (ymax - ymin) * j / (sy - 1) as f64;
    let stride = sy + 2;
    let mut n = vec![0.0; (sw + 2) * stride];
    for i in 0..sw {
        for j in 0..sy {
            n[(i + 1) * stride + j + 1] = reference(i as f64 / (sw - 1) as f64, y_of(j as f64));
        }
    }
    for j in 1..=sy {
        n[j] = 2.0 * n[stride + j] - n[2 * stride + j];
        n[(sw + 1) * stride + j] = if exact {
            reference(1.0 + 1.0 / (sw - 1) as f64, y_of(j as f64 - 1.0))
        } else {
            2.0 * n[sw * stride + j] - n[(sw - 1) * stride + j]
        };
    }
    for i in 0..sw + 2 {
        let row = i * stride;
        if exact && i > 0 {
            let w = (i as f64 - 1.0) / (sw - 1) as f64;
            n[row] = reference(w, y_of(-1.0));
            n[row + sy + 1] = reference(w, y_of(sy as f64));
        } else {
            n[row] = 2.0 * n[row + 1] - n[row + 2];
            n[row + sy + 1] = 2.0 * n[row + sy] - n[row + sy - 1];
        }
    }
    let (lo, hi) = n
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    println!("nodes with ghosts within {lo:.4} .. {hi:.4}");
    let mut worst = (0.0, 0.0, 0.0);
    let (mut by_w, mut by_y) = ([0.0f64; 8], [0.0f64; 8]);
    let m = 3;
    for a in 0..(sw - 1) * m {
        for b in 0..(sy - 1) * m {
            let pw = (a as f64 + 0.5) / m as f64;
            let py = (b as f64 + 0.5) / m as f64;
            let (i, j) = (pw.floor() as usize, py.floor() as usize);
            let (wx, wy) = (weights(pw - i as f64), weights(py - j as f64));
            let mut r = 0.0;
            for (p, wp) in wx.iter().enumerate() {
                for (q, wq) in wy.iter().enumerate() {
                    r += wp * wq * n[(i + p) * stride + j + q];
                }
            }
            let (w, y) = (pw / (sw - 1) as f64, y_of(py));
            let e = (r - reference(w, y)).abs();
            if e > worst.0 {
                worst = (e, w, y);
            }
            let bw = ((w * 8.0) as usize).min(7);
            let by = (((y - ymin) / (ymax - ymin) * 8.0) as usize).min(7);
            by_w[bw] = by_w[bw].max(e);
            by_y[by] = by_y[by].max(e);
        }
    }
    let show = |v: &[f64; 8]| v.map(|e| format!("{e:.1e}")).join(" ");
    println!(
        "max error {:.2e} at w {:.4}, log2 kappa x_a {:.3}",
        worst.0, worst.1, worst.2
    );
    println!("max error by eighths of w: {}", show(&by_w));
    println!("max error by eighths of y: {}", show(&by_y));
}
