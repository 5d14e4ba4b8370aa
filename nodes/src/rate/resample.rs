//! `resample`: a stream at any rate brought to another by rubato's
//! asynchronous resampler, streaming, with a fixed latency.

use super::resampler::{Quality, ResampleError, Stream, QUALITY_NAMES};
use evflow_engine::ports::{InPort, OutPort, SAME_AS_INPUT};
use evflow_engine::typed_params::{Choice, Float};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, RateSpec, Role};

/// Declaration of `resample`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "resample",
    "rate",
    Role::Filter,
    "Any ratio of rates (rubato's asynchronous resampler), interpolating, with a fixed stated latency.",
    build,
)
.doc(
    "Brings a stream to `rate` by rubato 5's asynchronous resampler (`Async`, any real ratio \
r = `rate`/input rate), so the samples between input samples are interpolated rather than \
held: a 40 Hz IR frame to the 1 kHz clock as a smooth path, a 44.1 kHz audio-interface \
recording or a 10 kHz force to 1 kHz. Both rates must be integer multiples or divisors of the \
base rate (44.1 kHz and 1 kHz together need a base of 100 Hz, say).\n\n\
`quality`: `fast` — rubato's cubic polynomial (4 points), no anti-alias filter (for raising \
the rate of smooth streams, or lowering that of streams already band-limited below the new \
Nyquist frequency); `balanced` — a 128-tap sinc (Blackman–Harris², cubic interpolation between \
256 phases) cut off at 0.895 of the lower Nyquist frequency; `best` — a 256-tap sinc cut off \
at 0.947. Lowering a rate, the sinc is lengthened to 128/r resp. 256/r taps with its cut-off \
scaled by r, so the anti-aliasing relative to the new Nyquist frequency is the same at any \
ratio (more than 65 536 input samples per output, or more than 262 144 taps, is refused: \
`decimate` first).\n\n\
**Latency.** Output sample l is the input signal at time l/`rate` − D, with the fixed latency \
D = (P − 1)/`rate` + a/f_in, where a is the interpolator's lag (2 input samples for `fast`, \
L/2 − 1/O for a sinc of L taps and O phases) and P = ⌈b·r + 1.5⌉ output samples the wait for \
the inputs it reads ahead (b = 2 for `fast`, 1 for a sinc); the first P outputs are 0 \
(`nodes/src/rate/resampler.rs` derives it). For example: 40 Hz → 1 kHz: 101 ms (`fast`), \
1.626 s (`balanced`), 3.226 s (`best`) — a long sinc at 40 Hz reads far ahead, so live \
control streams want `fast` or `hold`; 44.1 kHz → 1 kHz: 65.0 ms (`balanced`), 129.1 ms \
(`best`); 10 kHz → 1 kHz: 65.0 ms (`balanced`).\n\n\
Every block size gives the same samples (rubato is driven one output frame at a time from an \
input FIFO sized in `prepare`; nothing is allocated while processing). Non-finite input \
samples stop the run with an error naming the sample, as `butterworth` and `decimate` do; \
inputs are scaled by 2⁻¹⁰ inside (exact), so no weighted sum of finite inputs overflows, and \
outputs beyond the f64 range are clamped to ±f64::MAX. Checked against: the stated latency (the \
centre of a smooth bump and of a step's rise come out at the stated time to 1e-6 output samples; \
a step through `fast` lowering a rate, to half a sample), \
tones from 44.1 kHz to 1 kHz against the analytic sine at t − D (largest error: `fast` 2e-7 for a \
pure tone up to 400 Hz, `balanced` 8e-11 up to 300 Hz and 6e-6 at 400 Hz, `best` 8e-11 up to \
400 Hz), tones above the new Nyquist frequency (520 Hz left at 3e-9, 600 Hz at 6e-12 by the \
sincs; folded onto the band nearly whole by `fast`), a 40 Hz ramp to 1 kHz (the ramp to 2e-14 \
with `fast`, 1.1e-6 with `balanced`; every 1 ms step moves on), linearity, blocks of 1, 7 and 64 \
≡ the whole signal bit for bit, ±1e300 and ±f64::MAX inputs. The qualities are rows of \
`evflow report resample`.\n\n\
**Ports.** `in` at any rate; `out` at `rate`.",
)
.ports(PORTS)
.params(&[RATE.spec(), QUALITY.spec()])
.rate_param(RATE.name())
.example("rate = 2000.0\nquality = \"balanced\"");

/// The ports: the stream at any rate in, resampled to `rate` out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("in", "1", "the stream").at(RateSpec::Any),
    PortSpec::output("out", SAME_AS_INPUT, "the stream resampled to `rate`, late by the stated latency"),
];
/// The stream.
const IN: InPort = InPort::named(PORTS, "in");
/// The stream resampled.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `rate`: the output rate (the node's rate).
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "output rate");

/// `quality`: the interpolator, arriving as a [`Quality`].
const QUALITY: Choice<Quality> = Choice::new(
    "quality",
    QUALITY_NAMES,
    &Quality::ALL,
    "balanced",
    "interpolator: fast (cubic), balanced (sinc of 128 taps) or best (256 taps)",
);

struct Resample {
    stream: Stream,
    received: u64,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let quality = QUALITY.get(p);
    let ratio = ctx.rate / ctx.input_rate(IN);
    let stream = Stream::new(ratio, quality).map_err(|e| match e {
        ResampleError::StepTooLarge { .. } | ResampleError::Ratio(_) => NodeError::param(RATE.name(), e.to_string()),
        _ => NodeError::Other(e.to_string()),
    })?;
    Ok(Box::new(Resample { stream, received: 0 }))
}

impl Node for Resample {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        self.stream.prepare(ctx.max_block);
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(IN, OUT);
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(NodeError::Data(format!(
                "input sample {} is {}; the resampler's filter would carry it into the next outputs, so \
                 repair or remove it upstream",
                self.received + i as u64,
                x[i]
            )));
        }
        self.received += x.len() as u64;
        self.stream.push(x).map_err(|e| NodeError::Other(e.to_string()))?;
        for out in y.iter_mut() {
            *out = self.stream.pull().map_err(|e| NodeError::Other(e.to_string()))?;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.stream.reset();
        self.received = 0;
    }
}

#[cfg(test)]
#[path = "resample_tests.rs"]
mod tests;
