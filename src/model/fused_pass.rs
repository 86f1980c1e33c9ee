//! The batch kernel's usual pass on the Cortex-M4F (`cfg(triad_fpu)`): both
//! triads of each raw sample corrected in one loop, the coefficients held
//! in FPU registers, for a kernel whose values never clip
//! (`ScaledTriad::never_clips` of both triads, 16-bit codes: the case of
//! every real calibration), with or without the gyroscope's g-sensitivity.
//!
//! It computes what the portable passes (`ScaledTriad::pass`) compute, with
//! the same operations in the same order, so the counts are the same bits:
//! each row is `o + k0·x0 + k1·x1 + k2·x2` (with G then `+ c0·a0 + c1·a1 +
//! c2·a2` on the raw accelerometer sample) left to right with VMLA (the
//! product rounded, then the sum: Rust's `a + b * c`, which LLVM emits as
//! VMLA too), and rounded to the nearest count, ties to even, by VCVTR
//! under the FPSCR's rounding mode, as the portable pass's magic add is.
//! The bench digests of `cargo xtask test` compare both on the emulated
//! Cortex-M4F with the host's, bit for bit.
//!
//! Why inline assembly: LLVM runs the portable form as two passes (one per
//! triad, 37 instructions per triad and sample without G), as a fused loop
//! needs more FPU registers than it has once each row's offset is kept and
//! copied. Here a VLDM per sample loads the rows' offsets as their starting
//! sums, one the six raw axes (an LDM the same words for the limit tests),
//! and VMOV moves two counts at a time. Without G the 18 coefficients stay
//! in s12-s29 for the whole batch: 60 instructions per sample, of which 15
//! are the two limit tests. With G there are 27 and the working registers
//! leave room for 21: the gyroscope's K stays in s21-s29, and per sample one
//! VLDM loads the accelerometer's offsets and K into s9-s20, then one the
//! gyroscope's offsets and C (12 words each, 13 cycles): 71 instructions
//! per sample (the portable passes take about 95).

use super::corrector::ClipFlags;
use super::limit_codes::QDADD_K;
use crate::sensor::RawSample;
use core::mem::{offset_of, size_of};

// The loops read a raw sample as six words: accelerometer x y z, then
// gyroscope x y z (the temperature's word unread).
const _: () = assert!(offset_of!(RawSample, accel) == 0);
const _: () = assert!(offset_of!(RawSample, gyro) == 12);

/// The coefficients of one of the loops, scaled to counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum FusedPass {
    /// Without G.
    WithoutG(Plain),
    /// With G.
    WithG(Crossed),
}

/// The loop without G's coefficients, as one VLDM loads them: the six
/// offsets (s6-s11), then the accelerometer's and the gyroscope's K
/// (s12-s20, s21-s29).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Plain {
    offset: [f32; 6],
    k: [[[f32; 3]; 3]; 2],
}

/// The loop with G's coefficients, in the order its VLDMs load them: the
/// gyroscope's K (s21-s29, once), then per sample the accelerometer's
/// offsets and K, and the gyroscope's offsets (k_g + c) and C (each into
/// s9-s20).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Crossed {
    gyro_k: [[f32; 3]; 3],
    accel: Block,
    gyro: Block,
}

/// One triad's offsets and a 3×3 matrix.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
struct Block {
    offset: [f32; 3],
    rows: [[f32; 3]; 3],
}

const _: () = assert!(offset_of!(Plain, k) == 24 && size_of::<Plain>() == 96);
const _: () = assert!(offset_of!(Crossed, accel) == 36 && offset_of!(Crossed, gyro) == 84);

/// The six raw axes of the sample at `{input}` as f32 in s0-s5 and as
/// i32 in r0-r5, `{input}` advanced to the next sample.
macro_rules! load_sample {
    () => {
        concat!(
            "vldm {input}, {{s0-s5}}\n",
            "ldm {input}, {{r0-r5}}\n",
            "add {input}, {input}, #{size}\n",
            "vcvt.f32.s32 s0, s0\n",
            "vcvt.f32.s32 s1, s1\n",
            "vcvt.f32.s32 s2, s2\n",
            "vcvt.f32.s32 s3, s3\n",
            "vcvt.f32.s32 s4, s4\n",
            "vcvt.f32.s32 s5, s5\n",
        )
    };
}

