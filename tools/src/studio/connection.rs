//! One connection to the studio: its request head parsed with `httparse`
//! and checked (GET only; a loopback `Host` unless public; the token when
//! one is required; a WebSocket only from the studio's own origin), then a
//! file of the page, or the browser's WebSocket (`tungstenite`): `hello`
//! and what was published, then the frames from its bounded queue, and
//! its parameter changes to [`super::steer`].

use super::hub::Hub;
use super::{assets, steer, token};
use evflow_engine::live::Control;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tungstenite::Message;

/// Connections (page loads and WebSockets) served at once.
pub(crate) const MAX_CONNECTIONS: usize = 32;
/// Connections still waiting for their request head; past it, the oldest
/// of them is closed to make room (an idle connection must not hold the
/// place of a browser's real request).
pub(crate) const MAX_PENDING: usize = 8;
/// Largest request head accepted.
const MAX_HEAD: usize = 8192;
/// How long a connection may take to send its request head.
const HEAD_DEADLINE: Duration = Duration::from_secs(3);
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

/// What every connection shares.
pub(crate) struct Ctx {
    pub(crate) hub: Arc<Hub>,
    pub(crate) hello: Arc<str>,
    /// Sent after `hello` (a recorded session's whole data, results).
    pub(crate) initial: Mutex<Vec<Arc<str>>>,
    pub(crate) token: Option<String>,
    pub(crate) control: Option<Arc<Mutex<Control>>>,
    pub(crate) stop: Arc<AtomicBool>,
    pub(crate) public: bool,
    pub(crate) active: AtomicUsize,
    /// Connections that have not sent their head yet, oldest first: an id
    /// and the flag that closes it.
    pub(crate) pending: Mutex<std::collections::VecDeque<(u64, Arc<AtomicBool>)>>,
}

impl Ctx {
    /// Notes a new connection as waiting for its head (closing the oldest
    /// waiting one when [`MAX_PENDING`] are); returns its flag.
    pub(crate) fn admit(&self, id: u64) -> Arc<AtomicBool> {
        let flag = Arc::new(AtomicBool::new(false));
        let mut p = self.pending.lock().unwrap_or_else(|e| e.into_inner());
        while p.len() >= MAX_PENDING {
            if let Some((_, old)) = p.pop_front() {
                old.store(true, Ordering::Release);
            }
        }
        p.push_back((id, flag.clone()));
        flag
    }

    /// Whether a connection waits for its head that could be closed to
    /// make room for a new one.
    pub(crate) fn any_pending(&self) -> bool {
        !self.pending.lock().unwrap_or_else(|e| e.into_inner()).is_empty()
    }

    /// Closes the oldest connection still waiting for its head.
    pub(crate) fn evict_oldest(&self) {
        if let Some((_, old)) = self.pending.lock().unwrap_or_else(|e| e.into_inner()).pop_front() {
            old.store(true, Ordering::Release);
        }
    }

    /// The connection `id` has its head (or is done): no longer waiting.
    pub(crate) fn settled(&self, id: u64) {
        self.pending.lock().unwrap_or_else(|e| e.into_inner()).retain(|(i, _)| *i != id);
    }
}

