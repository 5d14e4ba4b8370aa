//! The control side of a session (any non-real-time thread): parameter
//! changes checked against the declarations and queued with their tick,
//! stop requests, plan replacement.

use super::liveplan::{LiveError, LivePlan};
use super::message::{Command, Shared, StopReason};
use super::vars::LiveVar;
use crate::spec::{NodeSpec, ParamKind};
use std::sync::atomic::Ordering;
use std::sync::Arc;

/// Sends commands and plans to the real-time thread.
pub struct Control {
    pub(crate) commands: rtrb::Producer<Command>,
    pub(crate) plans: rtrb::Producer<Box<LivePlan>>,
    pub(crate) retired: rtrb::Consumer<Box<LivePlan>>,
    pub(crate) shared: Arc<Shared>,
    /// Node names and declarations, by plan index.
    pub(crate) nodes: Vec<(String, &'static NodeSpec)>,
    pub(crate) taps: Vec<super::liveplan::TapInfo>,
    pub(crate) base_rate: f64,
    /// Graph variables bound to live parameters ([`Control::bind_vars`]).
    pub(crate) vars: Vec<LiveVar>,
}

impl Control {
    /// Queues `node.param = value` for tick `at` (`None`: as soon as
    /// possible). The value is text as typed: a number, `true`/`false` for
    /// flags, a word for choices. Checked here against the declaration:
    /// the node exists, the parameter is declared live, the value is within
    /// its limits.
    pub fn set(&mut self, node: &str, param: &str, value: &str, at: Option<u64>) -> Result<(), LiveError> {
        let cmd = self.command(node, param, value, at)?;
        self.push(&[cmd], "parameter")
    }

    /// The checked command for `node.param = value` at tick `at`.
    fn command(&self, node: &str, param: &str, value: &str, at: Option<u64>) -> Result<Command, LiveError> {
        let Some(k) = self.nodes.iter().position(|(n, _)| n == node) else {
            let help = crate::suggest::help(node, self.nodes.iter().map(|(n, _)| n.as_str()));
            return Err(LiveError::Set(format!("no node `{node}` in the running plan; {help}")));
        };
        let spec = self.nodes[k].1;
        let Some(p) = spec.param(param) else {
            let help = crate::suggest::help(param, spec.params.iter().map(|p| p.name));
            return Err(LiveError::Set(format!("node type `{}` has no parameter `{param}`; {help}", spec.name)));
        };
        if !p.live {
            let live: Vec<&str> = spec.params.iter().filter(|p| p.live).map(|p| p.name).collect();
            let which = if live.is_empty() { "none".to_string() } else { live.join(", ") };
            return Err(LiveError::Set(format!(
                "`{node}.{param}` cannot change while running (live parameters of `{}`: {which})",
                spec.name
            )));
        }
        let v = parse_value(&p.kind, value.trim())
            .map_err(|why| LiveError::Set(format!("`{node}.{param}` = `{value}`: {why}")))?;
        Ok(Command { at: at.unwrap_or(0), node: k as u32, param: p.name, value: v })
    }

    /// Pushes `cmds` in one chunk: the real-time thread sees all of them or
    /// none, so commands stamped with the same tick apply at the same tick.
    fn push(&mut self, cmds: &[Command], what: &'static str) -> Result<(), LiveError> {
        let overrun = |s: &Shared| {
            s.command_overruns.fetch_add(1, Ordering::Relaxed);
            LiveError::QueueFull(what)
        };
        let Ok(chunk) = self.commands.write_chunk_uninit(cmds.len()) else { return Err(overrun(&self.shared)) };
        chunk.fill_from_iter(cmds.iter().copied());
        Ok(())
    }

    /// Tells the control side which graph variables set live parameters
    /// (see [`crate::live::live_vars`]), so `set_var` and `set_text("name=value")`
    /// can change them. A use naming a node the running plan does not hold
    /// (left out when the plan was built: it fed only a node that turned
    /// out constant, docs/pruning.md) is dropped, and so is a variable left
    /// with no use: changing it could change nothing that runs.
    pub fn bind_vars(&mut self, vars: Vec<LiveVar>) {
        let nodes = &self.nodes;
        self.vars = vars
            .into_iter()
            .filter_map(|mut v| {
                v.uses.retain(|(node, _)| nodes.iter().any(|(n, _)| n == node));
                (!v.uses.is_empty()).then_some(v)
            })
            .collect();
    }

    /// The bound variables.
    pub fn vars(&self) -> &[LiveVar] {
        &self.vars
    }

