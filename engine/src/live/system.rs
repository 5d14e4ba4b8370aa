//! What the operating system grants the real-time thread: no timer slack,
//! SCHED_FIFO, locked memory, a CPU of its own. Each is asked for and the
//! outcome reported; none is required (the runner falls back to sleeping
//! then spinning at normal priority).

use std::fmt;

/// What to ask of the system for the real-time thread.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RealtimeRequest {
    /// SCHED_FIFO at this priority (1–99); `None`: normal scheduling.
    pub priority: Option<i32>,
    /// Lock all current and future memory of the process (mlockall), so the
    /// real-time thread never waits for a page fault.
    pub lock_memory: bool,
    /// Pin the real-time thread to this CPU.
    pub cpu: Option<usize>,
}

impl Default for RealtimeRequest {
    /// Normal scheduling, no memory locking, no pinning (what tests use).
    fn default() -> Self {
        Self { priority: None, lock_memory: false, cpu: None }
    }
}

/// What the system granted. `Err` holds why a request was refused.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RealtimeReport {
    /// Timer slack set to 1 ns (prctl PR_SET_TIMERSLACK).
    pub timer_slack: Option<Result<(), String>>,
    /// SCHED_FIFO with the priority granted.
    pub fifo: Option<Result<i32, String>>,
    /// mlockall(MCL_CURRENT | MCL_FUTURE).
    pub memory_locked: Option<Result<(), String>>,
    /// The CPU the thread is pinned to.
    pub cpu: Option<Result<usize, String>>,
}

impl RealtimeReport {
    /// True when the thread runs under SCHED_FIFO.
    pub fn is_fifo(&self) -> bool {
        matches!(self.fifo, Some(Ok(_)))
    }
}

impl fmt::Display for RealtimeReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        match &self.timer_slack {
            Some(Ok(())) => parts.push("timer slack 1 ns".to_string()),
            Some(Err(e)) => parts.push(format!("timer slack not set ({e})")),
            None => {}
        }
        match &self.fifo {
            Some(Ok(p)) => parts.push(format!("SCHED_FIFO priority {p}")),
            Some(Err(e)) => parts.push(format!("SCHED_FIFO refused ({e}): normal priority")),
            None => parts.push("normal priority (SCHED_FIFO not asked for)".into()),
        }
        match &self.memory_locked {
            Some(Ok(())) => parts.push("memory locked".into()),
            Some(Err(e)) => parts.push(format!("memory not locked ({e})")),
            None => {}
        }
        match &self.cpu {
            Some(Ok(c)) => parts.push(format!("pinned to CPU {c}")),
            Some(Err(e)) => parts.push(format!("not pinned ({e})")),
            None => {}
        }
        write!(f, "{}", parts.join("; "))
    }
}

/// Applies `req` to the calling thread and reports what was granted.
#[cfg(all(target_os = "linux", not(miri)))]
pub fn apply(req: &RealtimeRequest) -> RealtimeReport {
    let errno = || std::io::Error::last_os_error().to_string();
    // Each block below is a plain system call on the calling thread; a
    // failure is reported through errno, never undefined behaviour.
    // SAFETY: prctl(PR_SET_TIMERSLACK) takes integer arguments only.
    let slack = unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong, 0, 0, 0) } == 0;
    let mut r = RealtimeReport { timer_slack: Some(if slack { Ok(()) } else { Err(errno()) }), ..Default::default() };
    if req.lock_memory {
        // SAFETY: mlockall takes flags only and touches no Rust memory.
        let ok = unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } == 0;
        r.memory_locked = Some(if ok { Ok(()) } else { Err(errno()) });
    }
    if let Some(cpu) = req.cpu {
        r.cpu = Some(if cpu >= libc::CPU_SETSIZE as usize {
            Err(format!("CPU {cpu} does not exist"))
        } else {
            // SAFETY: cpu_set_t is a plain bit array: all zeros is a valid (empty) set.
            let mut set: libc::cpu_set_t = unsafe { std::mem::zeroed() };
            // SAFETY: `cpu` < CPU_SETSIZE (checked above), so the bit is inside `set`.
            unsafe { libc::CPU_SET(cpu, &mut set) };
            // SAFETY: `set` is a valid cpu_set_t of the size passed; pid 0 is this thread.
            if unsafe { libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) } == 0 {
                Ok(cpu)
            } else {
                Err(errno())
            }
        });
    }
    if let Some(p) = req.priority {
        let param = libc::sched_param { sched_priority: p };
        // SAFETY: `param` is a valid sched_param that outlives the call; pid 0 is this thread.
        r.fifo = Some(if unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) } == 0 {
            Ok(p)
        } else {
            Err(errno())
        });
    }
    r
}

/// Applies `req` (unsupported outside Linux, and under Miri, which runs no
/// system call of these: everything is reported refused).
#[cfg(any(not(target_os = "linux"), miri))]
pub fn apply(req: &RealtimeRequest) -> RealtimeReport {
    let no = || "not supported on this system".to_string();
    RealtimeReport {
        timer_slack: Some(Err(no())),
        fifo: req.priority.map(|_| Err(no())),
        memory_locked: req.lock_memory.then(|| Err(no())),
        cpu: req.cpu.map(|_| Err(no())),
    }
}
