//! The record a chip model keeps of register accesses it does not model: a
//! reserved address, a bank or page it does not hold, or a setting whose
//! behaviour it leaves out. Such an access is never aliased onto another
//! register; it is counted here so that a test (or a driver author) can
//! fail on it instead of trusting data the real chip would not give.

/// One access the model does not model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnmodelledAccess {
    /// The bank (ICM-42688-P) or page (LSM6DSOX: 0 main, 1 embedded
    /// functions, 2 sensor hub) the access went to.
    pub page: u8,
    /// The register address.
    pub address: u8,
    /// The value written; `None` for a read.
    pub written: Option<u8>,
    /// What is not modelled, for the message.
    pub what: &'static str,
}

impl core::fmt::Display for UnmodelledAccess {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.written {
            Some(v) => write!(
                f,
                "write of {v:#04x} to page {} register {:#04x}: {}",
                self.page, self.address, self.what
            ),
            None => write!(
                f,
                "read of page {} register {:#04x}: {}",
                self.page, self.address, self.what
            ),
        }
    }
}

/// How many distinct accesses the log keeps (all are counted).
const KEPT: usize = 8;

/// Unmodelled accesses: a count of all, and the first few distinct ones.
#[derive(Clone, Debug, Default)]
pub struct UnmodelledLog {
    kept: [Option<UnmodelledAccess>; KEPT],
    count: u32,
}

impl UnmodelledLog {
    /// Records an access.
    pub fn record(&mut self, access: UnmodelledAccess) {
        self.count = self.count.saturating_add(1);
        if self.kept.iter().flatten().any(|a| *a == access) {
            return;
        }
        if let Some(slot) = self.kept.iter_mut().find(|s| s.is_none()) {
            *slot = Some(access);
        }
    }

    /// Accesses recorded (repeats included).
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Whether nothing unmodelled was touched.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The first distinct accesses recorded (at most 8).
    pub fn accesses(&self) -> impl Iterator<Item = &UnmodelledAccess> {
        self.kept.iter().flatten()
    }

    /// Forgets everything recorded.
    pub fn clear(&mut self) {
        *self = Self::default();
    }
}
