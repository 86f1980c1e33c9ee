//! Whether any raw axis of a batch sat at a 16-bit chip's limit code
//! (32767 or −32768: saturated, or the chip's "no data" marker), the test
//! the batch kernel's passes make on every axis they read.
//!
//! Two forms giving the same answer for every i16 input: the portable one
//! (three instructions per axis on the Cortex-M4F: an `eor` with shifted
//! operand, an `add` and an `orr` into the running flag) and, on cores with
//! the DSP extension, two instructions per axis whose result accumulates
//! in the sticky Q flag, read once per pass.

/// Accumulates the limit test over axes; [`Self::any`] says whether one
/// was at a limit.
#[derive(Clone, Copy, Debug)]
pub struct LimitCodes {
    #[cfg(not(triad_dsp))]
    bits: u32,
}

#[cfg(not(triad_dsp))]
impl LimitCodes {
    /// Nothing seen yet.
    #[inline(always)]
    pub fn start() -> Self {
        Self { bits: 0 }
    }

    /// Tests three axes, each an i16 code.
    #[inline(always)]
    pub fn add(&mut self, [x0, x1, x2]: [i32; 3]) {
        self.bits |= bit_15(x0) | bit_15(x1) | bit_15(x2);
    }

    /// True when an axis added since [`Self::start`] was at a limit code.
    #[inline(always)]
    pub fn any(self) -> bool {
        (self.bits >> 15) & 1 != 0
    }
}

#[cfg(any(not(triad_dsp), test))]
use crate::sensor::CodeRange;

/// Bit 15 set exactly for the limit codes of an i16 `x`.
#[cfg(any(not(triad_dsp), test))]
#[inline(always)]
fn bit_15(x: i32) -> u32 {
    CodeRange::i16_limit_bit(x)
}

/// `QDADD t, K, t` on t = x·(2¹⁵ + 1) (one `add` with shifted operand,
/// no constant register) saturates (setting Q) exactly for the limit codes
/// of an i16 x: 2t saturates below −2³¹ only for x = −32768 (t = −2³⁰ −
/// 2¹⁵; for −32767, t = −2³⁰ + 1), and K + 2t exceeds 2³¹ − 1 only for
/// x = 32767 (2t = 2³¹ − 2; for 32766, 2t = 2³¹ − 65540).
#[cfg(any(triad_dsp, test))]
pub(super) const QDADD_K: i32 = 2;

// Why inline assembly: the DSP extension's saturating arithmetic sets the
// sticky Q flag, so the test costs two instructions per axis and no
// accumulation, where the portable form costs three; Rust reaches neither
// QDADD nor the Q flag except through `asm!` (no stable intrinsics). The
// compiler neither reads nor writes Q in the code between `start` and `any`
// (no saturating instruction there), and an exception stacks and restores
// it with the rest of xPSR.
#[cfg(triad_dsp)]
#[allow(unsafe_code)]
impl LimitCodes {
    /// Nothing seen yet: clears Q (and the condition flags).
    #[inline(always)]
    pub fn start() -> Self {
        // SAFETY: writes the APSR's flags only.
        unsafe {
            core::arch::asm!("msr APSR_nzcvq, {zero}", zero = in(reg) 0u32, options(nomem, nostack));
        }
        Self {}
    }

    /// Tests three axes, each an i16 code: Q is set if one is at a limit.
    #[inline(always)]
    pub fn add(&mut self, [x0, x1, x2]: [i32; 3]) {
        // SAFETY: register arithmetic; sets Q, clobbers no memory.
        unsafe {
            core::arch::asm!(
                "add.w {t}, {x0}, {x0}, lsl #15",
                "qdadd {t}, {k}, {t}",
                "add.w {t}, {x1}, {x1}, lsl #15",
                "qdadd {t}, {k}, {t}",
                "add.w {t}, {x2}, {x2}, lsl #15",
                "qdadd {t}, {k}, {t}",
                t = out(reg) _,
                k = in(reg) QDADD_K,
                x0 = in(reg) x0,
                x1 = in(reg) x1,
                x2 = in(reg) x2,
                options(nomem, nostack),
            );
        }
    }

    /// True when an axis added since [`Self::start`] was at a limit code (Q).
    #[inline(always)]
    pub fn any(self) -> bool {
        let apsr: u32;
        // SAFETY: reads the APSR.
        unsafe {
            core::arch::asm!("mrs {apsr}, APSR", apsr = out(reg) apsr, options(nomem, nostack, preserves_flags));
        }
        (apsr >> 27) & 1 != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// QDADD Rd, Rm, Rn as the Arm ARM defines it: Rm + sat(2·Rn),
    /// saturated to 32 bits; and whether either step saturated (Q).
    fn qdadd(m: i32, n: i32) -> (i32, bool) {
        let doubled = 2 * i64::from(n);
        let d = doubled.clamp(i64::from(i32::MIN), i64::from(i32::MAX));
        let sum = i64::from(m) + d;
        let s = sum.clamp(i64::from(i32::MIN), i64::from(i32::MAX));
        (s as i32, d != doubled || s != sum)
    }

    /// Both forms flag exactly the two limit codes, over every i16.
    #[test]
    fn both_forms_flag_exactly_the_limit_codes() {
        for x in i32::from(i16::MIN)..=i32::from(i16::MAX) {
            let limit = x == 32767 || x == -32768;
            assert_eq!((bit_15(x) >> 15) & 1 != 0, limit, "portable, {x}");
            let t = x + (x << 15);
            assert_eq!(qdadd(QDADD_K, t).1, limit, "DSP, {x}");
        }
        let mut codes = LimitCodes::start();
        codes.add([0, 32766, -32767]);
        assert!(!codes.any());
        codes.add([5, -32768, 7]);
        assert!(codes.any());
    }
}
