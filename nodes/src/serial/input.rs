//! `serial.in`: touch position, load and force from a device on a serial
//! port, with the link's state.

use super::link::{self, InEnd, Link, LinkConfig};
use super::message::fault_names;
use super::params::{self, PORT_PARAMS};
use evflow_engine::ports::OutPort;
use evflow_engine::{
    BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, Role, RunMode, Summary,
};
use std::sync::atomic::Ordering;
use std::sync::Arc;

/// Declaration of `serial.in`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "serial.in",
    "serial",
    Role::Source,
    "Finger position, load and force from a device on a serial port (protocol: docs/serial-protocol.md).",
    build,
)
.doc(
    "Reads the device side of a friction display rig — a microcontroller with a touch sensor, a load cell and \
optionally a force sensor — over the framed serial protocol of `docs/serial-protocol.md` (version 1). The \
real-time rule holds: `process` never touches the port. One I/O thread per port (shared with a `serial.out` \
naming the same `port`) reads and writes it and exchanges samples with `process` through lock-free rings \
(rtrb); `process` only pops them and reads atomics.\n\
\n\
**Outputs**, all at the node's rate (the graph's base rate, 1 kHz for live graphs): `x`, `y` (m) and `load` \
(N) from the 40 Hz touch frames, held between frames (sample-and-hold; the newest frame wins); `contact` (1 \
while the device reports the finger on the display); `force` (N) one sample per tick from the 1 kHz force \
frames (held when none arrived; when more than 16 queue up — the device's clock runs faster than the \
host's — the oldest are skipped down to 4 and counted); `connected` (1 while the link is up: handshake done, \
a valid frame within `timeout`); `fault` (1 while the link is down or the device reports any fault bit — wire \
it to a `limit` fault input, e.g. `faults = [\"link\"]` and `dev.fault -> limit.link`, so the actuation fades \
to zero within 10 ms and stays off until re-armed). Non-finite values from the device are not passed on: the \
previous value is held and the sample counted.\n\
\n\
**Link**: in a live run (`evflow live`, ticks of one sample) preparing the node opens `port`, says HELLO and \
waits up to `wait` s for the device's answer (an error naming the port and the reason if it does not come; \
`wait = 0` starts unconnected). On a read or write error, end of file (device unplugged, emulator closed) or \
`timeout` s without a valid frame, the link goes down (`connected` = 0, `fault` = 1; the event is printed and \
reported) and the I/O thread reopens the port every `retry` s. In offline runs and replays (blocks of many \
ticks, as fast as the machine allows) and with `port = \"\"` the port is never opened: the outputs stay 0 with \
`connected` = 0 and `fault` = 1 (a replay replaces this source by the session's recording anyway).\n\
\n\
**Summary**: frames by type, bad frames (bad CRC, truncated, bad length, unknown type, wrong payload \
length), garbage bytes, frames lost by sequence number, ring overruns, connects, disconnects and every link \
event with the sample it happened at.\n\
\n\
**Checked against:** the protocol document's worked examples (byte for byte), the CRC check value, \
proptest streams of random, damaged and garbage-laden bytes, the host state machine against a scripted \
device (`nodes/src/serial/*_tests.rs`), and end to end over a pseudo-terminal against `evflow devsim` \
(`tools/tests/serial_e2e.rs`: the force the emulated display renders comes back; unplugging fades the \
output to zero, reconnecting works; injected corrupt frames are counted and skipped).",
)
.ports(PORTS)
.params(&PORT_PARAMS)
.example("port = \"\"   # e.g. \"/dev/ttyACM0\"; empty runs without a device\nbaud = 921600\nwait = 2.0");

/// The ports: what the device reports, and the link's state.
const PORTS: &[PortSpec] = &[
    PortSpec::output("x", "m", "finger position along x (held between 40 Hz touch frames)"),
    PortSpec::output("y", "m", "finger position along y (held)"),
    PortSpec::output("load", "N", "normal load of the finger (held)"),
    PortSpec::output("force", "N", "lateral force, one 1 kHz force sample per tick (held when none arrived)"),
    PortSpec::output("contact", "1", "1 while the device reports the finger on the display"),
    PortSpec::output("connected", "1", "1 while the link is up"),
    PortSpec::output("fault", "1", "1 while the link is down or the device reports a fault (feed a limit fault input)"),
];
/// `x`: finger position along x.
const X: OutPort = OutPort::named(PORTS, "x");
/// `y`: finger position along y.
const Y: OutPort = OutPort::named(PORTS, "y");
/// `load`: normal load of the finger.
const LOAD: OutPort = OutPort::named(PORTS, "load");
/// `force`: lateral force.
const FORCE: OutPort = OutPort::named(PORTS, "force");
/// `contact`: 1 while the finger is on the display.
const CONTACT: OutPort = OutPort::named(PORTS, "contact");
/// `connected`: 1 while the link is up.
const CONNECTED: OutPort = OutPort::named(PORTS, "connected");
/// `fault`: 1 while the link is down or the device reports a fault.
const FAULT: OutPort = OutPort::named(PORTS, "fault");

/// More queued force samples than this: skip the oldest, keep [`FORCE_KEEP`].
const FORCE_LAG: usize = 16;
const FORCE_KEEP: usize = 4;

