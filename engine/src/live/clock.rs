//! The real-time clock: `CLOCK_MONOTONIC` in nanoseconds, absolute sleeps
//! and a short spin before each deadline.

/// Nanoseconds on the monotonic clock (arbitrary origin).
#[cfg(unix)]
#[inline]
pub fn now_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_MONOTONIC always exists.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// Nanoseconds since the first call (non-Unix fallback).
#[cfg(not(unix))]
pub fn now_ns() -> u64 {
    use std::sync::OnceLock;
    use std::time::Instant;
    static ORIGIN: OnceLock<Instant> = OnceLock::new();
    ORIGIN.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

/// CPU time this thread has used, in nanoseconds (`CLOCK_THREAD_CPUTIME_ID`):
/// unlike the monotonic clock it does not advance while the thread is
/// preempted or descheduled, so the difference around a tick is what the
/// tick cost, not what the machine did meanwhile. `None` where there is no
/// such clock.
#[cfg(unix)]
pub fn thread_cpu_ns() -> Option<u64> {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec.
    let r = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (r == 0).then(|| ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64)
}

/// No per-thread CPU clock off Unix.
#[cfg(not(unix))]
pub fn thread_cpu_ns() -> Option<u64> {
    None
}

/// Sleeps until the monotonic clock reads `deadline` (absolute, so sleeps
/// do not accumulate drift), resuming after signals.
#[cfg(target_os = "linux")]
pub fn sleep_until(deadline: u64) {
    let ts = libc::timespec {
        tv_sec: (deadline / 1_000_000_000) as libc::time_t,
        tv_nsec: (deadline % 1_000_000_000) as libc::c_long,
    };
    loop {
        // SAFETY: `ts` is a valid timespec; the remaining-time pointer may be
        // null with TIMER_ABSTIME.
        let r = unsafe { libc::clock_nanosleep(libc::CLOCK_MONOTONIC, libc::TIMER_ABSTIME, &ts, std::ptr::null_mut()) };
        if r != libc::EINTR {
            return;
        }
    }
}

/// Sleeps until the clock reads `deadline` (relative-sleep fallback).
#[cfg(not(target_os = "linux"))]
pub fn sleep_until(deadline: u64) {
    let now = now_ns();
    if deadline > now {
        std::thread::sleep(std::time::Duration::from_nanos(deadline - now));
    }
}

/// How the real-time thread waits for its next deadline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wait {
    /// Sleep until the deadline.
    Sleep,
    /// Sleep until `spin_ns` before the deadline, then spin on the clock
    /// (a sleep alone wakes late by the timer's latency). The runner bounds
    /// the spin to a quarter period, so the thread never keeps the CPU
    /// (under SCHED_FIFO the kernel would throttle it).
    SleepThenSpin {
        /// How long before the deadline the sleep ends.
        spin_ns: u64,
    },
}

/// Waits until the clock reads `deadline` (returns at once when it has
/// passed).
#[inline]
pub fn wait_until(deadline: u64, how: Wait) {
    match how {
        Wait::Sleep => {
            if now_ns() < deadline {
                sleep_until(deadline);
            }
        }
        Wait::SleepThenSpin { spin_ns } => {
            let wake = deadline.saturating_sub(spin_ns);
            if now_ns() < wake {
                sleep_until(wake);
            }
            while now_ns() < deadline {
                std::hint::spin_loop();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn thread_cpu_time_stops_while_asleep_and_runs_while_busy() {
        let Some(start) = super::thread_cpu_ns() else { return };
        std::thread::sleep(std::time::Duration::from_millis(30));
        let slept = super::thread_cpu_ns().unwrap() - start;
        assert!(slept < 5_000_000, "30 ms asleep used {slept} ns of CPU");
        let (cpu0, wall0) = (super::thread_cpu_ns().unwrap(), super::now_ns());
        let mut x = 0u64;
        while super::thread_cpu_ns().unwrap() - cpu0 < 3_000_000 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
            assert!(super::now_ns() - wall0 < 30_000_000_000, "3 ms of CPU never came");
        }
        std::hint::black_box(x);
    }

    use super::*;

    #[test]
    fn waits_never_return_before_the_deadline() {
        for how in [Wait::Sleep, Wait::SleepThenSpin { spin_ns: 50_000 }] {
            let start = now_ns();
            for k in 1..=5u64 {
                let deadline = start + k * 1_000_000;
                wait_until(deadline, how);
                assert!(now_ns() >= deadline, "{how:?}");
            }
        }
    }

    #[test]
    fn a_deadline_in_the_past_returns_at_once() {
        let t = now_ns();
        wait_until(t.saturating_sub(1_000_000), Wait::Sleep);
        wait_until(t.saturating_sub(1_000_000), Wait::SleepThenSpin { spin_ns: 10_000 });
    }
}
