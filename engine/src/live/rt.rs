//! The real-time thread: one tick of the plan on each absolute deadline.
//!
//! Between its entry and exit hooks this code must not allocate, free, lock,
//! block (other than sleeping until the next deadline), print or do I/O —
//! `tests/live_alloc.rs` counts every allocation and free on this thread.
//! The one exception is a node failure, which ends the session: the
//! failure's message is built where it happens.

use super::clock::{self, Wait};
use super::liveplan::LivePlan;
use super::message::{Command, Event, EventKind, Shared, StopReason, TickStat};
use super::system::{self, RealtimeReport, RealtimeRequest};
use crate::plan::NodeFailure;
use std::sync::atomic::Ordering;
use std::sync::Arc;

/// Called on the real-time thread with `true` just before its first tick
/// and `false` just after its last (tests arm an allocation guard with it).
pub type RtHook = fn(bool);

/// Everything the real-time thread owns.
pub(crate) struct RtState {
    pub plan: Box<LivePlan>,
    pub commands: rtrb::Consumer<Command>,
    pub plans: rtrb::Consumer<Box<LivePlan>>,
    pub retired: rtrb::Producer<Box<LivePlan>>,
    pub taps: Vec<rtrb::Producer<f64>>,
    pub events: rtrb::Producer<Event>,
    pub stats: rtrb::Producer<TickStat>,
    pub shared: Arc<Shared>,
    pub request: RealtimeRequest,
    pub period_ns: u64,
    pub spin_ns: u64,
    pub stop_ticks: u64,
    pub duration_ticks: Option<u64>,
    pub miss_streak: u64,
    pub hook: Option<RtHook>,
}

/// How the real-time thread ended.
pub struct RtExit {
    /// The plan that ran last (finish it, then drop it, off the real-time
    /// thread).
    pub plan: Box<LivePlan>,
    /// Session ticks run.
    pub ticks: u64,
    /// Why it stopped (`None` after a node failure).
    pub reason: Option<StopReason>,
    /// A node failure that ended the session.
    pub failure: Option<Box<NodeFailure>>,
    /// What the system granted the thread.
    pub realtime: RealtimeReport,
}

/// The tick at which a plan's first finite source runs out, minus the
/// stop sequence, counted from `now`.
fn sources_stop(plan: &LivePlan, now: u64, stop_ticks: u64) -> Option<u64> {
    plan.plan.remaining_ticks().map(|r| now + r.saturating_sub(stop_ticks))
}

