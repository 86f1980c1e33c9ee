//! A register-level model of the TDK InvenSense ICM-42688-P (DS-000347),
//! serving a [`SampleSource`] over SPI and I²C like the chip does.
//!
//! Modelled: the bank-0 register map with reset values (§13), bank
//! selection, WHO_AM_I, soft reset with RESET_DONE, power modes (PWR_MGMT0),
//! full-scale ranges and output data rates (GYRO_CONFIG0, ACCEL_CONFIG0)
//! changing sensitivity, saturation and sample timing, temperature output,
//! INT_STATUS with clear-on-read, the FIFO (packet 3, 16 bytes; bypass,
//! stream and stop-on-full modes; watermark; lost-packet count; flush), the
//! self-test (SELF_TEST_CONFIG adds the unit's [`SelfTestResponse`] to the
//! enabled axes at once; the factory codes read in banks 1 and 2), and
//! injected faults. Not modelled: the rest of banks 1–4 (read as 0, writes ignored),
//! filters and their group delay, noise (that is the source's business),
//! packets other than 3, the 20-bit mode, timestamps beyond a µs counter.
//!
//! Time moves only through [`Icm42688Model::advance`]: one new sample per
//! ODR period elapsed. No allocation; about 2.3 KiB of state.

use embedded_hal::i2c::{self, I2c};
use embedded_hal::spi::{self, SpiDevice};

use super::fault::Fault;
use super::icm42688_factory_trim::FactoryTrim;
use super::model_clock::Clocked;
use super::packet_fifo::PacketFifo;
use super::register_bus::{quantise, BusPort, RegisterFile};
use super::self_test_response::{DeadAxes, SelfTestResponse};
use super::source::{SampleSource, TrueSample};
use crate::icm42688_registers as reg;
use triad::units::{rad_to_deg, STANDARD_GRAVITY};

/// FIFO of packet-3 entries: 2 KiB.
type Fifo = PacketFifo<{ reg::FIFO_CAPACITY_PACKETS as usize }, { reg::FIFO_PACKET_LEN }>;

/// §13: bank-0 registers whose reset value is not 0x00.
const RESET_VALUES: [(u8, u8); 13] = [
    (0x13, 0x05), // DRIVE_CONFIG
    (reg::INTF_CONFIG0, 0x30),
    (0x4D, 0x91), // INTF_CONFIG1
    (reg::GYRO_CONFIG0, 0x06),
    (reg::ACCEL_CONFIG0, 0x06),
    (0x51, 0x16), // GYRO_CONFIG1
    (0x52, 0x11), // GYRO_ACCEL_CONFIG0
    (0x53, 0x0D), // ACCEL_CONFIG1
    (0x54, 0x23), // TMST_CONFIG
    (0x62, 0x10), // FSYNC_CONFIG
    (reg::INT_CONFIG1, reg::INT_ASYNC_RESET),
    (reg::INT_SOURCE0, 0x10), // RESET_DONE drives INT1
    (reg::WHO_AM_I, reg::WHO_AM_I_VALUE),
];

/// The chip's state behind the bus.
struct Chip<S> {
    source: S,
    bank: u8,
    regs: [u8; 128],
    status: u8,
    fifo: Fifo,
    lost_packets: u16,
    phase_ns: u64,
    timestamp_us: u64,
    samples: u64,
    clipped: bool,
    who_am_i_override: Option<u8>,
    stuck: bool,
    self_test: SelfTestResponse,
    factory_trim: FactoryTrim,
    dead_self_test: DeadAxes,
}

/// The default unit's self-test response relative to its factory trim: 4 %
/// stronger than at the factory (well inside the 0.5–1.5 ratio window).
const UNIT_SELF_TEST_DRIFT: f64 = 1.04;

/// A simulated ICM-42688-P on a bus, fed by `S`.
pub struct Icm42688Model<S> {
    chip: Chip<S>,
    port: BusPort,
}

/// §3.2 Table 2 (model's own copy, so the driver's table is checked against it):
/// LSB/g by ACCEL_FS_SEL; codes 4–7 are reserved and read as ±16 g here.
fn accel_lsb_per_g(fs_sel: u8) -> f64 {
    match fs_sel {
        1 => 4096.0,
        2 => 8192.0,
        3 => 16384.0,
        _ => 2048.0,
    }
}

