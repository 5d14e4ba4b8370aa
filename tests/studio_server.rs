//! The studio's server from outside, without a browser: who may connect
//! (loopback by default; a public address only with `--studio-public`, and
//! then only with the one-time token, on the page and on the WebSocket;
//! no foreign Host or Origin), what the page is told first, and that a
//! browser that stops reading does not hold the session up.

use crate::studio_common as common;

use serde_json::Value;
use std::process::Command;
use std::time::{Duration, Instant};
use tungstenite::Message;

#[test]
fn a_public_address_needs_the_flag() {
    let tmp = tempfile::tempdir().unwrap();
    let out = Command::new(common::evflow())
        .arg("live")
        .arg(evflow_tests::root().join("graphs/texture-live.toml"))
        .arg("--session")
        .arg(tmp.path().join("s"))
        .args(["--no-realtime", "--duration", "0.2", "-q", "--studio", "0.0.0.0:0"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("not a loopback address") && err.contains("--studio-public"), "{err}");
}

#[test]
fn a_taken_port_stops_the_session_before_it_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let out = Command::new(common::evflow())
        .arg("live")
        .arg(evflow_tests::root().join("graphs/texture-live.toml"))
        .arg("--session")
        .arg(tmp.path().join("s"))
        .args(["--no-realtime", "--duration", "0.2", "-q", "--studio", &addr])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains(&format!("studio: cannot listen on {addr}")), "{err}");
    assert!(!tmp.path().join("s").exists(), "no session folder was made");
}

#[test]
fn a_public_studio_requires_its_token_everywhere() {
    let tmp = tempfile::tempdir().unwrap();
    let s = common::start("texture-live.toml", tmp.path(), &["127.0.0.1:0", "--studio-public"], &["--endless"]);
    let host = s.host();
    let token = s.url.split("token=").nth(1).expect("the address carries a token").to_string();
    assert_eq!(token.len(), 32);
    assert_eq!(common::get(&host, "/", "").0, 403, "no token");
    assert_eq!(common::get(&host, "/studio.js", "").0, 403, "no token for the files either");
    assert_eq!(common::get(&host, "/?token=0123456789abcdef0123456789abcdef", "").0, 403, "a wrong token");
    let (code, body) = common::get(&host, &format!("/?token={token}"), "");
    assert_eq!(code, 200);
    assert!(body.contains("evflow studio"));
    assert!(tungstenite::connect(format!("ws://{host}/ws")).is_err(), "a WebSocket without the token");
    let (mut ws, _) = tungstenite::connect(format!("ws://{host}/ws?token={token}")).expect("with the token");
    let Message::Text(t) = ws.read().unwrap() else { panic!("a text message first") };
    let hello: Value = serde_json::from_str(t.as_str()).unwrap();
    assert_eq!(hello["type"], "hello");
    assert_eq!(hello["graph"]["name"], "texture-live");
    drop(ws);
    s.stop();
}

