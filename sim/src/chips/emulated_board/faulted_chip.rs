//! The emulated board's chip behind its fault schedule: a wrapper around the
//! chip model's bus (SPI and I²C) and clock that shows each scheduled fault
//! at its time (see [`crate::chips::fault_schedule`]). What a fault does to
//! the chip itself (a failed transaction, frozen output, a reset) goes
//! through the model's own fault injection and registers; what it does to
//! the wires (a chip gone from the bus, a data-ready line that gives no
//! edge) is here and on the board.

use embedded_hal::{i2c, spi};

use super::EmulatedChip;
use crate::chips::fault::Fault;
use crate::chips::fault_schedule::{BoardFault, FaultSchedule, MAX_FAULTS};
use crate::chips::model_clock::Clocked;

/// A chip model that shows the faults of a schedule, in device time read
/// from `now_us` at every bus transaction and clock step.
pub struct FaultedChip {
    chip: EmulatedChip,
    schedule: FaultSchedule,
    now_us: fn() -> u64,
    /// Per entry: occurrences started, and ended.
    started: [u64; MAX_FAULTS],
    ended: [u64; MAX_FAULTS],
}

impl FaultedChip {
    /// `chip` showing `schedule`, its time read from `now_us` (µs since
    /// the board started).
    pub fn new(chip: EmulatedChip, schedule: FaultSchedule, now_us: fn() -> u64) -> Self {
        Self {
            chip,
            schedule,
            now_us,
            started: [0; MAX_FAULTS],
            ended: [0; MAX_FAULTS],
        }
    }

    /// The chip model.
    pub fn chip(&self) -> &EmulatedChip {
        &self.chip
    }

    /// Starts and ends the faults due by now: each occurrence's start and
    /// end happen once, in order, even when both fall between two looks (a
    /// brown-out then still resets the chip).
    pub fn sync(&mut self) {
        let now = (self.now_us)();
        let entries = self.schedule;
        for (i, entry) in entries.entries().enumerate() {
            loop {
                let open = self.started[i] > self.ended[i];
                if open && entry.end_of(self.ended[i]).is_some_and(|end| now >= end) {
                    self.ended[i] += 1;
                    self.end(entry.fault);
                } else if (!open || entry.end_us.is_none())
                    && entry.start_of(self.started[i]).is_some_and(|at| now >= at)
                {
                    self.started[i] += 1;
                    self.start(entry.fault);
                } else {
                    break;
                }
            }
        }
    }

    fn start(&mut self, fault: BoardFault) {
        match fault {
            BoardFault::NackStorm { transactions } => {
                self.chip.inject(Fault::BusError { transactions })
            }
            BoardFault::OutputStops => self.chip.inject(Fault::StuckOutput),
            _ => {}
        }
    }

    fn end(&mut self, fault: BoardFault) {
        match fault {
            BoardFault::OutputStops if !self.is(BoardFault::OutputStops) => {
                self.chip.clear_faults()
            }
            BoardFault::BrownOut => {
                self.chip.clear_faults();
                self.chip.power_on_reset();
            }
            _ => {}
        }
    }

    /// Whether a fault of `kind` (any count) has started and not ended.
    fn is(&self, kind: BoardFault) -> bool {
        self.schedule.entries().enumerate().any(|(i, e)| {
            core::mem::discriminant(&e.fault) == core::mem::discriminant(&kind)
                && self.started[i] > self.ended[i]
        })
    }

    /// A register read's bytes (`address` the first's) as the faults on
    /// show them: the FIFO count impossible.
    fn patch_read(&self, address: u8, bytes: &mut [u8]) {
        if self.is(BoardFault::ImpossibleFifoCount) {
            for (i, b) in bytes.iter_mut().enumerate() {
                *b = self
                    .chip
                    .impossible_fifo_count(address.wrapping_add(i as u8), *b);
            }
        }
    }

    /// Whether the chip is off the bus (vanished, or browned out).
    pub fn gone(&self) -> bool {
        self.is(BoardFault::Vanish) || self.is(BoardFault::BrownOut)
    }

