//! The studio's server: plain std threads over a `TcpListener` — HTTP/1.1
//! requests parsed with `httparse`, the page's WebSocket by `tungstenite`
//! (docs/studio.md says why this stack). One thread accepts, one per
//! browser, one (live sessions) turns the feed into frames.
//!
//! Security: loopback by default; any other address needs `public`, and
//! then every request (page, files, WebSocket) must carry the one-time
//! token. The `Host` header must name a loopback host unless public (a
//! DNS-rebinding page cannot reach a loopback studio), and a WebSocket's
//! `Origin`, when present, must be the studio itself (another site's page
//! open in the same browser cannot steer the session).

use super::connection::{connection, Ctx, MAX_CONNECTIONS};
use super::describe::Description;
use super::feed::{FeedState, Ingest};
use super::hub::Hub;
use super::token;
use evflow_engine::live::{Control, Shared};
use std::net::{SocketAddr, TcpListener};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Where and how to serve.
#[derive(Debug, Clone)]
pub struct StudioConfig {
    /// Address to listen on (port 0: any free port).
    pub addr: SocketAddr,
    /// Allow a non-loopback address (a token is then required).
    pub public: bool,
}

/// Why the studio cannot serve.
#[derive(Debug, thiserror::Error)]
pub enum StudioError {
    /// A non-loopback address without `public`.
    #[error(
        "studio address {0} is not a loopback address: serving the studio beyond this machine needs \
         --studio-public (the page then asks for a one-time token printed here)"
    )]
    NotLoopback(SocketAddr),
    /// The address cannot be bound.
    #[error("studio: cannot listen on {addr}: {why}")]
    Bind {
        /// The address.
        addr: SocketAddr,
        /// Why.
        why: std::io::Error,
    },
    /// Any other I/O failure while starting.
    #[error("studio: {0}")]
    Io(#[from] std::io::Error),
}

/// Frames per second sent to each browser.
const FRAME_PERIOD: Duration = Duration::from_millis(50);
/// A studio's address, bound but not yet served: bind before a session
/// starts, so that a taken port stops nothing that runs.
pub struct Bound {
    listener: TcpListener,
    addr: SocketAddr,
    token: Option<String>,
    public: bool,
}