#[test]
fn a_loopback_studio_refuses_foreign_hosts_and_origins() {
    let tmp = tempfile::tempdir().unwrap();
    let s = common::start("mesh-live.toml", tmp.path(), &["127.0.0.1:0"], &["--endless"]);
    let host = s.host();
    assert_eq!(common::get(&host, "/", "").0, 200);
    assert_eq!(common::get(&host, "/nothing", "").0, 404);
    // A DNS-rebinding page reaches the port under another host name.
    let mut s2 = std::net::TcpStream::connect(&host).unwrap();
    use std::io::{Read, Write};
    write!(s2, "GET / HTTP/1.1\r\nHost: evil.example\r\nConnection: close\r\n\r\n").unwrap();
    let mut r = String::new();
    let _ = s2.read_to_string(&mut r);
    assert!(r.starts_with("HTTP/1.1 403"), "{r}");
    // Another site's page in the same browser opens the WebSocket.
    let mut req = tungstenite::client::IntoClientRequest::into_client_request(format!("ws://{host}/ws")).unwrap();
    req.headers_mut().insert("Origin", "http://evil.example".parse().unwrap());
    assert!(tungstenite::connect(req).is_err(), "a foreign origin");
    let mut req = tungstenite::client::IntoClientRequest::into_client_request(format!("ws://{host}/ws")).unwrap();
    req.headers_mut().insert("Origin", format!("http://{host}").parse().unwrap());
    let (mut ws, _) = tungstenite::connect(req).expect("the studio's own origin");
    let Message::Text(t) = ws.read().unwrap() else { panic!() };
    let hello: Value = serde_json::from_str(t.as_str()).unwrap();
    let vars: Vec<&str> = hello["vars"].as_array().unwrap().iter().map(|v| v["name"].as_str().unwrap()).collect();
    assert!(vars.contains(&"scene") && vars.contains(&"gain"), "{vars:?}");
    let scene = hello["vars"].as_array().unwrap().iter().find(|v| v["name"] == "scene").unwrap();
    assert_eq!(scene["uses"], serde_json::json!(["surface.scene", "edges.scene"]));
    // Steering over the socket: a scene switch lands at one tick for both nodes.
    ws.send(Message::text(r#"{"type":"set","id":7,"target":"scene","value":"4"}"#)).unwrap();
    let deadline = Instant::now() + Duration::from_secs(30);
    let (mut replied, mut ticks) = (false, Vec::new());
    while (!replied || ticks.len() < 2) && Instant::now() < deadline {
        let Message::Text(t) = ws.read().unwrap() else { continue };
        let v: Value = serde_json::from_str(t.as_str()).unwrap();
        if v["type"] == "reply" {
            assert_eq!(v["id"], 7);
            assert_eq!(v["ok"], true, "{v}");
            replied = true;
        }
        for e in v["events"].as_array().into_iter().flatten() {
            if e["param"] == "scene" {
                ticks.push(e["tick"].as_u64().unwrap());
            }
        }
    }
    assert!(replied, "a reply");
    assert_eq!(ticks.len(), 2, "both nodes changed: {ticks:?}");
    assert_eq!(ticks[0], ticks[1], "at one tick");
    drop(ws);
    s.stop();
}

/// The status line's code of a raw request `head` sent to `host`.
fn raw_status(host: &str, head: &str) -> String {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(host).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    s.write_all(head.as_bytes()).unwrap();
    let mut r = String::new();
    let _ = s.read_to_string(&mut r);
    r.lines().next().unwrap_or("").to_string()
}

#[test]
fn odd_or_doubled_host_headers_are_refused_and_idle_connections_do_not_starve_a_page() {
    let tmp = tempfile::tempdir().unwrap();
    let s = common::start("texture-live.toml", tmp.path(), &["127.0.0.1:0"], &["--endless"]);
    let host = s.host();
    let port = host.rsplit(':').next().unwrap().to_string();
    let get = |h: &str| raw_status(&host, &format!("GET / HTTP/1.1\r\n{h}Connection: close\r\n\r\n"));
    assert_eq!(get(&format!("Host: 127.0.0.1:{port}\r\n")), "HTTP/1.1 200 OK");
    for bad in [
        format!("Host: 127.0.0.1:{port}@evil.com\r\n"),
        format!("Host: 127.0.0.1:{port}\r\nHost: evil.example\r\n"),
        format!("Host: 127.0.0.1:{port}\r\nHost: 127.0.0.1:{port}\r\n"),
        "Host: 127.0.0.1:\r\n".to_string(),
        String::new(),
    ] {
        assert_eq!(get(&bad), "HTTP/1.1 400 Bad Request", "{bad:?}");
    }
    // 40 connections that never send a byte, held open: a page still loads.
    let idle: Vec<std::net::TcpStream> = (0..40).map(|_| std::net::TcpStream::connect(&host).unwrap()).collect();
    std::thread::sleep(Duration::from_millis(100));
    for k in 0..3 {
        assert_eq!(get(&format!("Host: 127.0.0.1:{port}\r\n")), "HTTP/1.1 200 OK", "request {k} beside 40 idle ones");
    }
    drop(idle);
    s.stop();
}

/// A TCP connection to `host` whose receive buffer is a few kilobytes
/// from the start (set before connecting), so a peer that is not read
/// from fills it within a second.
fn small_window(host: &str) -> std::net::TcpStream {
    use std::os::fd::FromRawFd;
    let addr: std::net::SocketAddrV4 = host.parse().unwrap();
    // SAFETY: a plain socket, option and connect; the fd is owned by the TcpStream after.
    unsafe {
        let fd = libc::socket(libc::AF_INET, libc::SOCK_STREAM, 0);
        assert!(fd >= 0);
        let size: libc::c_int = 2048;
        let p = &size as *const libc::c_int as *const libc::c_void;
        assert_eq!(libc::setsockopt(fd, libc::SOL_SOCKET, libc::SO_RCVBUF, p, 4), 0);
        let sa = libc::sockaddr_in {
            sin_family: libc::AF_INET as libc::sa_family_t,
            sin_port: addr.port().to_be(),
            sin_addr: libc::in_addr { s_addr: u32::from(*addr.ip()).to_be() },
            sin_zero: [0; 8],
        };
        let r = libc::connect(fd, &sa as *const _ as *const libc::sockaddr, std::mem::size_of_val(&sa) as u32);
        assert_eq!(r, 0, "connect");
        std::net::TcpStream::from_raw_fd(fd)
    }
}

#[test]
fn a_browser_that_stops_reading_loses_frames_not_ticks() {
    let tmp = tempfile::tempdir().unwrap();
    let s = common::start("texture-live.toml", tmp.path(), &["127.0.0.1:0"], &["--duration", "6"]);
    let host = s.host();
    // Connected, then never read again.
    let (_stuck, _) = tungstenite::client(format!("ws://{host}/ws"), small_window(&host)).unwrap();
    let started = Instant::now();
    let mut s = s;
    let status = s.child.wait().unwrap();
    let mut stdout = String::new();
    std::io::Read::read_to_string(&mut s.child.stdout.take().unwrap(), &mut stdout).unwrap();
    let mut stderr = Vec::new();
    while let Ok(l) = s.lines.recv_timeout(Duration::from_secs(5)) {
        stderr.push(l);
    }
    assert!(status.success(), "{stdout}");
    let ticks: u64 = stdout.split(": ").nth(1).and_then(|r| r.split(' ').next()).and_then(|n| n.parse().ok()).unwrap();
    assert!(ticks >= 6000 && stdout.contains("stopped: duration"), "every tick ran: {stdout}");
    assert!(started.elapsed() < Duration::from_secs(40), "the session ended on time");
    let lost =
        stderr.iter().find(|l| l.contains("browsers lost")).unwrap_or_else(|| panic!("no frames lost? {stderr:?}"));
    let n: u64 = lost.split_whitespace().nth(3).and_then(|n| n.parse().ok()).unwrap();
    assert!(n > 0, "{lost}");
}

/// A browser that joins a running session late gets its recent frames
/// first: the page's "last 10 s" starts full (it showed 0.6 s of a session
/// joined 8 s in) (issue 37, point 12).
#[test]
fn a_browser_joining_late_gets_the_recent_seconds() {
    let tmp = tempfile::tempdir().unwrap();
    let s = common::start("display-live.toml", tmp.path(), &["127.0.0.1:0"], &["--duration", "30"]);
    let host = s.host();
    std::thread::sleep(Duration::from_secs(4));
    let (mut ws, _) = tungstenite::client(format!("ws://{host}/ws"), std::net::TcpStream::connect(&host).unwrap())
        .expect("the websocket");
    let mut first_t0 = None;
    let mut last_t = 0.0;
    let started = Instant::now();
    while started.elapsed() < Duration::from_secs(20) && last_t < 3.0 {
        let Ok(Message::Text(m)) = ws.read() else { continue };
        let v: Value = serde_json::from_str(m.as_str()).unwrap();
        if v["type"] != "frame" {
            continue;
        }
        if first_t0.is_none() {
            first_t0 = v["taps"].as_array().and_then(|t| t.first()).and_then(|t| t["t0"].as_f64());
        }
        last_t = v["t"].as_f64().unwrap_or(0.0);
    }
    let first = first_t0.expect("frames with samples arrive");
    assert!(last_t >= 3.0, "joined {last_t} s in");
    assert!(first < 0.5, "the first frame it gets starts at {first} s, not when it joined ({last_t} s)");
    drop(s);
}
