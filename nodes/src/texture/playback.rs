//! `playback`: plays the tables `interp` sends, time-based (§6.5) or locked
//! to the finger's travel, crossfading between tables.

use super::frame::{Header, HEADER};
use crate::rate::clock::Clock;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::typed_params::{Choice, Float, Int};
use evflow_engine::{
    BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, RateSpec, Role, Summary,
};

/// Declaration of `playback`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "playback",
    "texture",
    Role::Filter,
    "Plays interpolated texture tables at the output rate, time-based or position-locked, with click-free switching.",
    build,
)
.doc(
    "Receives the table frames of `interp` on `table` (any rate; see `docs/texture.md`) and plays the \
current table as a loop at the node's rate (the rate of `velocity`, 1 kHz for actuation):\n\n\
* `mode = \"time\"` (default, §6.5): the table is played at its own sample rate, as the user-study \
program did with the signal it updated every 100 ms;\n\
* `mode = \"position\"`: the playhead follows the finger's travel: it moves by v·Δt / L of the loop per \
sample (v the signed `velocity`, L the loop length in cm), so a finger going back meets the same texture \
backwards and a finger at rest stays on one spot.\n\n\
**Switching without a click.** The playhead is kept as a fraction of the loop (a place on the texture), \
so a new table continues at the same place; over `crossfade` ms the output moves from the old table to \
the new one with a raised-cosine weight (both tables read at the same place; consecutive tables are \
strongly correlated, so their linear mix keeps the level). The first table fades in from silence. The \
loop's seam is hidden by crossfading the table's overlap (the samples after the loop's end) into its \
start. Between table samples the playhead reads by linear interpolation.\n\n\
**Look-ahead.** With `lookahead` = L > 0 each output sample is read L samples ahead of the playhead, \
as far as the current step carries it — in position mode, where the finger will be after L samples at \
its current velocity (its predicted path); in time mode, L samples later in the table. `synth.live` \
takes the texture force this way, so that each tick it knows the force of its whole horizon.\n\n\
**Rest.** Below `rest_speed` (|velocity|) the output fades to 0 over `rest_fade` ms, and back when the \
finger moves: a resting finger feels nothing, in both modes (0 disables this).\n\n\
**Carrier.** A table flagged as a carrier's envelope (`interp`'s cells ride a Nyquist-rate carrier) is \
read like any other and multiplied by (−1)ᵐ at output sample m, so the carrier stays at this node's \
Nyquist rate through re-sampling, playhead steps and crossfades.\n\n\
A frame whose header is not a valid table (wrong magic, length or frame size, non-finite samples) is \
ignored and counted in the run's summary; until the first valid frame the output is 0. `update_rate` \
must equal `interp`'s, so the frame length matches (a mismatch shows as rejected frames).\n\n\
**Checked against:** constant tables (level and phase continuity across switches and seams), time and \
position modes on known travel (forward, reversed, at rest), block ≡ tick processing.",
)
.ports(PORTS)
.params(&[MODE.spec(), UPDATE_RATE.spec(), CROSSFADE.spec(), REST_SPEED.spec(), REST_FADE.spec(), LOOKAHEAD.spec()])
.example("mode = \"time\"\nupdate_rate = 10.0\ncrossfade = 20.0");

/// The ports: table frames and the finger's velocity in, the actuation out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("table", "frame", "table frames from `interp.table`").at(RateSpec::Any),
    PortSpec::input("velocity", "cm/s", "signed finger velocity (rest detection; playhead in position mode)"),
    PortSpec::output("out", "1", "the actuation signal"),
];
/// `table`: the table frames.
const TABLE: InPort = InPort::named(PORTS, "table");
/// `velocity`: the signed finger velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// `out`: the actuation signal.
const OUT: OutPort = OutPort::named(PORTS, "out");

/// How the playhead moves (`mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// At the table's own sample rate (§6.5).
    Time,
    /// With the finger's travel.
    Position,
}

/// `mode`: time-based or position-locked playhead.
const MODE: Choice<Mode> = Choice::new(
    "mode",
    &["time", "position"],
    &[Mode::Time, Mode::Position],
    "time",
    "time-based (§6.5) or position-locked playhead",
);
/// `update_rate`: interp's update rate.
const UPDATE_RATE: Float =
    Float::new("update_rate", 0.01, 1000.0, 10.0, "Hz", "interp's update rate (sets the frame length)");