/// The limit tests of r0-r5 (see [`FusedPass::correct`]).
macro_rules! limit_tests {
    () => {
        concat!(
            "add.w r0, r0, r0, lsl #15\n",
            "qdadd r0, {k}, r0\n",
            "add.w r1, r1, r1, lsl #15\n",
            "qdadd r1, {k}, r1\n",
            "add.w r2, r2, r2, lsl #15\n",
            "qdadd r2, {k}, r2\n",
            "eor.w r3, r3, r3, asr #15\n",
            "eor.w r4, r4, r4, asr #15\n",
            "eor.w r5, r5, r5, asr #15\n",
            "add.w r3, r3, #1\n",
            "add.w r4, r4, #1\n",
            "add.w r5, r5, #1\n",
            "orr.w {gyro}, {gyro}, r3\n",
            "orr.w {gyro}, {gyro}, r4\n",
            "orr.w {gyro}, {gyro}, r5\n",
        )
    };
}

/// Rounds the gyroscope's rows in s9-s11 to counts in place and stores
/// s6-s11's six counts (the accelerometer's already rounded in s6-s8) as
/// the sample at `{output}` (halfwords: its alignment is 2), `{output}`
/// advanced to the next; then loops.
macro_rules! store_counts_and_loop {
    () => {
        concat!(
            "vcvtr.s32.f32 s9, s9\n",
            "vcvtr.s32.f32 s10, s10\n",
            "vcvtr.s32.f32 s11, s11\n",
            "vmov r0, r1, s6, s7\n",
            "vmov r2, r3, s8, s9\n",
            "vmov r4, r5, s10, s11\n",
            "strh r1, [{output}, #2]\n",
            "strh r2, [{output}, #4]\n",
            "strh r3, [{output}, #6]\n",
            "strh r4, [{output}, #8]\n",
            "strh r5, [{output}, #10]\n",
            "strh r0, [{output}], #12\n",
            "cmp {input}, {end}\n",
            "bne 2b\n",
            "mrs {k}, APSR\n",
        )
    };
}

/// The loop without G (see [`Plain`]).
macro_rules! without_g {
    () => {
        concat!(
            "vldm {coefficients}, {{s6-s29}}\n",
            "2:\n",
            load_sample!(),
            "vldm {coefficients}, {{s6-s11}}\n",
            "vmla.f32 s6, s12, s0\n",
            "vmla.f32 s7, s15, s0\n",
            "vmla.f32 s8, s18, s0\n",
            "vmla.f32 s9, s21, s3\n",
            "vmla.f32 s10, s24, s3\n",
            "vmla.f32 s11, s27, s3\n",
            "vmla.f32 s6, s13, s1\n",
            "vmla.f32 s7, s16, s1\n",
            "vmla.f32 s8, s19, s1\n",
            "vmla.f32 s9, s22, s4\n",
            "vmla.f32 s10, s25, s4\n",
            "vmla.f32 s11, s28, s4\n",
            "vmla.f32 s6, s14, s2\n",
            "vmla.f32 s7, s17, s2\n",
            "vmla.f32 s8, s20, s2\n",
            "vmla.f32 s9, s23, s5\n",
            "vmla.f32 s10, s26, s5\n",
            "vmla.f32 s11, s29, s5\n",
            limit_tests!(),
            "vcvtr.s32.f32 s6, s6\n",
            "vcvtr.s32.f32 s7, s7\n",
            "vcvtr.s32.f32 s8, s8\n",
            store_counts_and_loop!(),
        )
    };
}

/// s9-s11 += the products of the matrix in s12-s20 (rows s12-s14,
/// s15-s17, s18-s20) with the raw accelerometer sample in s0-s2, term by
/// term: the accelerometer's rows, and C's part of the gyroscope's.
macro_rules! rows_of_accel_sample {
    () => {
        concat!(
            "vmla.f32 s9, s12, s0\n",
            "vmla.f32 s10, s15, s0\n",
            "vmla.f32 s11, s18, s0\n",
            "vmla.f32 s9, s13, s1\n",
            "vmla.f32 s10, s16, s1\n",
            "vmla.f32 s11, s19, s1\n",
            "vmla.f32 s9, s14, s2\n",
            "vmla.f32 s10, s17, s2\n",
            "vmla.f32 s11, s20, s2\n",
        )
    };
}

/// The loop with G (see [`Crossed`]): `{coefficients}` moves on to the
/// gyroscope's block and back per sample (VLDM takes no offset); each
/// block's offsets start the rows in s9-s11, its matrix in s12-s20; the
/// accelerometer's counts wait in s6-s8 while the gyroscope's rows run.
macro_rules! with_g {
    () => {
        concat!(
            "vldmia {coefficients}!, {{s21-s29}}\n",
            "2:\n",
            load_sample!(),
            "vldmia {coefficients}!, {{s9-s20}}\n",
            rows_of_accel_sample!(),
            "vcvtr.s32.f32 s6, s9\n",
            "vcvtr.s32.f32 s7, s10\n",
            "vcvtr.s32.f32 s8, s11\n",
            "vldm {coefficients}, {{s9-s20}}\n",
            "sub {coefficients}, {coefficients}, #48\n",
            "vmla.f32 s9, s21, s3\n",
            "vmla.f32 s10, s24, s3\n",
            "vmla.f32 s11, s27, s3\n",
            "vmla.f32 s9, s22, s4\n",
            "vmla.f32 s10, s25, s4\n",
            "vmla.f32 s11, s28, s4\n",
            "vmla.f32 s9, s23, s5\n",
            "vmla.f32 s10, s26, s5\n",
            "vmla.f32 s11, s29, s5\n",
            rows_of_accel_sample!(),
            limit_tests!(),
            store_counts_and_loop!(),
        )
    };
}

