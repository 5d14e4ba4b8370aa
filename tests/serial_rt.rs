//! The serial nodes keep the real-time rule while connected: a live session
//! of `graphs/display-serial.toml` talking to `evflow devsim` over a pty,
//! with an allocation-counting allocator armed on the real-time thread for
//! its whole loop (the stop sequence included), allocates and frees nothing.
//! (`tests/live_alloc.rs` runs the same graph without a device and also
//! traps system calls; here the nodes' connected path — ring pops and
//! pushes, atomics — is the one exercised.)
#![cfg(unix)]

use evflow_engine::live::{self, LiveConfig, LivePlan};
use evflow_engine::{check, graph::parse_graph, Override, Plan, PlanOptions};
use evflow_tests::alloc_counter;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

#[path = "studio_common.rs"]
mod common;

#[global_allocator]
static GLOBAL: alloc_counter::Counting = alloc_counter::Counting;

fn hook(on: bool) {
    alloc_counter::arm(on);
}

#[test]
fn connected_serial_nodes_do_not_allocate_on_the_real_time_thread() {
    // The counter counts: an allocation while armed is seen.
    let n0 = alloc_counter::allocations();
    alloc_counter::arm(true);
    let v = std::hint::black_box(vec![1u8; 10]);
    drop(v);
    alloc_counter::arm(false);
    assert_eq!(alloc_counter::allocations() - n0, 2, "one allocation and one free counted");

    let tmp = tempfile::tempdir().unwrap();
    let link = tmp.path().join("dev");
    let mut dev = Command::new(common::evflow())
        .arg("devsim")
        .arg("--link")
        .arg(&link)
        .args(["--duration", "60"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(dev.stdout.take().unwrap()).lines();
    assert!(lines.next().unwrap().unwrap().contains("emulated device"));
    std::thread::spawn(move || for _ in lines {});

    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/display-serial.toml");
    let g = parse_graph(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
    let o = [Override::parse(&format!("port={}", link.display())).unwrap()];
    let checked = check(&g, &evflow_nodes::registry(), &o).unwrap();
    let plan = Plan::build(
        &checked,
        &PlanOptions { max_block: 1, mode: evflow_engine::RunMode::Live, timing: false, ..Default::default() },
    )
    .unwrap();
    let mut taps = LivePlan::source_taps(&plan);
    taps.extend(LivePlan::guard_taps(&plan));
    let lp = LivePlan::new(plan, &taps).unwrap();
    let cfg = LiveConfig { duration: Some(1.0), miss_streak: 0, hook: Some(hook), ..LiveConfig::default() };
    let (before, armings) = (alloc_counter::allocations(), alloc_counter::armings());
    let mut session = live::start(lp, &cfg).unwrap();
    // Drain the taps meanwhile, as the recorder does (a full ring is fine
    // too: the real-time thread drops the tick's samples without waiting).
    let mut taps = std::mem::take(&mut session.taps);
    let mut connected = Vec::new();
    let t = std::time::Instant::now();
    while !session.is_finished() && t.elapsed().as_secs() < 30 {
        for (info, ring) in &mut taps {
            while let Ok(x) = ring.pop() {
                if info.node == "device" && info.port == "connected" {
                    connected.push(x);
                }
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let mut exit = session.join();
    assert!(exit.failure.is_none());
    let allocations = alloc_counter::allocations() - before;
    let _ = exit.plan.plan_mut().finish();
    drop(exit);
    dev.kill().unwrap();
    dev.wait().unwrap();
    assert_eq!(alloc_counter::armings(), armings + 1, "the hook armed the counter");
    assert!(connected.len() > 900 && connected.iter().all(|&c| c == 1.0), "the device was connected throughout");
    assert_eq!(allocations, 0, "allocations or frees on the real-time thread with the serial nodes connected");
}
