//! Whole-plot tests: every SVG produced is checked by a small well-formedness checker (balanced
//! tags, one root, quoted attributes, escaped text), for realistic and for hostile input.

use super::wellformed::check_well_formed;
use super::*;
/// Deterministic pseudo-random numbers in -1..1 (64-bit LCG), for noisy test signals.
fn noise(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A synthetic closed-loop scene (100 000 samples over 2 s): an integral controller drives the
/// amplitude so friction `0.45 * load * (1 - 0.8 amplitude)` tracks a stepped target; the load
/// steps at 1.2 s (the injected fault); the estimate is noisy, with a glitch and a dropout.
struct Scene {
    t: Vec<f64>,
    target: Vec<f64>,
    estimated: Vec<f64>,
    truth: Vec<f64>,
    amplitude: Vec<f64>,
    load: Vec<f64>,
}

fn scene() -> Scene {
    let n = 100_000;
    let dt = 2.0 / n as f64;
    let mut s = Scene {
        t: vec![],
        target: vec![],
        estimated: vec![],
        truth: vec![],
        amplitude: vec![],
        load: vec![],
    };
    let (mut amplitude, mut rng) = (0.0_f64, 7_u64);
    for i in 0..n {
        let t = i as f64 * dt;
        let target = if t < 0.5 {
            0.8
        } else if t < 1.4 {
            0.5
        } else {
            0.7
        };
        let load = if t < 1.2 { 2.0 } else { 2.6 } + 0.01 * noise(&mut rng);
        let truth = 0.45 * load * (1.0 - 0.8 * amplitude);
        let mut estimated = truth + 0.006 * noise(&mut rng);
        if i == 61_234 {
            estimated += 0.3;
        }
        if (80_000..80_050).contains(&i) {
            estimated = f64::NAN;
        }
        amplitude = (amplitude + 40.0 * (truth - target) * dt).clamp(0.0, 1.0);
        for (v, x) in [
            (&mut s.t, t),
            (&mut s.target, target),
            (&mut s.estimated, estimated),
        ] {
            v.push(x);
        }
        for (v, x) in [
            (&mut s.truth, truth),
            (&mut s.amplitude, amplitude),
            (&mut s.load, load),
        ] {
            v.push(x);
        }
    }
    s
}

fn scene_plot(s: &Scene) -> TimeSeriesPlot<'_> {
    TimeSeriesPlot::new("Scene: friction steps with a load fault at 1.2 s")
        .x_label("time (s)")
        .panel(
            Panel::new("friction", "N")
                .band(Band::around("target ±2 %", &s.t, &s.target, 0.02).color("#0072b2"))
                .series(
                    Series::line("target", &s.t, &s.target)
                        .color("#0072b2")
                        .dashed(),
                )
                .series(
                    Series::line("estimated", &s.t, &s.estimated)
                        .color("#e69f00")
                        .width(1.0),
                )
                .series(
                    Series::line("true", &s.t, &s.truth)
                        .color("#000000")
                        .width(1.0),
                ),
        )
        .panel(
            Panel::new("drive amplitude", "fraction")
                .y_range(0.0, 1.0)
                .series(Series::line("amplitude", &s.t, &s.amplitude).color("#009e73")),
        )
        .panel(
            Panel::new("normal load", "N")
                .band(Band::vertical("fault active", 1.2, 1.3).color("#d55e00"))
                .series(Series::line("load", &s.t, &s.load).color("#cc79a7")),
        )
        .marker(Marker::new("fault: load +30 %", 1.2))
        .marker(Marker::new("target step", 1.4).color("#555555"))
}

/// Method rows for the speed-versus-accuracy example: (label, instructions, error, group).
const TRADE_ROWS: [(&str, f64, f64, &str); 12] = [
    ("poly3 q15", 18.0, 2.1e-4, "polynomial"),
    ("poly5 q31", 34.0, 3.0e-7, "polynomial"),
    ("poly7 q31", 47.0, 8.2e-9, "polynomial"),
    ("poly9 f64", 140.0, 6.0e-12, "polynomial"),
    ("table 64", 22.0, 1.2e-3, "table"),
    ("table 256 + lerp", 40.0, 5.0e-6, "table"),
    ("table 1024 + lerp", 42.0, 3.1e-7, "table"),
    ("CORDIC 16 it", 260.0, 1.5e-5, "CORDIC"),
    ("CORDIC 32 it", 510.0, 4.7e-10, "CORDIC"),
    ("libm f64", 2400.0, 1.1e-16, "reference"),
    ("quadrature 1e-15", 4.0e5, 8.0e-16, "reference"),
    ("bisection & refine <1 ulp>", 9.0e4, 2.0e-13, "reference"),
];

fn trade_plot() -> ScatterPlot {
    let mut plot = ScatterPlot::new("Speed vs accuracy")
        .log_x()
        .log_y()
        .x_range(10.0, 1e6)
        .x_label("instructions per evaluation")
        .y_label("max abs error");
    for (label, x, y, group) in TRADE_ROWS {
        plot = plot.point(label, x, y, group);
    }
    let xy: Vec<(f64, f64)> = TRADE_ROWS.iter().map(|r| (r.1, r.2)).collect();
    plot.pareto(&pareto_front(&xy))
}

