//! `normalize`: maps a stream from a given range to [−1, 1] (MATLAB
//! `mapminmax` with fixed settings).

use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::{BoundArgs, PortBound};
use evflow_engine::typed_params::{Flag, Float};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `normalize`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "normalize",
    "filters",
    Role::Filter,
    "Maps a stream from [min, max] to [−1, 1] (mapminmax with given settings), optionally clamped.",
    build,
)
.doc(
    "y[n] = 2·(x[n] − min)/(max − min) − 1: MATLAB `mapminmax` with its settings given, so that \
     `min` maps to −1 and `max` to +1. Dissertation §5.2.2 normalizes each force sequence before it \
     enters an inverse model; record-and-playback (§6.5.2) plays a recording's force, normalized \
     the same way per recording, as the actuation. With `clamp` the output is held inside [−1, 1] \
     (an actuation range); without, values outside [min, max] map outside it. The range comes from \
     the recording (its extremes over the samples that count) and is written into the graph — a \
     stream cannot know its own extremes before it has ended. Runs at the rate of its input.\n\n\
     Checked: the ends map to ±1 exactly, the midpoint to 0, clamping, refusal of an empty range.",
)
.ports(PORTS)
.params(&[MIN.spec(), MAX.spec(), CLAMP.spec()])
.bound(output_bound)
.example("min = -0.08\nmax = 0.11\nclamp = true");

/// The ports: one signal in, the normalized signal out.
const PORTS: &[PortSpec] = &[PortSpec::input("in", "1", "signal"), PortSpec::output("out", "1", "normalized signal")];
/// The signal.
const IN: InPort = InPort::named(PORTS, "in");
/// The normalized signal.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// `min`: the input value that maps to −1.
const MIN: Float = Float::new("min", -1e12, 1e12, -1.0, "1", "input value that maps to −1").required();
/// `max`: the input value that maps to +1.
const MAX: Float = Float::new("max", -1e12, 1e12, 1.0, "1", "input value that maps to +1").required();
/// `clamp`: whether the output is held inside [−1, 1].
const CLAMP: Flag = Flag::new("clamp", true, "hold the output inside [−1, 1]");

struct Normalize {
    scale: f64,
    min: f64,
    clamp: bool,
}

/// The output bound the stability suite checks: with `clamp`, |out| ≤ 1.
fn output_bound(b: &BoundArgs<'_>) -> Option<PortBound> {
    b.flag(&CLAMP.spec()).then(|| ("out", 1.0, "clamped to [−1, 1]".into()))
}

fn build(p: &Params, _ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let (min, max) = (MIN.get(p), MAX.get(p));
    if max.partial_cmp(&min) != Some(std::cmp::Ordering::Greater) {
        return Err(NodeError::param(MAX.name(), format!("must be above min = {min} (got {max}): the range is empty")));
    }
    Ok(Box::new(Normalize { scale: 2.0 / (max - min), min, clamp: CLAMP.get(p) }))
}

impl Node for Normalize {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let (x, y) = io.io(IN, OUT);
        for (y, x) in y.iter_mut().zip(x) {
            let v = self.scale * (x - self.min) - 1.0;
            *y = if self.clamp { v.clamp(-1.0, 1.0) } else { v };
        }
        Ok(())
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;

    fn run(params: &str, x: &[f64]) -> Result<Vec<f64>, String> {
        Single::new(&SPEC, params)
            .input("in", x.to_vec(), 1000.0)
            .output("out")
            .ticks(x.len() as u64)
            .block(7)
            .run()
            .map(|mut o| o.remove(0))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn the_range_maps_to_plus_minus_one_and_clamps() {
        let y = run("min = -0.08\nmax = 0.12", &[-0.08, 0.12, 0.02, 0.5, -1.0]).unwrap();
        assert_eq!(y[0], -1.0);
        assert!((y[1] - 1.0).abs() < 1e-15);
        assert!(y[2].abs() < 1e-15);
        assert_eq!((y[3], y[4]), (1.0, -1.0));
        let y = run("min = 0.0\nmax = 2.0\nclamp = false", &[4.0, -2.0]).unwrap();
        assert_eq!(y, vec![3.0, -3.0]);
        assert!(run("min = 1.0\nmax = 1.0", &[0.0]).unwrap_err().contains("empty"));
    }
}
