//! The device's command path: its decoder and command handler
//! ([`triad::device::CommandHandler`]) as the firmware runs them, over a
//! RAM flash, its built-in calibration a realistic one. The input is bytes
//! a host sent. Invariants: at most one reply per packet; a refused command
//! (a corrupted upload's chunk or commit, a save, anything) changes
//! nothing (the calibration in force, the store, the flash); the counters
//! `identify` reports add up.

use std::sync::OnceLock;

use triad::device::{
    ActiveCalibration, CalibrationStore, CommandHandler, DeviceFacts, Handled, SharedCounters,
};
use triad::model::{blob, Orientation};
use triad::protocol::{CalibrationSource, Decoder, Packet, Status, StoredState};
use triad_bench::ram_flash::{RamFlash, ERASE_SIZE};

use crate::invariants::{
    counters_add_up, one_reply_per_packet, refused_changes_nothing, Broken, DeviceState,
};

/// The command code of reset-counters.
const RESET_COUNTERS: u8 = 0x09;

/// The device's built-in calibration (a realistic one), as a blob.
pub fn built_in() -> &'static [u8; blob::BLOB_LEN] {
    static BLOB: OnceLock<[u8; blob::BLOB_LEN]> = OnceLock::new();
    BLOB.get_or_init(|| {
        let mut cal = triad_bench::inputs::realistic();
        cal.id = 0x0B11_7100;
        blob::encode(&cal)
    })
}

/// A device over an erased RAM flash, running its built-in calibration.
fn device() -> CommandHandler<RamFlash> {
    let store = CalibrationStore::new(RamFlash::new(), 0, ERASE_SIZE as u32)
        .expect("an erased RAM flash makes a store");
    let facts = DeviceFacts {
        firmware: "0.1.0",
        board: "fuzz",
        chip: "icm42688",
        bus: "spi",
        sample_rate_hz: 1000.0,
        baud: 921_600,
        scale: triad_bench::inputs::scale(),
        orientation: Orientation::RotationNone,
        cycles_hz: 84_000_000,
    };
    let active = ActiveCalibration {
        blob: Some(*built_in()),
        id: 0x0B11_7100,
        source: CalibrationSource::BuiltIn,
    };
    CommandHandler::new(facts, active, 1, Some(store), StoredState::Empty)
}

/// What a command may change.
fn state(handler: &mut CommandHandler<RamFlash>) -> DeviceState {
    let active = handler.active();
    let active = (active.blob, active.id, active.source);
    let stored = handler.stored();
    let ops = handler
        .store_mut()
        .map(|s| s.flash_mut().ops())
        .unwrap_or_default();
    DeviceState {
        active,
        stored,
        flash_ops: (ops.writes, ops.erases),
    }
}

/// Feeds `bytes` to a fresh device; the commands it carried out.
pub fn command_path(bytes: &[u8]) -> Result<u64, Broken> {
    let mut handler = device();
    let counters = SharedCounters::new();
    let mut decoder = Decoder::new();
    // The device's decoder is in step from its start (as after the host's
    // first delimiter).
    decoder.push(0);
    let (mut replies, mut errors, mut delimiters, mut accepted) = (0u32, 0u32, 0u32, 0u64);
    // Replies and refusals before the last reset of the counters.
    let mut at_reset = (0u32, 0u32);
    // The last command handled (its number and CRC): the same again is a
    // retry, answered but not carried out again (a reset does not reset twice).
    let mut last_command = None;
    for &b in bytes {
        delimiters += u32::from(b == 0);
        let Some(decoded) = decoder.push(b) else {
            continue;
        };
        let before = state(&mut handler);
        let key = match &decoded {
            Ok(Packet::Command(p)) => {
                let raw = decoder.last_packet_bytes();
                Some((p.sequence, raw[raw.len().saturating_sub(4)..].to_vec()))
            }
            _ => None,
        };
        let retry = key.is_some() && key == last_command;
        if key.is_some() {
            last_command = key;
        }
        let handled = handler.on_packet(
            &decoded,
            decoder.last_packet_bytes(),
            &counters,
            &mut |_| true,
        );
        match handled {
            Handled::Reply(reply) => {
                replies += 1;
                if reply.status == Status::Ok {
                    accepted += u64::from(!retry);
                    if reply.command == RESET_COUNTERS && !retry {
                        at_reset = (replies - 1, errors);
                    }
                } else {
                    errors += 1;
                }
                refused_changes_nothing(&reply, &before, &state(&mut handler))?;
            }
            // The firmware runs a self-test and replies (counted then):
            // nothing to run here, nothing counted.
            Handled::SelfTest { .. } => last_command = None,
            Handled::Nothing => {}
        }
    }
    one_reply_per_packet(replies, delimiters)?;
    let info = handler.info(&counters);
    counters_add_up(
        info.counters.commands,
        info.counters.command_errors,
        replies - at_reset.0,
        errors - at_reset.1,
    )?;
    Ok(accepted)
}
