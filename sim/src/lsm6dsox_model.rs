//! A register-level model of the ST LSM6DSOX (DS12814), serving a
//! [`SampleSource`] over SPI and I²C like the chip does.
//!
//! Modelled: the register map with reset values (§8), WHO_AM_I, SW_RESET,
//! IF_INC auto-increment (with the FIFO output registers wrapping from 0x7E
//! to 0x78), full-scale ranges and output data rates (CTRL1_XL, CTRL2_G)
//! changing sensitivity, saturation and sample timing, temperature output,
//! STATUS_REG data-ready bits cleared by reading the outputs, and the tagged
//! FIFO (gyro and accel words per sample; bypass, FIFO and continuous modes;
//! watermark; overrun flags; reading FIFO_DATA_OUT_Z_H pops a word), the
//! self-test (CTRL5_C ST_XL / ST_G add the unit's [`SelfTestResponse`],
//! positive or negative, at once), plus injected faults. Not modelled: batch rates different from the ODR,
//! temperature and timestamp batching, the 52 Hz temperature rate (the
//! temperature updates with every sample), low-power modes, filters, the
//! embedded functions, BDU timing (time never moves during a transaction).
//!
//! Time moves only through [`Lsm6dsoxModel::advance`]: one new sample per
//! ODR period elapsed, with the nominal rates (12.5 Hz, 26 Hz, ... 6667 Hz)
//! kept exact by counting in ns·mHz. No allocation; about 3.8 KiB of state.

use embedded_hal::i2c::{self, I2c};
use embedded_hal::spi::{self, SpiDevice};

use super::fault::Fault;
use super::model_clock::Clocked;
use super::packet_fifo::PacketFifo;
use super::register_bus::{quantise, BusPort, RegisterFile};
use super::self_test_response::{DeadAxes, SelfTestResponse};
use super::source::SampleSource;
use crate::lsm6dsox_registers as reg;
use triad::units::{rad_to_deg, STANDARD_GRAVITY};

/// The tagged FIFO: 512 words of tag + 6 bytes.
type Fifo = PacketFifo<{ reg::FIFO_CAPACITY_WORDS as usize }, { reg::FIFO_WORD_LEN }>;

/// One sample period is this many ns·mHz (1 s = 1e9 ns, 1 Hz = 1e3 mHz).
const NS_MHZ_PER_SECOND: u128 = 1_000_000_000_000;

/// §8: registers whose reset value is not 0x00.
const RESET_VALUES: [(u8, u8); 4] = [
    (0x02, 0x3F), // PIN_CTRL
    (reg::CTRL3_C, reg::CTRL3_C_RESET),
    (0x18, 0xE0), // CTRL9_XL
    (reg::WHO_AM_I, reg::WHO_AM_I_VALUE),
];

/// The chip's state behind the bus.
struct Chip<S> {
    source: S,
    regs: [u8; 128],
    status: u8,
    fifo: Fifo,
    overrun: bool,
    overrun_latched: bool,
    tag_counter: u8,
    phase: u128,
    samples: u64,
    clipped: bool,
    who_am_i_override: Option<u8>,
    stuck: bool,
    self_test: SelfTestResponse,
    dead_self_test: DeadAxes,
}

/// The default unit's positive self-test response, mg and °/s: inside
/// DS12814's limits (50–1700 mg, 150–700 °/s), a different value per axis so
/// a mixed-up axis shows.
const UNIT_SELF_TEST_MG: [f64; 3] = [490.0, 510.0, 530.0];
/// See [`UNIT_SELF_TEST_MG`].
const UNIT_SELF_TEST_DPS: [f64; 3] = [290.0, 300.0, 310.0];

/// A simulated LSM6DSOX on a bus, fed by `S`.
pub struct Lsm6dsoxModel<S> {
    chip: Chip<S>,
    port: BusPort,
}

/// §4.1 Table 2 (the model's own copy): mg/LSB by FS_XL code (XL_FS_MODE = 0).
fn accel_mg_per_lsb(fs_xl: u8) -> f64 {
    match fs_xl & 0b11 {
        0b00 => 0.061,
        0b01 => 0.488,
        0b10 => 0.122,
        _ => 0.244,
    }
}

