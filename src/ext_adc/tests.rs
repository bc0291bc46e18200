//! Host tests of the ADS131M02 driver against a scripted mock `SpiDevice`.
//!
//! The mock holds the exact frames the driver must send and the frames a device would answer
//! with (CRC computed like the device does); a frame the driver sends out of script fails the
//! test. Faults are injected by scripting them: a corrupted CRC, a wrong ID, a missing reset
//! acknowledgement, an SPI error, a device that reset itself.

use std::collections::VecDeque;

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{self, ErrorKind, ErrorType, Operation, SpiDevice};

use super::crc::crc16_ccitt;
use super::frame::{CrcMismatch, FRAME_BYTES, command, encode};
use super::registers::{Config, Gain, MODE_VALUE, Osr, Status, address};
use super::{Ads131m02, Error};
use crate::sense::AdcCode;

/// An SPI error from the mock bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct BusFault;

impl spi::Error for BusFault {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

/// One scripted frame: what the host must send and what the device answers.
enum Step {
    Frame {
        expect: [u8; FRAME_BYTES],
        reply: [u8; FRAME_BYTES],
    },
    Fail,
}

#[derive(Default)]
struct MockSpi {
    script: VecDeque<Step>,
    transactions: usize,
}

impl MockSpi {
    fn expect(mut self, command: u16, data: u16, reply: [u8; FRAME_BYTES]) -> Self {
        self.script.push_back(Step::Frame {
            expect: encode(command, data),
            reply,
        });
        self
    }

    fn fail(mut self) -> Self {
        self.script.push_back(Step::Fail);
        self
    }

    fn done(&self) -> bool {
        self.script.is_empty()
    }
}

impl ErrorType for MockSpi {
    type Error = BusFault;
}

impl SpiDevice<u8> for MockSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), BusFault> {
        self.transactions += 1;
        // The driver sends every frame as one full-duplex transfer with CS held.
        let [Operation::Transfer(read, write)] = operations else {
            panic!("transaction {}: expected one transfer", self.transactions);
        };
        match self.script.pop_front() {
            Some(Step::Frame { expect, reply }) => {
                assert_eq!(*write, &expect[..], "frame {} sent", self.transactions);
                read.copy_from_slice(&reply);
                Ok(())
            }
            Some(Step::Fail) => Err(BusFault),
            None => panic!("frame {} beyond the script", self.transactions),
        }
    }
}

/// Records the delays the driver asks for.
#[derive(Default)]
struct Delay {
    total_ns: u64,
}

impl DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        self.total_ns += u64::from(ns);
    }
}

/// A device frame with a correct CRC.
fn device(response: u16, codes: [i32; 2]) -> [u8; FRAME_BYTES] {
    let mut frame = [0u8; FRAME_BYTES];
    frame[..2].copy_from_slice(&response.to_be_bytes());
    for (i, code) in codes.iter().enumerate() {
        frame[3 + 3 * i..6 + 3 * i].copy_from_slice(&code.to_be_bytes()[1..]);
    }
    let crc = crc16_ccitt(&frame[..9]);
    frame[9..11].copy_from_slice(&crc.to_be_bytes());
    frame
}

fn reply(response: u16) -> [u8; FRAME_BYTES] {
    device(response, [0, 0])
}

const CONFIG: Config = Config {
    osr: Osr::X1024,
    gains: [Gain::X64, Gain::X64],
};

/// Register values as the device would hold them after the driver's writes.
fn written() -> [(u8, u16); 3] {
    [
        (address::MODE, MODE_VALUE),
        (address::CLOCK, CONFIG.clock_register()),
        (address::GAIN, CONFIG.gain_register()),
    ]
}

/// The script of a successful init up to and including the ID read, with `id` as the ID.
fn reset_and_id(id: u16) -> MockSpi {
    MockSpi::default()
        // Before the reset the device may answer anything, even garbage without a valid CRC.
        .expect(command::RESET, 0, [0xAB; FRAME_BYTES])
        .expect(command::NULL, 0, reply(command::RESET_ACK))
        .expect(command::read_register(address::ID), 0, reply(0x0500))
        .expect(command::NULL, 0, reply(id))
}

/// The three register writes of init, each acknowledged.
fn acknowledged_writes(mut spi: MockSpi) -> MockSpi {
    for (register, value) in written() {
        spi = spi
            .expect(command::write_register(register), value, reply(0x0500))
            .expect(
                command::NULL,
                0,
                reply(command::write_acknowledge(register)),
            );
    }
    spi
}

/// A complete successful init.
fn full_init() -> MockSpi {
    let mut spi = acknowledged_writes(reset_and_id(0x2200));
    for (register, value) in written() {
        spi = spi
            .expect(command::read_register(register), 0, reply(0x0500))
            .expect(command::NULL, 0, reply(value));
    }
    spi
}

#[test]
fn init_resets_checks_the_id_and_verifies_the_configuration() {
    let mut adc = Ads131m02::new(full_init());
    let mut delay = Delay::default();
    assert_eq!(adc.init(&CONFIG, &mut delay), Ok(0x2200));
    assert_eq!(delay.total_ns, 1_000_000);
    let spi = adc.release();
    assert!(spi.done());
    assert_eq!(spi.transactions, 16);
}