impl Bound {
    /// Checks the address (loopback unless `public`) and listens on it.
    pub fn bind(cfg: &StudioConfig) -> Result<Self, StudioError> {
        if !cfg.addr.ip().is_loopback() && !cfg.public {
            return Err(StudioError::NotLoopback(cfg.addr));
        }
        let listener = TcpListener::bind(cfg.addr).map_err(|why| StudioError::Bind { addr: cfg.addr, why })?;
        let addr = listener.local_addr()?;
        listener.set_nonblocking(true)?;
        let token = if cfg.public { Some(token::new_token()?) } else { None };
        Ok(Self { listener, addr, token, public: cfg.public })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Serves the page of a live session (see [`Studio::start_live`]).
    pub fn start_live(
        self,
        d: &Description,
        control: Arc<Mutex<Control>>,
        shared: Arc<Shared>,
    ) -> Result<(Studio, Ingest), StudioError> {
        let mut studio = self.serve(d.hello.to_string(), Vec::new(), Some(control))?;
        let feed = Arc::new(Mutex::new(FeedState::new(d, Some(shared))));
        let ingest = Ingest { feed: feed.clone() };
        let (stop, hub) = (studio.stop.clone(), studio.hub.clone());
        studio.threads.push(std::thread::Builder::new().name("evflow-studio-feed".into()).spawn(move || {
            let mut next = Instant::now();
            while !stop.load(Ordering::Acquire) {
                next += FRAME_PERIOD;
                std::thread::sleep(next.saturating_duration_since(Instant::now()));
                let frame = {
                    let mut f = feed.lock().unwrap_or_else(|e| e.into_inner());
                    f.frame(hub.drops.load(Ordering::Relaxed), hub.len())
                };
                hub.broadcast_frame(Arc::from(frame.to_string()));
            }
        })?);
        Ok((studio, ingest))
    }

    /// Serves a page that receives `hello` then `initial` on connecting
    /// (and steers `control`, if any).
    fn serve(
        self,
        hello: String,
        initial: Vec<String>,
        control: Option<Arc<Mutex<Control>>>,
    ) -> Result<Studio, StudioError> {
        let Bound { listener, addr, token, public } = self;
        let stop = Arc::new(AtomicBool::new(false));
        let hub = Arc::new(Hub::default());
        let ctx = Arc::new(Ctx {
            hub: hub.clone(),
            hello: Arc::from(hello),
            initial: Mutex::new(initial.into_iter().map(Arc::from).collect()),
            token: token.clone(),
            control,
            stop: stop.clone(),
            public,
            active: AtomicUsize::new(0),
            pending: Mutex::new(std::collections::VecDeque::new()),
        });
        let ctx2 = ctx.clone();
        let acceptor = std::thread::Builder::new().name("evflow-studio".into()).spawn(move || {
            let mut next_id = 0u64;
            while !ctx.stop.load(Ordering::Acquire) {
                match listener.accept() {
                    Ok((s, _)) => {
                        if ctx.active.load(Ordering::Acquire) >= MAX_CONNECTIONS {
                            if !ctx.any_pending() {
                                continue; // dropped: closes the connection
                            }
                            // Full of connections that have sent nothing:
                            // the oldest makes room (it ends within ms).
                            ctx.evict_oldest();
                        }
                        ctx.active.fetch_add(1, Ordering::AcqRel);
                        next_id += 1;
                        let (id, closed) = (next_id, ctx.admit(next_id));
                        let c = ctx.clone();
                        let spawned = std::thread::Builder::new().name("evflow-studio-conn".into()).spawn(move || {
                            connection(s, &c, id, &closed);
                            c.active.fetch_sub(1, Ordering::AcqRel);
                        });
                        if spawned.is_err() {
                            ctx.settled(id);
                            ctx.active.fetch_sub(1, Ordering::AcqRel);
                        }
                    }
                    Err(_) => std::thread::sleep(Duration::from_millis(20)),
                }
            }
        })?;
        Ok(Studio { addr, token, stop, hub, ctx: ctx2, threads: vec![acceptor] })
    }
}

/// A running studio.
pub struct Studio {
    addr: SocketAddr,
    token: Option<String>,
    stop: Arc<AtomicBool>,
    hub: Arc<Hub>,
    ctx: Arc<Ctx>,
    threads: Vec<JoinHandle<()>>,
}

impl Studio {
    /// Serves the page of a live session: `control` is the session's
    /// command queue (shared with the console), `shared` its counters.
    /// Returns the studio and the intake the session's threads feed.
    pub fn start_live(
        cfg: &StudioConfig,
        d: &Description,
        control: Arc<Mutex<Control>>,
        shared: Arc<Shared>,
    ) -> Result<(Self, Ingest), StudioError> {
        Bound::bind(cfg)?.start_live(d, control, shared)
    }

    /// Serves a page that receives `hello` then `initial` on connecting
    /// (and steers `control`, if any).
    pub(crate) fn serve(
        cfg: &StudioConfig,
        hello: String,
        initial: Vec<String>,
        control: Option<Arc<Mutex<Control>>>,
    ) -> Result<Self, StudioError> {
        Bound::bind(cfg)?.serve(hello, initial, control)
    }

    /// Sends `message` to every browser, and to every browser that
    /// connects later (a result that arrives after the page opened).
    pub(crate) fn publish(&self, message: String) {
        let m: Arc<str> = Arc::from(message);
        self.ctx.initial.lock().unwrap_or_else(|e| e.into_inner()).push(m.clone());
        self.hub.broadcast(m);
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address (with the token, if one is required).
    pub fn url(&self) -> String {
        match &self.token {
            Some(t) => format!("http://{}/?token={t}", self.addr),
            None => format!("http://{}/", self.addr),
        }
    }

    /// The one-time token, when serving beyond loopback.
    pub fn token(&self) -> Option<&str> {
        self.token.as_deref()
    }

    /// Frames the browsers lost so far (queues full).
    pub fn frames_dropped(&self) -> u64 {
        self.hub.drops.load(Ordering::Relaxed)
    }

    /// Browsers connected now.
    pub fn browsers(&self) -> usize {
        self.hub.len()
    }

    /// Stops serving: the browsers are disconnected and the threads end.
    pub fn close(self) {
        self.stop.store(true, Ordering::Release);
        self.hub.close();
        for t in self.threads {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_public_address_needs_the_flag() {
        let cfg = StudioConfig { addr: "0.0.0.0:0".parse().unwrap(), public: false };
        let e = Studio::serve(&cfg, "{}".into(), vec![], None).err().unwrap();
        assert!(e.to_string().contains("--studio-public"), "{e}");
    }
}
