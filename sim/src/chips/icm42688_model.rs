//! A register-level model of the TDK InvenSense ICM-42688-P (DS-000347),
//! serving a [`SampleSource`] over SPI and I²C like the chip does.
//!
//! Modelled: the register map of banks 0, 1 and 2 with reset values (§13;
//! every address the data sheet lists keeps what a driver writes), bank
//! selection, WHO_AM_I, soft reset with RESET_DONE, power modes (PWR_MGMT0),
//! full-scale ranges and independent accelerometer and gyroscope output data
//! rates (GYRO_CONFIG0, ACCEL_CONFIG0; both sensors count time from one chip
//! clock), temperature output, INT_STATUS with clear-on-read, the sensor data
//! endianness (INTF_CONFIG0), I²C switched off by INTF_CONFIG0 UI_SIFS_CFG,
//! the FIFO_COUNTH → FIFO_COUNTL latch, the FIFO (§6: packets 1 and 2 with
//! one sensor, 3 with both, 4 with 20-bit data when FIFO_HIRES_EN; a sensor
//! with no new sample in a packet reads the invalid marker; bypass, stream and
//! stop-on-full modes; watermark in records or bytes; lost-packet count;
//! flush; the header's ODR-change bits), the timestamp (TMST_CONFIG: 1 µs or
//! 16 µs resolution, absolute or delta; TMST_STROBE into TMSTVAL), the
//! self-test (SELF_TEST_CONFIG adds the unit's [`SelfTestResponse`] to the
//! enabled axes at once; the factory codes read in banks 1 and 2), and
//! injected faults.
//!
//! Inert (kept, no effect on the data): DRIVE_CONFIG, INT_CONFIG,
//! INT_CONFIG0/1, INT_SOURCE1/3/4, INTF_CONFIG1, GYRO_CONFIG1,
//! GYRO_ACCEL_CONFIG0, ACCEL_CONFIG1 (filters), FSYNC_CONFIG, APEX_CONFIG0,
//! SMD_CONFIG, bank 1 GYRO_CONFIG_STATIC2..10 (notch and anti-alias
//! filters), INTF_CONFIG4..6, bank 2 ACCEL_CONFIG_STATIC2..4. The model has no
//! filters, no group delay and no noise (the source's business).
//!
//! Not modelled, and recorded in [`Icm42688Model::unmodelled`] when touched:
//! reserved addresses, banks 3 and 4, SENSOR_CONFIG0 axis disables, SPI
//! switched off (UI_SIFS_CFG = 10), a stopped timestamp (TMST_EN = 0), the
//! signal-path and DMP-memory resets of SIGNAL_PATH_RESET.
//!
//! Time moves only through [`Icm42688Model::advance`]: one new sample per
//! ODR period elapsed; when the two sensors run at different rates the
//! source gives one true sample per instant at which either samples. No
//! allocation; about 2.8 KiB of state.

use super::icm42688_factory_trim::FactoryTrim;
use super::packet_fifo::PacketFifo;
use super::register_bus::{quantise, quantise_wide, BusPort, RegisterFile};
use super::self_test_response::{DeadAxes, SelfTestResponse};
use super::sensor_clock::{Rate, Rates, SensorClock};
use super::source::{SampleSource, TrueSample};
use super::unmodelled::{UnmodelledAccess, UnmodelledLog};
use crate::chips::icm42688_registers as reg;
use triad::units::{rad_to_deg, STANDARD_GRAVITY};

/// The 2 KiB FIFO, packets 1–4 mixed.
type Fifo = PacketFifo<{ reg::FIFO_BYTES }, { reg::FIFO_MAX_PACKETS }>;

/// Banks the model holds (0, 1, 2); 3 and 4 are not modelled.
const BANKS: usize = 3;

