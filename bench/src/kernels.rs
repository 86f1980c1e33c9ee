//! The benchmark's variants: each corrects a batch of raw samples into RAM.
//! The full model is timed in three numeric forms (f32, fixed point, f64)
//! beside the simpler models it replaces (bias only, diagonal scale + bias),
//! a port of xioTechnologies Fusion's `FusionModelInertial` (the reference
//! harness of the benchmark issue), the temperature refold at two rates and
//! the whole per-sample pipeline.
//!
//! Every kernel is `#[inline(never)]` so that the firmware's ELF holds it as
//! one symbol (`cargo xtask bench` reads its size as the variant's flash).

use super::digest::Digest;
use super::pipeline::{EncodedFrame, PipelineBench};
use super::sensor_reads;
use super::{inputs, BATCH, BATCHES};
use triad::model::{
    BatchKernel, Calibration, CalibrationError, ClipFlags, Corrector, FixedCorrector, FixedSample,
    Orientation, Sample, Triad, TriadCalibration,
};
use triad::sensor::{ImuScale, RawSample};

/// One row of the benchmark.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// m = s·raw − b (f32): what a bias-only calibration costs.
    BiasOnlyF32,
    /// m_i = K_ii·raw_i + k_i (f32): diagonal scale and bias, no misalignment.
    DiagonalF32,
    /// Fusion's M·((u − b)⊙s), called once per triad (f32).
    FusionF32,
    /// The full folded model m = K·raw + k with clip flags (f32): the firmware's hot path.
    FullF32,
    /// The same, one out-of-line call per sample as the firmware's data-ready
    /// task makes it: the coefficients come from memory at every call.
    FullF32PerCall,
    /// The full folded model in integer-only fixed point.
    FullFixed,
    /// The firmware's batch path ([`BatchKernel::correct`]): FIFO batches of
    /// 8 raw samples straight to a batch frame's counts, with clip flags.
    BatchF32W8,
    /// The same with batches of 32.
    BatchF32W32,
    /// The full folded model in f64 (software floating point on both cores).
    FullF64,
    /// Temperature terms refolded (f64 inversion) before every sample, then f32.
    RefoldEverySample,
    /// Temperature terms refolded once per batch of 100 samples (10 Hz at 1 kHz), then f32.
    RefoldLowRate,
    /// The whole step: burst read through the driver from a bus that only
    /// hands back bytes, correction, averaging, framing, CRC and COBS.
    Pipeline,
    /// The driver's 14-byte burst read, one per sample (no correction).
    ReadBurst,
    /// FIFO drains of 1 packet (no correction).
    ReadFifo1,
    /// FIFO drains of 8 packets (no correction).
    ReadFifo8,
    /// FIFO drains of 32 packets (no correction).
    ReadFifo32,
    /// [`Variant::FullF32`] with the gyroscope's g-sensitivity G
    /// ([`inputs::with_g_sensitivity`]): the gyro's row reads the raw
    /// accelerometer sample too (a 3×6 map).
    FullF32G,
    /// [`Variant::FullFixed`] with G.
    FullFixedG,
    /// [`Variant::BatchF32W32`] with G.
    BatchF32W32G,
}

impl Variant {
    /// Every row, in the report's order.
    pub const ALL: [Variant; 19] = [
        Variant::BiasOnlyF32,
        Variant::DiagonalF32,
        Variant::FusionF32,
        Variant::FullF32,
        Variant::FullF32PerCall,
        Variant::FullFixed,
        Variant::BatchF32W8,
        Variant::BatchF32W32,
        Variant::FullF64,
        Variant::RefoldEverySample,
        Variant::RefoldLowRate,
        Variant::Pipeline,
        Variant::ReadBurst,
        Variant::ReadFifo1,
        Variant::ReadFifo8,
        Variant::ReadFifo32,
        Variant::FullF32G,
        Variant::FullFixedG,
        Variant::BatchF32W32G,
    ];

    /// For a row with the gyroscope's g-sensitivity, the same row without
    /// it (its kernel, run on [`inputs::with_g_sensitivity`]); `None` for
    /// the other rows.
    pub fn without_g_sensitivity(self) -> Option<Variant> {
        match self {
            Variant::FullF32G => Some(Variant::FullF32),
            Variant::FullFixedG => Some(Variant::FullFixed),
            Variant::BatchF32W32G => Some(Variant::BatchF32W32),
            _ => None,
        }
    }

