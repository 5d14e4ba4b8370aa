//! Real-time hygiene: every live-capable shipped graph (and a few built
//! here to cover more node types) runs on the live runner with an
//! allocation-counting allocator armed on the real-time thread for its whole
//! loop — every tick, every parameter change, the stop sequence. Any
//! allocation or free there fails the test.
//!
//! On x86-64 Linux a seccomp filter is also installed on the real-time
//! thread when the loop starts: it allows only the clock (sleep, read) and
//! the memory and exit calls a thread makes when it ends; any other system
//! call — a write (printing, file I/O), a read, a futex wait (a contended
//! lock), an open — traps, is counted, and fails the test.
//!
//! Graphs added to `graphs/` later join automatically; a graph that cannot
//! run live (an offline-only node) is listed and skipped.

use evflow_engine::live::{self, LiveConfig, LivePlan};
use evflow_engine::{load_file, Plan, PlanOptions};
use evflow_tests::alloc_counter;
use std::sync::atomic::Ordering;
use std::sync::Mutex;

/// The counters are process-wide: the tests of this file take turns.
static TURN: Mutex<()> = Mutex::new(());

#[global_allocator]
static GLOBAL: alloc_counter::Counting = alloc_counter::Counting;

fn hook(on: bool) {
    if on {
        syscalls::forbid_on_this_thread();
    }
    alloc_counter::arm(on);
}

/// The seccomp filter and the SIGSYS handler that counts trapped calls.
#[cfg(all(target_os = "linux", target_arch = "x86_64"))]
mod syscalls {
    use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};

    pub static TRAPPED: AtomicU64 = AtomicU64::new(0);
    pub static FIRST: AtomicI64 = AtomicI64::new(-1);

    /// System calls the real-time thread may make: the clock, and what a
    /// thread's exit needs (memory, signal stack, exit).
    const ALLOWED: &[i64] = &[
        libc::SYS_clock_nanosleep,
        libc::SYS_clock_gettime,
        libc::SYS_rt_sigreturn,
        libc::SYS_mmap,
        libc::SYS_munmap,
        libc::SYS_madvise,
        libc::SYS_mprotect,
        libc::SYS_brk,
        libc::SYS_sigaltstack,
        libc::SYS_rt_sigprocmask,
        libc::SYS_exit,
        libc::SYS_exit_group,
    ];
    const AUDIT_ARCH_X86_64: u32 = 0xC000_003E;

    extern "C" fn on_sigsys(_: libc::c_int, info: *mut libc::siginfo_t, _: *mut libc::c_void) {
        // SAFETY: for SIGSYS the kernel fills `si_syscall` at offset 24 of
        // siginfo_t on x86-64 (after signo, errno, code and the call address).
        let nr = unsafe { *(info as *const u8).add(24).cast::<libc::c_int>() };
        TRAPPED.fetch_add(1, Ordering::SeqCst);
        let _ = FIRST.compare_exchange(-1, nr as i64, Ordering::SeqCst, Ordering::SeqCst);
    }

    /// Installs the process-wide SIGSYS handler (once).
    pub fn install_handler() {
        // SAFETY: a plain sigaction with a handler that only touches atomics.
        unsafe {
            let mut sa: libc::sigaction = std::mem::zeroed();
            sa.sa_sigaction = on_sigsys as *const () as usize;
            sa.sa_flags = libc::SA_SIGINFO;
            assert_eq!(libc::sigaction(libc::SIGSYS, &sa, std::ptr::null_mut()), 0);
        }
    }

    fn stmt(code: u16, k: u32) -> libc::sock_filter {
        libc::sock_filter { code, jt: 0, jf: 0, k }
    }

    /// Installs the filter on the calling thread only.
    pub fn forbid_on_this_thread() {
        const LD: u16 = (libc::BPF_LD | libc::BPF_W | libc::BPF_ABS) as u16;
        const JEQ: u16 = (libc::BPF_JMP | libc::BPF_JEQ | libc::BPF_K) as u16;
        const RET: u16 = (libc::BPF_RET | libc::BPF_K) as u16;
        let mut prog = vec![
            stmt(LD, 4), // arch
            libc::sock_filter { code: JEQ, jt: 1, jf: 0, k: AUDIT_ARCH_X86_64 },
            stmt(RET, libc::SECCOMP_RET_ALLOW),
            stmt(LD, 0), // syscall number
        ];
        let n = ALLOWED.len();
        for (i, &nr) in ALLOWED.iter().enumerate() {
            // Jump over the remaining tests and the trap to the allow.
            prog.push(libc::sock_filter { code: JEQ, jt: (n - i) as u8, jf: 0, k: nr as u32 });
        }
        prog.push(stmt(RET, libc::SECCOMP_RET_TRAP));
        prog.push(stmt(RET, libc::SECCOMP_RET_ALLOW));
        let fprog = libc::sock_fprog { len: prog.len() as u16, filter: prog.as_mut_ptr() };
        // SAFETY: valid filter program; no_new_privs is required to install
        // a filter without CAP_SYS_ADMIN and affects only this thread.
        unsafe {
            assert_eq!(libc::prctl(libc::PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), 0);
            assert_eq!(libc::prctl(libc::PR_SET_SECCOMP, libc::SECCOMP_MODE_FILTER, &fprog as *const _), 0);
        }
        drop(prog);
    }
}

