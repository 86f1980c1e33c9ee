//! A register-level model of the ST LSM6DSOX (DS12814), serving a
//! [`SampleSource`] over SPI and I²C like the chip does.
//!
//! Modelled: the main register page with reset values (§8; every address
//! the data sheet lists keeps what a driver writes), the embedded-functions
//! page selected by FUNC_CFG_ACCESS (its reset values, writes that stick,
//! and the main page untouched while it is selected), WHO_AM_I, SW_RESET,
//! IF_INC auto-increment (with the FIFO output registers wrapping from 0x7E
//! to 0x78), full-scale ranges and independent accelerometer and gyroscope
//! output data rates (CTRL1_XL, CTRL2_G; both count time from one chip
//! clock) changing sensitivity, saturation and sample timing, temperature
//! output, STATUS_REG data-ready bits cleared by reading the outputs, I²C
//! switched off by CTRL4_C I2C_disable, and the tagged FIFO (a gyro word and
//! an accel word each at its own sensor's rate; bypass, FIFO and continuous
//! modes; watermark; overrun flags; reading FIFO_DATA_OUT_Z_H pops a word),
//! the self-test (CTRL5_C ST_XL / ST_G add the unit's [`SelfTestResponse`],
//! positive or negative, at once), plus injected faults.
//!
//! Inert (kept, no effect on the data): PIN_CTRL, S4S_*, COUNTER_BDR_REG1/2,
//! INT2_CTRL, CTRL3_C BDU/H_LACTIVE/PP_OD/SIM, CTRL4_C except I2C_disable,
//! CTRL6_C, CTRL7_G, CTRL8_XL filters, CTRL9_XL, TAP_*/WAKE_UP_*/FREE_FALL/
//! MD1_CFG/MD2_CFG, I3C_BUS_AVB, the OIS and user-offset registers, and in
//! the embedded-functions page everything but the enables listed below. The
//! temperature updates with every sample (the chip: 52 Hz); BDU timing is
//! moot (time never moves during a transaction).
//!
//! Not modelled, and recorded in [`Lsm6dsoxModel::unmodelled`] when touched:
//! reserved addresses, the sensor-hub page, the embedded functions
//! themselves (EMB_FUNC_EN_A/B, FSM_ENABLE_A/B, PAGE_RW and PAGE_VALUE
//! non-zero), XL_FS_MODE, the timestamp counter (TIMESTAMP_EN), FIFO batch
//! rates other than the ODR, temperature and timestamp batching, and the
//! FIFO modes other than bypass, FIFO and continuous.
//!
//! Time moves only through [`Lsm6dsoxModel::advance`]: one new sample per
//! ODR period elapsed, with the nominal rates (12.5 Hz, 26 Hz, ... 6667 Hz)
//! kept exact by counting in ns·mHz; when the two sensors run at different
//! rates the source gives one true sample per instant at which either
//! samples. No allocation; about 4.4 KiB of state.

use super::packet_fifo::PacketFifo;
use super::register_bus::{quantise, BusPort, RegisterFile};
use super::self_test_response::{DeadAxes, SelfTestResponse};
use super::sensor_clock::{Rate, Rates, SensorClock};
use super::source::SampleSource;
use super::unmodelled::{UnmodelledAccess, UnmodelledLog};
use crate::chips::lsm6dsox_registers as reg;
use triad::units::{rad_to_deg, STANDARD_GRAVITY};

/// The tagged FIFO: 512 words of tag + 6 bytes.
type Fifo = PacketFifo<{ reg::FIFO_BYTES }, { reg::FIFO_CAPACITY_WORDS as usize }>;

/// §8: registers whose reset value is not 0x00.
const RESET_VALUES: [(u8, u8); 4] = [
    (0x02, 0x3F), // PIN_CTRL
    (reg::CTRL3_C, reg::CTRL3_C_RESET),
    (0x18, 0xE0), // CTRL9_XL
    (reg::WHO_AM_I, reg::WHO_AM_I_VALUE),
];

/// §10: embedded-functions registers whose reset value is not 0x00.
const EMBEDDED_RESET_VALUES: [(u8, u8); 3] = [
    (0x02, 0x01), // PAGE_SEL
    (0x5F, 0x4B), // EMB_FUNC_ODR_CFG_B
    (0x60, 0x15), // EMB_FUNC_ODR_CFG_C
];