/// §4.1 Table 2: mdps/LSB by CTRL2_G (FS_125 overrides FS_G).
fn gyro_mdps_per_lsb(ctrl2_g: u8) -> f64 {
    if ctrl2_g & reg::FS_125 != 0 {
        return 4.375;
    }
    match (ctrl2_g >> 2) & 0b11 {
        0b00 => 8.75,
        0b01 => 17.5,
        0b10 => 35.0,
        _ => 70.0,
    }
}

/// §9 CTRL1_XL/CTRL2_G: the rate in mHz of an ODR code; `None` for power-down
/// or reserved. 0xB is 1.6 Hz (accelerometer low-power only).
fn odr_millihertz(code: u8) -> Option<u32> {
    Some(match code {
        0x1 => 12_500,
        0x2 => 26_000,
        0x3 => 52_000,
        0x4 => 104_000,
        0x5 => 208_000,
        0x6 => 416_000,
        0x7 => 833_000,
        0x8 => 1_666_000,
        0x9 => 3_333_000,
        0xA => 6_667_000,
        0xB => 1_600,
        _ => return None,
    })
}

impl<S: SampleSource> Lsm6dsoxModel<S> {
    /// A powered-up chip answering I²C at 0x6A (SA0 low).
    pub fn new(source: S) -> Self {
        let mut chip = Chip {
            source,
            regs: [0; 128],
            status: 0,
            fifo: Fifo::new(),
            overrun: false,
            overrun_latched: false,
            tag_counter: 0,
            phase: 0,
            samples: 0,
            clipped: false,
            who_am_i_override: None,
            stuck: false,
            self_test: SelfTestResponse::from_data_sheet_units(
                UNIT_SELF_TEST_MG,
                UNIT_SELF_TEST_DPS,
            ),
            dead_self_test: DeadAxes::default(),
        };
        chip.reset();
        Self {
            chip,
            port: BusPort::new(reg::I2C_ADDRESS_SA0_LOW),
        }
    }

    /// The same chip with positive self-test response `response` (by
    /// default 490/510/530 mg and 290/300/310 °/s on x/y/z).
    pub fn with_self_test(mut self, response: SelfTestResponse) -> Self {
        self.chip.self_test = response;
        self
    }

    /// What the positive self-test adds to each axis when enabled, SI.
    pub fn self_test_response(&self) -> SelfTestResponse {
        self.chip.self_test
    }

    /// The same chip with SA0 high (I²C address 0x6B) or low (0x6A).
    pub fn with_sa0(mut self, high: bool) -> Self {
        self.port = BusPort::new(if high {
            reg::I2C_ADDRESS_SA0_HIGH
        } else {
            reg::I2C_ADDRESS_SA0_LOW
        });
        self
    }

    /// Lets `ns` nanoseconds pass: one sample per ODR period elapsed.
    pub fn advance(&mut self, ns: u64) {
        self.chip.advance(ns);
    }

    /// The whole nanoseconds until the next sample at the rate the chip
    /// runs (the one its driver wrote): the model's clock then stands on or
    /// just after each exact sample instant, ⌈(n+1)·P⌉ − ⌈n·P⌉ from a start
    /// at 0, with no repeat and no skip however long it runs. `None`: both
    /// sensors off.
    pub fn ns_to_next_sample(&self) -> Option<u64> {
        let rate = u128::from(self.chip.rate_millihertz()?);
        // At most one period (about 1.2 ms at 833 Hz): fits in u64.
        u64::try_from((NS_MHZ_PER_SECOND - self.chip.phase).div_ceil(rate)).ok()
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

    /// Words in the FIFO (two per sample).
    pub fn fifo_len(&self) -> usize {
        self.chip.fifo.len()
    }

    /// A register's stored value, without read side effects (for tests).
    pub fn peek(&self, address: u8) -> u8 {
        self.chip.reg(address)
    }

    /// Whether INT1 is asserted: a routed data-ready or FIFO-watermark condition.
    pub fn int1(&self) -> bool {
        let routed = self.chip.reg(reg::INT1_CTRL);
        let drdy = routed & reg::INT1_DRDY_G != 0 && self.chip.status & reg::GDA != 0
            || routed & reg::INT1_DRDY_XL != 0 && self.chip.status & reg::XLDA != 0;
        drdy || routed & reg::INT1_FIFO_TH != 0 && self.chip.watermark_reached()
    }

    /// The sample source.
    pub fn source_mut(&mut self) -> &mut S {
        &mut self.chip.source
    }
}

impl<S: SampleSource> Chip<S> {
    /// Power-on / software reset: §8 reset values, FIFO empty.
    fn reset(&mut self) {
        self.regs = [0; 128];
        for (address, value) in RESET_VALUES {
            self.regs[usize::from(address)] = value;
        }
        self.status = 0;
        self.fifo.clear();
        self.overrun = false;
        self.overrun_latched = false;
        self.tag_counter = 0;
        self.phase = 0;
    }

