//! `evflow devsim`: a device emulator that speaks the serial protocol
//! (`docs/serial-protocol.md`) on a pseudo-terminal (or a given port), with
//! the simulated lab inside: a virtual finger scans the virtual display,
//! whose friction force responds to the actuation the host sends.
//!
//! Each millisecond of its own clock the emulator plays one actuation
//! sample from its FIFO (the protocol's device checklist, implemented by
//! `DeviceSession`), steps the display model of `sim.display` with it and
//! the finger's load and velocity, and sends the force (1 kHz); every 25 ms
//! a touch frame (40 Hz); every 100 ms a heartbeat.

mod corrupt;
mod finger;

use anyhow::{anyhow, Context, Result};
use corrupt::Corrupter;
use evflow_nodes::lab::display_model::DisplayModel;
use evflow_nodes::lab::integrator::Method;
use evflow_nodes::lab::LabProfile;
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use evflow_nodes::serial::device::{DeviceConfig, DeviceSession};
use evflow_nodes::serial::frame::MAX_FRAME;
use evflow_nodes::serial::message::{caps, Message, Touch, VERSION};
use finger::Finger;
use serialport::SerialPort;
use std::io::{ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Arguments of `evflow devsim`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Speak on this serial port instead of a new pseudo-terminal (e.g. one
    /// end of a USB-serial loopback cable).
    #[arg(long, value_name = "PATH")]
    port: Option<String>,
    /// Also point a symbolic link at the pseudo-terminal (replaced if it
    /// exists), so a graph can name a fixed path and finds a restarted
    /// emulator again.
    #[arg(long, value_name = "PATH", conflicts_with = "port")]
    link: Option<PathBuf>,
    /// Baud rate with --port.
    #[arg(long, default_value_t = 921_600)]
    baud: u32,
    /// Stop after this many seconds (default: run until Ctrl-C).
    #[arg(long)]
    duration: Option<f64>,
    /// Scanning speed of the virtual finger, cm/s.
    #[arg(long, default_value_t = 5.0)]
    speed: f64,
    /// Length of the scanned stretch, cm.
    #[arg(long, default_value_t = 8.0)]
    travel: f64,
    /// Mean load of the finger, N.
    #[arg(long, default_value_t = 0.8)]
    load: f64,
    /// Lab profile of the virtual display (TOML, see docs/simulated-lab.md;
    /// default: the nominal lab).
    #[arg(long, value_name = "FILE")]
    profile: Option<PathBuf>,
    /// Do not send force frames (a rig without a force sensor).
    #[arg(long)]
    no_force: bool,
    /// Damage this fraction of the frames sent (bad CRC, cut short, or
    /// garbage before them; equally likely) to test a host's receiver.
    #[arg(long, default_value_t = 0.0, value_name = "FRACTION")]
    corrupt: f64,
    /// Seed of the damage and of the display's noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Protocol version to claim in HELLO (to test a host's refusal).
    #[arg(long, default_value_t = VERSION)]
    protocol: u8,
    /// Write DIR/actuation.wav (every actuation sample received, in
    /// order), DIR/device.wav (1 kHz: actuation played, force, x, y, load,
    /// velocity) and DIR/stats.json (counters, refreshed every 100 ms);
    /// readable even if the emulator is killed.
    #[arg(long, value_name = "DIR")]
    log: Option<PathBuf>,
}

/// The port the emulator speaks on.
enum Wire {
    /// The master side of a pty: the host is attached while reads do not hang up.
    Pty(Box<dyn SerialPort>),
    /// A real port: the host is assumed attached.
    Port(Box<dyn SerialPort>),
}

/// Runs `evflow devsim`.
pub fn main(a: Args) -> Result<()> {
    if !(a.speed > 0.0 && a.travel > 0.0 && a.load >= 0.0 && (0.0..=1.0).contains(&a.corrupt)) {
        return Err(anyhow!("--speed and --travel must be > 0, --load ≥ 0, --corrupt within 0..=1"));
    }
    let profile = match &a.profile {
        Some(p) => LabProfile::load(p).map_err(|e| anyhow!("{e}"))?,
        None => LabProfile::default(),
    };
    let model =
        DisplayModel::new(&profile, 1000.0, Method::Exact, 4, 1.0, a.seed).map_err(|e| anyhow!("lab profile: {e}"))?;
    let (mut wire, name) = open(&a)?;
    let log = a.log.as_deref().map(Log::create).transpose()?;

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    println!("evflow devsim: emulated device on {name}");
    if let Some(l) = &a.link {
        println!("evflow devsim: linked from {}", l.display());
    }
    println!(
        "evflow devsim: run e.g.  evflow live graphs/display-serial.toml --set port={}",
        a.link.as_ref().map(|l| l.display().to_string()).unwrap_or(name.clone())
    );
    let _ = std::io::stdout().flush();

    let t0 = Instant::now();
    let mut emu = Emulator::new(&a, model, log, matches!(wire, Wire::Port(_)), t0);
    let end = a.duration.map(|d| t0 + Duration::from_secs_f64(d.max(0.0)));
    while !stop.load(Ordering::SeqCst) && end.is_none_or(|e| Instant::now() < e) {
        emu.read(&mut wire);
        emu.clock(Instant::now())?;
        emu.write(&mut wire, &name)?;
        emu.log_received()?;
        std::thread::sleep(Duration::from_micros(300));
    }
    let c = emu.dev.counters();
    let i = emu.corrupter.injected;
    println!(
        "evflow devsim: {:.1} s; actuation frames received {}, lost {}, host connects {}, watchdog {}, \
         FIFO underruns {}; damaged: {} bad CRC, {} truncated, {} garbage bursts",
        t0.elapsed().as_secs_f64(),
        c.actuation,
        c.lost,
        emu.connects,
        c.watchdog,
        c.fifo_underruns,
        i.bad_crc,
        i.truncated,
        i.garbage_bursts
    );
    if let Some(l) = emu.log {
        l.finish(&emu.dev, &emu.corrupter, emu.connects)?;
    }
    Ok(())
}

/// The emulated device: its protocol session, the display model the
/// virtual finger scans, and what passes between them and the host.
struct Emulator {
    dev: DeviceSession,
    corrupter: Corrupter,
    model: DisplayModel,
    finger: Finger,
    log: Option<Log>,
    no_force: bool,
    /// True while a host is attached.
    host: bool,
    /// Times a host attached.
    connects: u64,
    /// Milliseconds of the device's clock played.
    tick: u64,
    t0: Instant,
    /// Actuation samples received since the log last took them.
    received: Vec<i16>,
    buf: [u8; 4096],
    /// Bytes to send the host.
    out: Vec<u8>,
    frame: Vec<u8>,
}

impl Emulator {
    fn new(a: &Args, model: DisplayModel, log: Option<Log>, host: bool, t0: Instant) -> Self {
        let finger = Finger { x0: 0.01, travel: a.travel * 0.01, speed: a.speed * 0.01, y: 0.03, load: a.load };
        let caps = caps::TOUCH | if a.no_force { 0 } else { caps::FORCE };
        Emulator {
            dev: DeviceSession::new(DeviceConfig { version: a.protocol, caps, ..DeviceConfig::default() }, t0),
            corrupter: Corrupter::new(a.corrupt, a.seed),
            model,
            finger,
            log,
            no_force: a.no_force,
            host,
            connects: 0,
            tick: 0,
            t0,
            received: Vec::new(),
            buf: [0u8; 4096],
            out: Vec::new(),
            frame: Vec::with_capacity(MAX_FRAME),
        }
    }

    /// Bytes from the host, and whether one is attached.
    fn read(&mut self, wire: &mut Wire) {
        let (port, pty) = match wire {
            Wire::Pty(p) => (p, true),
            Wire::Port(p) => (p, false),
        };
        match port.read(&mut self.buf) {
            Ok(n) if n > 0 => {
                if !self.host {
                    self.connects += 1;
                }
                self.host = true;
                let received = &mut self.received;
                self.dev.receive(Instant::now(), &self.buf[..n], &mut self.out, &mut |v| received.push(v));
            }
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted) => {
                if pty && !self.host {
                    self.connects += 1;
                }
                self.host = true;
            }
            _ if pty && self.host => {
                // Nobody has the pty open (it hangs up): the host is gone.
                self.dev.host_gone();
                self.host = false;
            }
            _ => {}
        }
    }

    /// The device's 1 kHz clock up to `now`: each millisecond plays one
    /// actuation sample on the display and, while a host is engaged, sends
    /// the force (1 kHz), a touch frame (40 Hz) and a heartbeat (10 Hz).
    fn clock(&mut self, now: Instant) -> Result<()> {
        let due = now.duration_since(self.t0).as_millis() as u64;
        while self.tick < due {
            self.tick += 1;
            let tick = self.tick;
            let u = self.dev.play(now, &mut self.out);
            let f = self.finger.at(tick as f64 * 1e-3);
            let force = self.model.step(u, f.load, f.velocity);
            if self.dev.engaged() {
                let (dev, c, frame, out) = (&mut self.dev, &mut self.corrupter, &mut self.frame, &mut self.out);
                if !self.no_force {
                    send(dev, c, Message::Force(force as f32), frame, out);
                }
                if tick.is_multiple_of(25) {
                    let t = Touch { x: f.x as f32, y: f.y as f32, load: f.load as f32, flags: 1 };
                    send(dev, c, Message::Touch(t), frame, out);
                }
                if tick.is_multiple_of(100) {
                    frame.clear();
                    dev.heartbeat(now, frame);
                    c.append(frame, out);
                }
            }
            if let Some(l) = &mut self.log {
                l.tick([u, force, f.x, f.y, f.load, f.velocity])?;
            }
        }
        Ok(())
    }

    /// Sends what is due to an attached host (a write error ends a real
    /// port's session; a pty's host may come back).
    fn write(&mut self, wire: &mut Wire, name: &str) -> Result<()> {
        let (port, pty) = match wire {
            Wire::Pty(p) => (p, true),
            Wire::Port(p) => (p, false),
        };
        if self.host && !self.out.is_empty() {
            if let Err(e) = port.write_all(&self.out) {
                if !pty {
                    return Err(anyhow!("{name}: write error: {e}"));
                }
            }
        }
        self.out.clear();
        Ok(())
    }

    /// Hands the actuation received to the log (and its counters, every
    /// 100 ms); without a log, forgets it.
    fn log_received(&mut self) -> Result<()> {
        if let Some(l) = &mut self.log {
            for v in self.received.drain(..) {
                l.actuation(v)?;
            }
            l.maybe_flush(&self.dev, &self.corrupter, self.connects)?;
        } else {
            self.received.clear();
        }
        Ok(())
    }
}