#[test]
fn scene_plot_is_well_formed_small_and_deterministic() {
    let s = scene();
    let svg = scene_plot(&s).to_svg();
    assert!(
        check_well_formed(&svg).is_ok(),
        "{:?}",
        check_well_formed(&svg)
    );
    assert!(
        svg.contains("3 panels, 5 series, 500000 points"),
        "{}",
        &svg[..400]
    );
    assert!(svg.contains(" 50 non-finite points skipped"));
    assert!(svg.len() < 400_000, "{} bytes", svg.len());
    assert_eq!(svg, scene_plot(&s).to_svg());
    assert!(svg.contains("target ±2 %") && svg.contains("fault: load +30 %"));
}

#[test]
fn scatter_plot_is_well_formed_escaped_and_deterministic() {
    let svg = trade_plot().to_svg();
    assert!(
        check_well_formed(&svg).is_ok(),
        "{:?}",
        check_well_formed(&svg)
    );
    assert!(svg.contains("bisection &amp; refine &lt;1 ulp&gt;"));
    assert!(
        svg.contains("12 points, 12 drawn, 5 Pareto, 0 skipped"),
        "{}",
        &svg[..400]
    );
    assert!(svg.contains(">10<tspan dy=\"-5\" font-size=\"8\">-16</tspan>"));
    assert_eq!(svg, trade_plot().to_svg());
}

#[test]
fn hostile_text_is_escaped() {
    let title = "a & b <script> \"q\" -- x";
    let x = [0.0, 1.0];
    let ts = TimeSeriesPlot::new(title)
        .x_label("<t>")
        .panel(Panel::new("f&g", "\"N\"").series(Series::line("<s>", &x, &x).color("\"red\"")))
        .marker(Marker::new("m&m", 0.5))
        .to_svg();
    let sc = ScatterPlot::new(title)
        .point("<p>", 1.0, 2.0, "g&h")
        .to_svg();
    for svg in [ts, sc] {
        assert!(
            check_well_formed(&svg).is_ok(),
            "{:?}\n{svg}",
            check_well_formed(&svg)
        );
        assert!(svg.contains("a &amp; b &lt;script&gt; &quot;q&quot; -- x"));
        assert!(!svg.contains("<script>") && !svg.contains("<p>"));
    }
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let nan = [f64::NAN; 10];
    let t: Vec<f64> = (0..10).map(f64::from).collect();
    let flat = [2.0; 10];
    let spikes = [
        0.0,
        f64::INFINITY,
        1.0,
        f64::NEG_INFINITY,
        -1e308,
        1e308,
        0.0,
        0.0,
        f64::NAN,
        3.0,
    ];
    let plots = [
        TimeSeriesPlot::new("").to_svg(),
        TimeSeriesPlot::new("empty panel")
            .panel(Panel::new("x", ""))
            .to_svg(),
        TimeSeriesPlot::new("")
            .panel(Panel::new("x", "u").series(Series::line("", &[], &[])))
            .to_svg(),
        TimeSeriesPlot::new("all NaN")
            .panel(Panel::new("x", "u").series(Series::line("n", &nan, &nan)))
            .to_svg(),
        TimeSeriesPlot::new("NaN y")
            .panel(Panel::new("x", "u").series(Series::line("n", &t, &nan)))
            .to_svg(),
        TimeSeriesPlot::new("flat")
            .panel(Panel::new("x", "u").series(Series::line("f", &t, &flat)))
            .to_svg(),
        TimeSeriesPlot::new("one point")
            .panel(Panel::new("x", "u").series(Series::line("p", &t[..1], &flat)))
            .to_svg(),
        TimeSeriesPlot::new("spikes")
            .panel(
                Panel::new("x", "u")
                    .series(Series::line("s", &t, &spikes))
                    .band(Band::between("b", &t, &spikes, &flat))
                    .band(Band::horizontal("h", f64::NAN, 1.0))
                    .marker(Marker::new("m", f64::INFINITY)),
            )
            .to_svg(),
        TimeSeriesPlot::new("reversed range")
            .x_range(9.0, 1.0)
            .size(f64::NAN, -5.0)
            .panel(
                Panel::new("x", "u")
                    .y_range(3.0, 3.0)
                    .series(Series::line("f", &t, &spikes)),
            )
            .to_svg(),
        ScatterPlot::new("").to_svg(),
        ScatterPlot::new("nan")
            .log_x()
            .log_y()
            .point("a", f64::NAN, 1.0, "")
            .point("b", -1.0, 0.0, "")
            .to_svg(),
        ScatterPlot::new("one")
            .log_x()
            .log_y()
            .point("a", 1e3, 1e-6, "g")
            .pareto(&[0, 7])
            .to_svg(),
        ScatterPlot::new("linear flat")
            .point("a", 1.0, 1.0, "")
            .point("b", 1.0, 1.0, "")
            .to_svg(),
        ScatterPlot::new("bad ranges")
            .log_x()
            .x_range(-1.0, 0.0)
            .y_range(f64::NAN, 1.0)
            .to_svg(),
    ];
    for svg in &plots {
        assert!(
            check_well_formed(svg).is_ok(),
            "{:?}\n{svg}",
            check_well_formed(svg)
        );
    }
    assert!(plots[3].contains("10 non-finite points skipped"));
    assert!(plots[10].contains("2 skipped"));
}

#[test]
#[ignore = "writes example SVGs to /tmp/plot-examples for manual inspection"]
fn write_examples() {
    let dir = std::env::temp_dir().join("plot-examples");
    std::fs::create_dir_all(&dir).expect("create example directory");
    let s = scene();
    std::fs::write(dir.join("scene.svg"), scene_plot(&s).to_svg()).expect("write scene.svg");
    std::fs::write(dir.join("trade.svg"), trade_plot().to_svg()).expect("write trade.svg");
}
