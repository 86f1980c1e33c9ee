//! The tagged FIFO with the accelerometer and the gyroscope at different
//! rates (DS12814 §9 FIFO_DATA_OUT_TAG; ST AN5272 §9 "FIFO data"): one word
//! per sensor sample, each tagged with its sensor and TAG_CNT, a 2-bit count
//! of the time slot (an instant of the faster sensor's rate) it belongs to.
//! A slot holds the faster sensor's word and, every `ratio`-th slot, the
//! slower sensor's. The driver makes one sample per slot, the slower triad
//! held (its latest value) in the slots that have none.
//!
//! A slot is known to be whole only when the next slot's first word is read,
//! or when every word the FIFO counted has been read (the chip writes a
//! slot's words together). So the slot being assembled when the output is
//! full stays open here, to be completed by the next read; and a word of a
//! slot already delivered (written after the count was read) updates the
//! held value for the samples that follow.

use super::registers as reg;
use crate::sensor::RawSample;

/// A slot being assembled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct OpenSlot {
    tag_cnt: u8,
    sample: RawSample,
    has_fast: bool,
    has_slow: bool,
}

/// The state of the tagged FIFO's reading between drains.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TaggedFifo {
    open: Option<OpenSlot>,
    /// TAG_CNT of the last slot delivered.
    last_tag_cnt: Option<u8>,
    /// Slots delivered since the last one with the slower sensor's word
    /// (`None`: none seen yet).
    since_slow: Option<u16>,
}

/// Which sensor is faster, and by how much.
#[derive(Clone, Copy, Debug)]
pub struct Rates {
    /// The gyroscope is the faster sensor (else the accelerometer).
    pub gyro_faster: bool,
    /// Faster rate / slower rate (the chip's rates are in ratios of powers of two).
    pub ratio: u16,
}

impl TaggedFifo {
    /// Takes one FIFO word; returns the slot it closes, if any. `held` is the
    /// last sample delivered (the values a slot without a sensor's word
    /// keeps), updated by every slot delivered. Err: the tag byte of a word
    /// that is neither the gyroscope's nor the accelerometer's.
    pub fn push(
        &mut self,
        word: &[u8; reg::FIFO_WORD_LEN],
        rates: Rates,
        held: &mut RawSample,
    ) -> Result<Option<RawSample>, u8> {
        let tag = word[0];
        let tag_cnt = (tag >> 1) & 0b11;
        let data = super::triad_le(&word[1..]);
        let gyro = match tag >> reg::TAG_SENSOR_SHIFT {
            reg::TAG_GYRO => true,
            reg::TAG_ACCEL => false,
            _ => return Err(tag),
        };
        let fast = gyro == rates.gyro_faster;
        let mut closed = None;
        if self.open.is_some_and(|o| o.tag_cnt != tag_cnt) {
            closed = self.close(held);
        }
        if self.open.is_none() && self.last_tag_cnt == Some(tag_cnt) {
            // A late word of the slot delivered last: it holds from here on.
            set(held, gyro, data);
            if !fast {
                self.since_slow = Some(0);
            }
            return Ok(closed);
        }
        let open = self.open.get_or_insert(OpenSlot {
            tag_cnt,
            sample: *held,
            has_fast: false,
            has_slow: false,
        });
        set(&mut open.sample, gyro, data);
        if fast {
            open.has_fast = true;
        } else {
            open.has_slow = true;
        }
        Ok(closed)
    }

    /// After every word the FIFO counted was read: the open slot, whole
    /// (the chip writes a slot's words together).
    pub fn flush(&mut self, held: &mut RawSample) -> Option<RawSample> {
        self.close(held)
    }

    /// Closes the open slot: a sample if it has the faster sensor's word. A
    /// slot of the slower sensor's word alone (its grid off the faster
    /// one's: rates whose ratio is not a whole number) makes no sample; its
    /// value holds from the next one.
    fn close(&mut self, held: &mut RawSample) -> Option<RawSample> {
        let open = self.open.take()?;
        self.last_tag_cnt = Some(open.tag_cnt);
        *held = open.sample;
        if !open.has_fast {
            self.since_slow = Some(0);
            return None;
        }
        self.since_slow = match (open.has_slow, self.since_slow) {
            (true, _) => Some(0),
            (false, since) => since.map(|k| k.saturating_add(1)),
        };
        Some(open.sample)
    }

    /// Samples still waiting: the open slot and the slots of `words` unread
    /// words, counted from the slower sensor's pattern (its word in every
    /// `ratio`-th slot; before its first, taken as due `ratio` slots on).
    pub fn slots_waiting(&self, mut words: u16, rates: Rates) -> u16 {
        let mut slots = 0u16;
        let mut since = self.since_slow.unwrap_or(0);
        if let Some(open) = self.open {
            slots += 1;
            since = since.saturating_add(1);
            let slow_due = since >= rates.ratio;
            let missing = u16::from(!open.has_fast) + u16::from(slow_due && !open.has_slow);
            words = words.saturating_sub(missing);
            if slow_due || open.has_slow {
                since = 0;
            }
        }
        while words > 0 {
            since += 1;
            let slot_words = if since >= rates.ratio {
                since = 0;
                2
            } else {
                1
            };
            slots += 1;
            words = words.saturating_sub(slot_words);
        }
        slots
    }
}