fn send(dev: &mut DeviceSession, c: &mut Corrupter, m: Message, frame: &mut Vec<u8>, out: &mut Vec<u8>) {
    frame.clear();
    dev.send(m, frame);
    c.append(frame, out);
}

/// Opens the given port, or a pty pair (and the link to it).
fn open(a: &Args) -> Result<(Wire, String)> {
    if let Some(p) = &a.port {
        let port =
            serialport::new(p, a.baud).timeout(Duration::ZERO).open().map_err(|e| anyhow!("cannot open {p}: {e}"))?;
        return Ok((Wire::Port(port), p.clone()));
    }
    #[cfg(unix)]
    {
        let (mut master, slave) = serialport::TTYPort::pair().map_err(|e| anyhow!("cannot open a pty pair: {e}"))?;
        let name = slave.name().ok_or_else(|| anyhow!("the pty has no name"))?;
        // The host opens the slave itself; ours would hide its hang-ups.
        drop(slave);
        master.set_timeout(Duration::ZERO)?;
        if let Some(l) = &a.link {
            let tmp = l.with_extension("devsim-tmp");
            let _ = std::fs::remove_file(&tmp);
            std::os::unix::fs::symlink(&name, &tmp).with_context(|| format!("{}: cannot create", tmp.display()))?;
            std::fs::rename(&tmp, l).with_context(|| format!("{}: cannot replace", l.display()))?;
        }
        Ok((Wire::Pty(Box::new(master)), name))
    }
    #[cfg(not(unix))]
    Err(anyhow!("pseudo-terminals need a Unix system; give --port"))
}

