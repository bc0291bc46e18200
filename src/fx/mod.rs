//! Fixed-point arithmetic: formats and elementary functions used by the model's hot path.
//!
//! # Formats
//!
//! [`Q<FRAC>`](Q) is an `i32` with `FRAC` fractional bits (value = bits * 2^-FRAC); the format
//! is part of the type, so a Q16.16 cannot be added to a Q2.30 by mistake.
//!
//! | alias       | range              | resolution | use                                      |
//! |-------------|--------------------|------------|------------------------------------------|
//! | [`Q16_16`]  | [-32768, 32768)    | 1.5e-5     | general values (speeds, loads, um)       |
//! | [`Q8_24`]   | [-128, 128)        | 6.0e-8     | moderate values needing precision        |
//! | [`Q6_26`]   | [-32, 32)          | 1.5e-8     | logarithms of wide-range quantities      |
//! | [`Q5_27`]   | [-16, 16)          | 7.5e-9     | logarithms                               |
//! | [`Q3_29`]   | [-4, 4)            | 1.9e-9     | angles up to pi                          |
//! | [`Q2_30`]   | [-2, 2)            | 9.3e-10    | ratios with an exact 1.0, radians <= pi/2 |
//! | [`Q1_31`]   | [-1, 1)            | 4.7e-10    | states and sines (+1.0 not representable) |
//!
//! Quantities that span more decades than any 32-bit format (loads from 1 mN to 50 kN,
//! stiffness-amplitude products from 1e-9 to 1e13) are [`Scaled`]: `mantissa * 2^exp2`, a Q2.30
//! mantissa in [1, 2) with 30 significant bits; [`wide`] multiplies, inverts (Newton, no
//! division), adds and converts them with 32x32->64 multiplies only.
//!
//! # Never panic, never wrap
//!
//! There are no operator impls. Every operation is either checked (`Result<_, FxError>`, the
//! `checked_*` methods and all elementary functions) or saturating with a flag (a [`Sat`] with
//! `value` and `saturated`, the `saturating_*` methods). Nothing panics, at run time, with
//! overflow checks on; the only panicking functions are the `*_const` constructors, meant for
//! `const` items where a panic is a compile error.
//!
//! # Rounding
//!
//! Products, right shifts and format conversions round to nearest (add half an ulp, shift
//! arithmetically: ties toward +infinity); quotients and float/ratio conversions round to nearest
//! with ties away from zero. There is no truncation bias (tested over 1e4 accumulated products).
//!
//! # Elementary functions
//!
//! Errors are maximum absolute errors against f64, asserted by the tests (dense sweeps and, for
//! 32-bit domains, checked exhaustively while developing). Costs are instructions per call,
//! measured on the Cortex-M4 instruction set (QEMU `mps2-an386`, one instruction per translation
//! block, `opt-level = "s"`, fat LTO) including about 4-15 instructions of call and `Result`
//! overhead; SMULL/SMMLAR are single-cycle on the Cortex-M4F, so cycles are close to these counts.
//!
//! | function                      | input -> output           | max error            | cost   |
//! |-------------------------------|---------------------------|----------------------|--------|
//! | [`Q::sqrt`], [`Q::sqrt_to`]   | `Q<F>` >= 0 -> `Q<OUT>`   | 0.5 ulp (exact)      | ~95    |
//! | [`isqrt_u64`]                 | `u64` -> `u32`            | exact floor          | ~75    |
//! | [`Q::exp_neg`]                | `Q<F>` >= 0 -> Q2.30      | 0.75 ulp (7e-10)     | < 44   |
//! | [`Q::exp`]                    | `Q<F>` -> `Q<OUT>`        | 1 ulp or 1.5e-9 rel. | ~55    |
//! | [`Q::ln`], [`ln_scaled`]      | > 0 -> `Q<OUT>`           | 0.5 ulp + 8e-10      | ~55    |
//! | [`Q2_30::asin`](Q::asin)      | Q2.30 in [-1, 1] -> Q2.30 | 1 ulp, 1e-6 rel.     | 65/115 |
//! | [`sin`], [`cos`], [`sin_cos`] | `u32` turn -> Q1.31       | 1e-9                 | 35/40  |
//! | `checked_mul(_to)`, `lerp`    |                           | 0.5 ulp              | 10-20  |
//! | `checked_div(_to)`            |                           | 0.5 ulp              | ~200   |
//!
//! (asin: |z| <= 1/2 / |z| > 1/2, which needs a square root; sin / sin_cos. `exp_neg`: below
//! the Dahl update's count (row "Dahl update" of `docs/speed.md`), as the update calls it once.)
//!
//! # For the model code
//!
//! - Littmann law (physics-notes §1): `zeta: Q2_30 = v_s.checked_div_to(v_a)?` (precompute
//!   `1/v_a` when it changes to avoid the division), handle |zeta| >= 1 first, then the
//!   (2/pi) asin with the gain folded in (`littmann::mu_i`; its instruction count is the row
//!   "Littmann closed form" of `docs/speed.md`, which `scripts/speed-table` measures).
//! - Dahl update (§2): carry `f` in Q2.30 (exact +-1), `decay = kappa_dx.exp_neg()?` with
//!   `kappa |dx|` in the finest format that holds it (Q2.30 below 2, Q8.24 below 128), then
//!   `f = s.lerp(f, decay)?`, which stays in [-1, 1] by construction.
//! - Rough contact (§3): `d = (R_q / lambda) (ln K_F - ln F_n)`; take `ln F_n` with
//!   [`Q::ln`] or [`ln_scaled`] into Q6.26 and carry `ln K_F` precomputed, never `K_F`.
//! - Cube model (§4): phases as `u32` turn fractions (`k * 2^31 / n` for a half period),
//!   [`sin_cos`] per point, weights `exp_neg` of `2 lambda v / R_q` in Q16.16 or Q8.24.
//!
//! # Example
//!
//! Formats in the type, checked and saturating arithmetic, and the elementary functions
//! (`no_std` code; `cargo test --doc -p sonolube` runs it on the host):
//!
//! ```
//! use sonolube::fx::{FxError, Q1_31, Q2_30, Q8_24, Q16_16, sin_cos};
//!
//! // 40 N at half the ratio: a Q16.16 times a Q2.30, the result in Q16.16, rounded.
//! let load = Q16_16::from_f64(40.0)?;
//! let half = Q2_30::from_ratio(1, 2)?;
//! let product: Q16_16 = load.checked_mul_to(half)?;
//! assert_eq!(product.to_f64(), 20.0);
//!
//! // Out of range is an error or a flagged saturation, never a wrap.
//! assert_eq!(Q16_16::from_f64(40_000.0), Err(FxError::Overflow));
//! let clamped = Q16_16::from_f64_saturating(40_000.0);
//! assert!(clamped.saturated && clamped.value == Q16_16::MAX);
//! assert!(Q2_30::ONE.checked_add(Q2_30::ONE).is_err());
//!
//! // e^-1 in Q2.30, within 1 ulp of f64.
//! let decay = Q8_24::ONE.exp_neg()?;
//! assert!((decay.to_f64() - 0.367_879_441_171_442_3).abs() < 2e-9);
//!
//! // sqrt(2) and ln(2), each within an ulp of its format.
//! let two = Q8_24::from_int(2)?;
//! assert!((two.sqrt()?.to_f64() - core::f64::consts::SQRT_2).abs() < 1e-7);
//! let ln2: Q2_30 = two.ln()?;
//! assert!((ln2.to_f64() - core::f64::consts::LN_2).abs() < 2e-9);
//!
//! // Phases are u32 fractions of a turn: 2^29 is an eighth, 45 degrees.
//! let (sin, cos) = sin_cos(1 << 29);
//! assert!((sin.to_f64() - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-9);
//! assert!((cos.to_f64() - sin.to_f64()).abs() < 1e-9);
//! assert!(Q1_31::MAX.to_f64() < 1.0); // +1.0 is not a Q1.31
//! # Ok::<(), FxError>(())
//! ```

mod asin;
mod convert;
mod ctmath;
mod div;
mod error;
mod exp;
mod ln;
mod ops;
mod q;
mod raw;
pub mod scaled;
mod sqrt;
mod trig;
pub mod wide;

pub use error::{FxError, Sat};
pub use ln::ln_scaled;
pub use q::{Q, Q1_31, Q2_30, Q3_29, Q5_27, Q6_26, Q8_24, Q16_16};
pub use scaled::Scaled;
pub use sqrt::isqrt_u64;
pub(crate) use sqrt::sqrt_q32_approx;
pub use trig::{Turns, cos, sin, sin_cos};

/// The 64-bit helpers the rest of the core shares (one definition each).
pub(crate) use raw::{div_round_i64, mul_hi_round};