/// Puts `data` in the gyroscope or the accelerometer triad of `sample`.
fn set(sample: &mut RawSample, gyro: bool, data: [i32; 3]) {
    if gyro {
        sample.gyro = data;
    } else {
        sample.accel = data;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn word(gyro: bool, tag_cnt: u8, value: i16) -> [u8; reg::FIFO_WORD_LEN] {
        let sensor = if gyro { reg::TAG_GYRO } else { reg::TAG_ACCEL };
        let mut w = [0u8; reg::FIFO_WORD_LEN];
        w[0] = (sensor << reg::TAG_SENSOR_SHIFT) | (tag_cnt << 1);
        w[1..3].copy_from_slice(&value.to_le_bytes());
        w
    }

    /// Gyro at twice the accelerometer's rate: slots G, G+A, G, G+A, …
    const RATES: Rates = Rates {
        gyro_faster: true,
        ratio: 2,
    };

    #[test]
    fn slots_are_grouped_by_tag_cnt_and_the_slower_triad_held() {
        let mut fifo = TaggedFifo::default();
        let mut held = RawSample::default();
        let words = [
            word(true, 1, 10),
            word(true, 2, 11),
            word(false, 2, 100),
            word(true, 3, 12),
            word(true, 0, 13),
            word(false, 0, 101),
        ];
        let mut pairs = [(0i32, 0i32); 4];
        let mut n = 0;
        for w in &words {
            if let Some(s) = fifo.push(w, RATES, &mut held).unwrap() {
                pairs[n] = (s.gyro[0], s.accel[0]);
                n += 1;
            }
        }
        let last = fifo.flush(&mut held).unwrap();
        pairs[n] = (last.gyro[0], last.accel[0]);
        assert_eq!(n + 1, 4);
        assert_eq!(pairs, [(10, 0), (11, 100), (12, 100), (13, 101)]);
        assert_eq!(held.accel[0], 101);
    }

    #[test]
    fn a_slot_cut_by_a_full_output_is_completed_by_the_next_read() {
        let mut fifo = TaggedFifo::default();
        let mut held = RawSample::default();
        // Accelerometer faster here; the gyro's word comes first in its slot.
        let rates = Rates {
            gyro_faster: false,
            ratio: 2,
        };
        assert_eq!(fifo.push(&word(true, 1, 7), rates, &mut held), Ok(None));
        // The output is full here (no flush): the slot waits, its faster
        // word still in the FIFO.
        assert_eq!(fifo.slots_waiting(1, rates), 1);
        assert_eq!(fifo.push(&word(false, 1, 20), rates, &mut held), Ok(None));
        let s = fifo.flush(&mut held).unwrap();
        assert_eq!((s.gyro[0], s.accel[0]), (7, 20));
    }

    #[test]
    fn a_slot_of_the_slower_word_alone_makes_no_sample_and_holds() {
        let mut fifo = TaggedFifo::default();
        let mut held = RawSample::default();
        fifo.push(&word(true, 1, 10), RATES, &mut held).unwrap();
        let closing = fifo.push(&word(false, 2, 99), RATES, &mut held).unwrap();
        assert_eq!(closing.map(|s| s.gyro[0]), Some(10));
        assert_eq!(fifo.flush(&mut held), None, "no gyro word: no sample");
        fifo.push(&word(true, 3, 11), RATES, &mut held).unwrap();
        let s = fifo.flush(&mut held).unwrap();
        assert_eq!((s.gyro[0], s.accel[0]), (11, 99));
    }

    #[test]
    fn a_late_word_of_a_delivered_slot_holds_from_then_on() {
        let mut fifo = TaggedFifo::default();
        let mut held = RawSample::default();
        fifo.push(&word(true, 1, 10), RATES, &mut held).unwrap();
        assert!(fifo.flush(&mut held).is_some());
        assert_eq!(fifo.push(&word(false, 1, 55), RATES, &mut held), Ok(None));
        fifo.push(&word(true, 2, 11), RATES, &mut held).unwrap();
        let s = fifo.flush(&mut held).unwrap();
        assert_eq!((s.gyro[0], s.accel[0]), (11, 55));
    }

    #[test]
    fn slots_waiting_follow_the_slower_sensors_pattern() {
        let mut fifo = TaggedFifo::default();
        let mut held = RawSample::default();
        // A slot with the slower word was delivered last: the next slow word is two slots on.
        fifo.push(&word(true, 1, 1), RATES, &mut held).unwrap();
        fifo.push(&word(false, 1, 1), RATES, &mut held).unwrap();
        fifo.flush(&mut held).unwrap();
        // G | G+A | G | G+A: 6 words, 4 slots.
        assert_eq!(fifo.slots_waiting(6, RATES), 4);
        assert_eq!(fifo.slots_waiting(0, RATES), 0);
        let other = word(false, 1, 0);
        let mut bad = other;
        bad[0] = 0x1F << reg::TAG_SENSOR_SHIFT;
        assert_eq!(fifo.push(&bad, RATES, &mut held), Err(bad[0]));
    }
}
