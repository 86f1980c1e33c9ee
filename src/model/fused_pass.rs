//! The batch kernel's usual pass on the Cortex-M4F (`cfg(triad_fpu)`): both
//! triads of each raw sample corrected in one loop, the 18 coefficients held
//! in FPU registers across the batch, for a kernel whose values never clip
//! and whose gyroscope has no g-sensitivity (`ScaledTriad::never_clips` of
//! both triads, 16-bit codes: the case of every real calibration).
//!
//! It computes what the portable pass (`ScaledTriad::pass`) computes, with
//! the same operations in the same order, so the counts are the same bits:
//! each row is `o + k0·x0 + k1·x1 + k2·x2` left to right with VMLA (the
//! product rounded, then the sum: Rust's `a + b * c`, which LLVM emits as
//! VMLA too), and rounded to the nearest count, ties to even, by VCVTR
//! under the FPSCR's rounding mode, as the portable pass's magic add is.
//! The bench digests of `cargo xtask test` compare both on the emulated
//! Cortex-M4F with the host's, bit for bit.
//!
//! Why inline assembly: LLVM runs the portable form as two passes (one per
//! triad, 37 instructions per triad and sample on the Cortex-M4F), as a
//! fused loop would need more FPU registers than it has once each row's
//! offset is kept and copied; here one VLDM loads the 18 coefficients into
//! s12-s29 once per batch, one VLDM per sample loads the six offsets as
//! the rows' starting sums, one the six raw axes (an LDM the same words
//! for the limit tests), and VMOV moves two counts at a time: 60
//! instructions per sample, of which 15 are the two limit tests.

use super::corrector::ClipFlags;
use super::limit_codes::QDADD_K;
use crate::sensor::RawSample;
use core::mem::{offset_of, size_of};

// The loop reads a raw sample as seven words: accelerometer x y z, then
// gyroscope x y z (the temperature's word unread).
const _: () = assert!(offset_of!(RawSample, accel) == 0);
const _: () = assert!(offset_of!(RawSample, gyro) == 12);
const _: () = assert!(size_of::<RawSample>() == 28);

/// Both triads' coefficients scaled to counts, in the order the loop loads
/// them: the six offsets (the rows' starting sums), then the six rows of K.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct FusedCoefficients {
    /// Accelerometer x y z, then gyroscope x y z.
    offset: [f32; 6],
    /// Accelerometer rows, then gyroscope rows.
    k: [[f32; 3]; 6],
}

impl FusedCoefficients {
    /// The coefficients of the accelerometer's `(K, k)` and the gyroscope's.
    pub(super) fn new(accel: ([[f32; 3]; 3], [f32; 3]), gyro: ([[f32; 3]; 3], [f32; 3])) -> Self {
        let (ka, oa) = accel;
        let (kg, og) = gyro;
        FusedCoefficients {
            offset: [oa[0], oa[1], oa[2], og[0], og[1], og[2]],
            k: [ka[0], ka[1], ka[2], kg[0], kg[1], kg[2]],
        }
    }