    /// Sets graph variable `name` to `value`: every live parameter written
    /// `"$name"` takes the value at the same tick `at` (`None`: as soon as
    /// possible). All values are checked before any is queued.
    pub fn set_var(&mut self, name: &str, value: &str, at: Option<u64>) -> Result<(), LiveError> {
        let name = name.trim().trim_start_matches('$');
        let Some(var) = self.vars.iter().find(|v| v.name == name) else {
            let help = crate::suggest::help(name, self.vars.iter().map(|v| v.name.as_str()));
            let known = if self.vars.is_empty() {
                "this graph has none".to_string()
            } else {
                self.vars.iter().map(|v| v.name.as_str()).collect::<Vec<_>>().join(", ")
            };
            return Err(LiveError::Set(format!(
                "no graph variable `{name}` sets a live parameter (live variables: {known}); {help}"
            )));
        };
        let uses = var.uses.clone();
        // The same tick for every parameter, even "as soon as possible": a
        // chunk is applied within one tick.
        let cmds =
            uses.iter().map(|(node, param)| self.command(node, param, value, at)).collect::<Result<Vec<_>, _>>()?;
        self.push(&cmds, "parameter")
    }

    /// Parses `node.param=value` (or `node.param value`), or `var=value`
    /// for a graph variable bound to live parameters, and queues it.
    pub fn set_text(&mut self, text: &str, at: Option<u64>) -> Result<(), LiveError> {
        let (key, value) = text
            .split_once('=')
            .or_else(|| text.trim().split_once(char::is_whitespace))
            .ok_or_else(|| LiveError::Set(format!("`{text}`: expected node.param=value or variable=value")))?;
        match key.trim().split_once('.') {
            Some((node, param)) => self.set(node, param, value, at),
            None => self.set_var(key, value, at),
        }
    }

    /// Asks the session to stop: safety guards fade out, then the
    /// real-time thread ends.
    pub fn stop(&self) {
        self.shared.request_stop(StopReason::Requested);
    }

    /// Reports a fault (e.g. a device disconnect): the session stops the
    /// same way, with this reason.
    pub fn fault(&self, why: StopReason) {
        self.shared.request_stop(why);
    }

    /// Hands a replacement plan to the real-time thread. It fades the
    /// running plan's guards out, swaps, and returns the old plan through
    /// [`Control::collect_retired`]; the new plan starts at its own t = 0.
    /// Its taps must match the running plan's (same ports, same rates).
    pub fn replace(&mut self, plan: LivePlan) -> Result<(), LiveError> {
        let same = plan.info.len() == self.taps.len()
            && plan
                .info
                .iter()
                .zip(&self.taps)
                .all(|(a, b)| a.node == b.node && a.port == b.port && a.ratio == b.ratio);
        if !same {
            return Err(LiveError::TapMismatch(format!(
                "running: {}; replacement: {}",
                names(&self.taps),
                names(&plan.info)
            )));
        }
        let nodes = (0..plan.plan.len()).map(|k| (plan.plan.node_name(k).to_string(), plan.plan.spec(k))).collect();
        self.plans.push(Box::new(plan)).map_err(|_| LiveError::QueueFull("plan"))?;
        self.nodes = nodes;
        Ok(())
    }

    /// Drops the plans the real-time thread handed back (here, off the
    /// real-time thread); returns how many.
    pub fn collect_retired(&mut self) -> usize {
        let mut n = 0;
        while let Ok(p) = self.retired.pop() {
            drop(p);
            n += 1;
        }
        n
    }

    /// The tick index `seconds` into the session.
    pub fn tick_at(&self, seconds: f64) -> u64 {
        (seconds * self.base_rate).round().max(0.0) as u64
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.shared.ticks()
    }
}

fn names(t: &[super::liveplan::TapInfo]) -> String {
    t.iter().map(|t| format!("{}.{}", t.node, t.port)).collect::<Vec<_>>().join(", ")
}

/// A typed value for a parameter of kind `kind`, as the number `Node::set`
/// receives.
pub fn parse_value(kind: &ParamKind, text: &str) -> Result<f64, String> {
    match *kind {
        ParamKind::Float { min, max } => {
            let v: f64 = text.parse().map_err(|_| format!("not a number (expected {min} ..= {max})"))?;
            if v.is_finite() && v >= min && v <= max {
                Ok(v)
            } else {
                Err(format!("outside its limits {}", kind.limits()))
            }
        }
        ParamKind::Int { min, max } => {
            let v: i64 = text.parse().map_err(|_| format!("not an integer (expected {min} ..= {max})"))?;
            if (min..=max).contains(&v) {
                Ok(v as f64)
            } else {
                Err(format!("outside its limits {}", kind.limits()))
            }
        }
        ParamKind::Bool => match text {
            "true" | "1" | "on" => Ok(1.0),
            "false" | "0" | "off" => Ok(0.0),
            _ => Err("expected true or false".into()),
        },
        ParamKind::Choice(words) => {
            let w = text.trim_matches('"');
            words.iter().position(|x| *x == w).map(|i| i as f64).ok_or_else(|| {
                format!("not one of {}; {}", words.join(", "), crate::suggest::help(w, words.iter().copied()))
            })
        }
        _ => Err(format!("a {} parameter cannot change live", kind.type_name())),
    }
}
