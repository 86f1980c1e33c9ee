//! The DMA receive ring's arithmetic (`triad::device::dma_ring`) against a
//! model of the DMA stream: a circular stream writing numbered bytes into a
//! ring, raising the half-transfer flag on reaching the middle and the
//! transfer-complete flag on reaching the end, the flags cleared at each look.
//! What must hold: up to LEN/2 bytes between two looks are counted exactly;
//! from LEN on the loss is reported; and whatever a look accepts, the bytes
//! read are exactly the ones written, in order — nothing lost silently.

use triad::device::dma_ring::{Boundaries, Lapped, RingReader};

/// The DMA stream and the ring it fills.
struct Dma<const LEN: usize> {
    ring: [u64; LEN],
    /// The next position it writes (NDTR's complement).
    at: usize,
    /// Flags raised since the last look.
    reached: Boundaries,
    /// Bytes written so far (each byte's value is its number).
    written: u64,
}

impl<const LEN: usize> Dma<LEN> {
    fn new() -> Self {
        Self {
            ring: [u64::MAX; LEN],
            at: 0,
            reached: Boundaries::default(),
            written: 0,
        }
    }

    /// The stream writes `n` bytes.
    fn write(&mut self, n: usize) {
        for _ in 0..n {
            self.ring[self.at] = self.written;
            self.written += 1;
            self.at = (self.at + 1) % LEN;
            if self.at == LEN / 2 {
                self.reached.half = true;
            }
            if self.at == 0 {
                self.reached.end = true;
            }
        }
    }
}

/// The reader and what it has read.
struct Reader<const LEN: usize> {
    ring: RingReader<LEN>,
    /// The number of the next byte it expects.
    next: u64,
}

impl<const LEN: usize> Reader<LEN> {
    fn new() -> Self {
        Self {
            ring: RingReader::new(),
            next: 0,
        }
    }

    /// One look: sync with the stream's position and flags (clearing them),
    /// then read everything; checks every byte read is the next written.
    /// Returns the look's verdict and the bytes read.
    fn look(&mut self, dma: &mut Dma<LEN>) -> (Result<(), Lapped>, usize) {
        let verdict = self.ring.sync(dma.at, dma.reached);
        dma.reached = Boundaries::default();
        if verdict.is_err() {
            // Skipped to the stream: the next byte read is the next written.
            self.next = dma.written;
        }
        let mut read = 0;
        while let Some(i) = self.ring.take() {
            assert_eq!(
                dma.ring[i], self.next,
                "byte at ring index {i}: read {} where {} was next",
                dma.ring[i], self.next
            );
            self.next += 1;
            read += 1;
        }
        (verdict, read)
    }
}

/// Every start position and every run length up to two laps, for one ring size.
fn every_arc<const LEN: usize>() {
    for start in 0..LEN {
        for run in 0..=2 * LEN {
            let mut dma = Dma::<LEN>::new();
            let mut reader = Reader::<LEN>::new();
            // Bring the stream (and the reader) to `start`, in steps the
            // ring counts exactly.
            let (first, second) = (start / 2, start - start / 2);
            for n in [first, second] {
                dma.write(n);
                assert_eq!(
                    reader.look(&mut dma),
                    (Ok(()), n),
                    "LEN {LEN}, start {start}"
                );
            }
            dma.write(run);
            let (verdict, read) = reader.look(&mut dma);
            let context = format!("LEN {LEN}, start {start}, run {run}");
            if run <= LEN / 2 {
                assert_eq!((verdict, read), (Ok(()), run), "{context}: counted exactly");
            } else if run >= LEN {
                assert_eq!(verdict, Err(Lapped), "{context}: a whole lap is reported");
            } else if verdict.is_ok() {
                assert_eq!(read, run, "{context}: accepted, so counted exactly");
            }
            // And it goes on: the next short run is read whole.
            dma.write(1);
            assert_eq!(
                reader.look(&mut dma),
                (Ok(()), 1),
                "{context}, then one byte"
            );
        }
    }
}

#[test]
fn every_start_and_run_length_of_small_rings() {
    every_arc::<2>();
    every_arc::<4>();
    every_arc::<6>();
    every_arc::<8>();
    every_arc::<16>();
    every_arc::<30>();
    every_arc::<64>();
}

/// xorshift64*: the bursts' sizes, reproducible.
fn next(state: &mut u64) -> u64 {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    state.wrapping_mul(0x2545_F491_4F6C_DD1D)
}

#[test]
fn random_bursts_into_the_boards_512_byte_ring_lose_nothing_silently() {
    const LEN: usize = 512;
    let mut dma = Dma::<LEN>::new();
    let mut reader = Reader::<LEN>::new();
    let mut state = 0x9E37_79B9_7F4A_7C15;
    let (mut exact, mut lapped) = (0, 0);
    for _ in 0..20_000 {
        // Mostly command-sized bursts, now and then a stall's worth.
        let n = match next(&mut state) % 10 {
            0 => (next(&mut state) % (3 * LEN as u64)) as usize,
            _ => (next(&mut state) % 243) as usize,
        };
        dma.write(n);
        let (verdict, read) = reader.look(&mut dma);
        match verdict {
            Ok(()) => {
                assert_eq!(read, n);
                exact += 1;
            }
            Err(Lapped) => {
                assert!(
                    n > LEN / 2,
                    "{n} bytes reported lost: at most LEN/2 are exact"
                );
                lapped += 1;
            }
        }
    }
    assert!(
        exact > 15_000 && lapped > 500,
        "exact {exact}, lapped {lapped}"
    );
}
