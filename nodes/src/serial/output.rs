//! `serial.out`: actuation samples to a device on a serial port.

use super::link::{self, Link, LinkConfig};
use super::link_state::LinkReport;
use super::params::{self, PORT_PARAMS};
use evflow_engine::ports::InPort;
use evflow_engine::{
    BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, Role, RunMode, Summary,
};
use std::sync::atomic::Ordering;
use std::sync::Arc;

/// Declaration of `serial.out`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "serial.out",
    "serial",
    Role::Sink,
    "Actuation samples to a device on a serial port (protocol: docs/serial-protocol.md); must be fed by `limit`.",
    build,
)
.doc(
    "Sends its input `u` (1.0 = 50 V at the amplifier output, ±1 = 100 Vpp; dissertation §5.2.3) to the \
device as one ACTUATION frame per sample (`i16`, +32767 = +1.0; values beyond ±1 are clipped and counted) \
over the framed protocol of `docs/serial-protocol.md`. A hardware output: the loader refuses a graph in which \
`u` does not come straight from a `limit` node (`docs/safety.md`).\n\
\n\
`process` never touches the port: it pushes each sample into a lock-free ring (rtrb) that the port's I/O \
thread (shared with a `serial.in` naming the same `port`) drains about once a millisecond and writes. The \
I/O thread: sends nothing but HELLO until the device answered; drops samples while the link is down \
(counted); if more than 16 samples queued up while it was held up, sends only the newest 4 (counted); when \
samples stop coming for 5 ms (the real-time thread ended or stalled) it ramps the last value it sent to zero \
over 10 frames (10 ms) on its own; sends a heartbeat every 100 ms, and a zero sample when the link closes. \
The device's own watchdog ramps its output to zero when no host frame arrives for 100 ms.\n\
\n\
**Link**: as `serial.in` — in a live run (ticks of one sample) preparing the node opens `port` and waits up \
to `wait` s for the device; in offline runs and replays (blocks of many ticks) and with `port = \"\"` the port \
is never opened and the samples are only counted, so replaying a session never drives the device. The \
actuation rate announced in HELLO is the node's rate.\n\
\n\
**Summary**: samples taken, sent, clipped, dropped while the link was down, dropped after a stall, ring \
overruns, stall fades, and the link's events when no `serial.in` reports them.\n\
\n\
**Checked against:** the host state machine's tests (each sample sent in order with its sequence number, \
the stall fade ending at exactly 0, nothing but HELLO before the handshake) and end to end over a \
pseudo-terminal against `evflow devsim` (`tools/tests/serial_e2e.rs`: the samples the emulated device \
receives are the `limit` output the session recorded).",
)
.ports(PORTS)
.params(&PORT_PARAMS)
.hardware()
.example("port = \"\"   # e.g. \"/dev/ttyACM0\"; empty runs without a device\nbaud = 921600\nwait = 2.0");

/// The port: the actuation in.
const PORTS: &[PortSpec] =
    &[PortSpec::input("u", "1", "actuation from `limit` (1.0 = 50 V at the amplifier; clipped to ±1)")];
/// `u`: the actuation sent to the device.
const U: InPort = InPort::named(PORTS, "u");

struct Live {
    link: Arc<Link>,
    ring: rtrb::Producer<f32>,
}

struct SerialOut {
    name: String,
    rate: f64,
    config: Option<LinkConfig>,
    live: Option<Live>,
    idle: Option<String>,
    samples: u64,
    overruns: u64,
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let config = params::link_config(p);
    let idle = config.is_none().then(|| params::NO_PORT.to_string());
    Ok(Box::new(SerialOut {
        name: ctx.node.clone(),
        rate: ctx.rate,
        config,
        live: None,
        idle,
        samples: 0,
        overruns: 0,
    }))
}

impl Node for SerialOut {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        let Some(config) = &self.config else { return Ok(()) };
        if self.live.is_some() {
            return Ok(());
        }
        if ctx.mode != RunMode::Live {
            self.idle = Some(params::OFFLINE.to_string());
            return Ok(());
        }
        let hz = params::rate_hz(&self.name, self.rate)?;
        let (l, ring) = link::claim(config, &self.name, "serial.out", |l| l.take_out(hz)).map_err(NodeError::Other)?;
        self.idle = None;
        self.live = Some(Live { link: l, ring });
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let u = io.input(U);
        if let Some(l) = &mut self.live {
            for &x in u {
                if l.ring.push(x as f32).is_err() {
                    self.overruns += 1;
                }
            }
            l.link.state.out_samples.store(self.samples + u.len() as u64, Ordering::Relaxed);
        }
        self.samples += u.len() as u64;
        Ok(())
    }

    fn reset(&mut self) {
        self.samples = 0;
        self.overruns = 0;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let mut s = Summary::default().value("samples", self.samples as f64, "samples");
        let Some(l) = &self.live else {
            return Ok(s.line(self.idle.clone().unwrap_or_default()));
        };
        // Let the I/O thread send, or count as dropped, every sample still
        // queued before reporting (up to half a second: a loaded machine
        // may not run it for a while).
        let until = std::time::Instant::now() + std::time::Duration::from_millis(500);
        let mut r = l.link.state.report();
        let accounted = |r: &LinkReport| r.counters.sent + r.counters.dropped_down + r.stale_dropped + self.overruns;
        while accounted(&r) < self.samples && std::time::Instant::now() < until {
            std::thread::sleep(std::time::Duration::from_millis(1));
            r = l.link.state.report();
        }
        let c = r.counters;
        s = s
            .value("sent", c.sent as f64, "samples")
            .value("clipped", c.clipped as f64, "samples")
            .value("dropped_link_down", c.dropped_down as f64, "samples")
            .value("dropped_stale", r.stale_dropped as f64, "samples")
            .value("ring_overruns", self.overruns as f64, "samples")
            .value("stall_fades", c.stall_fades as f64, "1")
            .value("write_overflows", r.write_overflows as f64, "1");
        if !l.link.state.has_reader.load(Ordering::Relaxed) {
            for e in &r.events {
                s = s.line(e.clone());
            }
        }
        Ok(s)
    }
}
