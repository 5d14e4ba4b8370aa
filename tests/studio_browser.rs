//! The studio in a real browser: a short simulated-lab session
//! (graphs/texture-live.toml) runs with `--studio`; headless Chromium
//! opens the page and is driven through the Chrome DevTools Protocol. The
//! test checks that traces arrive and move, changes the texture from the
//! page (typing into its field and pressing its button), finds that change
//! applied at one tick in the session's event log — the same tick the page
//! was told — and replayed bit for bit, sees a change beyond the declared
//! limits refused with its reason on the page, and saves a screenshot
//! (`$CARGO_TARGET_TMPDIR/studio.png`, and the file named by
//! `EVFLOW_STUDIO_SCREENSHOT` if set: that is how docs/studio.png is made).
//!
//! Needs Debian's `chromium` (`.ci/run` installs it). Without it the test
//! fails, unless `EVFLOW_SKIP_BROWSER=1` says to skip it, which it then
//! says loudly.

#[path = "studio_common.rs"]
mod common;

use serde_json::{json, Value};
use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use tungstenite::{stream::MaybeTlsStream, Message, WebSocket};

fn chromium() -> Option<String> {
    if let Ok(p) = std::env::var("EVFLOW_CHROMIUM") {
        return Some(p);
    }
    ["chromium", "chromium-browser", "google-chrome"].into_iter().find_map(|c| {
        Command::new(c).arg("--version").output().ok().filter(|o| o.status.success()).map(|_| c.to_string())
    })
}

struct Browser {
    child: Child,
    _profile: tempfile::TempDir,
    port: u16,
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn launch(exe: &str, url: &str) -> Browser {
    let profile = tempfile::tempdir().unwrap();
    let mut child = Command::new(exe)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1400,1900",
            "--remote-debugging-port=0",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(url)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start chromium");
    let err = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for l in BufReader::new(err).lines().map_while(Result::ok) {
            if let Some(rest) = l.split("DevTools listening on ws://").nth(1) {
                let _ = tx.send(rest.to_string());
            }
        }
    });
    let line = rx.recv_timeout(Duration::from_secs(60)).expect("chromium printed its DevTools address");
    let port = line.split('/').next().unwrap().rsplit(':').next().unwrap().parse().unwrap();
    Browser { child, _profile: profile, port }
}

/// A DevTools session with one page.
struct Cdp {
    ws: WebSocket<MaybeTlsStream<TcpStream>>,
    next: u64,
}