    /// Corrects the samples of `raw` that `out` has room for into `out`
    /// (accelerometer x y z, gyroscope x y z counts), and gives the clip
    /// flags: a triad with a raw axis at a 16-bit limit code. Only for a
    /// kernel whose values never clip (no value reaches ±MAX_COUNTS, so
    /// each count is the rounded value's low 16 bits).
    #[allow(unsafe_code)]
    pub(super) fn correct(&self, raw: &[RawSample], out: &mut [[i16; 6]]) -> ClipFlags {
        let n = raw.len().min(out.len());
        if n == 0 {
            return ClipFlags::default();
        }
        let input = raw.as_ptr();
        // SAFETY: n ≤ raw.len(): one past the last sample read.
        let end = unsafe { input.add(n) };
        // The accelerometer's limit test accumulates in the sticky Q flag
        // (limit_codes.rs: x·(2¹⁵ + 1), then QDADD with QDADD_K saturates
        // exactly for 32767 and −32768); the gyroscope's in bit 15 of
        // `gyro` (the portable form there: (x ^ x >> 15) + 1), as Q holds
        // only one flag.
        let mut gyro: u32 = 0;
        let apsr: u32;
        // SAFETY: reads n samples from `raw` and writes n from `out` (n is
        // both lengths' minimum, n ≥ 1), each 12-byte sample of `out` by
        // halfwords (its alignment is 2); the coefficients are read from
        // `self`. Every register written is an output or a clobber; the
        // APSR's flags are written (Q cleared first), no stack is used.
        unsafe {
            core::arch::asm!(
                "msr APSR_nzcvq, {gyro}",
                // s6-s11: the offsets; s12-s29: the rows of K.
                "vldm {coefficients}, {{s6-s29}}",
                "2:",
                "vldm {input}, {{s0-s5}}",
                "ldm {input}, {{r0-r5}}",
                "add {input}, {input}, #{size}",
                "vcvt.f32.s32 s0, s0",
                "vcvt.f32.s32 s1, s1",
                "vcvt.f32.s32 s2, s2",
                "vcvt.f32.s32 s3, s3",
                "vcvt.f32.s32 s4, s4",
                "vcvt.f32.s32 s5, s5",
                "vldm {coefficients}, {{s6-s11}}",
                "add.w r0, r0, r0, lsl #15",
                "qdadd r0, {k}, r0",
                "vmla.f32 s6, s12, s0",
                "vmla.f32 s7, s15, s0",
                "vmla.f32 s8, s18, s0",
                "vmla.f32 s9, s21, s3",
                "vmla.f32 s10, s24, s3",
                "vmla.f32 s11, s27, s3",
                "add.w r1, r1, r1, lsl #15",
                "qdadd r1, {k}, r1",
                "vmla.f32 s6, s13, s1",
                "vmla.f32 s7, s16, s1",
                "vmla.f32 s8, s19, s1",
                "vmla.f32 s9, s22, s4",
                "vmla.f32 s10, s25, s4",
                "vmla.f32 s11, s28, s4",
                "add.w r2, r2, r2, lsl #15",
                "qdadd r2, {k}, r2",
                "vmla.f32 s6, s14, s2",
                "vmla.f32 s7, s17, s2",
                "vmla.f32 s8, s20, s2",
                "vmla.f32 s9, s23, s5",
                "vmla.f32 s10, s26, s5",
                "vmla.f32 s11, s29, s5",
                "eor.w r3, r3, r3, asr #15",
                "eor.w r4, r4, r4, asr #15",
                "eor.w r5, r5, r5, asr #15",
                "add.w r3, r3, #1",
                "add.w r4, r4, #1",
                "add.w r5, r5, #1",
                "orr.w {gyro}, {gyro}, r3",
                "orr.w {gyro}, {gyro}, r4",
                "orr.w {gyro}, {gyro}, r5",
                "vcvtr.s32.f32 s6, s6",
                "vcvtr.s32.f32 s7, s7",
                "vcvtr.s32.f32 s8, s8",
                "vcvtr.s32.f32 s9, s9",
                "vcvtr.s32.f32 s10, s10",
                "vcvtr.s32.f32 s11, s11",
                "vmov r0, r1, s6, s7",
                "vmov r2, r3, s8, s9",
                "vmov r4, r5, s10, s11",
                "strh r1, [{output}, #2]",
                "strh r2, [{output}, #4]",
                "strh r3, [{output}, #6]",
                "strh r4, [{output}, #8]",
                "strh r5, [{output}, #10]",
                "strh r0, [{output}], #12",
                "cmp {input}, {end}",
                "bne 2b",
                "mrs {k}, APSR",
                coefficients = in(reg) self,
                input = inout(reg) input => _,
                end = in(reg) end,
                output = inout(reg) out.as_mut_ptr() => _,
                k = inout(reg) QDADD_K as u32 => apsr,
                gyro = inout(reg) gyro,
                size = const size_of::<RawSample>(),
                out("r0") _, out("r1") _, out("r2") _, out("r3") _, out("r4") _, out("r5") _,
                out("s0") _, out("s1") _, out("s2") _, out("s3") _, out("s4") _, out("s5") _,
                out("s6") _, out("s7") _, out("s8") _, out("s9") _, out("s10") _, out("s11") _,
                out("s12") _, out("s13") _, out("s14") _, out("s15") _, out("s16") _,
                out("s17") _, out("s18") _, out("s19") _, out("s20") _, out("s21") _,
                out("s22") _, out("s23") _, out("s24") _, out("s25") _, out("s26") _,
                out("s27") _, out("s28") _, out("s29") _,
                options(nostack),
            );
        }
        ClipFlags {
            accel: (apsr >> 27) & 1 != 0,
            gyro: (gyro >> 15) & 1 != 0,
        }
    }
}