impl RtState {
    fn event(&mut self, tick: u64, kind: EventKind) {
        if self.events.push(Event { tick, kind }).is_err() {
            self.shared.event_overruns.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Fades every safety guard out from tick `k` on.
    fn disable_guards(&mut self, k: u64) {
        for i in 0..self.plan.guards.len() {
            let (g, gate) = self.plan.guards[i];
            let kind = match self.plan.plan.set(g, gate, 0.0) {
                Ok(()) => EventKind::Set { node: g as u32, param: gate, value: 0.0 },
                Err(_) => EventKind::Refused { node: g as u32, param: gate, value: 0.0 },
            };
            self.event(k, kind);
        }
    }

    /// Applies the queued commands due at tick `k`, in order.
    fn apply_commands(&mut self, k: u64, stopping: bool) {
        while let Ok(c) = self.commands.peek() {
            if c.at > k {
                break;
            }
            let Ok(c) = self.commands.pop() else { break };
            let node = c.node as usize;
            // While stopping, no command may reopen a guard.
            let blocked = stopping && self.plan.guards.contains(&(node, c.param));
            let ok = node < self.plan.plan.len() && !blocked && self.plan.plan.set(node, c.param, c.value).is_ok();
            let kind = if ok {
                EventKind::Set { node: c.node, param: c.param, value: c.value }
            } else {
                EventKind::Refused { node: c.node, param: c.param, value: c.value }
            };
            self.event(k, kind);
        }
    }

    /// Copies this tick's tap samples into their rings: all or none, so
    /// the rings stay aligned; returns false when a ring was too full.
    fn write_taps(&mut self) -> bool {
        let plan = &self.plan;
        let fits =
            self.taps.iter().zip(&plan.taps).all(|(ring, &(k, j))| ring.slots() >= plan.plan.output_at(k, j).len());
        if !fits {
            return false;
        }
        for (ring, &(k, j)) in self.taps.iter_mut().zip(&plan.taps) {
            let src = plan.plan.output_at(k, j);
            if src.is_empty() {
                continue;
            }
            if let Ok(mut chunk) = ring.write_chunk(src.len()) {
                let (a, b) = chunk.as_mut_slices();
                let split = a.len();
                a.copy_from_slice(&src[..split]);
                b.copy_from_slice(&src[split..]);
                chunk.commit_all();
            }
        }
        true
    }

    /// The loop. Returns when the stop sequence has run out, or a node failed.
    pub fn run(mut self) -> RtExit {
        let realtime = system::apply(&self.request);
        // Sleep to shortly before each deadline, then spin. The spin is
        // bounded to a quarter period, so even under SCHED_FIFO the thread
        // never keeps the CPU (the kernel would throttle it).
        let spin_ns = self.spin_ns.min(self.period_ns / 4);
        let wait = if spin_ns == 0 { Wait::Sleep } else { Wait::SleepThenSpin { spin_ns } };
        prefault_stack();
        if let Some(h) = self.hook {
            h(true);
        }
        let start = clock::now_ns() + self.period_ns;
        let mut k: u64 = 0;
        let mut course = Course {
            end: None,
            handover: None,
            stop_at_sources: sources_stop(&self.plan, 0, self.stop_ticks),
            gap_from: None,
            streak: 0,
        };
        let mut failure = None;
        loop {
            let deadline = start + k * self.period_ns;
            clock::wait_until(deadline, wait);
            let woke = clock::now_ns();
            if self.stop_sequence(k, &mut course) {
                break;
            }
            self.hand_over(k, &mut course);
            // Commands wait while a handover is under way (they are meant
            // for the plan that will run).
            if course.handover.is_none() {
                self.apply_commands(k, course.end.is_some());
            }
            if let Err(e) = self.plan.plan.tick() {
                failure = Some(e);
                break;
            }
            self.tap(k, &mut course);
            self.account(k, deadline, woke, &mut course);
            k += 1;
            self.shared.tick.store(k, Ordering::Relaxed);
        }
        if let Some(g) = course.gap_from.take() {
            self.event(g, EventKind::Gap { ticks: k - g });
        }
        if let Some(h) = self.hook {
            h(false);
        }
        RtExit { plan: self.plan, ticks: k, reason: course.end.map(|(_, r)| r), failure, realtime }
    }

    /// Stop: requested, by the duration, or before a source runs dry — at
    /// tick `k` the stop sequence begins (the guards fade out); true once
    /// it has run out, when the loop ends.
    #[inline]
    fn stop_sequence(&mut self, k: u64, c: &mut Course) -> bool {
        if c.end.is_none() {
            let why = self
                .shared
                .stop_requested()
                .or_else(|| self.duration_ticks.filter(|&d| k >= d).map(|_| StopReason::Duration))
                .or_else(|| c.stop_at_sources.filter(|&s| k >= s).map(|_| StopReason::SourcesEnded));
            if let Some(why) = why {
                self.event(k, EventKind::Stop(why));
                self.disable_guards(k);
                c.end = Some((k + self.stop_ticks, why));
            }
        }
        matches!(c.end, Some((e, _)) if k >= e)
    }

    /// A replacement plan: fade the old one out, then hand over (the old
    /// one goes to the retired ring, dropped off this thread).
    #[inline]
    fn hand_over(&mut self, k: u64, c: &mut Course) {
        if c.handover.is_none() && c.end.is_none() && !self.plans.is_empty() && self.retired.slots() > 0 {
            self.disable_guards(k);
            c.handover = Some(k + self.stop_ticks);
        }
        if let Some(h) = c.handover {
            if k >= h {
                if let Ok(next) = self.plans.pop() {
                    let old = std::mem::replace(&mut self.plan, next);
                    // A slot was checked free before the handover began.
                    let _ = self.retired.push(old);
                    self.event(k, EventKind::Replaced);
                    c.stop_at_sources = sources_stop(&self.plan, k, self.stop_ticks);
                }
                c.handover = None;
            }
        }
    }

    /// Copies tick `k`'s tap samples; while their rings are too full, a
    /// gap (one event when it closes) and an overrun per tick.
    #[inline]
    fn tap(&mut self, k: u64, c: &mut Course) {
        if self.write_taps() {
            if let Some(g) = c.gap_from.take() {
                self.event(g, EventKind::Gap { ticks: k - g });
            }
        } else {
            c.gap_from.get_or_insert(k);
            self.shared.tap_overruns.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Tick `k`'s timing, woken at `woke` for `deadline`: a missed
    /// deadline counts (a streak of them stops the session) and the tick's
    /// statistics go to their ring.
    #[inline]
    fn account(&mut self, k: u64, deadline: u64, woke: u64, c: &mut Course) {
        let done = clock::now_ns();
        let missed = done > deadline + self.period_ns;
        if missed {
            c.streak += 1;
            self.shared.misses.fetch_add(1, Ordering::Relaxed);
            if self.miss_streak > 0 && c.streak >= self.miss_streak {
                self.shared.request_stop(StopReason::DeadlineMisses);
            }
        } else {
            c.streak = 0;
        }
        let stat = TickStat {
            tick: k,
            jitter_ns: woke.saturating_sub(deadline),
            compute_ns: done.saturating_sub(woke),
            missed,
        };
        if self.stats.push(stat).is_err() {
            self.shared.stat_overruns.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// Where the loop stands between ticks (plain values: nothing allocated).
#[derive(Debug, Clone, Copy)]
struct Course {
    /// The tick the stop sequence ends at, and why it began.
    end: Option<(u64, StopReason)>,
    /// The tick a replacement plan takes over at, while one is under way.
    handover: Option<u64>,
    /// The tick to begin the stop sequence at before a source runs dry.
    stop_at_sources: Option<u64>,
    /// The first tick of a gap in the taps, while one is open.
    gap_from: Option<u64>,
    /// Deadlines missed in a row.
    streak: u64,
}

/// Touches the stack the loop will use, so its pages are mapped (and
/// locked, under mlockall) before the first deadline.
#[inline(never)]
fn prefault_stack() {
    let mut buf = [0u8; 64 * 1024];
    for i in (0..buf.len()).step_by(4096) {
        buf[i] = i as u8;
    }
    std::hint::black_box(&mut buf);
}