/// §13: registers whose reset value is not 0x00, as (bank, address, value).
const RESET_VALUES: [(u8, u8, u8); 22] = [
    (0, 0x13, 0x05), // DRIVE_CONFIG
    (0, reg::INTF_CONFIG0, 0x30),
    (0, 0x4D, 0x91), // INTF_CONFIG1
    (0, reg::GYRO_CONFIG0, 0x06),
    (0, reg::ACCEL_CONFIG0, 0x06),
    (0, 0x51, 0x16), // GYRO_CONFIG1
    (0, 0x52, 0x11), // GYRO_ACCEL_CONFIG0
    (0, 0x53, 0x0D), // ACCEL_CONFIG1
    (0, reg::TMST_CONFIG, 0x23),
    (0, reg::APEX_CONFIG0, 0x82), // DMP_POWER_SAVE, DMP_ODR 50 Hz
    (0, 0x62, 0x10),              // FSYNC_CONFIG
    (0, reg::INT_CONFIG1, reg::INT_ASYNC_RESET),
    (0, reg::INT_SOURCE0, 0x10), // RESET_DONE drives INT1
    (0, reg::WHO_AM_I, reg::WHO_AM_I_VALUE),
    (1, 0x0B, 0xA0), // GYRO_CONFIG_STATIC2
    (1, 0x0C, 0x0D), // GYRO_CONFIG_STATIC3: GYRO_AAF_DELT 13
    (1, 0x0D, 0xAA), // GYRO_CONFIG_STATIC4: GYRO_AAF_DELTSQR 170 (low byte)
    (1, 0x0E, 0x80), // GYRO_CONFIG_STATIC5: GYRO_AAF_BITSHIFT 8
    (1, 0x7A, 0x83), // INTF_CONFIG4
    (2, 0x03, 0x30), // ACCEL_CONFIG_STATIC2: ACCEL_AAF_DELT 24
    (2, 0x04, 0x40), // ACCEL_CONFIG_STATIC3: ACCEL_AAF_DELTSQR 576 (low byte)
    (2, 0x05, 0x62), // ACCEL_CONFIG_STATIC4: BITSHIFT 6, DELTSQR high 2
];

/// §13: the addresses each bank's map lists (inclusive ranges); REG_BANK_SEL
/// (0x76) is in every bank.
const MAP: [&[(u8, u8)]; BANKS] = [
    &[
        (0x11, 0x11),
        (0x13, 0x14),
        (0x16, 0x16),
        (0x1D, 0x38),
        (0x4B, 0x54),
        (0x56, 0x57),
        (0x5F, 0x66),
        (0x68, 0x69),
        (0x6C, 0x6D),
        (0x70, 0x70),
        (0x75, 0x76),
    ],
    &[
        (0x03, 0x03),
        (0x0B, 0x13),
        (0x5F, 0x64),
        (0x76, 0x76),
        (0x7A, 0x7C),
    ],
    &[(0x03, 0x05), (0x3B, 0x3D), (0x76, 0x76)],
];

/// Whether `address` is in bank `bank`'s map.
fn listed(bank: u8, address: u8) -> bool {
    MAP.get(usize::from(bank))
        .is_some_and(|ranges| ranges.iter().any(|&(a, b)| (a..=b).contains(&address)))
}

