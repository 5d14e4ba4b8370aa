//! One serial link per port, shared by the `serial.in` and `serial.out`
//! nodes that name it: the port, its I/O thread, and the lock-free rings
//! between that thread and the nodes' `process` (which runs on the live
//! runner's real-time thread and must not do I/O, lock or allocate).
//!
//! ```text
//!            ┌──────────── I/O thread (one per port) ────────────┐
//!  port ───▶ │ read (1 ms timeout) → StreamDecoder → HostSession │ ──touch ring──▶ serial.in.process
//!            │                                                   │ ──force ring──▶
//!  port ◀─── │ write ◀── HostSession (HELLO, heartbeat, fade) ◀──│ ◀─actuation ring── serial.out.process
//!            └───────────────────────────────────────────────────┘
//!   link state (atomics): connected, device faults, samples processed
//! ```
//!
//! Links are found by port path in a process-wide table, only while plans
//! are built (never on the real-time thread). The link lives while a node
//! holds it; dropping the last node stops the thread and closes the port.

use super::io;
pub use super::link_state::{LinkConfig, LinkReport, LinkState, ACTUATION_RING, EVENTS_KEPT, FORCE_RING, TOUCH_RING};
use super::message::Touch;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The ring ends `serial.in` reads.
pub struct InEnd {
    /// Touch frames.
    pub touch: rtrb::Consumer<Touch>,
    /// Force samples, N.
    pub force: rtrb::Consumer<f32>,
}

/// A running link.
pub struct Link {
    /// Its settings.
    pub config: LinkConfig,
    /// Shared state.
    pub state: Arc<LinkState>,
    /// The node that opened it.
    pub opened_by: String,
    in_end: Mutex<Option<InEnd>>,
    out_end: Mutex<Option<rtrb::Producer<f32>>>,
    thread: Mutex<Option<JoinHandle<()>>>,
}

static LINKS: Mutex<Vec<(String, Weak<Link>)>> = Mutex::new(Vec::new());

/// The link on `config.port` for the node `node` of type `kind`
/// (`serial.in`, `serial.out`) and its end of it, `take`n — refused when
/// another node of that type holds it — once the link is connected (or
/// its `wait` is over): what each serial node's `prepare` does.
pub fn claim<T>(
    config: &LinkConfig,
    node: &str,
    kind: &str,
    take: impl FnOnce(&Link) -> Option<T>,
) -> Result<(Arc<Link>, T), String> {
    let link = attach(config, node)?;
    let end = take(&link).ok_or_else(|| {
        format!(
            "port {} already has a `{kind}` node, in this plan or in a running one; one per port (a \
             replacement plan cannot take a port the running plan holds: stop the session and start anew)",
            config.port
        )
    })?;
    link.wait_connected()?;
    Ok((link, end))
}

/// The link on `config.port`: the running one, or a new one (its I/O
/// thread starts opening the port at once). `node` names the caller for
/// errors.
pub fn attach(config: &LinkConfig, node: &str) -> Result<Arc<Link>, String> {
    let mut links = LINKS.lock().map_err(|_| "the serial link table is poisoned".to_string())?;
    links.retain(|(_, w)| w.strong_count() > 0);
    if let Some(l) = links.iter().find(|(p, _)| *p == config.port).and_then(|(_, w)| w.upgrade()) {
        if l.config != *config {
            return Err(format!(
                "port {} is already opened by `{}` with other settings ({}); give every node on one port the same \
                 `baud`, `wait`, `timeout` and `retry`",
                config.port,
                l.opened_by,
                describe(&l.config)
            ));
        }
        return Ok(l);
    }
    let l = Link::start(config.clone(), node)?;
    links.push((config.port.clone(), Arc::downgrade(&l)));
    Ok(l)
}

fn describe(c: &LinkConfig) -> String {
    format!(
        "baud {}, wait {} s, timeout {} s, retry {} s",
        c.baud,
        c.wait.as_secs_f64(),
        c.timeout.as_secs_f64(),
        c.retry.as_secs_f64()
    )
}

impl Link {
    fn start(config: LinkConfig, node: &str) -> Result<Arc<Link>, String> {
        let state = Arc::new(LinkState::default());
        let (touch_tx, touch_rx) = rtrb::RingBuffer::new(TOUCH_RING);
        let (force_tx, force_rx) = rtrb::RingBuffer::new(FORCE_RING);
        let (act_tx, act_rx) = rtrb::RingBuffer::new(ACTUATION_RING);
        let thread = {
            let state = state.clone();
            let c = config.clone();
            std::thread::Builder::new()
                .name("evflow-serial".into())
                .spawn(move || io::run(c, state, touch_tx, force_tx, act_rx))
                .map_err(|e| format!("cannot start the I/O thread for {}: {e}", config.port))?
        };
        Ok(Arc::new(Link {
            config,
            state,
            opened_by: node.to_string(),
            in_end: Mutex::new(Some(InEnd { touch: touch_rx, force: force_rx })),
            out_end: Mutex::new(Some(act_tx)),
            thread: Mutex::new(Some(thread)),
        }))
    }

    /// The inbound rings, for the one `serial.in` of this port.
    pub fn take_in(&self) -> Option<InEnd> {
        let end = self.in_end.lock().ok()?.take();
        if end.is_some() {
            self.state.has_reader.store(true, Ordering::Relaxed);
        }
        end
    }

    /// The actuation ring, for the one `serial.out` of this port.
    pub fn take_out(&self, rate_hz: u16) -> Option<rtrb::Producer<f32>> {
        let end = self.out_end.lock().ok()?.take();
        if end.is_some() {
            self.state.actuation_hz.store(rate_hz, Ordering::Relaxed);
        }
        end
    }

    /// Waits up to `config.wait` for the link to come up; a `wait` of 0
    /// starts unconnected at once (the I/O thread keeps trying, and says
    /// why each attempt fails when the reason changes).
    pub fn wait_connected(&self) -> Result<(), String> {
        if self.config.wait.is_zero() {
            return Ok(());
        }
        let until = Instant::now() + self.config.wait;
        loop {
            if self.state.connected.load(Ordering::Acquire) {
                return Ok(());
            }
            if Instant::now() >= until {
                let why = self.state.report().last_error.unwrap_or_else(|| "the device did not answer HELLO".into());
                return Err(format!(
                    "no link to the device on {} within {} s: {why} (set `wait` to wait longer, 0 to start without \
                     the device)",
                    self.config.port,
                    self.config.wait.as_secs_f64()
                ));
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        self.state.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.get_mut().ok().and_then(Option::take) {
            let _ = t.join();
        }
    }
}
