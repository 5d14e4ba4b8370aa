//! Parameter changes sent from the page, applied through the session's
//! own [`Control`] — the command queue the console and `--change` use —
//! so they are checked against the node's declared limits here, on the
//! server, and land at one tick. The page is told what was queued or why
//! not.

use evflow_engine::live::Control;
use serde_json::{json, Value};
use std::sync::Mutex;

/// Handles one message from the page; returns the reply to send.
///
/// `{"type": "set", "id": N, "target": "node.param" | "variable", "value": "text"}`
pub(crate) fn handle(text: &str, control: Option<&Mutex<Control>>) -> Value {
    let msg: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => return json!({ "type": "reply", "ok": false, "message": format!("not a JSON message: {e}") }),
    };
    let id = msg.get("id").cloned().unwrap_or(Value::Null);
    let reply = |ok: bool, message: String| json!({ "type": "reply", "id": id, "ok": ok, "message": message });
    if msg["type"] != "set" {
        return reply(false, format!("unknown message type {}", msg["type"]));
    }
    let Some(control) = control else {
        return reply(false, "a recorded session cannot be steered".into());
    };
    let (Some(target), Some(value)) = (msg["target"].as_str(), value_text(&msg["value"])) else {
        return reply(false, "a change needs a `target` (node.param or variable) and a `value`".into());
    };
    let target = target.trim();
    if target.is_empty() || target.len() > 200 || value.len() > 200 {
        return reply(false, "empty or overlong target or value".into());
    }
    let mut c = control.lock().unwrap_or_else(|e| e.into_inner());
    let queued = match target.split_once('.') {
        Some((node, param)) => c.set(node, param, &value, None),
        None => c.set_var(target, &value, None),
    };
    match queued {
        Ok(()) => reply(true, format!("queued {target} = {value} (applies at the next tick, {} so far)", c.ticks())),
        Err(e) => reply(false, format!("{target} = {value}: {e}")),
    }
}

/// The value as the console would type it.
fn value_text(v: &Value) -> Option<String> {
    match v {
        Value::String(s) => Some(s.clone()),
        Value::Number(n) => Some(n.to_string()),
        Value::Bool(b) => Some(b.to_string()),
        _ => None,
    }
}