/// The chip's state behind the bus.
struct Chip<S> {
    source: S,
    bank: u8,
    regs: [[u8; 128]; BANKS],
    status: u8,
    fifo: Fifo,
    lost_packets: u16,
    clock: SensorClock,
    /// The timestamp counter's time, ns (runs while a sensor does).
    timestamp_ns: u64,
    /// The timestamp at the previous ODR event, in counter ticks (delta mode).
    previous_ticks: u64,
    /// FIFO_COUNT latched by reading FIFO_COUNTH, for FIFO_COUNTL.
    count_latch: Option<u16>,
    /// The ODR codes of the previous FIFO packet with accel / gyro data.
    fifo_accel_odr: Option<u8>,
    fifo_gyro_odr: Option<u8>,
    samples: u64,
    clipped: bool,
    who_am_i_override: Option<u8>,
    stuck: bool,
    self_test: SelfTestResponse,
    factory_trim: FactoryTrim,
    dead_self_test: DeadAxes,
    unmodelled: UnmodelledLog,
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
const fn accel_lsb_per_g(fs_sel: u8) -> f64 {
    match fs_sel {
        1 => 4096.0,
        2 => 8192.0,
        3 => 16384.0,
        _ => 2048.0,
    }
}

/// [`accel_lsb_per_g`] per m/s²: divided at compile time, not per sample.
fn accel_lsb_per_ms2(fs_sel: u8) -> f64 {
    const BY_CODE: [f64; 4] = [
        accel_lsb_per_g(0) / STANDARD_GRAVITY,
        accel_lsb_per_g(1) / STANDARD_GRAVITY,
        accel_lsb_per_g(2) / STANDARD_GRAVITY,
        accel_lsb_per_g(3) / STANDARD_GRAVITY,
    ];
    // Codes 4–7 read as ±16 g, as code 0.
    BY_CODE
        .get(usize::from(fs_sel))
        .copied()
        .unwrap_or(BY_CODE[0])
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

/// A 16-bit value in the byte order INTF_CONFIG0 SENSOR_DATA_ENDIAN asks for.
fn word(value: i16, big_endian: bool) -> [u8; 2] {
    if big_endian {
        value.to_be_bytes()
    } else {
        value.to_le_bytes()
    }
}

impl<S: SampleSource> Icm42688Model<S> {
    /// A powered-up chip (just after its power-on reset) answering I²C at 0x68.
    pub fn new(source: S) -> Self {
        let mut chip = Chip {
            source,
            bank: 0,
            regs: [[0; 128]; BANKS],
            status: 0,
            fifo: Fifo::new(),
            lost_packets: 0,
            clock: SensorClock::default(),
            timestamp_ns: 0,
            previous_ticks: 0,
            count_latch: None,
            fifo_accel_odr: None,
            fifo_gyro_odr: None,
            samples: 0,
            clipped: false,
            who_am_i_override: None,
            stuck: false,
            self_test: FactoryTrim::TYPICAL.response().scaled(UNIT_SELF_TEST_DRIFT),
            factory_trim: FactoryTrim::TYPICAL,
            dead_self_test: DeadAxes::default(),
            unmodelled: UnmodelledLog::default(),
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

    /// The same chip with its AP_AD0 pin high (I²C address 0x69) or low (0x68).
    pub fn with_ad0(mut self, high: bool) -> Self {
        self.port = BusPort::new(if high {
            reg::I2C_ADDRESS_AD0_HIGH
        } else {
            reg::I2C_ADDRESS_AD0_LOW
        });
        self
    }

    /// A bank-0 register's stored value, without read side effects (for tests).
    pub fn peek(&self, address: u8) -> u8 {
        self.peek_bank(0, address)
    }

    /// A register's stored value in bank `bank` (0–2; others read 0), without
    /// read side effects (for tests).
    pub fn peek_bank(&self, bank: u8, address: u8) -> u8 {
        self.chip
            .regs
            .get(usize::from(bank))
            .map_or(0, |r| r[usize::from(address & 0x7F)])
    }

    /// Whether INT1 is asserted (a pending status bit routed by INT_SOURCE0).
    pub fn int1(&self) -> bool {
        self.chip.status & self.chip.reg(reg::INT_SOURCE0) != 0
    }
}

impl<S: SampleSource> Chip<S> {
    /// Power-on / soft reset: §13 reset values, FIFO empty, RESET_DONE set.
    fn reset(&mut self) {
        self.regs = [[0; 128]; BANKS];
        for (bank, address, value) in RESET_VALUES {
            self.regs[usize::from(bank)][usize::from(address)] = value;
        }
        // Data registers read -32768 (0x8000) until a sensor produces data.
        for address in (reg::TEMP_DATA1..=reg::GYRO_DATA_Z0).step_by(2) {
            self.regs[0][usize::from(address)] = 0x80;
        }
        self.store_factory_trim();
        self.bank = 0;
        self.status = reg::RESET_DONE_INT;
        self.fifo.clear();
        self.lost_packets = 0;
        self.clock.reset();
        self.count_latch = None;
        self.fifo_accel_odr = None;
        self.fifo_gyro_odr = None;
    }

    /// The factory self-test codes (banks 1 and 2, read-only).
    fn store_factory_trim(&mut self) {
        let (gyro, accel) = (self.factory_trim.gyro, self.factory_trim.accel);
        let at = usize::from(reg::XG_ST_DATA_BANK1);
        self.regs[1][at..at + 3].copy_from_slice(&gyro);
        let at = usize::from(reg::XA_ST_DATA_BANK2);
        self.regs[2][at..at + 3].copy_from_slice(&accel);
    }

    /// A bank-0 register.
    fn reg(&self, address: u8) -> u8 {
        self.regs[0][usize::from(address & 0x7F)]
    }

    fn record(&mut self, address: u8, written: Option<u8>, what: &'static str) {
        self.unmodelled.record(UnmodelledAccess {
            page: self.bank,
            address,
            written,
            what,
        });
    }

    /// §14 PWR_MGMT0 ACCEL_MODE: 10 low-power, 11 low-noise; 00 and 01 off.
    fn accel_period_ns(&self) -> Option<u64> {
        let on = self.reg(reg::PWR_MGMT0) & 0b10 != 0;
        on.then(|| odr_period_ns(self.reg(reg::ACCEL_CONFIG0) & reg::ODR_MASK))?
    }

    /// §14 PWR_MGMT0 GYRO_MODE: 11 low-noise; standby and off give no data.
    fn gyro_period_ns(&self) -> Option<u64> {
        let on = self.reg(reg::PWR_MGMT0) & (0b11 << 2) == reg::GYRO_MODE_LOW_NOISE;
        on.then(|| odr_period_ns(self.reg(reg::GYRO_CONFIG0) & reg::ODR_MASK))?
    }

    fn rates(&self) -> Rates {
        [
            self.accel_period_ns().map(Rate::period_ns),
            self.gyro_period_ns().map(Rate::period_ns),
        ]
    }

    /// Time to the next sample of either sensor; `None` when both are off.
    fn ns_to_next_event(&self) -> Option<u64> {
        self.clock.ns_to_next(self.rates())
    }

    fn advance(&mut self, ns: u64) {
        let mut remaining = ns;
        while let Some(step) = self.clock.step(&mut remaining, self.rates()) {
            self.timestamp_ns += step.ns;
            let [accel_fired, gyro_fired] = step.fired;
            if !accel_fired && !gyro_fired {
                return; // `remaining` ran out before the next sample
            }
            if !self.stuck {
                self.produce_sample(accel_fired, gyro_fired);
            }
        }
    }

    fn overflow_fifo(&mut self, lost: u16) {
        let accel = self.accel_period_ns().is_some();
        let gyro = self.gyro_period_ns().is_some();
        if self.fifo_mode() == reg::FIFO_MODE_BYPASS || !self.fifo_takes(accel, gyro) {
            return;
        }
        let length = self.packet_len();
        while self.fifo.has_room(length) {
            self.produce_sample(accel, gyro);
        }
        for _ in 0..lost {
            self.produce_sample(accel, gyro);
        }
    }

    fn fifo_mode(&self) -> u8 {
        self.reg(reg::FIFO_CONFIG) & reg::FIFO_MODE_MASK
    }

    /// Whether a sample of these sensors puts a packet in the FIFO
    /// (FIFO_CONFIG1 enables at least one of them).
    fn fifo_takes(&self, accel: bool, gyro: bool) -> bool {
        let config = self.reg(reg::FIFO_CONFIG1);
        accel && config & reg::FIFO_ACCEL_EN != 0 || gyro && config & reg::FIFO_GYRO_EN != 0
    }

    /// §6.1: the packet FIFO_CONFIG1 selects: 4 with FIFO_HIRES_EN, 3 with
    /// both sensors, 1 or 2 with one.
    fn packet_len(&self) -> usize {
        let config = self.reg(reg::FIFO_CONFIG1);
        let both = reg::FIFO_ACCEL_EN | reg::FIFO_GYRO_EN;
        if config & reg::FIFO_HIRES_EN != 0 {
            reg::FIFO_PACKET_HIRES_LEN
        } else if config & both == both {
            reg::FIFO_PACKET_LEN
        } else {
            reg::FIFO_PACKET_ONE_SENSOR_LEN
        }
    }

    fn counts_records(&self) -> bool {
        self.reg(reg::INTF_CONFIG0) & reg::FIFO_COUNT_REC != 0
    }

    /// Whether the FIFO holds the watermark (FIFO_CONFIG2/3, in records or
    /// bytes per INTF_CONFIG0).
    fn watermark_reached(&self) -> bool {
        let wm = usize::from(u16::from_le_bytes([
            self.reg(reg::FIFO_CONFIG2),
            self.reg(reg::FIFO_CONFIG3) & 0x0F,
        ]));
        let held = if self.counts_records() {
            self.fifo.len()
        } else {
            self.fifo.bytes()
        };
        wm > 0 && held >= wm
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

    /// §14 TMST_CONFIG: the timestamp counter's tick, ns (1 µs or 16 µs).
    fn timestamp_tick_ns(&self) -> u64 {
        if self.reg(reg::TMST_CONFIG) & reg::TMST_RES_16US != 0 {
            16_000
        } else {
            1_000
        }
    }

    /// Takes one sample from the source into the data registers (of the
    /// sensors that sampled) and the FIFO.
    fn produce_sample(&mut self, accel_fired: bool, gyro_fired: bool) {
        let mut truth: TrueSample = self.source.next_sample();
        self.samples += 1;
        // Nothing to add with the self-test off (what it would add is ±0,
        // which no code shows): skipped, as the `f64` products cost
        // software floating point on the emulated board's core.
        if self.reg(reg::SELF_TEST_CONFIG) != 0 {
            let excitation = self.self_test_excitation();
            for axis in 0..3 {
                truth.specific_force[axis] += excitation.accel[axis];
                truth.angular_rate[axis] += excitation.gyro[axis];
            }
        }
        let temp_on = self.reg(reg::PWR_MGMT0) & (1 << 5) == 0;
        let accel_scale = accel_lsb_per_ms2(self.reg(reg::ACCEL_CONFIG0) >> 5);
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
            clipped |= (ca && accel_fired) || (cg && gyro_fired);
        }
        self.clipped = clipped;
        let celsius = truth.temperature - reg::TEMP_OFFSET_C;
        let (temp, _) = quantise(
            celsius * reg::TEMP_LSB_PER_C,
            -reg::LIMIT_CODE,
            reg::LIMIT_CODE,
        );

        let big_endian = self.reg(reg::INTF_CONFIG0) & reg::SENSOR_DATA_ENDIAN != 0;
        let put = |regs: &mut [u8; 128], address: u8, value: i16| {
            let at = usize::from(address);
            regs[at..at + 2].copy_from_slice(&word(value, big_endian));
        };
        if temp_on {
            put(&mut self.regs[0], reg::TEMP_DATA1, temp);
        }
        for axis in 0..3 {
            if accel_fired {
                put(&mut self.regs[0], 0x1F + 2 * axis as u8, accel[axis]);
            }
            if gyro_fired {
                put(&mut self.regs[0], 0x25 + 2 * axis as u8, gyro[axis]);
            }
        }
        self.status |= reg::DATA_RDY_INT;

        let ticks = self.timestamp_ns / self.timestamp_tick_ns();
        let delta = ticks - self.previous_ticks.min(ticks);
        self.previous_ticks = ticks;
        let mode = self.fifo_mode();
        if mode == reg::FIFO_MODE_BYPASS || !self.fifo_takes(accel_fired, gyro_fired) {
            return;
        }
        // §14 TMST_CONFIG TMST_DELTA_EN: the time since the previous ODR event.
        let timestamp = if self.reg(reg::TMST_CONFIG) & reg::TMST_DELTA_EN != 0 {
            delta
        } else {
            ticks
        };
        // The 20-bit values only for the packets that carry them.
        let with_hires = self.packet_len() == reg::FIFO_PACKET_HIRES_LEN;
        let data = PacketData {
            accel: accel_fired.then_some(accel),
            gyro: gyro_fired.then_some(gyro),
            hires_accel: (accel_fired && with_hires).then(|| hires(&truth.specific_force, true)),
            hires_gyro: (gyro_fired && with_hires).then(|| hires(&truth.angular_rate, false)),
            temp: temp_on.then_some(temp),
            fifo_temp: temp_on.then(|| {
                libm::round(celsius * reg::FIFO_TEMP_LSB_PER_C).clamp(-128.0, 127.0) as i8
            }),
            // The field holds 16 bits: the counter wraps.
            timestamp: timestamp as u16,
            big_endian,
        };
        let mut packet = [0u8; reg::FIFO_PACKET_HIRES_LEN];
        let length = self.build_packet(&data, &mut packet);
        let packet = &packet[..length];
        if !self.fifo.has_room(length) {
            self.lost_packets = self.lost_packets.saturating_add(1);
            if mode == reg::FIFO_MODE_STREAM {
                self.fifo.push_overwrite(packet);
            }
        } else {
            self.fifo.push(packet);
        }
        if !self.fifo.has_room(length) {
            self.status |= reg::FIFO_FULL_INT;
        }
        if self.watermark_reached() {
            self.status |= reg::FIFO_THS_INT;
        }
    }

    /// Lays out one FIFO packet (§6.1) in `out`; returns its length. A
    /// sensor in the packet with no new sample reads the invalid marker
    /// (-32768, or -524288 in 20-bit packets).
    fn build_packet(
        &mut self,
        data: &PacketData,
        out: &mut [u8; reg::FIFO_PACKET_HIRES_LEN],
    ) -> usize {
        let config = self.reg(reg::FIFO_CONFIG1);
        let length = self.packet_len();
        let with_accel =
            length != reg::FIFO_PACKET_ONE_SENSOR_LEN || config & reg::FIFO_ACCEL_EN != 0;
        let with_gyro =
            length != reg::FIFO_PACKET_ONE_SENSOR_LEN || config & reg::FIFO_GYRO_EN != 0;
        let mut header = 0;
        let mut at = 1;
        let accel_odr = self.reg(reg::ACCEL_CONFIG0) & reg::ODR_MASK;
        let gyro_odr = self.reg(reg::GYRO_CONFIG0) & reg::ODR_MASK;
        if with_accel {
            header |= reg::HEADER_ACCEL;
            let changed = odr_changed(&mut self.fifo_accel_odr, data.accel.map(|_| accel_odr));
            header |= if changed { reg::HEADER_ODR_ACCEL } else { 0 };
            at = put_words(out, at, data.accel, data.big_endian);
        }
        if with_gyro {
            header |= reg::HEADER_GYRO;
            let changed = odr_changed(&mut self.fifo_gyro_odr, data.gyro.map(|_| gyro_odr));
            header |= if changed { reg::HEADER_ODR_GYRO } else { 0 };
            at = put_words(out, at, data.gyro, data.big_endian);
        }
        if length == reg::FIFO_PACKET_HIRES_LEN {
            header |= reg::HEADER_20 | reg::HEADER_TIMESTAMP_ODR;
            let temp = data.temp.unwrap_or(i16::MIN);
            out[13..15].copy_from_slice(&word(temp, data.big_endian));
            out[15..17].copy_from_slice(&word(data.timestamp as i16, data.big_endian));
            // Bits 19:4 of each 20-bit value where packet 3 has its 16-bit
            // words; bits 3:0 in bytes 17..20 (accel high nibble, gyro low).
            let accel = data.hires_accel.unwrap_or([reg::HIRES_INVALID; 3]);
            let gyro = data.hires_gyro.unwrap_or([reg::HIRES_INVALID; 3]);
            for axis in 0..3 {
                let top = |v: i32| ((v >> 4) as i16, (v & 0x0F) as u8);
                let (a, a_low) = top(accel[axis]);
                let (g, g_low) = top(gyro[axis]);
                out[1 + 2 * axis..3 + 2 * axis].copy_from_slice(&word(a, data.big_endian));
                out[7 + 2 * axis..9 + 2 * axis].copy_from_slice(&word(g, data.big_endian));
                out[17 + axis] = (a_low << 4) | g_low;
            }
        } else {
            // §6.1: 8-bit temperature, -128 when invalid; the cast is exact
            // (clamped to the i8 range above).
            out[at] = data.fifo_temp.unwrap_or(i8::MIN) as u8;
            at += 1;
            if length == reg::FIFO_PACKET_LEN {
                header |= reg::HEADER_TIMESTAMP_ODR;
                out[at..at + 2].copy_from_slice(&word(data.timestamp as i16, data.big_endian));
            }
        }
        out[0] = header;
        length
    }

    /// FIFO_COUNT in records or bytes as INTF_CONFIG0 asks.
    fn fifo_count(&self) -> u16 {
        let count = if self.counts_records() {
            self.fifo.len()
        } else {
            self.fifo.bytes()
        };
        // At most 2048: fits.
        count as u16
    }

    /// §14 FIFO_COUNTH/L: the byte at `address` of `count` in the order
    /// INTF_CONFIG0 FIFO_COUNT_ENDIAN asks for.
    fn count_byte(&self, address: u8, count: u16) -> u8 {
        let big_endian = self.reg(reg::INTF_CONFIG0) & reg::FIFO_COUNT_ENDIAN != 0;
        let bytes = if big_endian {
            count.to_be_bytes()
        } else {
            count.to_le_bytes()
        };
        bytes[usize::from(address - reg::FIFO_COUNTH)]
    }

    /// Whether INTF_CONFIG0 UI_SIFS_CFG has switched I²C off.
    fn i2c_disabled(&self) -> bool {
        self.reg(reg::INTF_CONFIG0) & reg::UI_SIFS_CFG_MASK == reg::UI_SIFS_DISABLE_I2C
    }

    fn read_bank0(&mut self, address: u8) -> u8 {
        match address {
            reg::WHO_AM_I => self.who_am_i_override.unwrap_or(reg::WHO_AM_I_VALUE),
            reg::INT_STATUS => core::mem::take(&mut self.status),
            // §14: reading FIFO_COUNTH latches the count for FIFO_COUNTL.
            reg::FIFO_COUNTH => {
                let count = self.fifo_count();
                self.count_latch = Some(count);
                self.count_byte(address, count)
            }
            0x2F => {
                let count = self.count_latch.take().unwrap_or_else(|| self.fifo_count());
                self.count_byte(address, count)
            }
            // §6: an empty FIFO reads 0xFF (header bit 7: no valid packet).
            reg::FIFO_DATA => self.fifo.pop_byte().unwrap_or(0xFF),
            reg::FIFO_LOST_PKT0 => self.lost_packets.to_le_bytes()[0],
            0x6D => self.lost_packets.to_le_bytes()[1],
            _ => self.reg(address),
        }
    }

    fn write_bank0(&mut self, address: u8, value: u8) {
        let before = self.rates();
        match address {
            reg::DEVICE_CONFIG if value & reg::SOFT_RESET_CONFIG != 0 => {
                self.reset();
                return;
            }
            reg::SIGNAL_PATH_RESET => {
                if value & reg::FIFO_FLUSH != 0 {
                    self.fifo.clear();
                    self.lost_packets = 0;
                }
                if value & (reg::ABORT_AND_RESET | reg::DMP_MEM_RESET_EN) != 0 {
                    self.record(address, Some(value), "signal path or DMP memory reset");
                }
                if value & reg::TMST_STROBE != 0 {
                    let ticks = self.timestamp_ns / self.timestamp_tick_ns();
                    let at = usize::from(reg::TMSTVAL0_BANK1);
                    // 20 bits, little-endian.
                    self.regs[1][at..at + 3]
                        .copy_from_slice(&(ticks as u32 & 0xF_FFFF).to_le_bytes()[..3]);
                }
                return; // the bits self-clear
            }
            // Read-only: data, status, FIFO count and port, APEX outputs, lost count, identity.
            reg::TEMP_DATA1..=0x38 | reg::FIFO_LOST_PKT0 | 0x6D | reg::WHO_AM_I => return,
            reg::INTF_CONFIG0 if value & reg::UI_SIFS_CFG_MASK == reg::UI_SIFS_DISABLE_SPI => {
                self.record(address, Some(value), "SPI switched off (UI_SIFS_CFG = 10)");
            }
            reg::TMST_CONFIG if value & reg::TMST_EN == 0 => {
                self.record(
                    address,
                    Some(value),
                    "timestamp counter stopped (TMST_EN = 0)",
                );
            }
            _ => {}
        }
        self.regs[0][usize::from(address)] = value;
        if matches!(
            address,
            reg::PWR_MGMT0 | reg::GYRO_CONFIG0 | reg::ACCEL_CONFIG0
        ) {
            self.clock.rates_changed(before, self.rates());
        }
    }
}

/// What one sample puts in a FIFO packet: `None` where a sensor gave no new sample.
struct PacketData {
    accel: Option<[i16; 3]>,
    gyro: Option<[i16; 3]>,
    hires_accel: Option<[i32; 3]>,
    hires_gyro: Option<[i32; 3]>,
    temp: Option<i16>,
    fifo_temp: Option<i8>,
    timestamp: u16,
    big_endian: bool,
}

/// §6.2 HEADER_ODR_*: whether a sensor's data (`odr`: its ODR code, `None`
/// when the packet has no new data of it) comes at another ODR than its
/// previous packet's, `last`.
fn odr_changed(last: &mut Option<u8>, odr: Option<u8>) -> bool {
    let Some(odr) = odr else { return false };
    let changed = last.is_some_and(|previous| previous != odr);
    *last = Some(odr);
    changed
}

/// Puts a sensor's three 16-bit words (the invalid marker when `None`) at
/// `at`; returns where the next field starts.
fn put_words(out: &mut [u8], at: usize, values: Option<[i16; 3]>, big_endian: bool) -> usize {
    for axis in 0..3 {
        let value = values.map_or(i16::MIN, |v| v[axis]);
        out[at + 2 * axis..at + 2 * axis + 2].copy_from_slice(&word(value, big_endian));
    }
    at + 6
}

/// §6.1 packet 4: the 20-bit field of each axis, accelerometer (`accel`,
/// m/s², 18 bits at ±16 g) or gyroscope (rad/s, 19 bits at ±2000 °/s),
/// whatever the configured full-scale ranges.
fn hires(values: &[f64; 3], accel: bool) -> [i32; 3] {
    values.map(|v| {
        if accel {
            let lsb = v / STANDARD_GRAVITY * reg::HIRES_ACCEL_LSB_PER_G;
            quantise_wide(lsb, -reg::HIRES_ACCEL_LIMIT, reg::HIRES_ACCEL_LIMIT).0 << 2
        } else {
            let lsb = rad_to_deg(v) * reg::HIRES_GYRO_LSB_PER_DPS;
            quantise_wide(lsb, -reg::HIRES_GYRO_LIMIT, reg::HIRES_GYRO_LIMIT).0 << 1
        }
    })
}

impl<S: SampleSource> RegisterFile for Chip<S> {
    fn read_register(&mut self, address: u8) -> u8 {
        let address = address & 0x7F;
        if address == reg::REG_BANK_SEL {
            return self.bank;
        }
        if !listed(self.bank, address) {
            let what = if usize::from(self.bank) < BANKS {
                "reserved address"
            } else {
                "banks 3 and 4 are not modelled"
            };
            self.record(address, None, what);
            return 0;
        }
        match self.bank {
            0 => self.read_bank0(address),
            bank => self.regs[usize::from(bank)][usize::from(address)],
        }
    }

    fn write_register(&mut self, address: u8, value: u8) {
        let address = address & 0x7F;
        if address == reg::REG_BANK_SEL {
            self.bank = value & 0x07;
            return;
        }
        if !listed(self.bank, address) {
            let what = if usize::from(self.bank) < BANKS {
                "reserved address"
            } else {
                "banks 3 and 4 are not modelled"
            };
            self.record(address, Some(value), what);
            return;
        }
        match (self.bank, address) {
            (0, _) => self.write_bank0(address, value),
            (1, reg::SENSOR_CONFIG0_BANK1) if value != 0 => {
                self.record(address, Some(value), "axis disables (SENSOR_CONFIG0)");
                self.regs[1][usize::from(address)] = value;
            }
            // Read-only: the factory self-test codes and the latched timestamp.
            (1, 0x5F..=0x64) | (2, 0x3B..=0x3D) => {}
            (bank, _) => self.regs[usize::from(bank)][usize::from(address)] = value,
        }
    }

    /// Bursts auto-increment, except on FIFO_DATA which keeps returning FIFO bytes.
    fn next_address(&self, address: u8) -> u8 {
        if address == reg::FIFO_DATA && self.bank == 0 {
            address
        } else {
            address.wrapping_add(1) & 0x7F
        }
    }
}

super::chip_model::chip_model_common!(Icm42688Model);
