//! `decimate`: a stream lowered by an integer factor, with a linear-phase
//! anti-aliasing filter built in.

use super::decimator::{design, DecimateError, Decimator};
use evflow_engine::ports::{InPort, OutPort, SAME_AS_INPUT};
use evflow_engine::typed_params::Float;
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, RateSpec, Role};

/// Declaration of `decimate`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "decimate",
    "rate",
    Role::Filter,
    "Integer step down of a stream's rate, with a linear-phase FIR anti-aliasing filter built in.",
    build,
)
.doc(
    "Lowers a stream's rate by the integer factor M = (input rate) / `rate`: a linear-phase FIR \
low-pass at the input rate, of which every M-th output is kept (output sample l is the filter's \
output at input sample Ml, which falls at the same time). The filter is designed when the node is \
built by the Kaiser window method: passband up to `passband` × the new Nyquist frequency \
f_N = `rate`/2, stopband from f_N up, `attenuation` dB down, so anything that would alias onto \
the output's band is attenuated by at least that much. Its order is Kaiser's estimate rounded up \
to a multiple of 2M, lengthened until the response measured on a grid 32× finer than the filter \
meets both figures (`nodes/src/rate/decimator.rs`).\n\n\
With the defaults (`passband` = 0.8, `attenuation` = 100 dB): passband ripple ≤ 10⁻⁵ \
(8.7·10⁻⁵ dB) up to 0.8·f_N, ≥ 100 dB from f_N up, DC gain 1 (taps summing to 1); 10 kHz → \
1 kHz (M = 10, a 10 kHz force sensor to the 1 kHz model-building clock: pass to 400 Hz, stop \
from 500 Hz) takes 661 taps and delays every frequency by 330 input samples = 33 output samples \
= 33 ms; 1 kHz → 250 Hz (M = 4) takes 265 taps, a delay of 132 input = 33 output samples = \
132 ms. The \
group delay N/2 is always a whole number N/(2M) of output samples, so a `delay` node of that \
many samples aligns another stream with it exactly; at the defaults it is 33 output samples \
whatever the factor. Lower `passband` or `attenuation` for less delay (passband 0.5: 16 output \
samples; 60 dB: 19); the cost is N + 1 multiply-adds per output sample.\n\n\
Why an FIR and not a Butterworth: a Butterworth low-pass with its −3 dB point at 0.8·f_N reaches \
only about 16 dB at f_N at order 8 (`|H|² = 1/(1 + (f_N/f_c)^16)`, f_N/f_c ≈ 1.25) and would need \
order 51 for 100 dB; \
its delay varies across the passband, which changes the shape of texture waveforms that E_s \
compares. The FIR's delay is the same at every frequency.\n\n\
Factor 1 is the identity (one tap, no delay). Non-finite input samples stop the run with an \
error naming the sample, as `butterworth` does (a NaN would spoil N outputs); inputs are scaled \
by 2⁻¹⁰ inside (exact), so no sum of finite inputs overflows, and outputs beyond the f64 range \
are clamped to ±f64::MAX. Checked against: the convolution definition, the Kaiser formulas of \
Oppenheim & Schafer Ex. 7.8, steady-state tones below the new Nyquist frequency (gain within the \
stated ripple, phase = the stated delay) and above it (attenuated by the stated figure), DC gain \
1, linearity, blocks of 1, 7 and 64 samples ≡ the whole signal bit for bit, extreme inputs \
(±1e300, ±f64::MAX).\n\n\
**Ports.** `in` at any rate that is an integer multiple of `rate`; `out` at `rate`.",
)
.ports(PORTS)
.params(&[RATE.spec(), PASSBAND.spec(), ATTENUATION.spec()])
.rate_param(RATE.name())
.example("rate = 250.0");

/// The ports: the stream at M × `rate` in, at `rate` out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("in", "1", "the stream, at M × `rate`").at(RateSpec::Any),
    PortSpec::output("out", SAME_AS_INPUT, "the stream low-passed and decimated to `rate`"),
];
/// The stream.
const IN: InPort = InPort::named(PORTS, "in");
/// The stream decimated.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `rate`: the output rate (the node's rate).
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "output rate; the input's rate divided by an integer");
/// `passband`: the passband edge.
const PASSBAND: Float =
    Float::new("passband", 0.05, 0.95, 0.8, "1", "passband edge as a fraction of the new Nyquist frequency");
/// `attenuation`: the stopband attenuation.
const ATTENUATION: Float =
    Float::new("attenuation", 20.0, 200.0, 100.0, "dB", "stopband attenuation from the new Nyquist frequency up");

struct Decimate {
    dec: Decimator,
    received: u64,
}

/// The integer factor input/output, or an error saying which rate to choose.
fn factor(input: f64, output: f64) -> Result<usize, NodeError> {
    let q = input / output;
    if q < 1.0 - 1e-9 {
        return Err(NodeError::param(
            RATE.name(),
            format!(
                "{output} Hz is above the input's {input} Hz, and `decimate` only lowers a rate; use `hold` \
                 (a control stream) or `resample` to raise it"
            ),
        ));
    }
    let m = q.round();
    if (q - m).abs() > 1e-9 * q || m > usize::MAX as f64 {
        let (lo, hi) = (q.floor().max(1.0), q.ceil());
        return Err(NodeError::param(
            RATE.name(),
            format!(
                "the input's {input} Hz is {q:.6} × {output} Hz, not an integer multiple; choose `rate` = {} or {} Hz \
                 (factors {hi} and {lo}), or use `resample` for this ratio",
                input / hi,
                input / lo
            ),
        ));
    }
    Ok(m as usize)
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let m = factor(ctx.input_rate(IN), ctx.rate)?;
    let d = design(m, PASSBAND.get(p), ATTENUATION.get(p)).map_err(|e| match e {
        DecimateError::Passband(_) => NodeError::param(PASSBAND.name(), e.to_string()),
        DecimateError::Attenuation(_) => NodeError::param(ATTENUATION.name(), e.to_string()),
        DecimateError::Factor(_) | DecimateError::TooLong { .. } => NodeError::param(RATE.name(), e.to_string()),
    })?;
    Ok(Box::new(Decimate { dec: Decimator::new(&d), received: 0 }))
}

impl Node for Decimate {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(IN, OUT);
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(NodeError::Data(format!(
                "input sample {} is {}; the anti-aliasing filter would carry it into the next outputs, so \
                 repair or remove it upstream",
                self.received + i as u64,
                x[i]
            )));
        }
        let mut o = 0;
        for &v in x {
            if let Some(out) = self.dec.push(v) {
                if let Some(slot) = y.get_mut(o) {
                    *slot = out;
                }
                o += 1;
            }
        }
        self.received += x.len() as u64;
        if o != y.len() {
            return Err(NodeError::Other(format!(
                "{o} output samples from {} input samples where the engine expects {}",
                x.len(),
                y.len()
            )));
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.dec.reset();
        self.received = 0;
    }
}

#[cfg(test)]
#[path = "decimate_tests.rs"]
mod tests;