    fn reg(&self, address: u8) -> u8 {
        self.regs[usize::from(address & 0x7F)]
    }

    fn gyro_on(&self) -> bool {
        odr_millihertz(self.reg(reg::CTRL2_G) >> reg::ODR_SHIFT).is_some()
    }

    fn accel_on(&self) -> bool {
        odr_millihertz(self.reg(reg::CTRL1_XL) >> reg::ODR_SHIFT).is_some()
    }

    /// The rate of whichever sensor runs (gyro first); `None` when both are off.
    fn rate_millihertz(&self) -> Option<u32> {
        odr_millihertz(self.reg(reg::CTRL2_G) >> reg::ODR_SHIFT)
            .or_else(|| odr_millihertz(self.reg(reg::CTRL1_XL) >> reg::ODR_SHIFT))
    }

    fn advance(&mut self, ns: u64) {
        let Some(rate) = self.rate_millihertz() else {
            self.phase = 0;
            return;
        };
        self.phase += u128::from(ns) * u128::from(rate);
        while self.phase >= NS_MHZ_PER_SECOND {
            self.phase -= NS_MHZ_PER_SECOND;
            if !self.stuck {
                self.produce_sample();
            }
        }
    }

    fn fifo_mode(&self) -> u8 {
        self.reg(reg::FIFO_CTRL4) & reg::FIFO_MODE_MASK
    }

    fn fifo_batching(&self) -> bool {
        self.fifo_mode() != reg::FIFO_MODE_BYPASS && self.reg(reg::FIFO_CTRL3) != 0
    }

    fn overflow_fifo(&mut self, lost: u16) {
        if !self.fifo_batching() || self.rate_millihertz().is_none() {
            return;
        }
        let free_samples = (usize::from(reg::FIFO_CAPACITY_WORDS) - self.fifo.len())
            / usize::from(reg::WORDS_PER_SAMPLE);
        for _ in 0..free_samples + usize::from(lost) {
            self.produce_sample();
        }
    }

    fn watermark_words(&self) -> usize {
        usize::from(u16::from_le_bytes([
            self.reg(reg::FIFO_CTRL1),
            self.reg(reg::FIFO_CTRL2) & 0x01,
        ]))
    }

    fn watermark_reached(&self) -> bool {
        let wm = self.watermark_words();
        wm > 0 && self.fifo.len() >= wm
    }

    /// The self-test excitation CTRL5_C enables: ST_XL 01 positive, 10
    /// negative; ST_G 01 positive, 11 negative (the codes the data sheet
    /// does not allow excite nothing here).
    fn self_test_excitation(&self) -> SelfTestResponse {
        let ctrl5 = self.reg(reg::CTRL5_C);
        let accel: i8 = match ctrl5 & reg::ST_XL_MASK {
            0b01 => 1,
            0b10 => -1,
            _ => 0,
        };
        let gyro: i8 = match (ctrl5 >> reg::ST_G_SHIFT) & 0b11 {
            0b01 => 1,
            0b11 => -1,
            _ => 0,
        };
        self.dead_self_test
            .excitation(&self.self_test, [accel; 3], [gyro; 3])
    }