/// §8 Table 20: the main page's addresses (inclusive ranges).
const MAIN_MAP: &[(u8, u8)] = &[
    (0x01, 0x02),
    (0x04, 0x1E),
    (0x20, 0x2D),
    (0x35, 0x3B),
    (0x40, 0x50),
    (0x56, 0x5F),
    (0x62, 0x63),
    (0x6F, 0x75),
    (0x78, 0x7E),
];

/// §10 Table 22: the embedded-functions page's addresses (FUNC_CFG_ACCESS at
/// 0x01 is in every page).
const EMBEDDED_MAP: &[(u8, u8)] = &[
    (0x01, 0x02),
    (0x04, 0x05),
    (0x07, 0x15),
    (0x17, 0x17),
    (0x44, 0x44),
    (0x46, 0x4A),
    (0x4C, 0x5B),
    (0x5F, 0x60),
    (0x62, 0x64),
    (0x66, 0x67),
    (0x70, 0x77),
];

/// The register page FUNC_CFG_ACCESS selects (as recorded in the
/// unmodelled log): 0 main, 1 embedded functions, 2 sensor hub.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Page {
    Main = 0,
    Embedded = 1,
    SensorHub = 2,
}

fn listed(map: &[(u8, u8)], address: u8) -> bool {
    map.iter().any(|&(a, b)| (a..=b).contains(&address))
}

/// The chip's state behind the bus.
struct Chip<S> {
    source: S,
    regs: [u8; 128],
    embedded: [u8; 128],
    status: u8,
    fifo: Fifo,
    overrun: bool,
    overrun_latched: bool,
    tag_counter: u8,
    clock: SensorClock,
    samples: u64,
    clipped: bool,
    who_am_i_override: Option<u8>,
    stuck: bool,
    self_test: SelfTestResponse,
    dead_self_test: DeadAxes,
    unmodelled: UnmodelledLog,
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
            embedded: [0; 128],
            status: 0,
            fifo: Fifo::new(),
            overrun: false,
            overrun_latched: false,
            tag_counter: 0,
            clock: SensorClock::default(),
            samples: 0,
            clipped: false,
            who_am_i_override: None,
            stuck: false,
            self_test: SelfTestResponse::from_data_sheet_units(
                UNIT_SELF_TEST_MG,
                UNIT_SELF_TEST_DPS,
            ),
            dead_self_test: DeadAxes::default(),
            unmodelled: UnmodelledLog::default(),
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

    /// The same chip with SA0 high (I²C address 0x6B) or low (0x6A).
    pub fn with_sa0(mut self, high: bool) -> Self {
        self.port = BusPort::new(if high {
            reg::I2C_ADDRESS_SA0_HIGH
        } else {
            reg::I2C_ADDRESS_SA0_LOW
        });
        self
    }

    /// A main-page register's stored value, without read side effects (for tests).
    pub fn peek(&self, address: u8) -> u8 {
        self.chip.reg(address)
    }

    /// An embedded-functions register's stored value, without read side effects.
    pub fn peek_embedded(&self, address: u8) -> u8 {
        self.chip.embedded[usize::from(address & 0x7F)]
    }

    /// Whether INT1 is asserted: a routed data-ready or FIFO-watermark condition.
    pub fn int1(&self) -> bool {
        let routed = self.chip.reg(reg::INT1_CTRL);
        let drdy = routed & reg::INT1_DRDY_G != 0 && self.chip.status & reg::GDA != 0
            || routed & reg::INT1_DRDY_XL != 0 && self.chip.status & reg::XLDA != 0;
        drdy || routed & reg::INT1_FIFO_TH != 0 && self.chip.watermark_reached()
    }
}

impl<S: SampleSource> Chip<S> {
    /// Power-on / software reset: §8 reset values, FIFO empty.
    fn reset(&mut self) {
        self.regs = [0; 128];
        for (address, value) in RESET_VALUES {
            self.regs[usize::from(address)] = value;
        }
        self.embedded = [0; 128];
        for (address, value) in EMBEDDED_RESET_VALUES {
            self.embedded[usize::from(address)] = value;
        }
        self.status = 0;
        self.fifo.clear();
        self.overrun = false;
        self.overrun_latched = false;
        self.tag_counter = 0;
        self.clock.reset();
    }

    fn page(&self) -> Page {
        let access = self.reg(reg::FUNC_CFG_ACCESS);
        if access & reg::EMBEDDED_PAGE != 0 {
            Page::Embedded
        } else if access & reg::SENSOR_HUB_PAGE != 0 {
            Page::SensorHub
        } else {
            Page::Main
        }
    }

    fn record(&mut self, address: u8, written: Option<u8>, what: &'static str) {
        self.unmodelled.record(UnmodelledAccess {
            page: self.page() as u8,
            address,
            written,
            what,
        });
    }

