use sonolube_host::reference::dahl_models::{DahlSteadyInput, dahl_steady};
use std::f64::consts::PI;

fn r(zeta: f64, tau: f64) -> f64 {
    if zeta <= 0.0 {
        return 0.0;
    }
    if zeta >= 1.0 {
        return 1.0;
    }
    dahl_steady(&DahlSteadyInput {
        friction_coefficient: 1.0,
        normal_load: 1.0,
        tangential_stiffness: tau / zeta,
        sliding_velocity: zeta,
        vibration_velocity: 1.0,
        frequency: 1.0 / (2.0 * PI),
        shape_exponent: 1.0,
    })
    .unwrap()
    .friction_ratio
    .unwrap()
}
fn rw(w: f64, s: f64) -> f64 {
    let z = 1.0 - w * w;
    r(z, z * s.exp2())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let nw: usize = args[1].parse().unwrap(); // fine nodes in w (odd count)
    let s0: f64 = args[2].parse().unwrap();
    let s1: f64 = args[3].parse().unwrap();
    let ns: usize = args[4].parse().unwrap();
    let t = std::time::Instant::now();
    let mut g = vec![0.0; nw * ns];
    let rows: Vec<usize> = (0..nw).collect();
    let chunks: Vec<Vec<usize>> = vec![
        rows.iter().copied().filter(|i| i % 2 == 0).collect(),
        rows.iter().copied().filter(|i| i % 2 == 1).collect(),
    ];
    let res: Vec<Vec<(usize, Vec<f64>)>> = std::thread::scope(|sc| {
        let hs: Vec<_> = chunks
            .iter()
            .map(|c| {
                sc.spawn(move || {
                    c.iter()
                        .map(|&i| {
                            let w = i as f64 / (nw - 1) as f64;
                            (
                                i,
                                (0..ns)
                                    .map(|j| rw(w, s0 + (s1 - s0) * j as f64 / (ns - 1) as f64))
                                    .collect(),
                            )
                        })
                        .collect()
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for v in res {
        for (i, row) in v {
            g[i * ns..(i + 1) * ns].copy_from_slice(&row);
        }
    }
    eprintln!("{} evals in {:?}", nw * ns, t.elapsed());
    // clamp errors: compare edge columns with far values
    for &w in &[0.1, 0.5, 0.9, 0.99] {
        eprintln!(
            "w {w}: R(s0)={:.7} R(s0-6)={:.7} R(s1)={:.7} R(s1+6)={:.7}",
            rw(w, s0),
            rw(w, s0 - 6.0),
            rw(w, s1),
            rw(w, s1 + 6.0)
        );
    }
    // Catmull-Rom on the half grid (every other node), error at skipped nodes (and mid-cells in both)
    let cw = (nw - 1) / 2;
    let cs = (ns - 1) / 2;
    let node = |i: isize, j: isize| -> f64 {
        // coarse node with linear ghost extrapolation
        let ii = i.clamp(0, cw as isize);
        let jj = j.clamp(0, cs as isize);
        let base = |a: isize, b: isize| g[(2 * a as usize) * ns + 2 * b as usize];
        let mut v = base(ii, jj);
        if i < 0 {
            v = 2.0 * base(0, jj) - base(1, jj);
        }
        if i > cw as isize {
            v = 2.0 * base(cw as isize, jj) - base(cw as isize - 1, jj);
        }
        if j < 0 || j > cs as isize {
            let (e, n) = if j < 0 {
                (0, 1)
            } else {
                (cs as isize, cs as isize - 1)
            };
            let f = |a: isize| {
                let aa = a.clamp(0, cw as isize);
                if a < 0 {
                    2.0 * base(0, e) - base(1, e)
                } else if a > cw as isize {
                    2.0 * base(cw as isize, e) - base(cw as isize - 1, e)
                } else {
                    base(aa, e)
                }
            };
            let h = |a: isize| {
                let aa = a.clamp(0, cw as isize);
                if a < 0 {
                    2.0 * base(0, n) - base(1, n)
                } else if a > cw as isize {
                    2.0 * base(cw as isize, n) - base(cw as isize - 1, n)
                } else {
                    base(aa, n)
                }
            };
            v = 2.0 * f(i) - h(i);
        }
        v
    };
    let wts = |t: f64| {
        [
            (-t * t * t + 2.0 * t * t - t) / 2.0,
            (3.0 * t * t * t - 5.0 * t * t + 2.0) / 2.0,
            (-3.0 * t * t * t + 4.0 * t * t + t) / 2.0,
            (t * t * t - t * t) / 2.0,
        ]
    };
    let mut worst = (0.0, 0, 0);
    let mut worst_by_w = vec![0.0f64; nw];
    let mut worst_by_s = vec![0.0f64; ns];
    for fi in 0..nw {
        for fj in 0..ns {
            if fi % 2 == 0 && fj % 2 == 0 {
                continue;
            }
            let (i, tx) = ((fi / 2) as isize, if fi % 2 == 1 { 0.5 } else { 0.0 });
            let (j, ty) = ((fj / 2) as isize, if fj % 2 == 1 { 0.5 } else { 0.0 });
            let (wx, wy) = (wts(tx), wts(ty));
            let mut v = 0.0;
            for a in 0..4 {
                for b in 0..4 {
                    v += wx[a] * wy[b] * node(i - 1 + a as isize, j - 1 + b as isize);
                }
            }
            let e = (v - g[fi * ns + fj]).abs();
            worst_by_w[fi] = worst_by_w[fi].max(e);
            worst_by_s[fj] = worst_by_s[fj].max(e);
            if e > worst.0 {
                worst = (e, fi, fj);
            }
        }
    }
    eprintln!(
        "coarse {}x{} catmull-rom worst {:.2e} at w {} s {}",
        cw + 1,
        cs + 1,
        worst.0,
        worst.1 as f64 / (nw - 1) as f64,
        s0 + (s1 - s0) * worst.2 as f64 / (ns - 1) as f64
    );
    eprintln!(
        "by w: {:?}",
        worst_by_w
            .iter()
            .map(|e| format!("{e:.1e}"))
            .collect::<Vec<_>>()
    );
    eprintln!(
        "by s: {:?}",
        worst_by_s
            .iter()
            .map(|e| format!("{e:.1e}"))
            .collect::<Vec<_>>()
    );
}