    /// The FIFO watermark of a sensor-read row (1 for the burst read), `None`
    /// for the correction rows.
    pub fn read_watermark(self) -> Option<usize> {
        match self {
            Variant::ReadBurst | Variant::ReadFifo1 => Some(1),
            Variant::ReadFifo8 => Some(8),
            Variant::ReadFifo32 => Some(32),
            _ => None,
        }
    }

    /// The batch size W of a batch-kernel row, `None` for the other rows.
    pub fn batch_watermark(self) -> Option<usize> {
        match self.without_g_sensitivity().unwrap_or(self) {
            Variant::BatchF32W8 => Some(8),
            Variant::BatchF32W32 => Some(32),
            _ => None,
        }
    }

    /// The row's name in reports and in the firmware's output.
    pub fn name(self) -> &'static str {
        match self {
            Variant::BiasOnlyF32 => "bias_only_f32",
            Variant::DiagonalF32 => "diagonal_f32",
            Variant::FusionF32 => "fusion_f32",
            Variant::FullF32 => "full_f32",
            Variant::FullF32PerCall => "full_f32_per_call",
            Variant::FullFixed => "full_fixed",
            Variant::BatchF32W8 => "batch_f32_w8",
            Variant::BatchF32W32 => "batch_f32_w32",
            Variant::FullF64 => "full_f64",
            Variant::RefoldEverySample => "refold_every_sample",
            Variant::RefoldLowRate => "refold_low_rate",
            Variant::Pipeline => "pipeline",
            Variant::ReadBurst => "read_burst",
            Variant::ReadFifo1 => "read_fifo_1",
            Variant::ReadFifo8 => "read_fifo_8",
            Variant::ReadFifo32 => "read_fifo_32",
            Variant::FullF32G => "full_f32_g",
            Variant::FullFixedG => "full_fixed_g",
            Variant::BatchF32W32G => "batch_f32_w32_g",
        }
    }

    /// The kernel function's name (its symbol in the firmware ELF).
    pub fn kernel_symbol(self) -> &'static str {
        match self.without_g_sensitivity().unwrap_or(self) {
            Variant::Pipeline => "pipeline_batch",
            Variant::FullF32PerCall => "correct_one",
            Variant::ReadBurst => "read_burst",
            Variant::ReadFifo1 | Variant::ReadFifo8 | Variant::ReadFifo32 => "read_fifo",
            Variant::BatchF32W8 | Variant::BatchF32W32 => "batch_f32",
            v => v.name(),
        }
    }

    /// The variant named `name`.
    pub fn from_name(name: &str) -> Option<Variant> {
        Variant::ALL.into_iter().find(|v| v.name() == name)
    }
}

/// What the timer of a run sees: called right before and right after each
/// batch's kernel (the firmware reads SysTick and paints the stack there;
/// the host does nothing).
pub trait Meter {
    /// The kernel is about to run.
    fn start(&mut self);
    /// The kernel has returned.
    fn stop(&mut self);
}

/// A meter that measures nothing (the host's check of the outputs).
pub struct NoMeter;

impl Meter for NoMeter {
    fn start(&mut self) {}
    fn stop(&mut self) {}
}

/// Per triad m = s·raw·g + o, with a per-axis gain g and offset o in f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisGains {
    gain: [[f32; 3]; 2],
    offset: [[f32; 3]; 2],
}

impl AxisGains {
    /// m = s·raw − b: the calibration's bias only.
    pub fn bias_only(cal: &Calibration, scale: &ImuScale) -> AxisGains {
        AxisGains::per_axis(cal, scale, |_, _| 1.0)
    }

    /// m_i = (s·raw_i − b_i)/(1+Σ)_ii: the diagonal of (I+Σ) and the bias.
    pub fn diagonal(cal: &Calibration, scale: &ImuScale) -> AxisGains {
        AxisGains::per_axis(cal, scale, |t, i| t.scale_misalignment[i][i])
    }