/// §3.1 Table 1: LSB/(°/s) by GYRO_FS_SEL.
fn gyro_lsb_per_dps(fs_sel: u8) -> f64 {
    match fs_sel {
        1 => 32.8,
        2 => 65.5,
        3 => 131.0,
        4 => 262.0,
        5 => 524.3,
        6 => 1048.6,
        7 => 2097.2,
        _ => 16.4,
    }
}

/// §14 GYRO_CONFIG0/ACCEL_CONFIG0: sample period in ns by ODR code; `None` reserved.
fn odr_period_ns(code: u8) -> Option<u64> {
    Some(match code {
        0x1 => 31_250,
        0x2 => 62_500,
        0x3 => 125_000,
        0x4 => 250_000,
        0x5 => 500_000,
        0x6 => 1_000_000,
        0x7 => 5_000_000,
        0x8 => 10_000_000,
        0x9 => 20_000_000,
        0xA => 40_000_000,
        0xB => 80_000_000,
        0xC => 160_000_000,
        0xD => 320_000_000,
        0xE => 640_000_000,
        0xF => 2_000_000,
        _ => return None,
    })
}

impl<S: SampleSource> Icm42688Model<S> {
    /// A powered-up chip (just after its power-on reset) answering I²C at 0x68.
    pub fn new(source: S) -> Self {
        let mut chip = Chip {
            source,
            bank: 0,
            regs: [0; 128],
            status: 0,
            fifo: Fifo::new(),
            lost_packets: 0,
            phase_ns: 0,
            timestamp_us: 0,
            samples: 0,
            clipped: false,
            who_am_i_override: None,
            stuck: false,
            self_test: FactoryTrim::TYPICAL.response().scaled(UNIT_SELF_TEST_DRIFT),
            factory_trim: FactoryTrim::TYPICAL,
            dead_self_test: DeadAxes::default(),
        };
        chip.reset();
        Self {
            chip,
            port: BusPort::new(reg::I2C_ADDRESS_AD0_LOW),
        }
    }

    /// The same chip with factory self-test codes `trim` and a self-test
    /// response `response` (by default [`FactoryTrim::TYPICAL`] and its
    /// response × 1.04).
    pub fn with_self_test(mut self, trim: FactoryTrim, response: SelfTestResponse) -> Self {
        self.chip.factory_trim = trim;
        self.chip.self_test = response;
        self
    }

    /// What the self-test adds to each axis when enabled, SI.
    pub fn self_test_response(&self) -> SelfTestResponse {
        self.chip.self_test
    }

    /// The same chip with its AP_AD0 pin high (I²C address 0x69) or low (0x68).
    pub fn with_ad0(mut self, high: bool) -> Self {
        self.port = BusPort::new(if high {
            reg::I2C_ADDRESS_AD0_HIGH
        } else {
            reg::I2C_ADDRESS_AD0_LOW
        });
        self
    }

    /// Lets `ns` nanoseconds pass: one sample per ODR period elapsed.
    pub fn advance(&mut self, ns: u64) {
        self.chip.advance(ns);
    }

    /// The nanoseconds until the next sample at the rate the chip runs (the
    /// one its driver wrote; every ICM-42688-P period is a whole number of
    /// ns). `None`: both sensors off.
    pub fn ns_to_next_sample(&self) -> Option<u64> {
        Some(self.chip.period_ns()? - self.chip.phase_ns)
    }

    /// Injects a fault (see [`Fault`]).
    pub fn inject(&mut self, fault: Fault) {
        match fault {
            Fault::BusError { transactions } => self.port.fail_next(transactions),
            Fault::WrongWhoAmI(value) => self.chip.who_am_i_override = Some(value),
            Fault::StuckOutput => self.chip.stuck = true,
            Fault::FifoOverflow { lost } => self.chip.overflow_fifo(lost),
            Fault::DeadSelfTest { triad, axis } => self.chip.dead_self_test.kill(triad, axis),
        }
    }

    /// Clears every persistent fault (wrong identity, stuck output, dead
    /// self-test axes, pending bus errors).
    pub fn clear_faults(&mut self) {
        self.chip.who_am_i_override = None;
        self.chip.stuck = false;
        self.chip.dead_self_test = DeadAxes::default();
        self.port.fail_next(0);
    }

    /// Bytes moved on the bus so far (see [`BusPort::bytes`]).
    pub fn bus_bytes(&self) -> u64 {
        self.port.bytes()
    }

    /// Restarts the bus byte count.
    pub fn reset_bus_bytes(&mut self) {
        self.port.reset_bytes();
    }

    /// Samples taken from the source since creation.
    pub fn samples_produced(&self) -> u64 {
        self.chip.samples
    }

