//! The drive current for the resonance loop: ADC2 converts PA1 once per PWM period at a
//! trigger phase stepping a quarter period each period, the results land in a DMA ring, and
//! the control step drains the ring into `Station::push_current`
//! (`sonolube_g474_hw::current`, host-tested, has the register programming and the plan).
//!
//! - [`start`] (sensing task, after the drive is configured and before ADC1 starts): embassy
//!   brings ADC2 up (regulator, calibration, ADEN), then the hardware-glue crate programs
//!   ADC2, the two DMA channels (DMA1 channel 2: the ring; channel 3: the CCR4 table on
//!   TIM1_UP) and starts the sampling aligned to phase 0.
//! - [`change_timing`] (from [`crate::drive`], a new period and duty): the hardware glue's
//!   change that loses no conversion (the table and CCR4 kept below the smaller ARR across
//!   it), in a critical section, counting the update a change suppressed.
//! - [`follow_drive`] (from [`crate::drive`], whenever CCR1 alone is written): rewrites the
//!   table for the new duty, rotated by the updates frequency changes suppressed.
//! - [`RingReader`] (the control loop): the samples since the last step, in order, the first
//!   one a new station sees at phase 0.
//!
//! The ring and the table are `static` atomics: the DMA reads and writes their memory
//! directly (an atomic has its integer's layout), the firmware only through atomic loads and
//! stores, so no access is elided or torn.

use core::sync::atomic::{AtomicBool, AtomicU8, AtomicU16, AtomicU32, Ordering};

use embassy_stm32::Peri;
use embassy_stm32::adc::{Adc, AdcConfig, Resolution};
use embassy_stm32::pac;
use embassy_stm32::peripherals::{ADC2, DMA1_CH2, DMA1_CH3};
use sonolube::drive::{Amplitude, DriveTiming};
use sonolube::station::MAX_CURRENT_SAMPLES;
use sonolube_g474_hw::current::{self as plan, RING_LEN, TABLE_LEN};
use sonolube_g474_hw::tim1::UpdateEvents;

/// The CCR4 table the update DMA reads ([`plan::dma_order`]).
static TABLE: [AtomicU32; TABLE_LEN] = [const { AtomicU32::new(0) }; TABLE_LEN];
/// The ring ADC2's DMA writes.
static RING: [AtomicU16; RING_LEN] = [const { AtomicU16::new(0) }; RING_LEN];
/// Set once [`start`] succeeded: the table is the DMA's, CCR4 is no longer the firmware's.
static RUNNING: AtomicBool = AtomicBool::new(false);
/// Update events suppressed by frequency changes since [`start`], mod 4.
static SKIPPED: AtomicU8 = AtomicU8::new(0);
/// The same, counted (for the log: each costs up to 3 samples off their phase).
static SUPPRESSED: AtomicU32 = AtomicU32::new(0);

const _: () = assert!(RING_LEN < MAX_CURRENT_SAMPLES + 1, "a drain fits one push");

/// ADC2 and the two DMA channels, claimed.
pub struct Hardware {
    /// The current's converter (PA1 = ADC12_IN2, shared with ADC1's scan).
    pub adc: Peri<'static, ADC2>,
    /// DMA1 channel 2: ADC2_DR into the ring.
    pub ring_dma: Peri<'static, DMA1_CH2>,
    /// DMA1 channel 3: the table into TIM1_CCR4.
    pub table_dma: Peri<'static, DMA1_CH3>,
}

/// The running sampling: keeps the peripherals claimed. Keep it alive.
pub struct CurrentSense {
    _adc: Adc<'static, ADC2>,
    _ring_dma: Peri<'static, DMA1_CH2>,
    _table_dma: Peri<'static, DMA1_CH3>,
}

/// Why the stepped sampling did not start (the drive then runs without it: `freq auto` is
/// refused as `unavailable`, CCR4 stays at 3/4 of the period for ADC1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum StartError {
    /// No table for the drive's registers.
    Table(plan::TableError),
    /// The hardware glue refused (outputs on, ADC2 not enabled or converting).
    Refused(plan::StartRefused),
}

/// Starts ADC2's stepped sampling for the drive's `timing` at zero amplitude (call with the
/// outputs off: TIM1's counter stops for a few microseconds).
pub fn start(hw: Hardware, timing: &DriveTiming) -> Result<CurrentSense, StartError> {
    let adc = Adc::new(
        hw.adc,
        AdcConfig {
            resolution: Some(Resolution::BITS12),
            ..AdcConfig::default()
        },
    );
    let phases = plan::phase_table(
        timing.period().arr_register(),
        timing.duty_compare(Amplitude::ZERO),
    )
    .map_err(StartError::Table)?;
    plan::store_table(&TABLE, &plan::dma_order(&phases, 0));
    SKIPPED.store(0, Ordering::Relaxed);
    let addresses = plan::Addresses {
        adc_dr: pac::ADC2.dr().as_ptr() as u32,
        tim1_ccr4: pac::TIM1.ccr(3).as_ptr() as u32,
        ring: RING.as_ptr() as u32,
        table: TABLE.as_ptr() as u32,
    };
    plan::start(
        pac::TIM1,
        pac::ADC2,
        pac::DMA1,
        pac::DMAMUX1,
        &addresses,
        &phases,
        &mut |_| {},
    )
    .map_err(StartError::Refused)?;
    RUNNING.store(true, Ordering::Release);
    Ok(CurrentSense {
        _adc: adc,
        _ring_dma: hw.ring_dma,
        _table_dma: hw.table_dma,
    })
}