impl FusedPass {
    /// The coefficients from the accelerometer's `(K, k)`, the
    /// gyroscope's, and with G the gyroscope's C (its k then k_g + c).
    pub(super) fn new(
        (ka, oa): ([[f32; 3]; 3], [f32; 3]),
        (kg, og): ([[f32; 3]; 3], [f32; 3]),
        cross: Option<[[f32; 3]; 3]>,
    ) -> Self {
        match cross {
            None => FusedPass::WithoutG(Plain {
                offset: [oa[0], oa[1], oa[2], og[0], og[1], og[2]],
                k: [ka, kg],
            }),
            Some(c) => FusedPass::WithG(Crossed {
                gyro_k: kg,
                accel: Block {
                    offset: oa,
                    rows: ka,
                },
                gyro: Block {
                    offset: og,
                    rows: c,
                },
            }),
        }
    }

    /// Corrects the samples of `raw` that `out` has room for into `out`
    /// (accelerometer x y z, gyroscope x y z counts), and gives the clip
    /// flags: a triad with a raw axis at a 16-bit limit code. Only for a
    /// kernel whose values never clip (no value reaches ±MAX_COUNTS, so
    /// each count is the rounded value's low 16 bits).
    ///
    /// The accelerometer's limit test accumulates in the sticky Q flag
    /// (limit_codes.rs: x·(2¹⁵ + 1), then QDADD with QDADD_K saturates
    /// exactly for 32767 and −32768), the gyroscope's in bit 15 of `gyro`
    /// (the portable form there: (x ^ x >> 15) + 1), as Q holds one flag.
    #[allow(unsafe_code)]
    pub(super) fn correct(&self, raw: &[RawSample], out: &mut [[i16; 6]]) -> ClipFlags {
        let n = raw.len().min(out.len());
        if n == 0 {
            return ClipFlags::default();
        }
        let input = raw.as_ptr();
        // SAFETY: n ≤ raw.len(): one past the last sample read.
        let end = unsafe { input.add(n) };
        let output = out.as_mut_ptr();
        let mut gyro: u32 = 0;
        let apsr: u32;
        // SAFETY (both): each loop reads n samples from `raw` and writes n
        // into `out` (n is both lengths' minimum, n ≥ 1), and reads its
        // coefficients from `self`. Every register written is an output or
        // a clobber; the APSR's flags are written (Q cleared first); no
        // stack is used.
        macro_rules! run {
            ($template:expr, $coefficients:expr) => {
                unsafe {
                    core::arch::asm!(
                        "msr APSR_nzcvq, {gyro}",
                        $template,
                        coefficients = inout(reg) $coefficients => _,
                        input = inout(reg) input => _,
                        end = in(reg) end,
                        output = inout(reg) output => _,
                        k = inout(reg) QDADD_K as u32 => apsr,
                        gyro = inout(reg) gyro,
                        size = const size_of::<RawSample>(),
                        out("r0") _, out("r1") _, out("r2") _, out("r3") _, out("r4") _,
                        out("r5") _, out("s0") _, out("s1") _, out("s2") _, out("s3") _,
                        out("s4") _, out("s5") _, out("s6") _, out("s7") _, out("s8") _,
                        out("s9") _, out("s10") _, out("s11") _, out("s12") _, out("s13") _,
                        out("s14") _, out("s15") _, out("s16") _, out("s17") _, out("s18") _,
                        out("s19") _, out("s20") _, out("s21") _, out("s22") _, out("s23") _,
                        out("s24") _, out("s25") _, out("s26") _, out("s27") _, out("s28") _,
                        out("s29") _,
                        options(nostack),
                    )
                }
            };
        }
        match self {
            FusedPass::WithoutG(plain) => run!(without_g!(), plain as *const Plain),
            FusedPass::WithG(crossed) => run!(with_g!(), crossed as *const Crossed),
        }
        ClipFlags {
            accel: (apsr >> 27) & 1 != 0,
            gyro: (gyro >> 15) & 1 != 0,
        }
    }
}