/// Reads (without consuming) a whole request head, giving up after
/// [`HEAD_DEADLINE`] or as soon as `closed` is set.
fn peek_head(s: &TcpStream, closed: &AtomicBool) -> Option<Vec<u8>> {
    let mut buf = vec![0u8; MAX_HEAD];
    let deadline = Instant::now() + HEAD_DEADLINE;
    // Short reads, so that `closed` is seen within milliseconds.
    let _ = s.set_read_timeout(Some(Duration::from_millis(10)));
    while Instant::now() < deadline && !closed.load(Ordering::Acquire) {
        let n = match s.peek(&mut buf) {
            Ok(0) => return None,
            Ok(n) => n,
            Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => continue,
            Err(_) => return None,
        };
        if let Some(end) = buf[..n].windows(4).position(|w| w == b"\r\n\r\n") {
            buf.truncate(end + 4);
            let _ = s.set_read_timeout(Some(Duration::from_secs(3)));
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

/// The host name of a `Host` header value, `NAME` or `NAME:PORT` (an
/// IPv6 address in brackets), or `None` when it is anything else
/// (`127.0.0.1:8798@evil.com`, a path, a user, spaces, an empty port).
fn host_name(host: &str) -> Option<&str> {
    let (name, port) = if let Some(rest) = host.strip_prefix('[') {
        let (addr, after) = rest.split_once(']')?;
        addr.parse::<std::net::Ipv6Addr>().ok()?;
        (addr, if after.is_empty() { None } else { Some(after.strip_prefix(':')?) })
    } else {
        match host.split_once(':') {
            Some((n, p)) => (n, Some(p)),
            None => (host, None),
        }
    };
    if let Some(p) = port {
        if p.is_empty() || p.len() > 5 || !p.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
    }
    let plain = |b: u8| b.is_ascii_alphanumeric() || b == b'-' || b == b'.';
    if name.is_empty() || !(host.starts_with('[') || name.bytes().all(plain)) {
        return None;
    }
    Some(name)
}

/// True for `127.0.0.1`, `[::1]`, `localhost` (with any port), and
/// nothing malformed ([`host_name`]).
fn loopback_host(host: &str) -> bool {
    match host_name(host) {
        Some(h) if h.eq_ignore_ascii_case("localhost") => true,
        Some(h) => h.parse::<std::net::IpAddr>().is_ok_and(|ip| ip.is_loopback()),
        None => false,
    }
}

/// Serves one connection: a file, a refusal, or a browser's WebSocket.
/// `id` and `closed` are its place among the connections waiting for
/// their head ([`Ctx::admit`]).
pub(crate) fn connection(mut s: TcpStream, ctx: &Ctx, id: u64, closed: &AtomicBool) {
    let _ = s.set_nonblocking(false);
    let _ = s.set_write_timeout(Some(Duration::from_secs(3)));
    let head = peek_head(&s, closed);
    ctx.settled(id);
    let Some(head) = head else { return };
    let mut headers = [httparse::EMPTY_HEADER; 32];
    let mut req = httparse::Request::new(&mut headers);
    if !matches!(req.parse(&head), Ok(httparse::Status::Complete(_))) {
        let _ = s.read_exact(&mut vec![0; head.len()]);
        return respond(&mut s, "400 Bad Request", "text/plain", b"malformed request\n");
    }
    let target = req.path.unwrap_or("/").to_string();
    let hosts = req.headers.iter().filter(|h| h.name.eq_ignore_ascii_case("host")).count();
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
    if hosts != 1 || host_name(&host).is_none() {
        return refuse(&mut s, "400 Bad Request", "one Host header, NAME or NAME:PORT\n");
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
    let Some(super::hub::Joined { history, rx, drops }) = ctx.hub.join() else {
        let _ = ws.send(Message::text(r#"{"type":"error","message":"too many browsers are connected"}"#));
        let _ = ws.close(None);
        return;
    };
    let _ = ws.get_mut().set_read_timeout(Some(Duration::from_millis(2)));
    let _ = ws.get_mut().set_write_timeout(Some(Duration::from_secs(2)));
    let initial: Vec<Arc<str>> = ctx.initial.lock().unwrap_or_else(|e| e.into_inner()).clone();
    for m in std::iter::once(&ctx.hello).chain(&initial).chain(&history) {
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
        for h in [
            "evil.example:8080",
            "192.168.1.2:1",
            "",
            "[fe80::1]:2",
            "127.0.0.1:8798@evil.com",
            "127.0.0.1@evil.com",
            "localhost:80:81",
            "127.0.0.1:",
            "127.0.0.1:123456",
            "[::1]x",
            "127.0.0.1 :80",
            "127.0.0.1/evil",
        ] {
            assert!(!loopback_host(h), "{h}");
        }
    }

    #[test]
    fn host_names_are_name_or_name_and_port() {
        assert_eq!(host_name("studio.lab:8798"), Some("studio.lab"));
        assert_eq!(host_name("[::1]"), Some("::1"));
        assert_eq!(host_name("LOCALHOST"), Some("LOCALHOST"));
        assert!(loopback_host("LOCALHOST:1"));
        for h in ["a@b", "a:b", "[x]:1", "a b", "", ":80"] {
            assert_eq!(host_name(h), None, "{h}");
        }
    }
}