    /// Whether the latest sample had an axis beyond full scale (read as a limit code).
    pub fn clipped(&self) -> bool {
        self.chip.clipped
    }

    /// Packets in the FIFO.
    pub fn fifo_len(&self) -> usize {
        self.chip.fifo.len()
    }

    /// A bank-0 register's stored value, without read side effects (for tests).
    pub fn peek(&self, address: u8) -> u8 {
        self.chip.regs[usize::from(address & 0x7F)]
    }

    /// Whether INT1 is asserted (a pending status bit routed by INT_SOURCE0).
    pub fn int1(&self) -> bool {
        self.chip.status & self.chip.regs[usize::from(reg::INT_SOURCE0)] != 0
    }

    /// The sample source.
    pub fn source_mut(&mut self) -> &mut S {
        &mut self.chip.source
    }
}

impl<S: SampleSource> Chip<S> {
    /// Power-on / soft reset: §13 reset values, FIFO empty, RESET_DONE set.
    fn reset(&mut self) {
        self.regs = [0; 128];
        for (address, value) in RESET_VALUES {
            self.regs[usize::from(address)] = value;
        }
        // Data registers read -32768 (0x8000) until a sensor produces data.
        for address in (reg::TEMP_DATA1..=reg::GYRO_DATA_Z0).step_by(2) {
            self.regs[usize::from(address)] = 0x80;
        }
        self.bank = 0;
        self.status = reg::RESET_DONE_INT;
        self.fifo.clear();
        self.lost_packets = 0;
        self.phase_ns = 0;
    }

    fn reg(&self, address: u8) -> u8 {
        self.regs[usize::from(address & 0x7F)]
    }

    /// The sample period of whichever sensor runs (gyro first); `None` when both are off.
    fn period_ns(&self) -> Option<u64> {
        let power = self.reg(reg::PWR_MGMT0);
        let gyro_on = power & (0b11 << 2) == reg::GYRO_MODE_LOW_NOISE;
        let accel_on = power & 0b11 != 0;
        if gyro_on {
            odr_period_ns(self.reg(reg::GYRO_CONFIG0) & reg::ODR_MASK)
        } else if accel_on {
            odr_period_ns(self.reg(reg::ACCEL_CONFIG0) & reg::ODR_MASK)
        } else {
            None
        }
    }

    fn advance(&mut self, ns: u64) {
        let Some(period) = self.period_ns() else {
            self.phase_ns = 0;
            return;
        };
        self.phase_ns = self.phase_ns.saturating_add(ns);
        while self.phase_ns >= period {
            self.phase_ns -= period;
            self.timestamp_us = self.timestamp_us.wrapping_add(period / 1_000);
            if !self.stuck {
                self.produce_sample();
            }
        }
    }

    fn overflow_fifo(&mut self, lost: u16) {
        if self.fifo_mode() == reg::FIFO_MODE_BYPASS || self.period_ns().is_none() {
            return;
        }
        let room = self.fifo_capacity_left();
        for _ in 0..room + usize::from(lost) {
            self.produce_sample();
        }
    }

    fn fifo_capacity_left(&self) -> usize {
        usize::from(reg::FIFO_CAPACITY_PACKETS) - self.fifo.len()
    }

    fn fifo_mode(&self) -> u8 {
        self.reg(reg::FIFO_CONFIG) & reg::FIFO_MODE_MASK
    }

    /// The watermark in packets (FIFO_CONFIG2/3 count records or bytes per INTF_CONFIG0).
    fn watermark_packets(&self) -> usize {
        let wm = usize::from(u16::from_le_bytes([
            self.reg(reg::FIFO_CONFIG2),
            self.reg(reg::FIFO_CONFIG3) & 0x0F,
        ]));
        if self.reg(reg::INTF_CONFIG0) & reg::FIFO_COUNT_REC != 0 {
            wm
        } else {
            wm.div_ceil(reg::FIFO_PACKET_LEN)
        }
    }

    /// The self-test excitation SELF_TEST_CONFIG enables (positive on every
    /// enabled axis; the accelerometer's needs ACCEL_ST_POWER too).
    fn self_test_excitation(&self) -> SelfTestResponse {
        let config = self.reg(reg::SELF_TEST_CONFIG);
        let powered = config & reg::ACCEL_ST_POWER != 0;
        let on = |first: u8, i: u8| i8::from(config & (first << i) != 0);
        let accel = [0, 1, 2].map(|i| on(reg::EN_AX_ST, i) * i8::from(powered));
        let gyro = [0, 1, 2].map(|i| on(reg::EN_GX_ST, i));
        self.dead_self_test.excitation(&self.self_test, accel, gyro)
    }

