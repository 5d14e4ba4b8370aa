//! `foaw`: velocity from sampled positions by first-order adaptive
//! windowing ([`estimator`]), and its comparison with finite differences
//! and a moving average ([`compare`]).

pub mod compare;
pub mod estimator;

use estimator::{Fit, Foaw};
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::typed_params::{Choice, Float, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `foaw`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "foaw",
    "filters",
    Role::Filter,
    "Velocity from sampled positions by first-order adaptive windowing (Janabi-Sharifi, Hayward & Chen 2000).",
    build,
)
.doc(
    "Estimates the finger's velocity from the positions an IR touch frame reports (40 Hz, quantized; \
dissertation §6.5.1 uses the velocity to pick the texture's grid cell). At each sample the window grows \
while a line through the newest position, with the window's slope, passes within `noise` of every \
position in it; the slope of the longest such window (at most `max_window` samples) is the estimate. \
`fit = \"best\"` takes the least-squares slope of the window, `fit = \"end\"` the slope through its two \
ends (Janabi-Sharifi, Hayward & Chen, IEEE Trans. Control Systems Technology 8(6), 2000). Steady motion \
gets a long window and little noise; a change of speed or a reversal shortens it, so the lag stays small. \
A resting finger gives exactly 0.\n\n\
**Ports.** `x` (m) at any rate, the node's rate; `velocity` (m/s) at the same rate. A non-finite \
position is skipped and the last estimate held.\n\n\
**Parameters.** `noise` (m): the bound d on the position error — half the quantization step plus the \
sensor's noise; `max_window` (samples); `fit`. The defaults (d = 0.4 mm, N = 4 = 100 ms at 40 Hz) suit an IR \
frame of 0.5 mm resolution at 40 Hz: they had the lowest RMS error over the comparison's trajectories \
among d = 0.25–1 mm and N = 4–16 (`docs/texture.md`); at other rates or resolutions scale them.\n\n\
Checked against exact slopes on noiseless ramps, a direct least-squares fit, velocity steps, and — on \
known trajectories sampled at 40 Hz and quantized to 0.5 mm — against finite differences (RMS error) \
and a moving average (lag); figures in `docs/texture.md` (`evflow report foaw`).",
)
.ports(PORTS)
.params(&[NOISE.spec(), MAX_WINDOW.spec(), FIT.spec()])
.example("noise = 0.0004\nmax_window = 4\nfit = \"best\"");

/// The ports: positions in, velocities out, at the same rate.
const PORTS: &[PortSpec] =
    &[PortSpec::input("x", "m", "position"), PortSpec::output("velocity", "m/s", "velocity estimate")];
/// The position.
const X: InPort = InPort::named(PORTS, "x");
/// The velocity estimate.
const VELOCITY: OutPort = OutPort::named(PORTS, "velocity");

/// `noise`: the bound d on the position error.
const NOISE: Float = Float::new("noise", 0.0, 1.0, 0.0004, "m", "bound d on the position error (quantization + noise)");
/// `max_window`: the longest window.
const MAX_WINDOW: Int = Int::new("max_window", 1, 1024, 4, "1", "longest window, samples");
/// `fit`: which slope a window gets.
const FIT: Choice<Fit> = Choice::new(
    "fit",
    &["best", "end"],
    &[Fit::Best, Fit::End],
    "best",
    "slope of a window: least squares or through its ends",
);

struct FoawNode {
    foaw: Foaw,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let window = MAX_WINDOW.count(p);
    Ok(Box::new(FoawNode { foaw: Foaw::new(FIT.get(p), NOISE.get(p), 1.0 / ctx.rate, window) }))
}

impl Node for FoawNode {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, v) = io.io(X, VELOCITY);
        for (v, &x) in v.iter_mut().zip(x) {
            *v = self.foaw.push(x);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.foaw.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    #[test]
    fn runs_at_the_rate_of_its_input() {
        // A 40 Hz ramp at 5 cm/s: the estimate is 0.05 m/s once two samples are in.
        let x: Vec<f64> = (0..40).map(|k| 0.05 * k as f64 / 40.0).collect();
        let out = Single::new(&SPEC, "noise = 1e-9").input("x", x, 40.0).output("velocity").ticks(1000).run().unwrap();
        assert_eq!(out[0].len(), 40);
        assert_eq!(out[0][0], 0.0);
        for v in &out[0][1..] {
            assert!((v - 0.05).abs() < 1e-12, "{v}");
        }
    }
}
