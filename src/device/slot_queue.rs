//! A single-producer single-consumer queue whose items are written and read
//! where they lie: the producer gets the next free slot as `&mut T` (holding
//! whatever an earlier item left there) and fills it in place, then commits
//! it; the consumer peeks at the oldest item and releases it when done.
//! Between the data-ready task and the transmitter it carries the frames
//! (up to 236 bytes each), which a by-value queue (`heapless::spsc`) would
//! have the sampler build on its stack and copy in: about 95 instructions
//! per sample at 8 kHz with W = 32 (docs/BENCHMARKS.md).
//!
//! Two counters, each written by one side: `written` (items ever committed,
//! the producer's) and `read` (items ever released, the consumer's). Both
//! wrap at 2ⁿ (usize); item `i` lives in slot `i mod N`, the same across the
//! wrap because `N` is a power of two. Slots `read..written` hold items;
//! the producer writes only slot `written`, and only while fewer than `N`
//! are held, so the two sides never touch the same slot at once.
// The slots are shared between two tasks through `UnsafeCell`; every access
// is argued at its `unsafe` block.
#![allow(unsafe_code)]

use core::cell::UnsafeCell;
use core::marker::PhantomData;
use core::sync::atomic::{AtomicUsize, Ordering};

/// `N` slots of `T` and the two counters (see the module's comment).
pub struct SlotQueue<T, const N: usize> {
    slots: UnsafeCell<[T; N]>,
    written: AtomicUsize,
    read: AtomicUsize,
}

// SAFETY: the queue hands each slot to one side at a time (see the
// module's comment); the items move between threads, so `T: Send`.
unsafe impl<T: Send, const N: usize> Sync for SlotQueue<T, N> {}

impl<T: Copy, const N: usize> SlotQueue<T, N> {
    /// The counters wrap at 2ⁿ, which only a power of two divides.
    const POWER_OF_TWO: () = assert!(N.is_power_of_two(), "the queue's length must be 2ⁿ");

    /// An empty queue whose slots hold `fill` (what the producer finds in a
    /// slot never written yet).
    pub const fn new(fill: T) -> Self {
        let () = Self::POWER_OF_TWO;
        Self {
            slots: UnsafeCell::new([fill; N]),
            written: AtomicUsize::new(0),
            read: AtomicUsize::new(0),
        }
    }

    /// The producer's and the consumer's ends. Borrowing the queue for as
    /// long as they live, so there is one of each.
    pub fn split(&mut self) -> (SlotProducer<'_, T, N>, SlotConsumer<'_, T, N>) {
        let queue = &*self;
        (
            SlotProducer {
                queue,
                written: queue.written.load(Ordering::Relaxed),
                given: false,
                _not_sync: PhantomData,
            },
            SlotConsumer {
                queue,
                read: queue.read.load(Ordering::Relaxed),
                _not_sync: PhantomData,
            },
        )
    }

    /// Slot `index mod N`.
    fn slot(&self, index: usize) -> *mut T {
        let slots = self.slots.get().cast::<T>();
        // SAFETY: `index % N < N`: inside the array.
        unsafe { slots.add(index % N) }
    }
}

/// The producer's end: fills the next free slot in place and commits it.
pub struct SlotProducer<'a, T, const N: usize> {
    queue: &'a SlotQueue<T, N>,
    /// Items committed, the producer's own copy of `queue.written`.
    written: usize,
    /// A slot was given and not committed yet.
    given: bool,
    _not_sync: PhantomData<*const ()>,
}

// SAFETY: the end may move to another task (the one that produces); it is
// not `Sync`, so it is used from one at a time.
unsafe impl<T: Send, const N: usize> Send for SlotProducer<'_, T, N> {}

impl<T: Copy, const N: usize> SlotProducer<'_, T, N> {
    /// The next free slot, holding what an earlier item (or the queue's
    /// fill) left there, to be overwritten; `None` when the queue is full.
    /// Nothing is queued until [`SlotProducer::commit`].
    #[inline]
    pub fn slot(&mut self) -> Option<&mut T> {
        let read = self.queue.read.load(Ordering::Acquire);
        if self.written.wrapping_sub(read) >= N {
            return None;
        }
        self.given = true;
        // SAFETY: slot `written` is not among `read..written`, the items the
        // consumer may read, and only this end writes it; the Acquire load
        // of `read` orders this after the consumer's last read of the slot.
        // The borrow of `self` keeps a second `&mut` from being made.
        Some(unsafe { &mut *self.queue.slot(self.written) })
    }

    /// The slot [`SlotProducer::slot`] gave last holds an item: the
    /// consumer may read it. Does nothing when no slot was given since the
    /// last commit (the queue was full).
    #[inline]
    pub fn commit(&mut self) {
        if !core::mem::take(&mut self.given) {
            return;
        }
        self.written = self.written.wrapping_add(1);
        // Release: the item's bytes are written before the consumer sees it.
        self.queue.written.store(self.written, Ordering::Release);
    }

    /// Offers `item` by value: `Err(item)` when the queue is full.
    #[inline]
    pub fn enqueue(&mut self, item: T) -> Result<(), T> {
        match self.slot() {
            Some(slot) => *slot = item,
            None => return Err(item),
        }
        self.commit();
        Ok(())
    }

    /// Items queued and not yet released.
    pub fn len(&self) -> usize {
        self.written
            .wrapping_sub(self.queue.read.load(Ordering::Relaxed))
    }

    /// True when nothing is queued.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The consumer's end: reads the oldest item where it lies and releases it.