/// `crossfade`: the crossfade from one table to the next.
const CROSSFADE: Float = Float::new("crossfade", 0.0, 5000.0, 20.0, "ms", "crossfade from one table to the next");
/// `rest_speed`: below it the output fades to silence.
const REST_SPEED: Float =
    Float::new("rest_speed", 0.0, 1e3, 0.3, "cm/s", "below this speed the output fades to silence (0: never)");
/// `rest_fade`: the fade time to and from silence.
const REST_FADE: Float = Float::new("rest_fade", 0.1, 1000.0, 10.0, "ms", "fade time to and from silence at rest");
/// `lookahead`: how far ahead the texture is played.
const LOOKAHEAD: Int = Int::new(
    "lookahead",
    0,
    10_000,
    0,
    "samples",
    "play the texture this many samples ahead along the current velocity",
);

/// A table in one of the three buffers.
#[derive(Debug, Clone, Copy)]
struct Slot {
    buf: usize,
    head: Header,
}

struct Playback {
    position: bool,
    lookahead: f64,
    frame: usize,
    table_clock: Clock,
    out_clock: Clock,
    out_rate: f64,
    xfade_step: f64,
    rest_speed: f64,
    gate_step: f64,
    bufs: [Vec<f64>; 3],
    incoming: usize,
    cur: Option<Slot>,
    prev: Option<Slot>,
    /// Table samples received and output samples written since t = 0.
    received: u64,
    written: u64,
    phase: f64,
    fade: f64,
    gate: f64,
    accepted: u64,
    rejected: u64,
    scratch: [Vec<f64>; 2],
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let table_rate = ctx.input_rate(TABLE);
    let update = UPDATE_RATE.get(p);
    let frame_f = table_rate / update;
    let frame = frame_f.round() as usize;
    if (frame_f - frame as f64).abs() > 1e-9 * frame_f || frame <= HEADER {
        return Err(NodeError::param(
            UPDATE_RATE.name(),
            format!("the table arrives at {table_rate} Hz, which is not a whole number (> {HEADER}) of samples per update at {update} Hz; use interp's update_rate"),
        ));
    }
    let out_rate = ctx.rate;
    let xfade = CROSSFADE.get(p) * 1e-3 * out_rate;
    if CROSSFADE.get(p) * 1e-3 > 0.5 / update {
        return Err(NodeError::param(
            CROSSFADE.name(),
            format!("must be at most half the update period ({} ms)", 500.0 / update),
        ));
    }
    Ok(Box::new(Playback {
        position: MODE.get(p) == Mode::Position,
        lookahead: LOOKAHEAD.get(p) as f64,
        frame,
        table_clock: Clock::new(table_rate, ctx.base_rate, "table")?,
        out_clock: Clock::new(out_rate, ctx.base_rate, "out")?,
        out_rate,
        xfade_step: if xfade >= 1.0 { 1.0 / xfade } else { 1.0 },
        rest_speed: REST_SPEED.get(p),
        gate_step: 1.0 / (REST_FADE.get(p) * 1e-3 * out_rate).max(1.0),
        bufs: [Vec::new(), Vec::new(), Vec::new()],
        incoming: 0,
        cur: None,
        prev: None,
        received: 0,
        written: 0,
        phase: 0.0,
        fade: 1.0,
        gate: 0.0,
        accepted: 0,
        rejected: 0,
        scratch: [Vec::new(), Vec::new()],
    }))
}

/// The looped table read at `phase` ∈ [0, 1): linear interpolation between
/// loop samples; loop sample k < X is the seam crossfade of t[k] and t[T+k].
#[inline]
fn read(buf: &[f64], h: &Header, phase: f64) -> f64 {
    let t = &buf[HEADER..];
    let (len, x) = (h.len, h.overlap);
    let sample = |k: usize| -> f64 {
        if k < x {
            let w = (k + 1) as f64 / (x + 1) as f64;
            w * t[k] + (1.0 - w) * t[len + k]
        } else {
            t[k]
        }
    };
    let pos = phase * len as f64;
    let k = (pos.floor() as usize).min(len - 1);
    let f = pos - k as f64;
    let a = sample(k);
    let b = sample(if k + 1 == len { 0 } else { k + 1 });
    a + f * (b - a)
}

impl Playback {
    /// A frame has been received completely into the incoming buffer.
    fn commit(&mut self) {
        let b = self.incoming;
        match Header::read(&self.bufs[b], self.frame) {
            Some(head) => {
                self.accepted += 1;
                // The buffer of the table fading out is free again.
                let free = match self.prev {
                    Some(p) => p.buf,
                    None => (0..3).find(|i| *i != b && Some(*i) != self.cur.map(|c| c.buf)).unwrap_or(0),
                };
                self.prev = self.cur;
                self.cur = Some(Slot { buf: b, head });
                self.incoming = free;
                self.fade = 0.0;
            }
            None => self.rejected += 1,
        }
    }