    /// Takes one sample from the source into the data registers and the FIFO.
    fn produce_sample(&mut self) {
        let mut truth: TrueSample = self.source.next_sample();
        self.samples += 1;
        let excitation = self.self_test_excitation();
        for axis in 0..3 {
            truth.specific_force[axis] += excitation.accel[axis];
            truth.angular_rate[axis] += excitation.gyro[axis];
        }
        let power = self.reg(reg::PWR_MGMT0);
        let accel_on = power & 0b11 != 0;
        let gyro_on = power & (0b11 << 2) == reg::GYRO_MODE_LOW_NOISE;
        let temp_on = power & (1 << 5) == 0;

        let accel_scale = accel_lsb_per_g(self.reg(reg::ACCEL_CONFIG0) >> 5) / STANDARD_GRAVITY;
        let gyro_scale = gyro_lsb_per_dps(self.reg(reg::GYRO_CONFIG0) >> 5);
        let mut clipped = false;
        let mut accel = [0i16; 3];
        let mut gyro = [0i16; 3];
        for axis in 0..3 {
            let (a, ca) = quantise(
                truth.specific_force[axis] * accel_scale,
                -reg::LIMIT_CODE,
                reg::LIMIT_CODE,
            );
            let (g, cg) = quantise(
                rad_to_deg(truth.angular_rate[axis]) * gyro_scale,
                -reg::LIMIT_CODE,
                reg::LIMIT_CODE,
            );
            accel[axis] = a;
            gyro[axis] = g;
            clipped |= (ca && accel_on) || (cg && gyro_on);
        }
        self.clipped = clipped;
        let celsius = truth.temperature - reg::TEMP_OFFSET_C;
        let (temp, _) = quantise(
            celsius * reg::TEMP_LSB_PER_C,
            -reg::LIMIT_CODE,
            reg::LIMIT_CODE,
        );

        let put = |regs: &mut [u8; 128], address: u8, value: i16| {
            let [h, l] = value.to_be_bytes();
            regs[usize::from(address)] = h;
            regs[usize::from(address + 1)] = l;
        };
        if temp_on {
            put(&mut self.regs, reg::TEMP_DATA1, temp);
        }
        for axis in 0..3 {
            if accel_on {
                put(&mut self.regs, 0x1F + 2 * axis as u8, accel[axis]);
            }
            if gyro_on {
                put(&mut self.regs, 0x25 + 2 * axis as u8, gyro[axis]);
            }
        }
        self.status |= reg::DATA_RDY_INT;

        let fifo_enabled =
            self.reg(reg::FIFO_CONFIG1) & (reg::FIFO_ACCEL_EN | reg::FIFO_GYRO_EN) != 0;
        let mode = self.fifo_mode();
        if mode == reg::FIFO_MODE_BYPASS || !fifo_enabled {
            return;
        }
        let mut packet = [0u8; reg::FIFO_PACKET_LEN];
        packet[0] = reg::HEADER_ACCEL | reg::HEADER_GYRO | reg::HEADER_TIMESTAMP_ODR;
        for axis in 0..3 {
            packet[1 + 2 * axis..3 + 2 * axis].copy_from_slice(&accel[axis].to_be_bytes());
            packet[7 + 2 * axis..9 + 2 * axis].copy_from_slice(&gyro[axis].to_be_bytes());
        }
        let fifo_temp = libm::round(celsius * reg::FIFO_TEMP_LSB_PER_C).clamp(-128.0, 127.0);
        // Clamped to the i8 range just above: the cast is exact.
        packet[13] = (fifo_temp as i8) as u8;
        // The ODR timestamp, µs, 16 bits (§6.1): the counter wraps.
        let [_, _, _, _, _, _, th, tl] = self.timestamp_us.to_be_bytes();
        packet[14] = th;
        packet[15] = tl;
        if self.fifo.is_full() {
            self.lost_packets = self.lost_packets.saturating_add(1);
            if mode == reg::FIFO_MODE_STREAM {
                self.fifo.push_overwrite(packet);
            }
        } else {
            self.fifo.push(packet);
        }
        if self.fifo.is_full() {
            self.status |= reg::FIFO_FULL_INT;
        }
        let wm = self.watermark_packets();
        if wm > 0 && self.fifo.len() >= wm {
            self.status |= reg::FIFO_THS_INT;
        }
    }

