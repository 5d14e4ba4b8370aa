//! `mesh.path`: a scripted finger — straight scan lines over a scene in
//! given directions at a given speed — for end-to-end tests and reports.

use evflow_engine::ports::OutPort;
use evflow_engine::typed_params::{Float, Floats, Int};
use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};

/// Declaration of `mesh.path`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "mesh.path",
    "mesh",
    Role::Source,
    "Scripted finger: parallel scan lines over a scene in given directions at constant speed.",
    build,
)
.doc(
    "A finite source of touch points for mesh rendering without a person. For each direction in \
`directions` (degrees from +x, counter-clockwise) it draws `lines` parallel lines of `length`, \
`spacing` apart, centred on (`center_x`, `center_y`), each at constant `speed`; after each line the \
finger rests at the line's end for `pause` seconds (speed 0), then jumps to the next line's start (a \
lift: `mesh.gradient` restarts there). Positions are computed from the sample index, so block and \
per-sample runs agree exactly.\n\n\
**Ports** at `rate`: `x`, `y` (m), `speed` (m/s, the finger's speed for `sim.display`'s velocity \
input; 0 during pauses). **Checked against:** the analytic positions of the first and last samples \
of each line (unit test).",
)
.ports(PORTS)
.params(&[
    DIRECTIONS.spec(),
    SPEED.spec(),
    LENGTH.spec(),
    LINES.spec(),
    SPACING.spec(),
    CENTER_X.spec(),
    CENTER_Y.spec(),
    PAUSE.spec(),
    RATE.spec(),
])
.rate_param(RATE.name())
.example("directions = [0.0, 90.0]\nspeed = 0.05\nlength = 0.06\nlines = 2");

/// The ports: the touch point and the finger's speed out.
const PORTS: &[PortSpec] = &[
    PortSpec::output("x", "m", "touch x"),
    PortSpec::output("y", "m", "touch y"),
    PortSpec::output("speed", "m/s", "finger speed (0 while resting)"),
];
/// `x`: touch x.
const X: OutPort = OutPort::named(PORTS, "x");
/// `y`: touch y.
const Y: OutPort = OutPort::named(PORTS, "y");
/// `speed` (the port): the finger's speed, 0 while resting.
const SPEED_OUT: OutPort = OutPort::named(PORTS, "speed");

/// `directions`: the scan directions.
const DIRECTIONS: Floats = Floats::new("directions", -360.0, 360.0, "deg", "scan directions; empty: 0 (left to right)");
/// `speed`: the scanning speed.
const SPEED: Float = Float::new("speed", 1e-4, 10.0, 0.05, "m/s", "scanning speed");
/// `length`: the length of each line.
const LENGTH: Float = Float::new("length", 1e-4, 10.0, 0.12, "m", "length of each line");
/// `lines`: parallel lines per direction.
const LINES: Int = Int::new("lines", 1, 10_000, 3, "1", "parallel lines per direction");
/// `spacing`: the distance between parallel lines.
const SPACING: Float = Float::new("spacing", 0.0, 10.0, 0.02, "m", "distance between parallel lines");
/// `center_x`: the scanned area's centre, x.
const CENTER_X: Float = Float::new("center_x", -1e6, 1e6, 0.0, "m", "centre of the scanned area, x");
/// `center_y`: the scanned area's centre, y.
const CENTER_Y: Float = Float::new("center_y", -1e6, 1e6, 0.0, "m", "centre of the scanned area, y");
/// `pause`: the rest at the end of each line.
const PAUSE: Float = Float::new("pause", 0.0, 10.0, 0.05, "s", "rest at the end of each line");
/// `rate`: the node's sample rate.
const RATE: Float = Float::new("rate", 1e-3, 1e7, 1000.0, "Hz", "sample rate");

/// One scan line.
#[derive(Debug, Clone, Copy)]
struct Line {
    start: [f64; 2],
    step: [f64; 2],
}

struct Path {
    lines: Vec<Line>,
    moving: u64,
    resting: u64,
    speed: f64,
    n: u64,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let fs = ctx.rate;
    let (speed, length) = (SPEED.get(p), LENGTH.get(p));
    let dirs = DIRECTIONS.get(p);
    let dirs = if dirs.is_empty() { vec![0.0] } else { dirs.to_vec() };
    let count = LINES.count(p);
    let c = [CENTER_X.get(p), CENTER_Y.get(p)];
    let moving = (length / speed * fs).round().max(1.0) as u64;
    let mut lines = Vec::with_capacity(dirs.len() * count);
    for deg in dirs {
        let a = deg.to_radians();
        let (d, q) = ([a.cos(), a.sin()], [-a.sin(), a.cos()]);
        for k in 0..count {
            let o = (k as f64 - 0.5 * (count - 1) as f64) * SPACING.get(p);
            let start = [c[0] + o * q[0] - 0.5 * length * d[0], c[1] + o * q[1] - 0.5 * length * d[1]];
            lines.push(Line { start, step: [speed / fs * d[0], speed / fs * d[1]] });
        }
    }
    Ok(Box::new(Path { lines, moving, resting: (PAUSE.get(p) * fs).round() as u64, speed, n: 0 }))
}

impl Path {
    fn per_line(&self) -> u64 {
        self.moving + self.resting
    }
    fn total(&self) -> u64 {
        self.per_line() * self.lines.len() as u64
    }
}

impl Node for Path {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        for i in 0..io.len() {
            let n = self.n.min(self.total().saturating_sub(1));
            let l = self.lines[(n / self.per_line()) as usize];
            let k = n % self.per_line();
            let (j, v) = if k < self.moving { (k, self.speed) } else { (self.moving - 1, 0.0) };
            io.output(X)[i] = l.start[0] + j as f64 * l.step[0];
            io.output(Y)[i] = l.start[1] + j as f64 * l.step[1];
            io.output(SPEED_OUT)[i] = v;
            self.n += 1;
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.n = 0;
    }

    fn remaining(&self) -> Option<u64> {
        Some(self.total().saturating_sub(self.n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::harness::Single;
    use std::path::Path as FsPath;

    #[test]
    fn lines_run_at_speed_in_their_directions() {
        let out = Single::new(
            &SPEC,
            "directions = [0.0, 90.0]\nspeed = 0.05\nlength = 0.1\nlines = 2\nspacing = 0.02\npause = 0.01",
        )
        .outputs(["x", "y", "speed"])
        .ticks(4 * 2010)
        .block(333)
        .base_dir(FsPath::new("."))
        .run()
        .unwrap();
        // Line 0: y = −0.01, x from −0.05 at 0.05 mm per tick.
        assert!((out[0][0] + 0.05).abs() < 1e-15 && (out[1][0] + 0.01).abs() < 1e-15);
        assert!((out[0][1999] - (-0.05 + 1999.0 * 5e-5)).abs() < 1e-12);
        assert_eq!(out[2][1999], 0.05);
        assert_eq!((out[0][2005], out[2][2005]), (out[0][1999], 0.0));
        // Line 2 (90°): x = +0.01 (offset along −x is −0.01·(−1))… starts at y = −0.05.
        let s = 2 * 2010;
        assert!((out[1][s] + 0.05).abs() < 1e-15, "{}", out[1][s]);
        assert!((out[0][s] - 0.01).abs() < 1e-15, "{}", out[0][s]);
        assert!((out[1][s + 1000] - (-0.05 + 0.05)).abs() < 1e-12);
    }
}
