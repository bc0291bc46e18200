//! Compile-time maths for the tables and constants of the elementary functions.
//!
//! These run inside the compiler (in `const` items), so they may be slow and may use f64 or
//! u128; nothing here is called on the target at run time. The tests check them against std.

/// ln 2 in Q.62, exactly rounded, from the series `ln 2 = sum_{k>=1} 1 / (k 2^k)` evaluated in
/// Q.120 (each of the 120 truncated terms is off by less than 2^-120, and so is the tail).
pub(crate) const LN2_Q62: i64 = {
    let mut acc: u128 = 0;
    let mut k: u32 = 1;
    while k <= 120 {
        acc += (1u128 << (120 - k)) / k as u128;
        k += 1;
    }
    ((acc + (1u128 << 57)) >> 58) as i64
};

/// ln 2 in Q.40, exactly rounded.
pub(crate) const LN2_Q40: i64 = (LN2_Q62 + (1 << 21)) >> 22;

/// `ln(x)` for `x` in [1, 2], to about 1 ulp of f64: `2 atanh((x - 1) / (x + 1))` summed until
/// the terms vanish (|t| <= 1/3, so 30 terms are far more than enough).
pub(crate) const fn ln_f64(x: f64) -> f64 {
    let t = (x - 1.0) / (x + 1.0);
    let t2 = t * t;
    let mut power = t;
    let mut sum = 0.0;
    let mut k = 0;
    while k < 30 {
        sum += power / (2 * k + 1) as f64;
        power *= t2;
        k += 1;
    }
    2.0 * sum
}

/// `sin(x)` for `x` in [0, pi/2], to about 1 ulp of f64 (Taylor series to x^41).
pub(crate) const fn sin_f64(x: f64) -> f64 {
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    let mut n = 1;
    while n < 21 {
        term = -term * x2 / ((2 * n) * (2 * n + 1)) as f64;
        sum += term;
        n += 1;
    }
    sum
}

/// `round(x * 2^frac)` for a non-negative `x` below 2^(32 - frac), as `u32` (table entries).
pub(crate) const fn to_fixed_u32(x: f64, frac: u32) -> u32 {
    (x * (1u64 << frac) as f64 + 0.5) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// floor(v * 2^bits) for v given by its decimal digits after "0.", by repeated doubling of
    /// the decimal fraction (independent of f64 and of the series above).
    fn decimal_fraction_to_binary(digits: &str, bits: u32) -> u128 {
        let mut d: Vec<u8> = digits.bytes().map(|b| b - b'0').collect();
        let mut out: u128 = 0;
        for _ in 0..bits {
            let mut carry = 0;
            for digit in d.iter_mut().rev() {
                let v = *digit * 2 + carry;
                *digit = v % 10;
                carry = v / 10;
            }
            out = (out << 1) | carry as u128;
        }
        out
    }

    #[test]
    fn ln2_is_exactly_rounded() {
        let ln2 = "69314718055994530941723212145817656807550013436025525412068";
        let floor63 = decimal_fraction_to_binary(ln2, 63);
        let want = ((floor63 + 1) >> 1) as i64;
        assert_eq!(LN2_Q62, want);
        let floor41 = decimal_fraction_to_binary(ln2, 41);
        assert_eq!(LN2_Q40, ((floor41 + 1) >> 1) as i64);
    }

    #[test]
    fn series_match_std() {
        for i in 0..=1000 {
            let x = 1.0 + i as f64 / 1000.0;
            assert!((ln_f64(x) - x.ln()).abs() <= 2.0 * f64::EPSILON);
            let a = core::f64::consts::FRAC_PI_2 * i as f64 / 1000.0;
            assert!((sin_f64(a) - a.sin()).abs() <= 2.0 * f64::EPSILON);
        }
        assert_eq!(to_fixed_u32(0.5, 31), 1 << 30);
    }
}