pub struct SlotConsumer<'a, T, const N: usize> {
    queue: &'a SlotQueue<T, N>,
    /// Items released, the consumer's own copy of `queue.read`.
    read: usize,
    _not_sync: PhantomData<*const ()>,
}

// SAFETY: as for the producer's end.
unsafe impl<T: Send, const N: usize> Send for SlotConsumer<'_, T, N> {}

impl<T: Copy, const N: usize> SlotConsumer<'_, T, N> {
    /// The oldest item, `None` when the queue is empty.
    #[inline]
    pub fn peek(&self) -> Option<&T> {
        if !self.ready() {
            return None;
        }
        // SAFETY: slot `read` is among `read..written`: committed (the
        // Acquire load of `written` in `ready` orders its bytes before this
        // read) and not written again before this end releases it, which
        // needs `&mut self` while this borrow lives.
        Some(unsafe { &*self.queue.slot(self.read) })
    }

    /// Releases the oldest item (its slot is the producer's again); false
    /// when the queue was empty.
    #[inline]
    pub fn release(&mut self) -> bool {
        if !self.ready() {
            return false;
        }
        self.read = self.read.wrapping_add(1);
        // Release: the item is read before the producer may overwrite it.
        self.queue.read.store(self.read, Ordering::Release);
        true
    }

    /// True when an item is waiting.
    #[inline]
    pub fn ready(&self) -> bool {
        self.queue.written.load(Ordering::Acquire) != self.read
    }

    /// Items waiting.
    pub fn len(&self) -> usize {
        self.queue
            .written
            .load(Ordering::Acquire)
            .wrapping_sub(self.read)
    }

    /// True when nothing is waiting.
    pub fn is_empty(&self) -> bool {
        !self.ready()
    }
}

#[cfg(test)]
mod tests {
    use super::SlotQueue;

    #[test]
    fn items_come_out_in_order_across_the_wrap_and_a_full_queue_refuses() {
        let mut queue = SlotQueue::<u32, 4>::new(0);
        let (mut tx, mut rx) = queue.split();
        let mut next_in = 0;
        let mut next_out = 0;
        for round in 0..50 {
            // Fill in place until full (from 1 to 4 items each round).
            let want = round % 4 + 1;
            for _ in 0..want {
                match tx.slot() {
                    Some(slot) => {
                        *slot = next_in;
                        tx.commit();
                        next_in += 1;
                    }
                    None => break,
                }
            }
            assert!(tx.len() <= 4);
            if tx.len() == 4 {
                assert!(tx.slot().is_none(), "a full queue gives no slot");
                assert_eq!(tx.enqueue(99), Err(99));
            }
            // Drain all but one.
            while rx.len() > 1 {
                assert_eq!(rx.peek(), Some(&next_out));
                assert!(rx.release());
                next_out += 1;
            }
        }
        while let Some(&item) = rx.peek() {
            assert_eq!(item, next_out);
            rx.release();
            next_out += 1;
        }
        assert_eq!(next_out, next_in);
        assert!(!rx.release(), "nothing to release in an empty queue");
        assert!(rx.is_empty() && tx.is_empty());
    }

    #[test]
    fn a_slot_not_committed_is_not_seen_and_is_given_again() {
        let mut queue = SlotQueue::<u32, 2>::new(7);
        let (mut tx, rx) = queue.split();
        assert_eq!(tx.slot().copied(), Some(7), "a fresh slot holds the fill");
        if let Some(slot) = tx.slot() {
            *slot = 1;
        }
        assert!(rx.peek().is_none(), "not committed: not queued");
        assert_eq!(tx.slot().copied(), Some(1), "the same slot, as left");
        tx.commit();
        assert_eq!(rx.peek(), Some(&1));
    }

    #[test]
    fn a_commit_without_a_slot_given_changes_nothing() {
        let mut queue = SlotQueue::<u32, 2>::new(0);
        let (mut tx, mut rx) = queue.split();
        assert_eq!(tx.enqueue(1), Ok(()));
        assert_eq!(tx.enqueue(2), Ok(()));
        assert!(tx.slot().is_none());
        // Room freed after the refusal: the commit still queues nothing
        // (the slot it would queue was never written).
        rx.release();
        tx.commit();
        assert_eq!(rx.len(), 1);
        assert_eq!(rx.peek(), Some(&2));
        tx.commit();
        assert_eq!(rx.len(), 1, "a second commit of the same slot");
    }

    #[test]
    fn two_threads_pass_every_item_once_in_order() {
        extern crate std;
        const ITEMS: u64 = 200_000;
        let mut queue = SlotQueue::<[u64; 4], 8>::new([0; 4]);
        let (mut tx, mut rx) = queue.split();
        std::thread::scope(|scope| {
            scope.spawn(move || {
                let mut next = 0;
                while next < ITEMS {
                    if let Some(slot) = tx.slot() {
                        // Every word of the item, so a torn one shows.
                        *slot = [next; 4];
                        tx.commit();
                        next += 1;
                    }
                }
            });
            let mut expected = 0;
            while expected < ITEMS {
                if let Some(item) = rx.peek() {
                    assert_eq!(*item, [expected; 4]);
                    rx.release();
                    expected += 1;
                }
            }
        });
    }
}