    /// Whether the chip raises data-ready for its samples: on the bus,
    /// output not stopped, and sampling (a chip back from a brown-out is
    /// not, until configured). The line itself may still be faulty
    /// ([`FaultSchedule::silenced_at`]).
    pub fn gives_data_ready(&self) -> bool {
        !self.gone() && !self.is(BoardFault::OutputStops) && self.chip.next_sample_ns().is_some()
    }

    /// Runs the model's clock to its next sample (see
    /// [`EmulatedChip::advance_one_sample`]), once the schedule is applied.
    pub fn advance_one_sample(&mut self) {
        self.sync();
        self.chip.advance_one_sample();
    }
}

impl Clocked for FaultedChip {
    fn advance(&mut self, ns: u64) {
        self.sync();
        self.chip.advance(ns);
    }
}

impl spi::ErrorType for FaultedChip {
    type Error = spi::ErrorKind;
}

impl spi::SpiDevice for FaultedChip {
    /// A chip gone from the bus drives nothing: every byte read is 0xFF
    /// (MISO's pull-up), and the master cannot tell.
    fn transaction(
        &mut self,
        operations: &mut [spi::Operation<'_, u8>],
    ) -> Result<(), spi::ErrorKind> {
        self.sync();
        if !self.gone() {
            self.chip.transaction(operations)?;
            // A register read as the drivers make it: the address, then the bytes.
            if let [spi::Operation::Write([address]), spi::Operation::Read(bytes)] = operations {
                self.patch_read(*address & 0x7F, bytes);
            }
            return Ok(());
        }
        for op in operations.iter_mut() {
            match op {
                spi::Operation::Read(buf) | spi::Operation::TransferInPlace(buf) => buf.fill(0xFF),
                spi::Operation::Transfer(read, _) => read.fill(0xFF),
                spi::Operation::Write(_) | spi::Operation::DelayNs(_) => {}
            }
        }
        Ok(())
    }
}

impl i2c::ErrorType for FaultedChip {
    type Error = i2c::ErrorKind;
}

impl i2c::I2c for FaultedChip {
    /// A chip gone from the bus acknowledges nothing.
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [i2c::Operation<'_>],
    ) -> Result<(), i2c::ErrorKind> {
        self.sync();
        if self.gone() {
            return Err(i2c::ErrorKind::NoAcknowledge(
                i2c::NoAcknowledgeSource::Address,
            ));
        }
        self.chip.transaction(address, operations)?;
        // A register read as the drivers make it: the address, then the bytes.
        if let [i2c::Operation::Write([register]), i2c::Operation::Read(bytes)] = operations {
            self.patch_read(*register, bytes);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chips::emulated_board::source;
    use core::sync::atomic::{AtomicU64, Ordering};
    use embedded_hal::spi::{Operation, SpiDevice};

    static NOW_US: AtomicU64 = AtomicU64::new(0);
    fn now() -> u64 {
        NOW_US.load(Ordering::Relaxed)
    }

    fn chip(spec: &[&str]) -> FaultedChip {
        let mut schedule = FaultSchedule::new();
        for s in spec {
            schedule.add(s).unwrap();
        }
        let model = EmulatedChip::named("icm42688", source::demo).unwrap();
        FaultedChip::new(model, schedule, now)
    }

    fn read(chip: &mut FaultedChip, address: u8) -> Result<u8, spi::ErrorKind> {
        let mut b = [0u8];
        chip.transaction(&mut [Operation::Write(&[address | 0x80]), Operation::Read(&mut b)])?;
        Ok(b[0])
    }

    fn write(chip: &mut FaultedChip, address: u8, value: u8) {
        chip.transaction(&mut [Operation::Write(&[address, value])])
            .unwrap();
    }

    // One test: the schedule's clock is a static.
    #[test]
    fn each_fault_shows_at_its_time_and_ends_at_its_end() {
        use crate::chips::icm42688_registers as reg;
        let mut c = chip(&[
            "vanish@1+1",
            "nack@3*2",
            "stop@4+1",
            "brownout@6+1",
            "fifo-count@8+1",
        ]);
        NOW_US.store(0, Ordering::Relaxed);
        assert_eq!(read(&mut c, reg::WHO_AM_I), Ok(0x47));
        // Sensors on (low noise), so the chip samples.
        write(&mut c, reg::PWR_MGMT0, 0x0F);
        assert!(c.gives_data_ready());

        NOW_US.store(1_000_000, Ordering::Relaxed);
        assert_eq!(read(&mut c, reg::WHO_AM_I), Ok(0xFF), "vanished: MISO high");
        assert!(!c.gives_data_ready());
        NOW_US.store(2_000_000, Ordering::Relaxed);
        assert_eq!(read(&mut c, reg::WHO_AM_I), Ok(0x47));
        assert!(c.gives_data_ready(), "back with its configuration");

        NOW_US.store(3_000_000, Ordering::Relaxed);
        assert!(read(&mut c, reg::WHO_AM_I).is_err());
        assert!(read(&mut c, reg::WHO_AM_I).is_err());
        assert_eq!(
            read(&mut c, reg::WHO_AM_I),
            Ok(0x47),
            "two transactions failed"
        );

        NOW_US.store(4_000_000, Ordering::Relaxed);
        c.sync();
        assert!(!c.gives_data_ready());
        let before = c.chip().samples_produced();
        c.advance_one_sample();
        c.advance_one_sample();
        assert_eq!(
            read(&mut c, reg::WHO_AM_I),
            Ok(0x47),
            "a stopped chip answers"
        );
        NOW_US.store(5_000_000, Ordering::Relaxed);
        c.advance_one_sample();
        assert!(c.gives_data_ready());
        assert_eq!(
            c.chip().samples_produced(),
            before + 1,
            "no sample while stopped"
        );

        NOW_US.store(6_500_000, Ordering::Relaxed);
        assert_eq!(read(&mut c, reg::WHO_AM_I), Ok(0xFF));
        NOW_US.store(7_000_000, Ordering::Relaxed);
        assert_eq!(read(&mut c, reg::WHO_AM_I), Ok(0x47));
        assert_eq!(
            read(&mut c, reg::PWR_MGMT0),
            Ok(0),
            "back at its power-on registers"
        );
        assert!(!c.gives_data_ready(), "sensors off until configured again");

        NOW_US.store(8_000_000, Ordering::Relaxed);
        let mut count = [0u8; 3];
        c.transaction(&mut [
            Operation::Write(&[reg::INT_STATUS | 0x80]),
            Operation::Read(&mut count),
        ])
        .unwrap();
        assert_eq!(&count[1..], [0x0F, 0xFF], "4095 records in a FIFO of 128");
        write(&mut c, reg::PWR_MGMT0, 0x0F);
        assert!(c.gives_data_ready(), "data-ready carries on");
        NOW_US.store(9_000_000, Ordering::Relaxed);
        assert_eq!(read(&mut c, reg::FIFO_COUNTH), Ok(0));

        // A fault that comes back: each occurrence, even one a look skipped.
        let mut c = chip(&["brownout@10+1/5"]);
        NOW_US.store(9_000_000, Ordering::Relaxed);
        write(&mut c, reg::PWR_MGMT0, 0x0F);
        for (at, who_am_i) in [(10.5, 0xFF), (11.0, 0x47), (15.5, 0xFF), (16.0, 0x47)] {
            NOW_US.store((at * 1e6) as u64, Ordering::Relaxed);
            assert_eq!(read(&mut c, reg::WHO_AM_I), Ok(who_am_i), "at {at} s");
        }
        write(&mut c, reg::PWR_MGMT0, 0x0F);
        NOW_US.store(26_000_000, Ordering::Relaxed);
        assert_eq!(
            read(&mut c, reg::PWR_MGMT0),
            Ok(0),
            "reset by the skipped ones"
        );
    }
}
