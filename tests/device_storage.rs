//! The calibration store in flash (`triad::device::storage`) over a RAM NOR
//! flash that can lose power at any write unit or erase: after a cut at
//! every point of a save (and of an erase), a restarted device loads the old
//! calibration or the new one, complete, never a mix, never garbage.

mod ram_flash;

use ram_flash::*;
use triad::device::storage::{CalibrationStore, Loaded, StorageError, Stored};
use triad::model::blob::BLOB_LEN;

/// A recognisable blob per calibration.
fn blob(tag: u8) -> [u8; BLOB_LEN] {
    let mut b = [0u8; BLOB_LEN];
    for (i, byte) in b.iter_mut().enumerate() {
        *byte = tag.wrapping_mul(31).wrapping_add(i as u8);
    }
    b
}

/// Where a save went.
fn stored(generation: u32, slot: u8) -> Stored {
    Stored { generation, slot }
}

fn store(flash: RamFlash) -> CalibrationStore<RamFlash> {
    CalibrationStore::new(flash, BASE, SLOT_LEN).expect("valid layout")
}

/// What a restarted device loads.
fn load_after_restart(store: CalibrationStore<RamFlash>) -> (Loaded, [u8; BLOB_LEN], RamFlash) {
    let mut flash = store.release();
    flash.power_up();
    let mut s = self::store(flash);
    let mut out = [0u8; BLOB_LEN];
    let loaded = s.load(&mut out).expect("loads");
    (loaded, out, s.release())
}

#[test]
fn saves_alternate_slots_and_the_newest_wins() {
    let mut s = store(RamFlash::new());
    let mut out = [0u8; BLOB_LEN];
    assert_eq!(s.load(&mut out).unwrap().record, None, "blank flash");
    assert_eq!(s.save(&blob(1)).unwrap(), stored(1, 0));
    assert_eq!(s.save(&blob(2)).unwrap(), stored(2, 1));
    assert_eq!(s.save(&blob(3)).unwrap(), stored(3, 0));
    let (loaded, out, _) = load_after_restart(s);
    assert_eq!(loaded.record, Some(stored(3, 0)));
    assert_eq!(loaded.damaged_slots, 0);
    assert_eq!(out, blob(3));
}

/// The flash with `old` saved (or blank), and how many operations a save of
/// a new blob takes on it.
fn prepared(old: Option<u8>) -> (RamFlash, usize) {
    let mut s = store(RamFlash::new());
    if let Some(tag) = old {
        s.save(&blob(tag)).unwrap();
        s.save(&blob(tag)).unwrap(); // both slots written once: a worn-in state
    }
    let flash = s.release();
    let mut probe = store(RamFlash {
        memory: flash.memory.clone(),
        ..RamFlash::new()
    });
    probe.save(&blob(9)).unwrap();
    let ops = probe.release().operations;
    (flash, ops)
}

#[test]
fn a_power_cut_at_every_point_of_a_save_leaves_the_old_or_the_new_calibration() {
    for old in [None, Some(4)] {
        let (flash, ops) = prepared(old);
        // One erase and (16 + 512) / 4 = 132 write units.
        assert_eq!(
            ops,
            1 + (16 + BLOB_LEN) / WRITE_SIZE,
            "operations of a save"
        );
        // Cut before any operation, in each one, and none at all.
        let cuts = (0..=ops).map(Some).chain([None]);
        for cut in cuts {
            for noise in [0x9E37_79B9u32, 0x1234_5678, 0xFFFF_FFFF] {
                let mut f = RamFlash {
                    memory: flash.memory.clone(),
                    ..RamFlash::new()
                };
                f.noise = noise;
                f.cut_after = cut;
                let mut s = store(f);
                let saved = s.save(&blob(9));
                assert_eq!(
                    saved.is_ok(),
                    cut.is_none(),
                    "cut {cut:?}: the save reports it"
                );
                let (loaded, out, _) = load_after_restart(s);
                let new = loaded.record.is_some() && out == blob(9);
                match cut {
                    None => assert!(new, "an uncut save is loaded"),
                    // Until the header's last word is programmed, the old one.
                    Some(k) if k < ops => match old {
                        Some(tag) => assert_eq!(out, blob(tag), "cut {k}: the old calibration"),
                        None => assert_eq!(loaded.record, None, "cut {k}: still nothing"),
                    },
                    // Cut in the header's last word: old, or new if the half-done
                    // word happens to hold its value; never anything else.
                    Some(_) => match old {
                        Some(tag) => assert!(new || out == blob(tag), "{loaded:?}"),
                        None => assert!(new || loaded.record.is_none(), "{loaded:?}"),
                    },
                }
            }
        }
    }
}

#[test]
fn a_power_cut_during_erase_never_brings_back_an_older_calibration() {
    let mut s = store(RamFlash::new());
    s.save(&blob(1)).unwrap();
    s.save(&blob(2)).unwrap();
    let memory = s.release().memory;
    // Cut before the first erase, in the first (older slot), in the second
    // (newest slot), or none.
    for cut in [Some(0), Some(1), Some(2), None] {
        let mut f = RamFlash {
            memory: memory.clone(),
            ..RamFlash::new()
        };
        f.cut_after = cut;
        let mut s = store(f);
        assert_eq!(s.erase().is_ok(), cut.is_none());
        let (loaded, out, _) = load_after_restart(s);
        match (cut, loaded.record) {
            (None, record) => assert_eq!(record, None, "erased"),
            (Some(_), Some(_)) => assert_eq!(out, blob(2), "cut {cut:?}: only the newest"),
            (Some(k), None) => assert_eq!(k, 2, "only a cut in the newest's erase loses it"),
        }
    }
}

#[test]
fn a_damaged_slot_is_reported_and_ignored() {
    let mut s = store(RamFlash::new());
    s.save(&blob(1)).unwrap();
    s.save(&blob(2)).unwrap();
    let mut flash = s.release();
    // One bit of the newest record's blob flips (slot 1).
    flash.memory[BASE as usize + SLOT_LEN as usize + 16 + 100] ^= 0x04;
    let mut s = store(flash);
    let mut out = [0u8; BLOB_LEN];
    let loaded = s.load(&mut out).unwrap();
    assert_eq!(loaded.record, Some(stored(1, 0)));
    assert_eq!(loaded.damaged_slots, 0b10);
    assert_eq!(out, blob(1));
    // The next save goes over the damaged slot and wins.
    assert_eq!(s.save(&blob(3)).unwrap(), stored(2, 1));
}

#[test]
fn a_layout_that_does_not_fit_the_flash_is_refused_with_the_value() {
    let layout = |base, slot| match CalibrationStore::new(RamFlash::new(), base, slot) {
        Err(StorageError::Layout { what, value }) => (what, value),
        other => panic!("{:?}", other.map(|_| ())),
    };
    assert_eq!(layout(100, SLOT_LEN).1, 100);
    assert_eq!(layout(BASE, 1000).1, 1000);
    assert_eq!(
        layout(3 * ERASE_SIZE as u32, SLOT_LEN).1,
        5 * ERASE_SIZE as u32
    );
    assert!(layout(BASE, 0).0.contains("multiple of the erase size"));
}