    fn absorb(&mut self, s_first: u64, n: usize, until_out: u64) {
        while self.received < s_first + n as u64 && self.table_clock.before(self.received, &self.out_clock, until_out) {
            let k = (self.received - s_first) as usize;
            let pos = (self.received % self.frame as u64) as usize;
            self.bufs[self.incoming][pos] = self.scratch[0][k];
            self.received += 1;
            if pos + 1 == self.frame {
                self.commit();
            }
        }
    }

    /// One output sample, output sample number `o`, for signed velocity `v`.
    #[inline]
    fn next(&mut self, o: u64, v: f64) -> f64 {
        // A carrier's envelope is played on (−1)^o, this output's Nyquist rate
        // (at the sample looked ahead to).
        let parity = if (o + self.lookahead as u64).is_multiple_of(2) { 1.0 } else { -1.0 };
        let sign = |h: &Header| if h.carrier { parity } else { 1.0 };
        let v = if v.is_finite() { v } else { 0.0 };
        let target = if v.abs() >= self.rest_speed { 1.0 } else { 0.0 };
        if self.gate < target {
            self.gate = (self.gate + self.gate_step).min(1.0);
        } else if self.gate > target {
            self.gate = (self.gate - self.gate_step).max(0.0);
        }
        let Some(cur) = self.cur else { return 0.0 };
        let h = cur.head;
        let step =
            if self.position { v / (self.out_rate * h.loop_cm) } else { h.rate / (self.out_rate * h.len as f64) };
        let at = (self.phase + self.lookahead * step).rem_euclid(1.0);
        let at = if at.is_finite() && at < 1.0 { at } else { 0.0 };
        let y_new = sign(&h) * read(&self.bufs[cur.buf], &h, at);
        let y = if self.fade < 1.0 {
            let w = (0.5 * std::f64::consts::PI * self.fade).sin().powi(2);
            let y_old = match self.prev {
                Some(p) => {
                    let step_old = if self.position {
                        v / (self.out_rate * p.head.loop_cm)
                    } else {
                        p.head.rate / (self.out_rate * p.head.len as f64)
                    };
                    let at = (self.phase + self.lookahead * step_old).rem_euclid(1.0);
                    let at = if at.is_finite() && at < 1.0 { at } else { 0.0 };
                    sign(&p.head) * read(&self.bufs[p.buf], &p.head, at)
                }
                None => 0.0,
            };
            self.fade = (self.fade + self.xfade_step).min(1.0);
            w * y_new + (1.0 - w) * y_old
        } else {
            y_new
        };
        self.phase = (self.phase + step).rem_euclid(1.0);
        if self.phase.is_nan() || self.phase >= 1.0 {
            self.phase = 0.0;
        }
        self.gate * y
    }
}

impl Node for Playback {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        self.bufs = [vec![0.0; self.frame], vec![0.0; self.frame], vec![0.0; self.frame]];
        self.scratch = [vec![0.0; ctx.max_block], vec![0.0; ctx.max_block]];
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n_t = io.input_len(TABLE);
        let n_v = io.input_len(VELOCITY);
        self.scratch[0][..n_t].copy_from_slice(io.input(TABLE));
        self.scratch[1][..n_v].copy_from_slice(io.input(VELOCITY));
        let s_first = self.received;
        let out = io.output(OUT);
        for (q, y) in out.iter_mut().enumerate() {
            let o = self.written + q as u64;
            self.absorb(s_first, n_t, o + 1);
            *y = self.next(o, self.scratch[1].get(q).copied().unwrap_or(0.0));
        }
        self.written += out.len() as u64;
        self.absorb(s_first, n_t, u64::MAX / 4);
        Ok(())
    }

    fn reset(&mut self) {
        for b in &mut self.bufs {
            b.fill(0.0);
        }
        self.incoming = 0;
        self.cur = None;
        self.prev = None;
        self.received = 0;
        self.written = 0;
        self.phase = 0.0;
        self.fade = 1.0;
        self.gate = 0.0;
        self.accepted = 0;
        self.rejected = 0;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let mut s = Summary::default().value("tables", self.accepted as f64, "1");
        if self.rejected > 0 {
            s = s.value("rejected_frames", self.rejected as f64, "1").line(format!(
                "{} frame(s) on `table` were not interp table frames (is `table` connected to interp.table, with the same update_rate?)",
                self.rejected
            ));
        }
        Ok(s)
    }
}
