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

use super::describe::Description;
use super::feed::{FeedState, Ingest};
use super::hub::Hub;
use super::{assets, steer, token};
use evflow_engine::live::{Control, Shared};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::Message;

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
/// Connections (page loads and WebSockets) served at once.
const MAX_CONNECTIONS: usize = 32;
/// Largest request head accepted.
const MAX_HEAD: usize = 8192;
/// The kernel's send buffer per browser (about a second of frames): a
/// browser that stops reading is found out within seconds, not after
/// megabytes of stale frames, and then loses frames in its queue.
const SEND_BUFFER: libc::c_int = 64 * 1024;

/// Bounds the kernel's send buffer of `s` (best effort).
fn bound_send_buffer(s: &TcpStream) {
    use std::os::fd::AsRawFd;
    let size = SEND_BUFFER;
    // SAFETY: setsockopt on an open socket with a pointer to a c_int of the given size.
    unsafe {
        libc::setsockopt(
            s.as_raw_fd(),
            libc::SOL_SOCKET,
            libc::SO_SNDBUF,
            &size as *const libc::c_int as *const libc::c_void,
            std::mem::size_of::<libc::c_int>() as libc::socklen_t,
        );
    }
}

struct Ctx {
    hub: Arc<Hub>,
    hello: Arc<str>,
    /// Sent after `hello` (a recorded session's whole data, results).
    initial: Mutex<Vec<Arc<str>>>,
    token: Option<String>,
    control: Option<Arc<Mutex<Control>>>,
    stop: Arc<AtomicBool>,
    public: bool,
    active: AtomicUsize,
}

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
                hub.broadcast(Arc::from(frame.to_string()));
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
        });
        let ctx2 = ctx.clone();
        let acceptor = std::thread::Builder::new().name("evflow-studio".into()).spawn(move || {
            while !ctx.stop.load(Ordering::Acquire) {
                match listener.accept() {
                    Ok((s, _)) => {
                        if ctx.active.load(Ordering::Acquire) >= MAX_CONNECTIONS {
                            continue; // dropped: closes the connection
                        }
                        ctx.active.fetch_add(1, Ordering::AcqRel);
                        let c = ctx.clone();
                        let spawned = std::thread::Builder::new().name("evflow-studio-conn".into()).spawn(move || {
                            connection(s, &c);
                            c.active.fetch_sub(1, Ordering::AcqRel);
                        });
                        if spawned.is_err() {
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

/// Reads (without consuming) a whole request head.
fn peek_head(s: &TcpStream) -> Option<Vec<u8>> {
    let mut buf = vec![0u8; MAX_HEAD];
    let deadline = Instant::now() + Duration::from_secs(3);
    while Instant::now() < deadline {
        let n = s.peek(&mut buf).ok()?;
        if n == 0 {
            return None;
        }
        if let Some(end) = buf[..n].windows(4).position(|w| w == b"\r\n\r\n") {
            buf.truncate(end + 4);
            return Some(buf);
        }
        if n == MAX_HEAD {
            return None;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    None
}

fn respond(s: &mut TcpStream, status: &str, ctype: &str, body: &[u8]) {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {ctype}\r\nContent-Length: {}\r\nCache-Control: no-store\r\n\
         X-Content-Type-Options: nosniff\r\nContent-Security-Policy: default-src 'self'; connect-src 'self'; \
         frame-ancestors 'none'\r\nConnection: close\r\n\r\n",
        body.len()
    );
    let _ = s.write_all(head.as_bytes()).and_then(|_| s.write_all(body)).and_then(|_| s.flush());
}

fn header<'a>(req: &'a httparse::Request, name: &str) -> Option<&'a str> {
    req.headers.iter().find(|h| h.name.eq_ignore_ascii_case(name)).and_then(|h| std::str::from_utf8(h.value).ok())
}

/// True for `127.0.0.1`, `[::1]`, `localhost` (with any port).
fn loopback_host(host: &str) -> bool {
    let h = if host.starts_with('[') { host.split(']').next().map(|h| &h[1..]) } else { host.split(':').next() };
    match h {
        Some("localhost") => true,
        Some(h) => h.parse::<std::net::IpAddr>().is_ok_and(|ip| ip.is_loopback()),
        None => false,
    }
}

fn connection(mut s: TcpStream, ctx: &Ctx) {
    let _ = s.set_nonblocking(false);
    let _ = s.set_read_timeout(Some(Duration::from_secs(3)));
    let _ = s.set_write_timeout(Some(Duration::from_secs(3)));
    let Some(head) = peek_head(&s) else { return };
    let mut headers = [httparse::EMPTY_HEADER; 32];
    let mut req = httparse::Request::new(&mut headers);
    if !matches!(req.parse(&head), Ok(httparse::Status::Complete(_))) {
        let _ = s.read_exact(&mut vec![0; head.len()]);
        return respond(&mut s, "400 Bad Request", "text/plain", b"malformed request\n");
    }
    let target = req.path.unwrap_or("/").to_string();
    let host = header(&req, "host").unwrap_or("").to_string();
    let origin = header(&req, "origin").map(str::to_string);
    let upgrade = header(&req, "upgrade").is_some_and(|u| u.eq_ignore_ascii_case("websocket"));
    let method = req.method.unwrap_or("").to_string();
    let refuse = |s: &mut TcpStream, status: &str, why: &str| {
        let _ = s.read_exact(&mut vec![0; head.len()]);
        respond(s, status, "text/plain; charset=utf-8", why.as_bytes());
    };
    if method != "GET" {
        return refuse(&mut s, "405 Method Not Allowed", "only GET\n");
    }
    if !ctx.public && !loopback_host(&host) {
        return refuse(&mut s, "403 Forbidden", "this studio serves loopback host names only\n");
    }
    if let Some(t) = &ctx.token {
        if !token::query(&target, "token").is_some_and(|g| token::matches(t, g)) {
            return refuse(
                &mut s,
                "403 Forbidden",
                "this studio needs its one-time token: open the address printed by evflow (…/?token=…)\n",
            );
        }
    }
    let path = target.split('?').next().unwrap_or("/");
    if path == "/ws" && upgrade {
        if origin.as_deref().is_some_and(|o| o != format!("http://{host}")) {
            return refuse(&mut s, "403 Forbidden", "WebSocket from another origin\n");
        }
        return websocket(s, ctx);
    }
    let _ = s.read_exact(&mut vec![0; head.len()]);
    match assets::get(path) {
        Some((ctype, body)) => respond(&mut s, "200 OK", ctype, body.as_bytes()),
        None => respond(&mut s, "404 Not Found", "text/plain", b"not found\n"),
    }
}

fn websocket(s: TcpStream, ctx: &Ctx) {
    bound_send_buffer(&s);
    let Ok(mut ws) = tungstenite::accept(s) else { return };
    let Some((rx, drops)) = ctx.hub.join() else {
        let _ = ws.send(Message::text(r#"{"type":"error","message":"too many browsers are connected"}"#));
        let _ = ws.close(None);
        return;
    };
    let _ = ws.get_mut().set_read_timeout(Some(Duration::from_millis(2)));
    let _ = ws.get_mut().set_write_timeout(Some(Duration::from_secs(2)));
    let initial: Vec<Arc<str>> = ctx.initial.lock().unwrap_or_else(|e| e.into_inner()).clone();
    for m in std::iter::once(&ctx.hello).chain(&initial) {
        if ws.send(Message::text(m.to_string())).is_err() {
            return;
        }
    }
    let mut told = Instant::now();
    'session: while !ctx.stop.load(Ordering::Acquire) {
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok(frame) => {
                if ws.send(Message::text(frame.to_string())).is_err() {
                    break;
                }
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
        }
        loop {
            match ws.read() {
                Ok(Message::Text(t)) => {
                    let reply = steer::handle(t.as_str(), ctx.control.as_deref());
                    if ws.send(Message::text(reply.to_string())).is_err() {
                        break 'session;
                    }
                }
                Ok(Message::Close(_)) => break 'session,
                Ok(_) => {}
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) =>
                {
                    break
                }
                Err(_) => break 'session,
            }
        }
        if told.elapsed() >= Duration::from_secs(1) {
            let n = drops.load(Ordering::Relaxed);
            if ws.send(Message::text(format!(r#"{{"type":"drops","frames":{n}}}"#))).is_err() {
                break;
            }
            told = Instant::now();
        }
    }
    let _ = ws.close(None);
    let _ = ws.flush();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_hosts() {
        for h in ["127.0.0.1:8080", "localhost:1", "[::1]:99", "127.0.0.2"] {
            assert!(loopback_host(h), "{h}");
        }
        for h in ["evil.example:8080", "192.168.1.2:1", "", "[fe80::1]:2"] {
            assert!(!loopback_host(h), "{h}");
        }
    }

    #[test]
    fn a_public_address_needs_the_flag() {
        let cfg = StudioConfig { addr: "0.0.0.0:0".parse().unwrap(), public: false };
        let e = Studio::serve(&cfg, "{}".into(), vec![], None).err().unwrap();
        assert!(e.to_string().contains("--studio-public"), "{e}");
    }
}