    fn per_axis(
        cal: &Calibration,
        scale: &ImuScale,
        divisor: impl Fn(&TriadCalibration, usize) -> f64,
    ) -> AxisGains {
        let mut k = AxisGains {
            gain: [[0.0; 3]; 2],
            offset: [[0.0; 3]; 2],
        };
        for (t, (triad, s)) in [(&cal.accel, scale.accel), (&cal.gyro, scale.gyro)]
            .into_iter()
            .enumerate()
        {
            for i in 0..3 {
                let d = divisor(triad, i);
                k.gain[t][i] = (s.si_per_lsb / d) as f32;
                k.offset[t][i] = (-triad.bias[i] / d) as f32;
            }
        }
        k
    }
}

/// Fusion's inertial model for one triad: M·((u − b)⊙s), u and b in LSB.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FusionTriad {
    misalignment: [[f32; 3]; 3],
    sensitivity: [f32; 3],
    offset: [f32; 3],
}

impl FusionTriad {
    /// Both triads with M = (I+Σ)⁻¹, s the chip's sensitivity and b in LSB;
    /// `None` if an (I+Σ) is singular.
    pub fn pair(cal: &Calibration, scale: &ImuScale) -> Option<[FusionTriad; 2]> {
        let one = |triad: &TriadCalibration, s: f64| {
            let m = triad::model::matrix::inverse(&triad.scale_misalignment)?;
            let r = |row: &[f64; 3]| [row[0] as f32, row[1] as f32, row[2] as f32];
            Some(FusionTriad {
                misalignment: [r(&m[0]), r(&m[1]), r(&m[2])],
                sensitivity: [s as f32; 3],
                // Fusion subtracts the offset in LSB before scaling.
                offset: triad.bias.map(|b| (b / s) as f32),
            })
        };
        Some([
            one(&cal.accel, scale.accel.si_per_lsb)?,
            one(&cal.gyro, scale.gyro.si_per_lsb)?,
        ])
    }
}

/// The benchmark of one calibration at the chip scale of [`inputs::scale`].
/// Each variant builds what it needs when it runs (outside the timed
/// region), in its own stack frame: the Cortex-M0 core has 16 KiB of RAM.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bench {
    cal: Calibration,
}

impl Bench {
    /// The benchmark of the realistic calibration ([`inputs::realistic`]).
    pub fn realistic() -> Bench {
        Bench::new(&inputs::realistic())
    }

    /// The benchmark of `cal`. Its temperature terms are not used: the
    /// refold rows use [`inputs::with_temperature_terms`].
    pub fn new(cal: &Calibration) -> Bench {
        Bench { cal: *cal }
    }

    /// The full model's corrector of this calibration.
    pub fn corrector(&self) -> Result<Corrector, CalibrationError> {
        Corrector::new(&self.cal, &inputs::scale(), Orientation::RotationNone)
    }

    /// The corrector with temperature terms that the refold rows use, as
    /// folded before the first batch.
    pub fn temperature_corrector() -> Result<Corrector, CalibrationError> {
        Corrector::new(
            &inputs::with_temperature_terms(),
            &inputs::scale(),
            Orientation::RotationNone,
        )
    }

    /// Runs `variant` over all batches, metering each kernel call; returns
    /// the digest of every output.
    pub fn run(
        &self,
        variant: Variant,
        meter: &mut impl Meter,
    ) -> Result<Digest, CalibrationError> {
        let mut digest = Digest::new();
        self.each_output(variant, meter, |out| out.feed(&mut digest))?;
        Ok(digest)
    }