/// Whether the stepped sampling runs (CCR4 belongs to the table).
pub fn running() -> bool {
    RUNNING.load(Ordering::Acquire)
}

/// Changes TIM1's period and duty while the stepped sampling runs ([`plan::change_timing`]:
/// no conversion lost, the table rotated by a suppressed update), in a critical section: an
/// interrupt inside the UDIS window longer than a period would hide a counter wrap from the
/// suppressed-update detection. A few hundred cycles.
pub fn change_timing(
    timing: &DriveTiming,
    amplitude: Amplitude,
) -> Result<(), plan::ChangeRefused> {
    let skipped = u32::from(SKIPPED.load(Ordering::Relaxed));
    let changed = cortex_m::interrupt::free(|_| {
        plan::change_timing(pac::TIM1, &TABLE, timing, amplitude, skipped, &mut |_| {})
    })?;
    // `skipped` is below 4.
    SKIPPED.store(changed.skipped as u8, Ordering::Relaxed);
    if changed.events == UpdateEvents::OneSuppressed {
        let total = SUPPRESSED.load(Ordering::Relaxed);
        SUPPRESSED.store(total.saturating_add(1), Ordering::Relaxed);
    }
    Ok(())
}

/// Update events suppressed by frequency changes since [`start`].
pub fn suppressed_updates() -> u32 {
    SUPPRESSED.load(Ordering::Relaxed)
}

/// Rewrites the table for the registers `timing` and `amplitude` put in TIM1 (CCR1/2 moves the
/// fundamental's maximum; ARR the quarter period). Nothing before [`start`]. Eight stores and
/// a few additions.
pub fn follow_drive(timing: &DriveTiming, amplitude: Amplitude) {
    if !running() {
        return;
    }
    match plan::phase_table(
        timing.period().arr_register(),
        timing.duty_compare(amplitude),
    ) {
        Ok(phases) => plan::store_table(
            &TABLE,
            &plan::dma_order(&phases, u32::from(SKIPPED.load(Ordering::Relaxed))),
        ),
        // `DriveTiming` keeps ARR in the band and CCR1 at most half the period: not reached.
        Err(error) => defmt::error!("current sense: no phase table ({})", error),
    }
}

/// Realigns the table after `lost` conversions (mod 4) were lost: rotated as if the
/// suppressed updates were `lost` fewer ([`plan::realigned`]).
fn realign_table(lost: u32) {
    cortex_m::interrupt::free(|_| {
        let memory: [u32; TABLE_LEN] = core::array::from_fn(|i| TABLE[i].load(Ordering::Relaxed));
        plan::store_table(&TABLE, &plan::realigned(&memory, lost));
        let skipped = u32::from(SKIPPED.load(Ordering::Relaxed));
        // Below 4.
        SKIPPED.store(
            ((skipped + TABLE_LEN as u32 - lost % TABLE_LEN as u32) % TABLE_LEN as u32) as u8,
            Ordering::Relaxed,
        );
    });
}

/// The control loop's position in the ring.
pub struct RingReader {
    read: usize,
    audit: plan::ConversionAudit,
}

impl RingReader {
    /// A reader whose first sample is the newest one at phase 0 (up to 3 samples back), as a
    /// new station's lock-in expects. None while the sampling does not run.
    pub fn new() -> Option<Self> {
        let write = plan::ring_write_index(pac::DMA1).filter(|_| running())?;
        Some(Self {
            read: plan::aligned_start(write),
            audit: plan::ConversionAudit::default(),
        })
    }

    /// Starts again at phase 0, for a new station (scene change).
    pub fn realign(&mut self) {
        if let Some(write) = plan::ring_write_index(pac::DMA1) {
            self.read = plan::aligned_start(write);
        }
    }

    /// The codes converted since the last drain, oldest first, into `codes`; their count
    /// (0 to 15). Err when ADC2 or a DMA channel stopped (a DMA transfer error disables its
    /// channel): the reader then stays where it was.
    pub fn drain(
        &mut self,
        codes: &mut [u16; MAX_CURRENT_SAMPLES],
    ) -> Result<usize, plan::Stalled> {
        plan::check_running(pac::DMA1, pac::ADC2)?;
        let write = plan::ring_write_index(pac::DMA1).ok_or(plan::Stalled::RingChannel)?;
        let count = plan::pending(self.read, write);
        for (k, slot) in codes.iter_mut().take(count).enumerate() {
            if let Some(cell) = RING.get((self.read + k) % RING_LEN) {
                *slot = cell.load(Ordering::Relaxed);
            }
        }
        self.read = write;
        // The DMA counts against each other: a lost conversion (one the frequency change's
        // clamp did not prevent) is found and the table realigned. Ring count first.
        let ring_remaining = pac::DMA1.ch(plan::RING_DMA_CHANNEL).ndtr().read().ndt();
        let table_remaining = pac::DMA1.ch(plan::TABLE_DMA_CHANNEL).ndtr().read().ndt();
        let skipped = u32::from(SKIPPED.load(Ordering::Relaxed));
        if let Some(lost) = self.audit.observe(ring_remaining, table_remaining, skipped)
            && lost != 0
        {
            realign_table(lost);
            defmt::warn!(
                "current sense: {=u32} conversion(s) lost (DMA counts); table realigned",
                lost
            );
        }
        Ok(count)
    }
}