    /// Takes one sample from the source into the output registers and the FIFO.
    fn produce_sample(&mut self) {
        let mut truth = self.source.next_sample();
        self.samples += 1;
        let excitation = self.self_test_excitation();
        for axis in 0..3 {
            truth.specific_force[axis] += excitation.accel[axis];
            truth.angular_rate[axis] += excitation.gyro[axis];
        }
        let accel_on = self.accel_on();
        let gyro_on = self.gyro_on();
        let accel_lsb_per_si = 1.0
            / (accel_mg_per_lsb(self.reg(reg::CTRL1_XL) >> reg::FS_SHIFT)
                * 1e-3
                * STANDARD_GRAVITY);
        let gyro_lsb_per_dps = 1.0 / (gyro_mdps_per_lsb(self.reg(reg::CTRL2_G)) * 1e-3);
        let mut accel = [0i16; 3];
        let mut gyro = [0i16; 3];
        let mut clipped = false;
        for axis in 0..3 {
            let (a, ca) = quantise(
                truth.specific_force[axis] * accel_lsb_per_si,
                reg::LIMIT_MIN,
                reg::LIMIT_MAX,
            );
            let (g, cg) = quantise(
                rad_to_deg(truth.angular_rate[axis]) * gyro_lsb_per_dps,
                reg::LIMIT_MIN,
                reg::LIMIT_MAX,
            );
            accel[axis] = a;
            gyro[axis] = g;
            clipped |= (ca && accel_on) || (cg && gyro_on);
        }
        self.clipped = clipped;
        let (temp, _) = quantise(
            (truth.temperature - reg::TEMP_OFFSET_C) * reg::TEMP_LSB_PER_C,
            reg::LIMIT_MIN,
            reg::LIMIT_MAX,
        );
        let put = |regs: &mut [u8; 128], address: u8, value: i16| {
            let [l, h] = value.to_le_bytes();
            regs[usize::from(address)] = l;
            regs[usize::from(address + 1)] = h;
        };
        put(&mut self.regs, reg::OUT_TEMP_L, temp);
        self.status |= reg::TDA;
        for axis in 0..3u8 {
            if gyro_on {
                put(
                    &mut self.regs,
                    reg::OUTX_L_G + 2 * axis,
                    gyro[usize::from(axis)],
                );
            }
            if accel_on {
                put(
                    &mut self.regs,
                    reg::OUTX_L_A + 2 * axis,
                    accel[usize::from(axis)],
                );
            }
        }
        if gyro_on {
            self.status |= reg::GDA;
        }
        if accel_on {
            self.status |= reg::XLDA;
        }

        if !self.fifo_batching() {
            return;
        }
        self.tag_counter = (self.tag_counter + 1) & 0b11;
        let bdr = self.reg(reg::FIFO_CTRL3);
        if gyro_on && bdr >> 4 != 0 {
            self.push_word(reg::TAG_GYRO, gyro);
        }
        if accel_on && bdr & 0x0F != 0 {
            self.push_word(reg::TAG_ACCEL, accel);
        }
    }

    /// One tagged FIFO word (§9 FIFO_DATA_OUT_TAG): TAG_SENSOR, TAG_CNT, parity.
    fn push_word(&mut self, sensor: u8, data: [i16; 3]) {
        let mut tag = (sensor << reg::TAG_SENSOR_SHIFT) | (self.tag_counter << 1);
        tag |= (tag.count_ones() & 1) as u8; // even parity over the whole byte
        let mut word = [0u8; reg::FIFO_WORD_LEN];
        word[0] = tag;
        for (axis, value) in data.iter().enumerate() {
            word[1 + 2 * axis..3 + 2 * axis].copy_from_slice(&value.to_le_bytes());
        }
        if self.fifo.is_full() {
            self.overrun = true;
            self.overrun_latched = true;
            if self.fifo_mode() == reg::FIFO_MODE_CONTINUOUS {
                self.fifo.push_overwrite(word);
            }
        } else {
            self.fifo.push(word);
        }
    }