    /// Runs `variant` over all batches and hands each output to `sink`, in order.
    pub fn each_output(
        &self,
        variant: Variant,
        meter: &mut impl Meter,
        mut sink: impl FnMut(Output<'_>),
    ) -> Result<(), CalibrationError> {
        let sink: &mut dyn FnMut(Output<'_>) = &mut sink;
        match variant {
            Variant::FullF32G | Variant::FullFixedG | Variant::BatchF32W32G => {
                let base = variant.without_g_sensitivity().unwrap_or(variant);
                Bench::new(&inputs::with_g_sensitivity()).each_output(base, meter, sink)
            }
            Variant::BiasOnlyF32 | Variant::DiagonalF32 | Variant::FusionF32 => {
                self.run_simple(variant, meter, sink)
            }
            Variant::FullF32 | Variant::FullF32PerCall | Variant::FullF64 | Variant::FullFixed => {
                self.run_full(variant, meter, sink)
            }
            Variant::BatchF32W8 | Variant::BatchF32W32 => {
                self.run_batch(variant.batch_watermark().unwrap_or(1), meter, sink)
            }
            Variant::RefoldEverySample | Variant::RefoldLowRate => run_refold(variant, meter, sink),
            Variant::Pipeline => self.run_pipeline(meter, sink),
            Variant::ReadBurst | Variant::ReadFifo1 | Variant::ReadFifo8 | Variant::ReadFifo32 => {
                run_reads(variant, meter, sink);
                Ok(())
            }
        }
    }

    #[inline(never)]
    fn run_simple(
        &self,
        variant: Variant,
        meter: &mut impl Meter,
        sink: &mut dyn FnMut(Output<'_>),
    ) -> Result<(), CalibrationError> {
        let scale = inputs::scale();
        let wrap = |o: &[[f32; 3]; 2], sink: &mut dyn FnMut(Output<'_>)| sink(Output::Triads(o));
        match variant {
            Variant::BiasOnlyF32 => {
                let k = AxisGains::bias_only(&self.cal, &scale);
                batches(meter, sink, wrap, |i, o| bias_only_f32(&k, i, o))
            }
            Variant::DiagonalF32 => {
                let k = AxisGains::diagonal(&self.cal, &scale);
                batches(meter, sink, wrap, |i, o| diagonal_f32(&k, i, o))
            }
            _ => {
                // Validation first: it names what is wrong with a bad matrix,
                // and after it every (I+Σ) is invertible.
                self.corrector()?;
                let k = FusionTriad::pair(&self.cal, &scale).ok_or(CalibrationError::Singular {
                    triad: Triad::Accel,
                    determinant: 0.0,
                    temperature_c: None,
                })?;
                batches(meter, sink, wrap, |i, o| fusion_f32(&k, i, o))
            }
        }
        Ok(())
    }

    #[inline(never)]
    fn run_full(
        &self,
        variant: Variant,
        meter: &mut impl Meter,
        sink: &mut dyn FnMut(Output<'_>),
    ) -> Result<(), CalibrationError> {
        let c = self.corrector()?;
        match variant {
            Variant::FullF32 => batches(
                meter,
                sink,
                |o, sink| sink(Output::Sample(o)),
                |i, o| full_f32(&c, i, o),
            ),
            Variant::FullF32PerCall => batches(
                meter,
                sink,
                |o, sink| sink(Output::Sample(o)),
                |i, o| full_f32_per_call(&c, i, o),
            ),
            Variant::FullF64 => batches(
                meter,
                sink,
                |o, sink| sink(Output::F64(o)),
                |i, o| full_f64(&c, i, o),
            ),
            _ => {
                let fixed = FixedCorrector::new(&c)?;
                batches(
                    meter,
                    sink,
                    |o, sink| sink(Output::Fixed(o)),
                    |i, o| full_fixed(&fixed, i, o),
                )
            }
        }
        Ok(())
    }

    /// The batch kernel over each batch in FIFO batches of `w` samples (the
    /// last one shorter when `w` does not divide [`BATCH`]); each sample's
    /// output carries the clip flags of its FIFO batch.
    #[inline(never)]
    fn run_batch(
        &self,
        w: usize,
        meter: &mut impl Meter,
        sink: &mut dyn FnMut(Output<'_>),
    ) -> Result<(), CalibrationError> {
        let kernel = BatchKernel::new(&self.corrector()?);
        let lsb = [kernel.accel_lsb(), kernel.gyro_lsb()];
        let mut input = [RawSample::default(); BATCH];
        let mut out = BatchOutput::default();
        for batch in 0..BATCHES {
            inputs::raw_batch(batch, &mut input);
            meter.start();
            batch_f32(&kernel, w, &input, &mut out);
            meter.stop();
            for (n, &counts) in out.counts.iter().enumerate() {
                sink(Output::Counts(&CountsSample {
                    counts,
                    lsb,
                    clip: out.clip[n / w],
                }));
            }
        }
        Ok(())
    }

    #[inline(never)]
    fn run_pipeline(
        &self,
        meter: &mut impl Meter,
        sink: &mut dyn FnMut(Output<'_>),
    ) -> Result<(), CalibrationError> {
        let mut p = PipelineBench::new(self.corrector()?);
        batches(
            meter,
            sink,
            |o, sink| sink(Output::Frame(o)),
            |i, o| pipeline_batch(&mut p, i, o),
        );
        Ok(())
    }
}

#[inline(never)]
fn run_reads(variant: Variant, meter: &mut impl Meter, sink: &mut dyn FnMut(Output<'_>)) {
    let watermark = variant.read_watermark().unwrap_or(1);
    let mut imu = sensor_reads::canned_imu(watermark);
    // One array for the batch and what is read back (the canned bus holds
    // the batch's bytes once loaded): with 32-bit counts two arrays of
    // BATCH samples do not fit beside the canned bus in the Cortex-M0's 16 KiB.
    let mut samples = [RawSample::default(); BATCH];
    for batch in 0..BATCHES {
        inputs::raw_batch(batch, &mut samples);
        // Untimed: the canned bus takes the batch before the meter starts.
        imu.bus_mut().load(&samples);
        meter.start();
        if variant == Variant::ReadBurst {
            sensor_reads::read_burst(&mut imu, &mut samples);
        } else {
            sensor_reads::read_fifo(&mut imu, &mut samples);
        }
        meter.stop();
        samples.iter().for_each(|o| sink(Output::Raw(o)));
    }
}

/// Bus bytes (address and data) per sample of a sensor-read row, counted by
/// the canned bus over all batches; `None` for the correction rows.
pub fn bus_bytes_per_sample(variant: Variant) -> Option<f64> {
    let watermark = variant.read_watermark()?;
    let mut imu = sensor_reads::canned_imu(watermark);
    let mut input = [RawSample::default(); BATCH];
    let mut out = [RawSample::default(); BATCH];
    for batch in 0..BATCHES {
        inputs::raw_batch(batch, &mut input);
        imu.bus_mut().load(&input);
        if variant == Variant::ReadBurst {
            sensor_reads::read_burst(&mut imu, &mut out);
        } else {
            sensor_reads::read_fifo(&mut imu, &mut out);
        }
    }
    Some(imu.bus_mut().bytes as f64 / (BATCH * BATCHES) as f64)
}

#[inline(never)]
fn run_refold(
    variant: Variant,
    meter: &mut impl Meter,
    sink: &mut dyn FnMut(Output<'_>),
) -> Result<(), CalibrationError> {
    let mut c = Bench::temperature_corrector()?;
    let wrap = |o: &Sample, sink: &mut dyn FnMut(Output<'_>)| sink(Output::Sample(o));
    if variant == Variant::RefoldEverySample {
        batches(meter, sink, wrap, |i, o| refold_every_sample(&mut c, i, o));
    } else {
        batches(meter, sink, wrap, |i, o| refold_low_rate(&mut c, i, o));
    }
    Ok(())
}

/// Every batch through `kernel`, metered, each output to `sink` through
/// `wrap`. Not inlined, so that each output type's buffer lives in its own
/// stack frame (the Cortex-M0 core has 16 KiB of RAM).
#[inline(never)]
fn batches<T: Copy + Default>(
    meter: &mut impl Meter,
    sink: &mut dyn FnMut(Output<'_>),
    wrap: impl Fn(&T, &mut dyn FnMut(Output<'_>)),
    mut kernel: impl FnMut(&[RawSample; BATCH], &mut [T; BATCH]),
) {
    let mut input = [RawSample::default(); BATCH];
    let mut out = [T::default(); BATCH];
    for batch in 0..BATCHES {
        inputs::raw_batch(batch, &mut input);
        meter.start();
        kernel(&input, &mut out);
        meter.stop();
        out.iter().for_each(|o| wrap(o, sink));
    }
}

/// A batch-kernel row's outputs for one batch: the counts, and the clip
/// flags of each FIFO batch (entry i for the i-th FIFO batch).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchOutput {
    /// Accelerometer x y z then gyroscope x y z counts per sample.
    pub counts: [[i16; 6]; BATCH],
    /// Clip flags per FIFO batch.
    pub clip: [ClipFlags; BATCH],
}

impl Default for BatchOutput {
    fn default() -> Self {
        BatchOutput {
            counts: [[0; 6]; BATCH],
            clip: [ClipFlags::default(); BATCH],
        }
    }
}

/// One sample of a batch-kernel row as the sink sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CountsSample {
    /// Accelerometer x y z then gyroscope x y z counts.
    pub counts: [i16; 6],
    /// The counts' LSBs, accelerometer then gyroscope (SI units).
    pub lsb: [f32; 2],
    /// The clip flags of the sample's FIFO batch.
    pub clip: ClipFlags,
}

/// The f64 variant's output: both triads and the clip flags.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct F64Sample {
    /// Accelerometer then gyroscope, SI units.
    pub triads: [[f64; 3]; 2],
    /// Clipped triads.
    pub clip: ClipFlags,
}

/// One output of a variant, as the sink of [`Bench::each_output`] sees it.
#[derive(Clone, Copy, Debug)]
pub enum Output<'a> {
    /// Accelerometer then gyroscope in f32 SI units (the simple models).
    Triads(&'a [[f32; 3]; 2]),
    /// The f32 hot path's sample.
    Sample(&'a Sample),
    /// The fixed-point sample.
    Fixed(&'a FixedSample),
    /// A batch frame's counts.
    Counts(&'a CountsSample),
    /// The f64 sample.
    F64(&'a F64Sample),
    /// An encoded frame.
    Frame(&'a EncodedFrame),
    /// A raw sample as the driver read it.
    Raw(&'a RawSample),
}

impl Output<'_> {
    /// Feeds the output's bits to `digest`.
    pub fn feed(&self, digest: &mut Digest) {
        let clip = |c: &ClipFlags| u32::from(c.accel) | u32::from(c.gyro) << 1;
        match self {
            Output::Triads(t) => t.iter().flatten().for_each(|&x| digest.f32(x)),
            Output::Sample(s) => {
                s.accel.iter().chain(&s.gyro).for_each(|&x| digest.f32(x));
                digest.f32(s.temperature);
                digest.word(clip(&s.clip));
            }
            Output::Fixed(s) => {
                s.accel
                    .iter()
                    .chain(&s.gyro)
                    .for_each(|&x| digest.word(x as u32));
                digest.word(s.temperature as u32);
                digest.word(clip(&s.clip));
            }
            Output::Counts(s) => {
                s.counts
                    .iter()
                    .for_each(|&c| digest.word(u32::from(c as u16)));
                digest.word(clip(&s.clip));
            }
            Output::F64(s) => {
                s.triads.iter().flatten().for_each(|&x| digest.f64(x));
                digest.word(clip(&s.clip));
            }
            // The low 16 bits of each count: a 16-bit chip's code, as before counts were i32.
            Output::Raw(r) => r
                .accel
                .iter()
                .chain(&r.gyro)
                .copied()
                .chain([i32::from(r.temperature)])
                .for_each(|x| digest.word(x as u16 as u32)),
            Output::Frame(bytes) => bytes.0.iter().for_each(|&b| digest.word(u32::from(b))),
        }
    }
}

fn to_f32(v: &[i32; 3]) -> [f32; 3] {
    triad::model::corrector::counts_f32(v)
}

/// m = s·raw·g + o per axis.
#[inline(never)]
pub fn bias_only_f32(k: &AxisGains, input: &[RawSample; BATCH], out: &mut [[[f32; 3]; 2]; BATCH]) {
    axis_gains(k, input, out)
}

/// m_i = K_ii·raw_i + k_i.
#[inline(never)]
pub fn diagonal_f32(k: &AxisGains, input: &[RawSample; BATCH], out: &mut [[[f32; 3]; 2]; BATCH]) {
    axis_gains(k, input, out)
}

#[inline(always)]
fn axis_gains(k: &AxisGains, input: &[RawSample; BATCH], out: &mut [[[f32; 3]; 2]; BATCH]) {
    for (o, raw) in out.iter_mut().zip(input) {
        for (t, v) in [&raw.accel, &raw.gyro].into_iter().enumerate() {
            let x = to_f32(v);
            for i in 0..3 {
                o[t][i] = x[i] * k.gain[t][i] + k.offset[t][i];
            }
        }
    }
}

/// Fusion's `FusionModelInertial(u, M, s, b)` = M·((u − b)⊙s), once per triad.
#[inline(never)]
pub fn fusion_f32(
    k: &[FusionTriad; 2],
    input: &[RawSample; BATCH],
    out: &mut [[[f32; 3]; 2]; BATCH],
) {
    for (o, raw) in out.iter_mut().zip(input) {
        for (t, v) in [&raw.accel, &raw.gyro].into_iter().enumerate() {
            let f = &k[t];
            let x = to_f32(v);
            let u = [
                (x[0] - f.offset[0]) * f.sensitivity[0],
                (x[1] - f.offset[1]) * f.sensitivity[1],
                (x[2] - f.offset[2]) * f.sensitivity[2],
            ];
            for (out, m) in o[t].iter_mut().zip(&f.misalignment) {
                *out = m[0] * u[0] + m[1] * u[1] + m[2] * u[2];
            }
        }
    }
}

/// The firmware's hot path: [`Corrector::correct`].
#[inline(never)]
pub fn full_f32(c: &Corrector, input: &[RawSample; BATCH], out: &mut [Sample; BATCH]) {
    c.correct_batch(input, out);
}

/// [`Corrector::correct`] called out of line per sample.
#[inline(never)]
pub fn full_f32_per_call(c: &Corrector, input: &[RawSample; BATCH], out: &mut [Sample; BATCH]) {
    for (o, raw) in out.iter_mut().zip(input) {
        *o = correct_one(c, raw);
    }
}

/// One sample, never inlined: what the data-ready task pays per call.
#[inline(never)]
fn correct_one(c: &Corrector, raw: &RawSample) -> Sample {
    c.correct(raw)
}

/// [`FixedCorrector::correct_batch`]: [`FixedCorrector::correct`] of each sample.
#[inline(never)]
pub fn full_fixed(c: &FixedCorrector, input: &[RawSample; BATCH], out: &mut [FixedSample; BATCH]) {
    c.correct_batch(input, out);
}

/// [`BatchKernel::correct`] over FIFO batches of `w` samples, as the
/// firmware's data-ready task calls it once per FIFO watermark.
#[inline(never)]
pub fn batch_f32(k: &BatchKernel, w: usize, input: &[RawSample; BATCH], out: &mut BatchOutput) {
    let fifo_batches = input.chunks(w).zip(out.counts.chunks_mut(w));
    for ((raw, counts), clip) in fifo_batches.zip(out.clip.iter_mut()) {
        *clip = k.correct(raw, counts);
    }
}

/// K·raw + k in f64 with the folded f64 coefficients.
#[inline(never)]
pub fn full_f64(c: &Corrector, input: &[RawSample; BATCH], out: &mut [F64Sample; BATCH]) {
    let folded = [c.folded(Triad::Accel), c.folded(Triad::Gyro)];
    for (o, raw) in out.iter_mut().zip(input) {
        for (t, v) in [&raw.accel, &raw.gyro].into_iter().enumerate() {
            let x = [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])];
            o.triads[t] = folded[t].apply(&x);
        }
        o.clip = ClipFlags::of(raw, c.scale());
    }
}

/// Refold at each sample's temperature, then the f32 hot path.
#[inline(never)]
pub fn refold_every_sample(
    c: &mut Corrector,
    input: &[RawSample; BATCH],
    out: &mut [Sample; BATCH],
) {
    for (o, raw) in out.iter_mut().zip(input) {
        let _ = c.refold(c.scale().temperature_c(raw.temperature));
        *o = c.correct(raw);
    }
}

/// Refold once at the batch's first temperature, then the f32 hot path.
#[inline(never)]
pub fn refold_low_rate(c: &mut Corrector, input: &[RawSample; BATCH], out: &mut [Sample; BATCH]) {
    let _ = c.refold(c.scale().temperature_c(input[0].temperature));
    for (o, raw) in out.iter_mut().zip(input) {
        *o = c.correct(raw);
    }
}

/// The whole per-sample step, see [`PipelineBench::step`].
#[inline(never)]
pub fn pipeline_batch(
    p: &mut PipelineBench,
    input: &[RawSample; BATCH],
    out: &mut [EncodedFrame; BATCH],
) {
    for (o, raw) in out.iter_mut().zip(input) {
        p.step(raw, o);
    }
}