/// The emulator's log files.
struct Log {
    dir: PathBuf,
    actuation: RecordingWriter,
    device: RecordingWriter,
    flushed: Instant,
}

impl Log {
    fn create(dir: &Path) -> Result<Self> {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
        let act = RecordingMeta::new(1000.0, vec![Channel::new("u", "1")]);
        let dev = RecordingMeta::new(
            1000.0,
            ["u", "force", "x", "y", "load", "velocity"]
                .iter()
                .zip(["1", "N", "m", "m", "N", "m/s"])
                .map(|(n, u)| Channel::new(*n, u))
                .collect(),
        );
        let w = |name: &str, meta| RecordingWriter::create_live(&dir.join(name), meta).map_err(|e| anyhow!("{e}"));
        Ok(Self {
            dir: dir.to_path_buf(),
            actuation: w("actuation", act)?,
            device: w("device", dev)?,
            flushed: Instant::now(),
        })
    }

    fn actuation(&mut self, v: i16) -> Result<()> {
        let u = evflow_nodes::serial::message::actuation_from_i16(v);
        self.actuation.write_frame(&[u]).map_err(|e| anyhow!("{e}"))
    }

    fn tick(&mut self, row: [f64; 6]) -> Result<()> {
        self.device.write_frame(&row).map_err(|e| anyhow!("{e}"))
    }

