//! `PwmPeriod::compare_at` rounds to the nearest sixteenth of a tick (issue 18): checked
//! against exact rational arithmetic over the band and over fractions whose product is not a
//! whole number of sixteenths (a truncating form would be up to one sixteenth short).

use super::clock::TimerClock;
use super::frequency::Frequency;
use super::period::PwmPeriod;

#[test]
fn compare_values_are_rounded_to_nearest() {
    let clock = TimerClock::G474_TIM1;
    let mut rounded_up = 0;
    for hz in (20_000..=60_000).step_by(997) {
        let period = PwmPeriod::nearest(Frequency::from_hz(hz), clock).unwrap();
        let p = u128::from(period.sixteenths());
        for fraction in [
            1u32,
            3,
            1 << 20,
            123_456_789,
            1 << 29,
            700_000_001,
            (1 << 30) - 1,
        ] {
            // round(p f / 2^30) exactly: floor((2 p f + 2^30) / 2^31).
            let want = ((2 * p * u128::from(fraction) + (1 << 30)) >> 31) as u32;
            let got = period.compare_at(fraction);
            assert_eq!(got, want, "{hz} Hz, fraction {fraction}");
            let exact = p as f64 * f64::from(fraction) / f64::from(1u32 << 30);
            assert!((f64::from(got) - exact).abs() <= 0.5, "{hz} Hz, {fraction}");
            if f64::from(got) > exact {
                rounded_up += 1;
            }
        }
    }
    // About half of the cases round up: the rounding is to nearest, not down.
    assert!(rounded_up > 20, "{rounded_up}");
}