#[cfg(not(all(target_os = "linux", target_arch = "x86_64")))]
mod syscalls {
    use std::sync::atomic::{AtomicI64, AtomicU64};
    pub static TRAPPED: AtomicU64 = AtomicU64::new(0);
    pub static FIRST: AtomicI64 = AtomicI64::new(-1);
    pub fn install_handler() {}
    pub fn forbid_on_this_thread() {}
}

/// Allocations and frees, and forbidden system calls, counted on the
/// real-time thread.
#[derive(Debug, PartialEq)]
struct Counts {
    allocations: u64,
    syscalls: u64,
    first_syscall: i64,
}

/// Runs `plan` live for `seconds`, changing every live parameter of every
/// node halfway (to its default; integers such as `interp.texture` and
/// `mesh.gradient.scene` to the next index, a real switch), and counts
/// what the real-time thread did.
fn allocations(plan: Plan, seconds: f64) -> Result<Counts, String> {
    syscalls::TRAPPED.store(0, Ordering::SeqCst);
    syscalls::FIRST.store(-1, Ordering::SeqCst);
    let mut taps = LivePlan::source_taps(&plan);
    taps.extend(LivePlan::guard_taps(&plan));
    let mut changes = Vec::new();
    for k in 0..plan.len() {
        for p in plan.spec(k).params.iter().filter(|p| p.live) {
            changes.push((plan.node_name(k).to_string(), p));
        }
    }
    let lp = LivePlan::new(plan, &taps).map_err(|e| e.to_string())?;
    let cfg = LiveConfig { duration: Some(seconds), miss_streak: 0, hook: Some(hook), ..LiveConfig::default() };
    let before = alloc_counter::allocations();
    let armings = alloc_counter::armings();
    let mut session = live::start(lp, &cfg).map_err(|e| e.to_string())?;
    let half = session.control.tick_at(seconds / 2.0);
    for (node, p) in &changes {
        let v = match p.default {
            evflow_engine::spec::ParamDefault::Float(x) => x.to_string(),
            // A real change (a texture or scene switch); refused harmlessly if out of range.
            evflow_engine::spec::ParamDefault::Int(i) => (i + 1).to_string(),
            evflow_engine::spec::ParamDefault::Bool(b) => b.to_string(),
            evflow_engine::spec::ParamDefault::Text(t) => t.to_string(),
            _ => continue,
        };
        session.control.set(node, p.name, &v, Some(half)).map_err(|e| e.to_string())?;
    }
    let exit = session.join();
    if let Some(f) = exit.failure {
        return Err(f.to_string());
    }
    assert_eq!(alloc_counter::armings(), armings + 1, "the hook armed the guard");
    Ok(Counts {
        allocations: alloc_counter::allocations() - before,
        syscalls: syscalls::TRAPPED.load(Ordering::SeqCst),
        first_syscall: syscalls::FIRST.load(Ordering::SeqCst),
    })
}