#[test]
fn samples_are_signed_24_bit_with_their_status() {
    let spi = full_init()
        .expect(command::NULL, 0, device(0x0103, [-1_234_567, 7_654_321]))
        .expect(command::NULL, 0, device(0x0101, [-0x80_0000, 0x7F_FFFF]));
    let mut adc = Ads131m02::new(spi);
    adc.init(&CONFIG, &mut Delay::default()).unwrap();
    let first = adc.read_sample().unwrap();
    assert_eq!(first.codes, [-1_234_567, 7_654_321].map(AdcCode::new));
    assert!(first.status.data_ready(0) && first.status.data_ready(1));
    let second = adc.read_sample().unwrap();
    assert_eq!(second.codes, [-0x80_0000, 0x7F_FFFF].map(AdcCode::new));
    assert_eq!(second.status, Status(0x0101));
    assert!(!second.status.data_ready(1));
    assert!(adc.release().done());
}

#[test]
fn a_corrupted_sample_is_a_crc_error() {
    let mut corrupted = device(0x0103, [1000, 2000]);
    corrupted[5] ^= 0x01; // one bit of channel 0
    let spi = full_init().expect(command::NULL, 0, corrupted);
    let mut adc = Ads131m02::new(spi);
    adc.init(&CONFIG, &mut Delay::default()).unwrap();
    let good_crc = crc16_ccitt(&device(0x0103, [1000, 2000])[..9]);
    assert_eq!(
        adc.read_sample(),
        Err(Error::Crc(CrcMismatch {
            computed: crc16_ccitt(&corrupted[..9]),
            received: good_crc,
        }))
    );
}

#[test]
fn a_four_channel_part_is_the_wrong_id() {
    let mut adc = Ads131m02::new(reset_and_id(0x2400));
    assert_eq!(
        adc.init(&CONFIG, &mut Delay::default()),
        Err(Error::WrongId { id: 0x2400 })
    );
    assert!(adc.release().done());
}

#[test]
fn no_device_gives_no_reset_acknowledge_or_a_crc_error() {
    // MISO pulled low: all-zero frames fail the CRC.
    let spi = MockSpi::default()
        .expect(command::RESET, 0, [0; FRAME_BYTES])
        .expect(command::NULL, 0, [0; FRAME_BYTES]);
    let mut adc = Ads131m02::new(spi);
    assert!(matches!(
        adc.init(&CONFIG, &mut Delay::default()),
        Err(Error::Crc(_))
    ));
    // A device that answers STATUS instead of the acknowledgement did not reset.
    let spi = MockSpi::default()
        .expect(command::RESET, 0, reply(0x0500))
        .expect(command::NULL, 0, reply(0x0500));
    let mut adc = Ads131m02::new(spi);
    assert_eq!(
        adc.reset(&mut Delay::default()),
        Err(Error::NoResetAcknowledge { response: 0x0500 })
    );
}

#[test]
fn an_unacknowledged_write_and_a_wrong_read_back_are_reported() {
    let spi = reset_and_id(0x2200)
        .expect(
            command::write_register(address::MODE),
            MODE_VALUE,
            reply(0x0500),
        )
        .expect(command::NULL, 0, reply(0x0500));
    let mut adc = Ads131m02::new(spi);
    assert_eq!(
        adc.init(&CONFIG, &mut Delay::default()),
        Err(Error::UnexpectedResponse {
            expected: command::write_acknowledge(address::MODE),
            received: 0x0500
        })
    );
    // Writes acknowledged, but CLOCK reads back with another oversampling ratio.
    let spi = acknowledged_writes(reset_and_id(0x2200))
        .expect(command::read_register(address::MODE), 0, reply(0x0500))
        .expect(command::NULL, 0, reply(MODE_VALUE))
        .expect(command::read_register(address::CLOCK), 0, reply(0x0500))
        .expect(command::NULL, 0, reply(0x030A));
    let mut adc = Ads131m02::new(spi);
    assert_eq!(
        adc.init(&CONFIG, &mut Delay::default()),
        Err(Error::ConfigMismatch {
            address: address::CLOCK,
            written: CONFIG.clock_register(),
            read: 0x030A
        })
    );
    assert!(adc.release().done());
}

#[test]
fn a_bus_error_and_a_spontaneous_reset_are_reported() {
    let mut adc = Ads131m02::new(MockSpi::default().fail());
    assert_eq!(
        adc.init(&CONFIG, &mut Delay::default()),
        Err(Error::Spi(BusFault))
    );
    // STATUS with the RESET flag set: the device lost its configuration.
    let spi = full_init().expect(command::NULL, 0, device(0x0503, [1, 2]));
    let mut adc = Ads131m02::new(spi);
    adc.init(&CONFIG, &mut Delay::default()).unwrap();
    assert_eq!(
        adc.read_sample(),
        Err(Error::DeviceReset { status: 0x0503 })
    );
}

#[test]
fn the_script_catches_a_wrong_frame() {
    // Guard against a mock that accepts anything: a frame different from the script panics.
    let result = std::panic::catch_unwind(|| {
        let spi = MockSpi::default().expect(command::RESET, 0, reply(0));
        let mut adc = Ads131m02::new(spi);
        let _ = adc.read_register(address::ID);
    });
    assert!(result.is_err());
}