/// The values held between frames.
#[derive(Debug, Clone, Copy, Default)]
struct Held {
    x: f64,
    y: f64,
    load: f64,
    force: f64,
    contact: f64,
}

struct Live {
    link: Arc<Link>,
    rings: InEnd,
}

struct SerialIn {
    name: String,
    config: Option<LinkConfig>,
    live: Option<Live>,
    /// Why the port is not used (no port, offline run).
    idle: Option<String>,
    held: Held,
    samples: u64,
    force_skipped: u64,
    non_finite: u64,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let config = params::link_config(p);
    let idle = config.is_none().then(|| params::NO_PORT.to_string());
    Ok(Box::new(SerialIn {
        name: ctx.node.clone(),
        config,
        live: None,
        idle,
        held: Held::default(),
        samples: 0,
        force_skipped: 0,
        non_finite: 0,
    }))
}

/// `x` when finite, else `old` (and the sample is counted).
fn finite(x: f32, old: f64, bad: &mut u64) -> f64 {
    if x.is_finite() {
        x as f64
    } else {
        *bad += 1;
        old
    }
}

impl Node for SerialIn {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        let Some(config) = &self.config else { return Ok(()) };
        if self.live.is_some() {
            return Ok(());
        }
        if ctx.mode != RunMode::Live {
            self.idle = Some(params::OFFLINE.to_string());
            return Ok(());
        }
        let (l, rings) = link::claim(config, &self.name, "serial.in", |l| l.take_in()).map_err(NodeError::Other)?;
        self.idle = None;
        self.live = Some(Live { link: l, rings });
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n = io.len();
        for i in 0..n {
            let (connected, fault) = match &mut self.live {
                None => (0.0, 1.0),
                Some(l) => {
                    while let Ok(t) = l.rings.touch.pop() {
                        self.held.x = finite(t.x, self.held.x, &mut self.non_finite);
                        self.held.y = finite(t.y, self.held.y, &mut self.non_finite);
                        self.held.load = finite(t.load, self.held.load, &mut self.non_finite);
                        self.held.contact = if t.contact() { 1.0 } else { 0.0 };
                    }
                    let queued = l.rings.force.slots();
                    if queued > FORCE_LAG {
                        let skip = queued - FORCE_KEEP;
                        if let Ok(c) = l.rings.force.read_chunk(skip) {
                            c.commit_all();
                            self.force_skipped += skip as u64;
                        }
                    }
                    if let Ok(f) = l.rings.force.pop() {
                        self.held.force = finite(f, self.held.force, &mut self.non_finite);
                    }
                    let up = l.link.state.connected.load(Ordering::Acquire);
                    let faults = l.link.state.faults.load(Ordering::Relaxed);
                    (if up { 1.0 } else { 0.0 }, if up && faults == 0 { 0.0 } else { 1.0 })
                }
            };
            let h = self.held;
            let values = [
                (X, h.x),
                (Y, h.y),
                (LOAD, h.load),
                (FORCE, h.force),
                (CONTACT, h.contact),
                (CONNECTED, connected),
                (FAULT, fault),
            ];
            for (port, v) in values {
                io.output(port)[i] = v;
            }
        }
        self.samples += n as u64;
        if let Some(l) = &self.live {
            l.link.state.in_samples.store(self.samples, Ordering::Relaxed);
        }
        Ok(())
    }

    fn reset(&mut self) {
        self.held = Held::default();
        self.samples = 0;
        self.force_skipped = 0;
        self.non_finite = 0;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let Some(l) = &self.live else {
            return Ok(Summary::default().line(self.idle.clone().unwrap_or_default()));
        };
        let r = l.link.state.report();
        let c = r.counters;
        let s = c.stream;
        let mut sum = Summary::default()
            .value("frames", s.frames as f64, "frames")
            .value("touch_frames", c.touch as f64, "frames")
            .value("force_frames", c.force as f64, "frames")
            .value("bad_crc", s.bad_crc as f64, "frames")
            .value("truncated", s.truncated as f64, "frames")
            .value("bad_length", s.bad_length as f64, "frames")
            .value("unknown_type", c.unknown_type as f64, "frames")
            .value("bad_payload", c.bad_payload as f64, "frames")
            .value("garbage_bytes", s.garbage_bytes as f64, "bytes")
            .value("lost_frames", c.lost as f64, "frames")
            .value("ring_overruns", (r.touch_overruns + r.force_overruns) as f64, "samples")
            .value("force_skipped", self.force_skipped as f64, "samples")
            .value("non_finite", self.non_finite as f64, "samples")
            .value("connects", r.connects as f64, "1")
            .value("disconnects", r.disconnects as f64, "1");
        for e in &r.events {
            sum = sum.line(e.clone());
        }
        if r.events_dropped > 0 {
            sum = sum.line(format!("… and {} more link events", r.events_dropped));
        }
        let faults = l.link.state.faults.load(Ordering::Relaxed);
        if faults != 0 {
            sum = sum.line(format!("device faults at the end: {}", fault_names(faults)));
        }
        if !l.link.state.connected.load(Ordering::Acquire) {
            sum = sum.line(format!(
                "link down at the end: {}",
                r.last_error.unwrap_or_else(|| "no answer from the device".into())
            ));
        }
        Ok(sum)
    }
}