const CLEAN: Counts = Counts { allocations: 0, syscalls: 0, first_syscall: -1 };

fn build(path: &std::path::Path, text: Option<&str>) -> Plan {
    let reg = evflow_nodes::registry();
    let checked = match text {
        Some(t) => {
            let g = evflow_engine::graph::parse_graph(path, t).unwrap_or_else(|e| panic!("{e}"));
            evflow_engine::check(&g, &reg, &[]).unwrap_or_else(|e| panic!("{e}"))
        }
        None => load_file(path, &reg, &[]).unwrap_or_else(|e| panic!("{e}")),
    };
    let dir = tempfile::tempdir().unwrap();
    let opts = PlanOptions {
        max_block: 1,
        mode: evflow_engine::RunMode::Live,
        timing: false,
        out_dir: Some(dir.path().to_path_buf()),
        ..Default::default()
    };
    Plan::build(&checked, &opts).unwrap_or_else(|e| panic!("{e}"))
}

/// Graphs covering node types no shipped live graph uses yet.
const EXTRA: &[(&str, &str)] = &[
    (
        "filters-and-metric",
        r#"
[graph]
format = 1
name = "filters-and-metric"
rate = 1000.0
connections = [
    "excite.out -> low.in", "low.out -> mix.in", "mix.out -> limit.in",
    "limit.out -> back.in", "back.out -> met.virtual", "excite.out -> met.real",
    "limit.out -> st.in",
]
[nodes.excite]
type = "prbs"
order = 9
periods = 1000
[nodes.low]
type = "butterworth"
kind = "lowpass"
order = 4
cutoff = 100.0
[nodes.mix]
type = "gain"
gain = 0.5
[nodes.limit]
type = "limit"
[nodes.back]
type = "delay"
samples = 3
[nodes.met]
type = "metric"
nfft = 256
[nodes.st]
type = "stats"
"#,
    ),
    (
        "rate-nodes",
        r#"
[graph]
format = 1
name = "rate-nodes"
rate = 1000.0
connections = [
    "force.out -> down.in", "down.out -> up.in", "up.out -> level.in",
    "ir.out -> smooth.in", "smooth.out -> path.in",
]
[nodes.force]
type = "sine"
rate = 10000.0
frequency = 50.0
[nodes.down]
type = "decimate"
rate = 1000.0
[nodes.up]
type = "resample"
rate = 2000.0
quality = "best"
[nodes.level]
type = "stats"
[nodes.ir]
type = "sine"
rate = 40.0
frequency = 1.0
[nodes.smooth]
type = "resample"
rate = 1000.0
quality = "fast"
[nodes.path]
type = "stats"
"#,
    ),
];

/// A node that allocates in `process`: the guard must see it.
mod allocating {
    use evflow_engine::{BuildContext, Io, Node, NodeError, NodeSpec, Params, PortSpec, Role};
    pub static SPEC: NodeSpec = NodeSpec::new("test.alloc", "test", Role::Sink, "allocates (test only)", build)
        .ports(&[PortSpec::input("in", "1", "x")]);
    struct A(Vec<Vec<f64>>);
    fn build(_: &Params, _: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
        Ok(Box::new(A(Vec::new())))
    }
    impl Node for A {
        fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
            self.0.push(io.input(evflow_engine::ports::InPort::at(0)).to_vec());
            // File I/O: a system call the filter traps.
            let _ = std::fs::metadata("/");
            Ok(())
        }
        fn reset(&mut self) {}
    }
}