    /// FIFO_COUNT in records or bytes as INTF_CONFIG0 asks.
    fn fifo_count(&self) -> u16 {
        let count = if self.reg(reg::INTF_CONFIG0) & reg::FIFO_COUNT_REC != 0 {
            self.fifo.len()
        } else {
            self.fifo.bytes()
        };
        // At most 2048: fits.
        count as u16
    }
}

impl<S: SampleSource> RegisterFile for Chip<S> {
    fn read_register(&mut self, address: u8) -> u8 {
        let address = address & 0x7F;
        if address == reg::REG_BANK_SEL {
            return self.bank;
        }
        let codes = |first: u8, trim: [u8; 3]| {
            let i = usize::from(address.wrapping_sub(first));
            trim.get(i).copied().unwrap_or(0)
        };
        match self.bank {
            0 => {}
            1 => return codes(reg::XG_ST_DATA_BANK1, self.factory_trim.gyro),
            2 => return codes(reg::XA_ST_DATA_BANK2, self.factory_trim.accel),
            _ => return 0,
        }
        match address {
            reg::WHO_AM_I => self.who_am_i_override.unwrap_or(reg::WHO_AM_I_VALUE),
            reg::INT_STATUS => core::mem::take(&mut self.status),
            reg::FIFO_COUNTH | 0x2F => {
                let [high, low] = self.fifo_count().to_be_bytes();
                let big_endian = self.reg(reg::INTF_CONFIG0) & reg::FIFO_COUNT_ENDIAN != 0;
                match (address == reg::FIFO_COUNTH, big_endian) {
                    (true, true) | (false, false) => high,
                    _ => low,
                }
            }
            // §6: an empty FIFO reads 0xFF (header bit 7: no valid packet).
            reg::FIFO_DATA => self.fifo.pop_byte().unwrap_or(0xFF),
            reg::FIFO_LOST_PKT0 => self.lost_packets.to_le_bytes()[0],
            0x6D => self.lost_packets.to_le_bytes()[1],
            _ => self.reg(address),
        }
    }

    fn write_register(&mut self, address: u8, value: u8) {
        let address = address & 0x7F;
        if address == reg::REG_BANK_SEL {
            self.bank = value & 0x07;
            return;
        }
        if self.bank != 0 {
            return;
        }
        match address {
            reg::DEVICE_CONFIG => {
                if value & reg::SOFT_RESET_CONFIG != 0 {
                    self.reset();
                } else {
                    self.regs[usize::from(address)] = value;
                }
            }
            reg::SIGNAL_PATH_RESET => {
                if value & reg::FIFO_FLUSH != 0 {
                    self.fifo.clear();
                    self.lost_packets = 0;
                }
            }
            // Read-only: data, status, FIFO count and port, lost count, identity.
            reg::TEMP_DATA1..=reg::FIFO_DATA | reg::FIFO_LOST_PKT0 | 0x6D | reg::WHO_AM_I => {}
            reg::PWR_MGMT0 => {
                // A sensor turning on starts its ODR clock afresh.
                if self.period_ns().is_none() {
                    self.phase_ns = 0;
                }
                self.regs[usize::from(address)] = value;
            }
            _ => self.regs[usize::from(address)] = value,
        }
    }

    /// Bursts auto-increment, except on FIFO_DATA which keeps returning FIFO bytes.
    fn next_address(&self, address: u8) -> u8 {
        if address == reg::FIFO_DATA {
            address
        } else {
            address.wrapping_add(1) & 0x7F
        }
    }
}

impl<S: SampleSource> Clocked for Icm42688Model<S> {
    fn advance(&mut self, ns: u64) {
        self.chip.advance(ns);
    }
}

impl<S> spi::ErrorType for Icm42688Model<S> {
    type Error = spi::ErrorKind;
}

impl<S: SampleSource> SpiDevice for Icm42688Model<S> {
    fn transaction(
        &mut self,
        operations: &mut [spi::Operation<'_, u8>],
    ) -> Result<(), spi::ErrorKind> {
        self.port.spi(&mut self.chip, operations)
    }
}

impl<S> i2c::ErrorType for Icm42688Model<S> {
    type Error = i2c::ErrorKind;
}

impl<S: SampleSource> I2c for Icm42688Model<S> {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [i2c::Operation<'_>],
    ) -> Result<(), i2c::ErrorKind> {
        self.port.i2c(&mut self.chip, address, operations)
    }
}
