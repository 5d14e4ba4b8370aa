//! Time the hypervisor took from this machine's CPUs ("steal", the eighth
//! field of the `cpu` line of `/proc/stat`, in clock ticks): on a virtual
//! machine, the stalls no real-time setting inside the guest can prevent.
//! Read off the real-time thread, before and after a session.

/// Total steal time of all CPUs so far, in seconds; `None` where
/// `/proc/stat` is missing or has no steal field (not Linux, old kernels).
pub fn steal_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/stat").ok()?;
    parse(&text, clock_ticks_per_second())
}

fn clock_ticks_per_second() -> f64 {
    // SAFETY: sysconf has no preconditions.
    let t = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    if t > 0 {
        t as f64
    } else {
        100.0
    }
}

/// The steal field of the aggregate `cpu` line, in seconds.
fn parse(stat: &str, ticks_per_second: f64) -> Option<f64> {
    let line = stat.lines().find(|l| l.split_whitespace().next() == Some("cpu"))?;
    let steal: f64 = line.split_whitespace().nth(8)?.parse().ok()?;
    Some(steal / ticks_per_second)
}

#[cfg(test)]
mod tests {
    use super::parse;

    #[test]
    fn reads_the_steal_field_of_the_aggregate_line() {
        let stat = "cpu  299723 0 22019 1672083 2000 0 283 150 0 0\ncpu0 1 2 3 4 5 6 7 8 9 10\nintr 1 2\n";
        assert_eq!(parse(stat, 100.0), Some(1.5));
        assert_eq!(parse("cpu  1 2 3 4\n", 100.0), None, "no steal field");
        assert_eq!(parse("intr 1 2\n", 100.0), None);
    }
}