#[test]
fn no_allocation_on_the_real_time_thread() {
    let _turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
    syscalls::install_handler();
    // The guard works: a node that allocates is caught.
    {
        let mut reg = evflow_nodes::registry();
        reg.add(&allocating::SPEC);
        let doc = "[graph]\nformat = 1\nname = \"a\"\nrate = 1000.0\nconnections = [\"s.out -> a.in\"]\n\
                   [nodes.s]\ntype = \"sine\"\n[nodes.a]\ntype = \"test.alloc\"\n";
        let g = evflow_engine::graph::parse_graph(std::path::Path::new("a.toml"), doc).unwrap();
        let checked = evflow_engine::check(&g, &reg, &[]).unwrap();
        let plan = Plan::build(
            &checked,
            &PlanOptions { max_block: 1, mode: evflow_engine::RunMode::Live, ..Default::default() },
        )
        .unwrap();
        let n = allocations(plan, 0.05).unwrap();
        assert!(n.allocations >= 50, "the guard must count the allocating node's allocations ({n:?})");
        if cfg!(all(target_os = "linux", target_arch = "x86_64")) {
            assert!(n.syscalls >= 50, "the filter must trap the node's file I/O ({n:?})");
        }
    }

    let mut ran = Vec::new();
    let mut skipped = Vec::new();
    for (path, _) in evflow_tests::shipped_graphs() {
        match allocations(build(&path, None), 0.4) {
            Ok(n) => {
                assert_eq!(n, CLEAN, "{}: allocations/frees or system calls on the real-time thread", path.display());
                ran.push(path.display().to_string());
            }
            Err(why) if why.contains("cannot run live") => skipped.push(format!("{}: {why}", path.display())),
            Err(why) => panic!("{}: {why}", path.display()),
        }
    }
    for (name, text) in EXTRA {
        let n = allocations(build(std::path::Path::new(name), Some(text)), 0.4).unwrap();
        assert_eq!(n, CLEAN, "{name}: allocations/frees or system calls on the real-time thread");
        ran.push(name.to_string());
    }
    eprintln!("ran live without allocating: {ran:?}\nnot live-capable: {skipped:?}");
    for live in ["display-live.toml", "mesh-live.toml", "texture-live.toml"] {
        assert!(ran.iter().any(|g| g.ends_with(live)), "the shipped live graph {live} ran");
    }
}