impl Cdp {
    fn attach(b: &Browser, studio_url: &str) -> Self {
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            let (code, body) = common::get(&format!("127.0.0.1:{}", b.port), "/json/list", "");
            if code == 200 {
                let list: Value = serde_json::from_str(&body).unwrap_or(json!([]));
                let page = list
                    .as_array()
                    .into_iter()
                    .flatten()
                    .find(|t| t["type"] == "page" && t["url"].as_str().is_some_and(|u| u.starts_with(studio_url)));
                if let Some(ws) = page.and_then(|p| p["webSocketDebuggerUrl"].as_str()) {
                    let (ws, _) = tungstenite::connect(ws).expect("DevTools WebSocket");
                    return Self { ws, next: 1 };
                }
            }
            assert!(Instant::now() < deadline, "chromium never listed the studio page: {body}");
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    fn call(&mut self, method: &str, params: Value) -> Value {
        let id = self.next;
        self.next += 1;
        self.ws.send(Message::text(json!({ "id": id, "method": method, "params": params }).to_string())).unwrap();
        loop {
            let m = self.ws.read().expect("DevTools reply");
            if let Message::Text(t) = m {
                let v: Value = serde_json::from_str(t.as_str()).unwrap();
                if v["id"] == id {
                    assert!(v.get("error").is_none(), "{method}: {v}");
                    return v["result"].clone();
                }
            }
        }
    }

    /// Evaluates `expr` in the page; its value (JSON-able).
    fn eval(&mut self, expr: &str) -> Value {
        let r = self.call("Runtime.evaluate", json!({ "expression": expr, "returnByValue": true }));
        assert!(r.get("exceptionDetails").is_none(), "{expr}: {r}");
        r["result"]["value"].clone()
    }

    /// Waits until `expr` is true in the page.
    fn until(&mut self, expr: &str, secs: u64) {
        let deadline = Instant::now() + Duration::from_secs(secs);
        while self.eval(expr) != json!(true) {
            assert!(Instant::now() < deadline, "timed out waiting for `{expr}`");
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

fn base64_decode(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let bytes: Vec<u8> = s.bytes().filter(|&c| c != b'=' && !c.is_ascii_whitespace()).map(val).collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for ch in bytes.chunks(4) {
        let n = ch.iter().enumerate().fold(0u32, |acc, (i, &v)| acc | (u32::from(v) << (18 - 6 * i)));
        out.extend_from_slice(&n.to_be_bytes()[1..ch.len()]);
    }
    out
}

#[test]
fn base64_round_trip() {
    assert_eq!(base64_decode("TWFu"), b"Man");
    assert_eq!(base64_decode("TWE="), b"Ma");
    assert_eq!(base64_decode("TQ=="), b"M");
}

/// Chromium, or `None` (after saying so loudly) when it is missing and
/// `EVFLOW_SKIP_BROWSER=1` allows that.
fn browser_or_skip() -> Option<String> {
    let exe = chromium();
    if exe.is_none() {
        if std::env::var("EVFLOW_SKIP_BROWSER").is_ok_and(|v| v == "1") {
            eprintln!("\n*** SKIPPED: no chromium; EVFLOW_SKIP_BROWSER=1 says to skip the studio's browser test ***\n");
            return None;
        }
        panic!("the studio's browser test needs chromium (`apt-get install chromium`; .ci/run does it), or EVFLOW_SKIP_BROWSER=1");
    }
    exe
}

#[test]
fn the_page_shows_a_recorded_session_with_its_events_and_replay_check() {
    let Some(exe) = browser_or_skip() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let s = tmp.path().join("s");
    let out = Command::new(common::evflow())
        .arg("live")
        .arg(evflow_tests::root().join("graphs/texture-live.toml"))
        .arg("--session")
        .arg(&s)
        .args(["--no-realtime", "--miss-streak", "0", "-q", "--duration", "3"])
        .args(["--change", "1:texture=2", "--change", "1.5:limit.enable=false", "--change", "2:limit.enable=true"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut studio = Command::new(common::evflow())
        .arg("studio")
        .arg(&s)
        .args(["--addr", "127.0.0.1:0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(studio.stdout.take().unwrap()).lines();
    let _studio = common::KillOnDrop(studio);
    let url = lines
        .by_ref()
        .map_while(Result::ok)
        .find_map(|l| l.strip_prefix("studio: ").map(str::to_string))
        .expect("evflow studio prints its address");
    let browser = launch(&exe, &url);
    let mut cdp = Cdp::attach(&browser, &url);
    cdp.until("!!(window.studio && studio.hello && studio.frames >= 1)", 60);
    assert_eq!(cdp.eval("studio.hello.mode"), json!("recorded"));
    // The whole session is there, at most ~4000 pairs per stream.
    let i = cdp.eval("studio.taps.findIndex(t => t.node === 'limit' && t.port === 'out')").as_i64().unwrap();
    let last = cdp.eval(&format!("studio.series[{i}].t.at(-1)")).as_f64().unwrap();
    assert!((2.9..3.02).contains(&last), "the trace covers the session: ends at {last} s");
    // Its events, on the time axis.
    let ev = cdp.eval("studio.events.filter(e => e.event === 'set').map(e => [e.t, e.node + '.' + e.param, e.value])");
    let row =
        |k: usize| (ev[k][0].as_f64().unwrap(), ev[k][1].as_str().unwrap().to_string(), ev[k][2].as_f64().unwrap());
    assert_eq!(row(0), (1.0, "interp.texture".to_string(), 2.0), "{ev}");
    assert_eq!(row(1), (1.5, "limit.enable".to_string(), 0.0), "{ev}");
    // The limiter's states over time: armed, fading, faded, armed again, then the stop's fade.
    let segs = cdp.eval("studio.timelines[0].segments.map(s => s.state)");
    let states: Vec<&str> = segs.as_array().unwrap().iter().map(|s| s.as_str().unwrap()).collect();
    let at = |w: &str| states.iter().position(|s| *s == w);
    assert!(at("armed") < at("faded") && states[at("faded").unwrap()..].contains(&"armed"), "{states:?}");
    // Read from the recorded `limit.state`, the node's own report: faded
    // in the window of the disable (the 10 ms fade ends inside it), armed
    // in the window of the re-arm, and the stop's fade at the end.
    assert_eq!(cdp.eval("studio.limiters.limit.source"), json!("node"));
    let mut t0 =
        |w: &str| cdp.eval(&format!("studio.timelines[0].segments.find(s => s.state === '{w}' && s.t0 > 1).t0"));
    assert!((t0("faded").as_f64().unwrap() - 1.5).abs() < 1e-9, "{states:?}");
    assert!((t0("armed").as_f64().unwrap() - 2.0).abs() < 1e-9, "{states:?}");
    assert_eq!(states.last(), Some(&"faded"), "the stop fades the limiter out: {states:?}");
    // The limiter panel gives the session's peaks, not its last window's
    // (the fade-out: it read "peak in 0 out 0.265" where the output
    // peaked at 0.66), and says its input was not recorded.
    let info = cdp.eval("document.getElementById('limiter-info-limit').textContent");
    let out_peak =
        cdp.eval(&format!("Math.max(...studio.series[{i}].hi.map(Math.abs), ...studio.series[{i}].lo.map(Math.abs))"));
    let want = format!(
        "peak over the session in – (input not recorded) out {}",
        cdp.eval(&format!("plot.fmt({out_peak})")).as_str().unwrap()
    );
    assert!(info.as_str().unwrap().contains(&want), "{info} / {want}");
    // The Steer panel lists the session's changes (it was an empty list).
    let changes = cdp.eval("[...document.querySelectorAll('#steer-log li')].map(l => l.textContent)");
    assert_eq!(changes[0], json!("at 1.000 s: interp.texture = 2"), "{changes}");
    assert_eq!(changes[1], json!("at 1.500 s: limit.enable = 0"), "{changes}");
    // The Finger panel shows the recorded finger (it said none was tapped)
    // and says how to record the grid's inputs.
    let finger = cdp.eval("document.getElementById('scene-note').textContent");
    assert!(
        finger.as_str().unwrap().contains("--tap") && finger.as_str().unwrap().contains("user.x × user.y"),
        "{finger}"
    );
    // The traces' heading says what they show (it read "last scrub s").
    let heading = cdp.eval("document.getElementById('traces-window').textContent");
    assert!(heading.as_str().is_some_and(|h| h.contains("whole session") && !h.contains("last")), "{heading}");
    // Scrubbing: a narrower span shows fewer pairs.
    cdp.eval("document.getElementById('scrub-span').value = 0.5; document.getElementById('scrub-span').dispatchEvent(new Event('input'))");
    assert_eq!(cdp.eval("studio.view[1] - studio.view[0] < 0.51"), json!(true));
    // The replay check's result arrives.
    cdp.until("!!studio.replay", 120);
    assert_eq!(cdp.eval("studio.replay.ok"), json!(true), "{}", cdp.eval("studio.replay.summary"));
    assert_eq!(cdp.eval("document.getElementById('replay-check').textContent.startsWith('✓ reproduced')"), json!(true));
}

#[test]
fn the_page_shows_and_steers_a_live_session_in_chromium() {
    let Some(exe) = browser_or_skip() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let session =
        common::start("texture-live.toml", tmp.path(), &["127.0.0.1:0"], &["--endless", "--change", "0.5:gain=0.8"]);
    let browser = launch(&exe, &session.url);
    let mut cdp = Cdp::attach(&browser, &session.url);

    // A scripted change shows in the Steer field of its variable (the field
    // kept the graph's value before).
    cdp.until("document.getElementById('var-gain') && document.getElementById('var-gain').value === '0.8'", 30);

    // Traces arrive and move.
    cdp.until("!!(window.studio && studio.hello && studio.frames > 5)", 60);
    let tap = cdp.eval("studio.taps.findIndex(t => t.node === 'limit' && t.port === 'out')");
    let i = tap.as_i64().expect("limit.out is among the taps");
    assert!(i >= 0, "limit.out is tapped");
    let probe = format!("(() => {{ const s = studio.series[{i}]; return [s.t.length, s.t[s.t.length - 1], Math.min(...s.lo), Math.max(...s.hi)]; }})()");
    let a = cdp.eval(&probe);
    std::thread::sleep(Duration::from_millis(1500));
    let b = cdp.eval(&probe);
    assert!(b[0].as_f64() > a[0].as_f64() && b[1].as_f64() > a[1].as_f64(), "the trace grows: {a} then {b}");
    assert!(b[3].as_f64().unwrap() > b[2].as_f64().unwrap(), "the actuation moves: {b}");
    assert!(
        cdp.eval("document.getElementById('limiter-limit').textContent") == json!("ARMED"),
        "the limiter shows armed"
    );
    assert_eq!(cdp.eval("studio.limiters.limit.source"), json!("node"), "the state the node reports");
    assert_eq!(
        cdp.eval("document.getElementById('limiter-info-limit').textContent.includes('state reported by the node')"),
        json!(true)
    );
    assert!(cdp.eval("studio.compute.t.length > 5") == json!(true), "compute times arrive");
    // The finger view: the texture's (load, velocity) grid and the four cells in use.
    assert_eq!(cdp.eval("studio.hello.scene.kind"), json!("grid"));
    assert_eq!(cdp.eval("studio.hello.scene.grids[0].loads_g.join()"), json!("60,110"));
    cdp.until("Array.isArray(studio.cells) && studio.cells.length === 4", 20);

    // A change beyond the declared limits is refused by the server, with the reason on the page.
    cdp.eval("document.getElementById('var-gain').value = '1e9'; document.getElementById('set-gain').click()");
    cdp.until("studio.replies.length >= 1", 20);
    let r = cdp.eval("studio.replies[0]");
    assert_eq!(r["ok"], false, "{r}");
    assert!(r["message"].as_str().unwrap().contains("outside its limits"), "{r}");
    assert!(cdp.eval("document.getElementById('steer-log').textContent.includes('outside its limits')") == json!(true));

    // Change the texture from the page: type into its field, press its button.
    cdp.eval("document.getElementById('var-texture').value = '3'; document.getElementById('set-texture').click()");
    cdp.until("studio.replies.length >= 2", 20);
    let r = cdp.eval("studio.replies[1]");
    assert_eq!(r["ok"], true, "{r}");
    cdp.until(
        "studio.events.some(e => e.event === 'set' && e.node === 'interp' && e.param === 'texture' && e.value === 3)",
        20,
    );
    let page_tick =
        cdp.eval("studio.events.find(e => e.event === 'set' && e.param === 'texture').tick").as_u64().unwrap();
    std::thread::sleep(Duration::from_millis(2500));

    let shot = cdp.call("Page.captureScreenshot", json!({ "format": "png" }));
    let png = base64_decode(shot["data"].as_str().unwrap());
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "a PNG");
    let width = u32::from_be_bytes(png[16..20].try_into().unwrap());
    assert!(width >= 1000, "a full page screenshot ({width} px wide)");
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("studio.png");
    std::fs::write(&out, &png).unwrap();
    if let Ok(p) = std::env::var("EVFLOW_STUDIO_SCREENSHOT") {
        std::fs::write(&p, &png).unwrap();
    }
    eprintln!("screenshot: {}", out.display());
    // Fade out from the page: the badge follows the node's state to FADED;
    // re-arm: ARMED again.
    cdp.eval("document.getElementById('disable-limit').click()");
    cdp.until("document.getElementById('limiter-limit').textContent === 'FADED'", 20);
    cdp.eval("document.getElementById('rearm-limit').click()");
    cdp.until("document.getElementById('limiter-limit').textContent === 'ARMED'", 20);
    drop(cdp);
    drop(browser);

    let dir = session.dir.clone();
    let stdout = session.stop();
    assert!(stdout.contains("stopped: requested"), "{stdout}");
    // The session's event log holds the change at the tick the page was told.
    let log = std::fs::read_to_string(dir.join("events.jsonl")).unwrap();
    let sets: Vec<Value> = log
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap())
        .filter(|e| e["event"] == "set" && e["param"] == "texture")
        .collect();
    assert_eq!(sets.len(), 1, "one texture change: {log}");
    assert_eq!(sets[0]["node"], "interp");
    assert_eq!(sets[0]["value"], 3.0);
    assert_eq!(sets[0]["tick"].as_u64(), Some(page_tick), "the recording and the page agree on the tick");
    // And the recording replays bit for bit with the change at that tick.
    let out = Command::new(common::evflow()).arg("replay").arg(&dir).args(["--check", "-q"]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "replay --check: {text}");
}
