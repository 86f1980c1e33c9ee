//! What every chip model offers besides its register map: time, faults,
//! bus counters, the unmodelled-access log, and the bus traits (SPI as a
//! device or byte by byte, I²C). One definition, stamped on each model by
//! `chip_model_common!`, so the models keep only
//! what differs: their registers and behaviour (the `Chip` state behind the
//! bus, with `advance`, `ns_to_next_event`, `overflow_fifo` and
//! `i2c_disabled`).

/// Implements the shared API on `$model<S>`, a struct with fields `chip`
/// (the chip's state: `source`, `samples`, `clipped`, `fifo`, `stuck`,
/// `who_am_i_override`, `self_test`, `dead_self_test`, `unmodelled`) and
/// `port` (a [`BusPort`](crate::chips::register_bus::BusPort)).
macro_rules! chip_model_common {
    ($model:ident) => {
        impl<S: $crate::chips::source::SampleSource> $model<S> {
            /// What the self-test adds to each axis when enabled (positive), SI.
            pub fn self_test_response(
                &self,
            ) -> $crate::chips::self_test_response::SelfTestResponse {
                self.chip.self_test
            }

            /// Lets `ns` nanoseconds pass: one sample per ODR period elapsed.
            pub fn advance(&mut self, ns: u64) {
                self.chip.advance(ns);
            }

            /// The whole nanoseconds until the next sample of either sensor
            /// at the rates the chip runs (the ones its driver wrote): the
            /// model's clock then stands on or just after each exact sample
            /// instant, with no repeat and no skip however long it runs.
            /// `None`: both sensors off.
            pub fn ns_to_next_sample(&self) -> Option<u64> {
                self.chip.ns_to_next_event()
            }

            /// Injects a fault (see [`Fault`](crate::chips::fault::Fault)).
            pub fn inject(&mut self, fault: $crate::chips::fault::Fault) {
                use $crate::chips::fault::Fault;
                match fault {
                    Fault::BusError { transactions } => self.port.fail_next(transactions),
                    Fault::WrongWhoAmI(value) => self.chip.who_am_i_override = Some(value),
                    Fault::StuckOutput => self.chip.stuck = true,
                    Fault::FifoOverflow { lost } => self.chip.overflow_fifo(lost),
                    Fault::DeadSelfTest { triad, axis } => {
                        self.chip.dead_self_test.kill(triad, axis)
                    }
                }
            }

            /// Clears every persistent fault (wrong identity, stuck output,
            /// dead self-test axes, pending bus errors).
            pub fn clear_faults(&mut self) {
                self.chip.who_am_i_override = None;
                self.chip.stuck = false;
                self.chip.dead_self_test = Default::default();
                self.port.fail_next(0);
            }

            /// Bytes moved on the bus so far (see
            /// [`BusPort::bytes`](crate::chips::register_bus::BusPort::bytes)).
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

            /// Packets (tagged words on the LSM6DSOX) in the FIFO.
            pub fn fifo_len(&self) -> usize {
                self.chip.fifo.len()
            }

            /// The register accesses the model does not model (see
            /// [`UnmodelledLog`](crate::chips::unmodelled::UnmodelledLog)).
            pub fn unmodelled(&self) -> &$crate::chips::unmodelled::UnmodelledLog {
                &self.chip.unmodelled
            }

            /// The sample source.
            pub fn source_mut(&mut self) -> &mut S {
                &mut self.chip.source
            }
        }

        impl<S: $crate::chips::source::SampleSource> $crate::chips::model_clock::Clocked
            for $model<S>
        {
            fn advance(&mut self, ns: u64) {
                self.chip.advance(ns);
            }
        }

        impl<S> embedded_hal::spi::ErrorType for $model<S> {
            type Error = embedded_hal::spi::ErrorKind;
        }

        impl<S: $crate::chips::source::SampleSource> embedded_hal::spi::SpiDevice for $model<S> {
            fn transaction(
                &mut self,
                operations: &mut [embedded_hal::spi::Operation<'_, u8>],
            ) -> Result<(), embedded_hal::spi::ErrorKind> {
                self.port.spi(&mut self.chip, operations)
            }
        }

        impl<S: $crate::chips::source::SampleSource> $crate::chips::spi_wire::SpiWire
            for $model<S>
        {
            fn select(&mut self, selected: bool) {
                self.port.wire_select(selected);
            }

            fn exchange(&mut self, mosi: u8) -> u8 {
                self.port.wire_byte(&mut self.chip, mosi).unwrap_or(0xFF)
            }
        }

        impl<S> embedded_hal::i2c::ErrorType for $model<S> {
            type Error = embedded_hal::i2c::ErrorKind;
        }

        impl<S: $crate::chips::source::SampleSource> embedded_hal::i2c::I2c for $model<S> {
            fn transaction(
                &mut self,
                address: u8,
                operations: &mut [embedded_hal::i2c::Operation<'_>],
            ) -> Result<(), embedded_hal::i2c::ErrorKind> {
                // The interface configuration may have switched I²C off:
                // the chip no longer answers.
                if self.chip.i2c_disabled() {
                    return Err(embedded_hal::i2c::ErrorKind::NoAcknowledge(
                        embedded_hal::i2c::NoAcknowledgeSource::Address,
                    ));
                }
                self.port.i2c(&mut self.chip, address, operations)
            }
        }
    };
}

pub(crate) use chip_model_common;