/// The studio attached (`evflow live --studio`): its intake fed from the
/// tap, event and timing rings the way the recorder and metrics threads
/// feed it, a browser connected over the WebSocket steering the texture,
/// the gain and the limiter (the same command queue as the console) while
/// it receives frames — and still no allocation, free or forbidden system
/// call on the real-time thread.
#[test]
fn no_allocation_on_the_real_time_thread_with_the_studio_attached() {
    use evflow_tools::studio::{default_taps, Description, Studio, StudioConfig};
    use tungstenite::Message;
    let _turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
    syscalls::install_handler();
    syscalls::TRAPPED.store(0, Ordering::SeqCst);
    syscalls::FIRST.store(-1, Ordering::SeqCst);
    let path = evflow_tests::root().join("graphs/texture-live.toml");
    let checked = load_file(&path, &evflow_nodes::registry(), &[]).unwrap_or_else(|e| panic!("{e}"));
    let opts = PlanOptions { max_block: 1, mode: evflow_engine::RunMode::Live, timing: false, ..Default::default() };
    let plan = Plan::build(&checked, &opts).unwrap_or_else(|e| panic!("{e}"));
    let mut taps = LivePlan::source_taps(&plan);
    taps.extend(LivePlan::guard_taps(&plan));
    taps.extend(default_taps(&checked, &plan));
    let lp = LivePlan::new(plan, &taps).unwrap();
    let vars = live::live_vars(&checked);
    let description = Description::live(&checked, &lp, &vars);
    let cfg = LiveConfig { duration: Some(2.0), miss_streak: 0, hook: Some(hook), ..LiveConfig::default() };
    let before = alloc_counter::allocations();
    let armings = alloc_counter::armings();
    let mut session = live::start(lp, &cfg).unwrap();
    session.control.bind_vars(vars);
    let parts = session.into_parts();
    let control = std::sync::Arc::new(Mutex::new(parts.control));
    let scfg = StudioConfig { addr: "127.0.0.1:0".parse().unwrap(), public: false };
    let (studio, ingest) = Studio::start_live(&scfg, &description, control, parts.shared.clone()).unwrap();

    // The recorder's and metrics thread's part: drain every ring into the studio.
    let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let drain = {
        let (done, mut rings, mut events, mut stats) = (done.clone(), parts.taps, parts.events, parts.stats);
        std::thread::spawn(move || loop {
            let last = done.load(Ordering::Acquire);
            for (i, (_, r)) in rings.iter_mut().enumerate() {
                if let Ok(c) = r.read_chunk(r.slots()) {
                    let (a, b) = c.as_slices();
                    ingest.samples(i, a);
                    ingest.samples(i, b);
                    c.commit_all();
                }
            }
            while let Ok(e) = events.pop() {
                ingest.event(&e);
            }
            if let Ok(c) = stats.read_chunk(stats.slots()) {
                let (a, b) = c.as_slices();
                ingest.stats(a);
                ingest.stats(b);
                c.commit_all();
            }
            if last {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        })
    };

    // A browser: reads frames, steers.
    let (mut ws, _) = tungstenite::connect(format!("ws://{}/ws", studio.addr())).unwrap();
    let mut frames = 0;
    let mut replies = Vec::new();
    let mut applied = Vec::new();
    let sets =
        [("texture", "2"), ("gain", "0.5"), ("limit.enable", "false"), ("limit.enable", "true"), ("gain", "9e9")];
    let mut sent = 0;
    while !parts.thread.is_finished() {
        let Ok(Message::Text(t)) = ws.read() else { break };
        let v: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
        match v["type"].as_str() {
            Some("frame") => {
                frames += 1;
                for e in v["events"].as_array().into_iter().flatten() {
                    applied.push(format!("{}.{}={}", e["node"].as_str().unwrap_or(""), e["param"], e["value"]));
                }
                if frames % 4 == 0 && sent < sets.len() {
                    let (target, value) = sets[sent];
                    let m = serde_json::json!({ "type": "set", "id": sent, "target": target, "value": value });
                    ws.send(Message::text(m.to_string())).unwrap();
                    sent += 1;
                }
            }
            Some("reply") => replies.push(v),
            _ => {}
        }
    }
    let exit = parts.thread.join();
    assert!(exit.failure.is_none());
    done.store(true, Ordering::Release);
    drain.join().unwrap();
    studio.close();
    assert_eq!(alloc_counter::armings(), armings + 1, "the hook armed the guard");
    let n = Counts {
        allocations: alloc_counter::allocations() - before,
        syscalls: syscalls::TRAPPED.load(Ordering::SeqCst),
        first_syscall: syscalls::FIRST.load(Ordering::SeqCst),
    };
    assert_eq!(n, CLEAN, "allocations/frees or system calls on the real-time thread with the studio attached");
    // The studio did its part: frames flowed and every change was answered,
    // the out-of-limits one refused.
    assert!(frames >= 20, "{frames} frames");
    assert_eq!(replies.len(), sets.len(), "{replies:?}");
    assert!(replies[..4].iter().all(|r| r["ok"] == true), "{replies:?}");
    assert_eq!(replies[4]["ok"], false, "{replies:?}");
    for want in ["interp.\"texture\"=2.0", "gain.\"gain\"=0.5", "limit.\"enable\"=0.0", "limit.\"enable\"=1.0"] {
        assert!(applied.iter().any(|a| a == want), "{want} applied: {applied:?}");
    }
}