    fn fifo_status2(&mut self) -> u8 {
        let words = self.fifo.len();
        let mut v = ((words >> 8) as u8) & reg::DIFF_FIFO_HIGH_MASK;
        if self.watermark_reached() {
            v |= reg::FIFO_WTM_IA;
        }
        if self.overrun {
            v |= reg::FIFO_OVR_IA;
        }
        // Full at the next ODR: no room for another gyro + accel pair.
        if words + usize::from(reg::WORDS_PER_SAMPLE) > usize::from(reg::FIFO_CAPACITY_WORDS) {
            v |= reg::FIFO_FULL_IA;
        }
        if core::mem::take(&mut self.overrun_latched) {
            v |= reg::FIFO_OVR_LATCHED;
        }
        v
    }
}

impl<S: SampleSource> RegisterFile for Chip<S> {
    fn read_register(&mut self, address: u8) -> u8 {
        let address = address & 0x7F;
        match address {
            reg::WHO_AM_I => self.who_am_i_override.unwrap_or(reg::WHO_AM_I_VALUE),
            reg::STATUS_REG => self.status,
            reg::OUT_TEMP_L | 0x21 => {
                self.status &= !reg::TDA;
                self.reg(address)
            }
            reg::OUTX_L_G..=0x27 => {
                self.status &= !reg::GDA;
                self.reg(address)
            }
            reg::OUTX_L_A..=reg::OUTZ_H_A => {
                self.status &= !reg::XLDA;
                self.reg(address)
            }
            // DIFF_FIFO counts words; at most 512: the low byte and 2 high bits.
            reg::FIFO_STATUS1 => (self.fifo.len() & 0xFF) as u8,
            reg::FIFO_STATUS2 => self.fifo_status2(),
            reg::FIFO_DATA_OUT_TAG..=reg::FIFO_DATA_OUT_Z_H => {
                let byte = self
                    .fifo
                    .peek_byte(usize::from(address - reg::FIFO_DATA_OUT_TAG))
                    .unwrap_or(0);
                if address == reg::FIFO_DATA_OUT_Z_H && !self.fifo.is_empty() {
                    self.fifo.pop_packet();
                    // A word left: the FIFO is no longer overrun.
                    self.overrun = false;
                }
                byte
            }
            _ => self.reg(address),
        }
    }

    fn write_register(&mut self, address: u8, value: u8) {
        let address = address & 0x7F;
        match address {
            reg::CTRL3_C if value & reg::SW_RESET != 0 => self.reset(),
            reg::FIFO_CTRL4 => {
                if value & reg::FIFO_MODE_MASK == reg::FIFO_MODE_BYPASS {
                    // §9 FIFO_CTRL4: bypass mode empties the FIFO.
                    self.fifo.clear();
                    self.overrun = false;
                }
                self.regs[usize::from(address)] = value;
            }
            reg::CTRL1_XL | reg::CTRL2_G => {
                if self.rate_millihertz().is_none() {
                    self.phase = 0; // the first sensor on starts the ODR clock
                }
                self.regs[usize::from(address)] = value;
            }
            // Read-only: identity, status, outputs, FIFO status and data.
            reg::WHO_AM_I
            | reg::STATUS_REG
            | reg::OUT_TEMP_L..=reg::OUTZ_H_A
            | reg::FIFO_STATUS1
            | reg::FIFO_STATUS2
            | reg::FIFO_DATA_OUT_TAG..=reg::FIFO_DATA_OUT_Z_H => {}
            _ => self.regs[usize::from(address)] = value,
        }
    }

    /// IF_INC on: next register, and the FIFO output wraps 0x7E → 0x78 so a
    /// burst reads word after word. IF_INC off: the same register.
    fn next_address(&self, address: u8) -> u8 {
        if self.reg(reg::CTRL3_C) & reg::IF_INC == 0 {
            address
        } else if address == reg::FIFO_DATA_OUT_Z_H {
            reg::FIFO_DATA_OUT_TAG
        } else {
            address.wrapping_add(1) & 0x7F
        }
    }
}

impl<S: SampleSource> Clocked for Lsm6dsoxModel<S> {
    fn advance(&mut self, ns: u64) {
        self.chip.advance(ns);
    }
}

impl<S> spi::ErrorType for Lsm6dsoxModel<S> {
    type Error = spi::ErrorKind;
}

impl<S: SampleSource> SpiDevice for Lsm6dsoxModel<S> {
    fn transaction(
        &mut self,
        operations: &mut [spi::Operation<'_, u8>],
    ) -> Result<(), spi::ErrorKind> {
        self.port.spi(&mut self.chip, operations)
    }
}

impl<S> i2c::ErrorType for Lsm6dsoxModel<S> {
    type Error = i2c::ErrorKind;
}

impl<S: SampleSource> I2c for Lsm6dsoxModel<S> {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [i2c::Operation<'_>],
    ) -> Result<(), i2c::ErrorKind> {
        self.port.i2c(&mut self.chip, address, operations)
    }
}