    fn maybe_flush(&mut self, dev: &DeviceSession, c: &Corrupter, connects: u64) -> Result<()> {
        if self.flushed.elapsed() < Duration::from_millis(100) {
            return Ok(());
        }
        self.flushed = Instant::now();
        self.actuation.flush().map_err(|e| anyhow!("{e}"))?;
        self.device.flush().map_err(|e| anyhow!("{e}"))?;
        self.stats(dev, c, connects)
    }

    fn stats(&self, dev: &DeviceSession, c: &Corrupter, connects: u64) -> Result<()> {
        let d = dev.counters();
        let i = c.injected;
        let v = serde_json::json!({
            "actuation_received": d.actuation,
            "actuation_lost": d.lost,
            "host_hellos": d.hellos,
            "host_connects": connects,
            "watchdog": d.watchdog,
            "fifo_overflows": d.fifo_overflows,
            "fifo_underruns": d.fifo_underruns,
            "bad_frames_received": d.stream.bad_crc + d.stream.truncated + d.stream.bad_length,
            "injected": { "bad_crc": i.bad_crc, "truncated": i.truncated, "garbage_bursts": i.garbage_bursts, "garbage_bytes": i.garbage_bytes },
        });
        let path = self.dir.join("stats.json");
        evflow_engine::atomic_file::write_atomically(&path, serde_json::to_string_pretty(&v)?)
            .with_context(|| format!("{}: cannot write", path.display()))
    }

    fn finish(self, dev: &DeviceSession, c: &Corrupter, connects: u64) -> Result<()> {
        self.stats(dev, c, connects)?;
        self.actuation.finish().map_err(|e| anyhow!("{e}"))?;
        self.device.finish().map_err(|e| anyhow!("{e}"))?;
        Ok(())
    }
}
