//! A plan made ready for the real-time thread: checked for live use, its
//! safety guards and taps resolved to indices (all off the real-time thread).

use crate::plan::Plan;
use crate::rate::Ratio;
use crate::spec::{ParamKind, Role};

/// Why a graph or a request cannot run live.
#[derive(Debug, thiserror::Error)]
pub enum LiveError {
    /// A plan built to run offline handed to the live runner.
    #[error(
        "the plan was built to run offline (PlanOptions::mode); build it with RunMode::Live to run it live, \
         so that its hardware nodes know they may open their devices"
    )]
    NotLive,
    /// A node that cannot run live.
    #[error("node `{node}` ({kind}) cannot run live: {reason}")]
    OfflineOnly {
        /// The node.
        node: String,
        /// Its type.
        kind: &'static str,
        /// Why.
        reason: &'static str,
    },
    /// A safety guard whose gate is not a live flag.
    #[error("safety guard `{node}` ({kind}) declares no live flag `{gate}`, so the runner cannot fade it out on stop")]
    GuardWithoutGate {
        /// The node.
        node: String,
        /// Its type.
        kind: &'static str,
        /// The gate its declaration names.
        gate: &'static str,
    },
    /// A tap names a node or port the plan does not have.
    #[error("cannot record `{node}.{port}`: {why}")]
    UnknownTap {
        /// Node name.
        node: String,
        /// Port name.
        port: String,
        /// What is wrong, with a suggestion.
        why: String,
    },
    /// The base rate is too high for a live tick.
    #[error("base rate {0} Hz is above the live runner's 20 kHz limit (a tick every 50 µs)")]
    RateTooHigh(f64),
    /// A replacement plan whose taps differ from the running one's.
    #[error("the replacement plan's recorded ports differ from the running plan's ({0})")]
    TapMismatch(String),
    /// A parameter change that cannot be applied.
    #[error("{0}")]
    Set(String),
    /// The command or plan ring is full.
    #[error("the {0} queue is full; the real-time thread is not keeping up")]
    QueueFull(&'static str),
    /// The session has ended.
    #[error("the session has ended")]
    Ended,
    /// The real-time thread could not be started.
    #[error("cannot start the real-time thread: {0}")]
    Spawn(std::io::Error),
}

/// An output port to copy out of the real-time thread each tick.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tap {
    /// Node name.
    pub node: String,
    /// Output port name.
    pub port: String,
}

impl Tap {
    /// A tap on `node.port`.
    pub fn new(node: &str, port: &str) -> Self {
        Self { node: node.to_string(), port: port.to_string() }
    }
}

/// A tap resolved against a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct TapInfo {
    /// Node name.
    pub node: String,
    /// Output port name.
    pub port: String,
    /// Rate relative to the base rate.
    pub ratio: Ratio,
    /// Rate in Hz.
    pub rate: f64,
}

/// A plan ready to run live.
pub struct LivePlan {
    pub(crate) plan: Plan,
    /// The safety guards: node index and gate parameter.
    pub(crate) guards: Vec<(usize, &'static str)>,
    pub(crate) taps: Vec<(usize, usize)>,
    pub(crate) info: Vec<TapInfo>,
}

impl LivePlan {
    /// Checks that the plan was built to run live ([`crate::RunMode::Live`]),
    /// that every node can run live and that every safety guard can be
    /// faded out, and resolves the taps.
    pub fn new(plan: Plan, taps: &[Tap]) -> Result<Self, LiveError> {
        if plan.mode() != crate::node::RunMode::Live {
            return Err(LiveError::NotLive);
        }
        if plan.base_rate() > 20_000.0 {
            return Err(LiveError::RateTooHigh(plan.base_rate()));
        }
        let mut guards = Vec::new();
        for k in 0..plan.len() {
            let spec = plan.spec(k);
            if let Some(reason) = spec.offline_only {
                return Err(LiveError::OfflineOnly { node: plan.node_name(k).to_string(), kind: spec.name, reason });
            }
            if let Some(gate) = spec.safety_guard {
                let ok = spec.params.iter().any(|p| p.name == gate && p.live && p.kind == ParamKind::Bool);
                if !ok {
                    return Err(LiveError::GuardWithoutGate {
                        node: plan.node_name(k).to_string(),
                        kind: spec.name,
                        gate,
                    });
                }
                guards.push((k, gate));
            }
        }
        let mut resolved = Vec::new();
        let mut info = Vec::new();
        for t in taps {
            let unknown = |why: String| LiveError::UnknownTap { node: t.node.clone(), port: t.port.clone(), why };
            let k = plan
                .index(&t.node)
                .ok_or_else(|| unknown(crate::suggest::help(&t.node, (0..plan.len()).map(|k| plan.node_name(k)))))?;
            let names = plan.output_names(k);
            let j = names.iter().position(|n| *n == t.port).ok_or_else(|| {
                unknown(format!(
                    "node `{}` has no output `{}`; {}",
                    t.node,
                    t.port,
                    crate::suggest::help(&t.port, names.iter().map(String::as_str))
                ))
            })?;
            if plan.output_dropped(k, j) {
                let why = plan.folded().iter().find(|f| f.node == t.node).map_or("", |f| f.reason.as_str());
                return Err(unknown(format!(
                    "`{}` is replaced by a constant for this plan ({why}) and this output, read by no node, is not \
                     computed; connect it to a sink to keep the node (docs/pruning.md)",
                    t.node
                )));
            }
            let ratio = plan.output_ratio(k, j);
            resolved.push((k, j));
            info.push(TapInfo { node: t.node.clone(), port: t.port.clone(), ratio, rate: ratio.hz(plan.base_rate()) });
        }
        Ok(Self { plan, guards, taps: resolved, info })
    }

    /// Every output of every source node, in plan order: what a session
    /// records as its inputs (replay feeds them back in place of the
    /// sources).
    pub fn source_taps(plan: &Plan) -> Vec<Tap> {
        let mut v = Vec::new();
        for k in 0..plan.len() {
            if plan.spec(k).role == Role::Source {
                for p in plan.output_names(k) {
                    v.push(Tap::new(plan.node_name(k), p));
                }
            }
        }
        v
    }

    /// Every output of every safety guard: what reaches hardware.
    pub fn guard_taps(plan: &Plan) -> Vec<Tap> {
        let mut v = Vec::new();
        for k in 0..plan.len() {
            if plan.spec(k).is_guard() {
                for p in plan.output_names(k) {
                    v.push(Tap::new(plan.node_name(k), p));
                }
            }
        }
        v
    }

    /// The plan.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }
    /// The plan, for `finish` after the session.
    pub fn plan_mut(&mut self) -> &mut Plan {
        &mut self.plan
    }
    /// The resolved taps, in the order requested.
    pub fn taps(&self) -> &[TapInfo] {
        &self.info
    }
    /// The safety guards: node index and the live flag that opens its gate.
    pub fn guards(&self) -> &[(usize, &'static str)] {
        &self.guards
    }
}
