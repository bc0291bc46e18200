//! Instruction counts of the model's hot paths, measured in QEMU (build feature `bench`).
//!
//! Each benchmark evaluates one call `CALLS` times over a fixed grid of inputs and divides the
//! elapsed virtual time by the call count. Under `-icount shift=0` one guest instruction advances
//! virtual time by 1 ns, and one 25 MHz SysTick cycle is 40 ns, so instructions per call =
//! 40 x cycles / calls (resolution 40 / CALLS instructions). Inputs and results go through
//! `black_box` so the compiler can neither hoist nor drop the call; the cost of making the
//! inputs is measured alone and subtracted, but the call and the memory traffic `black_box`
//! forces on its arguments and result (about 10-25 instructions) stay in the figure. Results
//! print as `bench NAME: N instructions per call`.

use core::hint::black_box;

use sonolube::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
use sonolube::model::{FrictionModel, OperatingPoint};
use sonolube::plant::AnyModel;

use crate::time_driver;

/// Calls per benchmark.
const CALLS: u32 = 2_000;
/// Guest instructions per 25 MHz core cycle under `-icount shift=0`.
const INSTRUCTIONS_PER_CYCLE: u64 = 40;

/// Virtual-time cost of `CALLS` runs of `body(k)`, in instructions (x 1000 for 3 decimals).
fn measure(mut body: impl FnMut(u32)) -> u64 {
    let start = time_driver::cycles();
    for k in 0..CALLS {
        body(black_box(k));
    }
    (time_driver::cycles() - start) * INSTRUCTIONS_PER_CYCLE * 1000 / u64::from(CALLS)
}

/// Measures `call` on the inputs `make(k)`, minus the cost of making the inputs alone, and
/// prints the result.
fn bench<I, O>(name: &str, make: impl Fn(u32) -> I, call: impl Fn(I) -> O) {
    let inputs_only = measure(|k| {
        black_box(make(k));
    });
    let with_call = measure(|k| {
        black_box(call(black_box(make(k))));
    });
    let net = with_call.saturating_sub(inputs_only);
    defmt::info!(
        "bench {=str}: {=u64}.{=u64:03} instructions per call",
        name,
        net / 1000,
        net % 1000
    );
}

/// Runs every benchmark; returns false if a model could not be built.
pub fn run() -> bool {
    let half = CALLS as i32 / 2;
    // Littmann closed form over zeta in [-1, 1) (both branches of asin).
    bench(
        "Littmann closed form",
        |k| Q2_30::from_bits((k as i32 - half) * ((1 << 30) / half)),
        sonolube::model::littmann::mu_i,
    );
    // One exact Dahl update (alpha = 1) with a per-step travel kappa |dx| below 2.
    bench(
        "Dahl update",
        |k| {
            let f = Q2_30::from_bits((k as i32) << 18);
            let travel = Q2_30::from_bits(((k as i32) & 0x3FF) << 19);
            (f, k & 1 == 0, travel)
        },
        |(f, forward, travel)| sonolube::model::dahl::update(f, forward, travel),
    );
    // Cube reduction, elastic-plastic contact, 16-point quadrature: the load-ramp scene's plant
    // model, at loads 40..240 N and amplitudes over the whole range.
    let Some(scene) = sonolube::scene::builtin::find("load-ramp") else {
        defmt::error!("bench: no load-ramp scene");
        return false;
    };
    let Ok(cube) = AnyModel::new(scene, &scene.plant) else {
        defmt::error!("bench: the load-ramp plant model cannot be built");
        return false;
    };
    bench(
        "cube ep N=16",
        |k| {
            let point = OperatingPoint {
                normal_force: Q16_16::from_bits((40 + (k % 200) as i32) << 16),
                sliding_velocity: Q8_24::from_bits(1 << 19),
            };
            let amplitude = Q1_31::from_bits((k.wrapping_mul(2_654_435_761) >> 1) as i32);
            (point, amplitude)
        },
        |(point, amplitude)| cube.ratio(&point, amplitude),
    );
    true
}