    fn reg(&self, address: u8) -> u8 {
        self.regs[usize::from(address & 0x7F)]
    }

    fn accel_rate(&self) -> Option<u32> {
        odr_millihertz(self.reg(reg::CTRL1_XL) >> reg::ODR_SHIFT)
    }

    fn gyro_rate(&self) -> Option<u32> {
        odr_millihertz(self.reg(reg::CTRL2_G) >> reg::ODR_SHIFT)
    }

    fn gyro_on(&self) -> bool {
        self.gyro_rate().is_some()
    }

    fn accel_on(&self) -> bool {
        self.accel_rate().is_some()
    }

    fn rates(&self) -> Rates {
        [
            self.accel_rate().map(Rate::millihertz),
            self.gyro_rate().map(Rate::millihertz),
        ]
    }

    /// Whole ns until the next sample of either sensor; `None` when both are off.
    fn ns_to_next_event(&self) -> Option<u64> {
        self.clock.ns_to_next(self.rates())
    }

    fn advance(&mut self, ns: u64) {
        let mut remaining = ns;
        while let Some(step) = self.clock.step(&mut remaining, self.rates()) {
            let [accel_fired, gyro_fired] = step.fired;
            if !accel_fired && !gyro_fired {
                return; // `remaining` ran out before the next sample
            }
            if !self.stuck {
                self.produce_sample(accel_fired, gyro_fired);
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
        let bdr = self.reg(reg::FIFO_CTRL3);
        let (accel, gyro) = (self.accel_on(), self.gyro_on());
        let words_per_sample =
            usize::from(accel && bdr & 0x0F != 0) + usize::from(gyro && bdr >> 4 != 0);
        if !self.fifo_batching() || words_per_sample == 0 {
            return;
        }
        let free_samples =
            (usize::from(reg::FIFO_CAPACITY_WORDS) - self.fifo.len()) / words_per_sample;
        for _ in 0..free_samples + usize::from(lost) {
            self.produce_sample(accel, gyro);
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
    fn produce_sample(&mut self, accel_fired: bool, gyro_fired: bool) {
        let mut truth = self.source.next_sample();
        self.samples += 1;
        let excitation = self.self_test_excitation();
        for axis in 0..3 {
            truth.specific_force[axis] += excitation.accel[axis];
            truth.angular_rate[axis] += excitation.gyro[axis];
        }
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
            clipped |= (ca && accel_fired) || (cg && gyro_fired);
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
            if gyro_fired {
                put(
                    &mut self.regs,
                    reg::OUTX_L_G + 2 * axis,
                    gyro[usize::from(axis)],
                );
            }
            if accel_fired {
                put(
                    &mut self.regs,
                    reg::OUTX_L_A + 2 * axis,
                    accel[usize::from(axis)],
                );
            }
        }
        if gyro_fired {
            self.status |= reg::GDA;
        }
        if accel_fired {
            self.status |= reg::XLDA;
        }

        if !self.fifo_batching() {
            return;
        }
        self.tag_counter = (self.tag_counter + 1) & 0b11;
        let bdr = self.reg(reg::FIFO_CTRL3);
        let (bdr_gyro, bdr_accel) = (bdr >> 4, bdr & 0x0F);
        // §9 FIFO_CTRL3: a batch rate other than the sensor's ODR is not modelled.
        let gyro_odr = self.reg(reg::CTRL2_G) >> reg::ODR_SHIFT;
        let accel_odr = self.reg(reg::CTRL1_XL) >> reg::ODR_SHIFT;
        if bdr_gyro != 0 && bdr_gyro != gyro_odr || bdr_accel != 0 && bdr_accel != accel_odr {
            self.unmodelled.record(UnmodelledAccess {
                page: Page::Main as u8,
                address: reg::FIFO_CTRL3,
                written: Some(bdr),
                what: "FIFO batch rate other than the ODR",
            });
        }
        if gyro_fired && bdr_gyro != 0 {
            self.push_word(reg::TAG_GYRO, gyro);
        }
        if accel_fired && bdr_accel != 0 {
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
        if !self.fifo.has_room(word.len()) {
            self.overrun = true;
            self.overrun_latched = true;
            if self.fifo_mode() == reg::FIFO_MODE_CONTINUOUS {
                self.fifo.push_overwrite(&word);
            }
        } else {
            self.fifo.push(&word);
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

impl<S: SampleSource> Chip<S> {
    fn read_main(&mut self, address: u8) -> u8 {
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

    fn write_main(&mut self, address: u8, value: u8) {
        let unmodelled = match address {
            reg::CTRL8_XL if value & reg::XL_FS_MODE != 0 => Some("XL_FS_MODE"),
            reg::CTRL10_C if value & reg::TIMESTAMP_EN != 0 => Some("timestamp counter"),
            reg::FIFO_CTRL4 if value & 0xF0 != 0 => Some("temperature or timestamp batching"),
            reg::FIFO_CTRL4
                if !matches!(
                    value & reg::FIFO_MODE_MASK,
                    reg::FIFO_MODE_BYPASS | reg::FIFO_MODE_FIFO | reg::FIFO_MODE_CONTINUOUS
                ) =>
            {
                Some("FIFO mode other than bypass, FIFO and continuous")
            }
            _ => None,
        };
        if let Some(what) = unmodelled {
            self.record(address, Some(value), what);
        }
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
                let before = self.rates();
                self.regs[usize::from(address)] = value;
                self.clock.rates_changed(before, self.rates());
            }
            // Read-only: identity, event sources, status, outputs, FIFO
            // status, timestamp, OIS outputs, FIFO data.
            reg::WHO_AM_I
            | 0x1A..=reg::STATUS_REG
            | reg::OUT_TEMP_L..=reg::OUTZ_H_A
            | 0x35..=reg::FIFO_STATUS2
            | 0x40..=0x50
            | 0x63
            | reg::FIFO_DATA_OUT_TAG..=reg::FIFO_DATA_OUT_Z_H => {}
            _ => self.regs[usize::from(address)] = value,
        }
    }

    fn write_embedded(&mut self, address: u8, value: u8) {
        let unmodelled = match address {
            reg::EMB_FUNC_EN_A | reg::EMB_FUNC_EN_B if value != 0 => Some("embedded functions"),
            reg::FSM_ENABLE_A | reg::FSM_ENABLE_B if value != 0 => Some("finite state machines"),
            reg::PAGE_RW if value != 0 => Some("advanced pages (PAGE_RW)"),
            0x09 => Some("advanced page memory (PAGE_VALUE)"),
            _ => None,
        };
        if let Some(what) = unmodelled {
            self.record(address, Some(value), what);
        }
        match address {
            // Read-only: status, FSM outputs, step counter, MLC sources.
            0x07 | 0x12..=0x15 | 0x4C..=0x5B | 0x62 | 0x63 | 0x70..=0x77 => {}
            _ => self.embedded[usize::from(address)] = value,
        }
    }

    /// Whether CTRL4_C has switched I²C off.
    fn i2c_disabled(&self) -> bool {
        self.reg(reg::CTRL4_C) & reg::I2C_DISABLE != 0
    }
}

impl<S: SampleSource> RegisterFile for Chip<S> {
    fn read_register(&mut self, address: u8) -> u8 {
        let address = address & 0x7F;
        if address == reg::FUNC_CFG_ACCESS {
            return self.reg(address);
        }
        match self.page() {
            Page::Main if listed(MAIN_MAP, address) => self.read_main(address),
            Page::Embedded if listed(EMBEDDED_MAP, address) => self.embedded[usize::from(address)],
            page => {
                let what = if page == Page::SensorHub {
                    "sensor-hub page"
                } else {
                    "reserved address"
                };
                self.record(address, None, what);
                0
            }
        }
    }

    fn write_register(&mut self, address: u8, value: u8) {
        let address = address & 0x7F;
        if address == reg::FUNC_CFG_ACCESS {
            self.regs[usize::from(address)] = value;
            return;
        }
        match self.page() {
            Page::Main if listed(MAIN_MAP, address) => self.write_main(address, value),
            Page::Embedded if listed(EMBEDDED_MAP, address) => self.write_embedded(address, value),
            page => {
                let what = if page == Page::SensorHub {
                    "sensor-hub page"
                } else {
                    "reserved address"
                };
                self.record(address, Some(value), what);
            }
        }
    }

    /// IF_INC on: next register, and the FIFO output wraps 0x7E → 0x78 so a
    /// burst reads word after word. IF_INC off: the same register.
    fn next_address(&self, address: u8) -> u8 {
        if self.reg(reg::CTRL3_C) & reg::IF_INC == 0 {
            address
        } else if address == reg::FIFO_DATA_OUT_Z_H && self.page() == Page::Main {
            reg::FIFO_DATA_OUT_TAG
        } else {
            address.wrapping_add(1) & 0x7F
        }
    }
}

super::chip_model::chip_model_common!(Lsm6dsoxModel);
