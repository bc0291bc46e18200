//! The watchdog keeper: feeds the watchdog only while the firmware shows signs of life.
//!
//! Until the control loop runs, the sign of life is the boot heartbeat (it stops after the
//! self-check); then it is the control loop's step count. A hung control task stops the
//! feeding even if every other task still runs, and the watchdog resets the machine.

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Timer};

use crate::{heartbeat, link};

/// Heartbeat wake-ups plus control steps so far (wrapping).
pub fn signs_of_life() -> u32 {
    heartbeat::alive_count().wrapping_add(link::STEPS.load(Ordering::Relaxed))
}

/// Checks every `every` and calls `feed` when [`signs_of_life`] advanced since the last check.
pub async fn keeper(every: Duration, mut feed: impl FnMut()) -> ! {
    let mut last = signs_of_life();
    loop {
        Timer::after(every).await;
        let now = signs_of_life();
        if now != last {
            feed();
            last = now;
        }
    }
}
