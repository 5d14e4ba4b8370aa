//! Shared helpers of the texture tests: grids of sine "actuation signals",
//! written as recordings, and amplitude readings from the spectrum.
#![allow(dead_code)]

use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::f64::consts::TAU;
use std::path::Path;

/// A sine of `f` Hz and amplitude `a`, `n` samples at 1 kHz.
pub fn sine(f: f64, a: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| a * (TAU * f * i as f64 / 1000.0).sin()).collect()
}

/// Writes one grid cell: a recording with channel `u` at 1 kHz and the condition.
pub fn write_cell(dir: &Path, name: &str, load: f64, velocity: f64, samples: &[f64]) {
    let mut meta = RecordingMeta::new(1000.0, vec![Channel::new("u", "1")]);
    meta.condition.load_g = Some(load);
    meta.condition.velocity_cm_s = Some(velocity);
    meta.condition.material = Some("sines".into());
    let mut w = RecordingWriter::create(&dir.join(name), meta).expect("create cell");
    for x in samples {
        w.write_frame(&[*x]).expect("frame");
    }
    w.finish().expect("finish cell");
}

/// A grid of sines whose frequency is `k`·velocity (a texture of `k`
/// cycles per cm), amplitude `amp(load, velocity)`, 8 s each.
pub fn write_sine_grid(dir: &Path, loads: &[f64], velocities: &[f64], k: f64, amp: impl Fn(f64, f64) -> f64) {
    std::fs::create_dir_all(dir).unwrap();
    for &m in loads {
        for &v in velocities {
            write_cell(dir, &format!("cell_{m}g_{v}cms"), m, v, &sine(k * v, amp(m, v), 8000));
        }
    }
}

/// The amplitude of the component at each bin of a 1 Hz-resolution
/// spectrum (nfft = 1000 at 1 kHz, Hann window, half overlap; §5.2.3 uses an
/// FFT as long as the sampling rate): 2·|X_k| / Σw.
pub fn amplitudes(x: &[f64]) -> Vec<f64> {
    let cfg = SpectrumConfig { rate: 1000.0, nfft: 1000, window: Window::Hann, overlap: 0.5 };
    let s = averaged_spectrum(x, cfg).unwrap().unwrap();
    s.magnitude.iter().map(|m| 2.0 * m / s.window_sum).collect()
}

/// The bin of the largest amplitude above 0 Hz.
pub fn peak(a: &[f64]) -> usize {
    (1..a.len()).max_by(|&i, &j| a[i].total_cmp(&a[j])).unwrap()
}

/// Runs `feed(load) + feed(velocity) → interp → playback → tap` for
/// `ticks` base ticks (1 kHz) in blocks of `block`, and returns playback's
/// output. `interp` and `playback` take the extra parameters given.
pub fn run_chain(
    dir: &Path,
    interp: &str,
    playback: &str,
    load: &[f64],
    velocity: &[f64],
    ticks: u64,
    block: usize,
) -> Result<Vec<f64>, String> {
    run_chain_with(dir, interp, playback, load, velocity, ticks, block, &[])
}

/// [`run_chain`] with live changes of `interp`'s parameters: `(tick,
/// param, value)`, applied before that tick as a live session (or a
/// replay) applies them.
#[allow(clippy::too_many_arguments)]
pub fn run_chain_with(
    dir: &Path,
    interp: &str,
    playback: &str,
    load: &[f64],
    velocity: &[f64],
    ticks: u64,
    block: usize,
    changes: &[(u64, &'static str, f64)],
) -> Result<Vec<f64>, String> {
    use evflow_engine::harness::{FEED, TAP};
    use evflow_engine::params::toml_float;
    use evflow_engine::{check, graph::parse_graph, Plan, PlanOptions};
    let list = |v: &[f64]| v.iter().map(|x| toml_float(*x)).collect::<Vec<_>>().join(",");
    let doc = format!(
        "[graph]\nformat = 1\nname = \"chain\"\nrate = 1000\nconnections = [\"m.out -> ip.load\", \"v.out -> ip.velocity\", \
         \"ip.table -> pb.table\", \"v.out -> pb.velocity\", \"pb.out -> tap.in\"]\n\
         [nodes.m]\ntype = \"harness.feed\"\nrate = 1000.0\nvalues = [{}]\n\
         [nodes.v]\ntype = \"harness.feed\"\nrate = 1000.0\nvalues = [{}]\n\
         [nodes.ip]\ntype = \"interp\"\n{interp}\n[nodes.pb]\ntype = \"playback\"\n{playback}\n[nodes.tap]\ntype = \"harness.tap\"\n",
        list(load),
        list(velocity)
    );
    let mut reg = evflow_nodes::registry();
    reg.add(&FEED).add(&TAP);
    let g = parse_graph(&dir.join("chain.toml"), &doc).map_err(|e| e.to_string())?;
    let checked = check(&g, &reg, &[]).map_err(|e| e.to_string())?;
    let opts = PlanOptions {
        max_block: block,
        timing: false,
        base_dir: Some(dir.to_path_buf()),
        out_dir: Some(dir.to_path_buf()),
        ..PlanOptions::default()
    };
    let mut plan = Plan::build(&checked, &opts).map_err(|e| e.to_string())?;
    let ip = (0..plan.len()).find(|&k| plan.node_name(k) == "ip").ok_or("no interp in the plan")?;
    let mut out = Vec::new();
    let mut done = 0;
    while done < ticks {
        for &(at, param, value) in changes.iter().filter(|c| c.0 == done) {
            plan.set(ip, param, value).map_err(|e| format!("tick {at}: {e}"))?;
        }
        let next_change = changes.iter().map(|c| c.0).filter(|&t| t > done).min().unwrap_or(u64::MAX);
        let n = (plan.max_block() as u64).min(ticks - done).min(next_change - done);
        plan.step(n as usize).map_err(|e| e.to_string())?;
        out.extend_from_slice(plan.output("pb", 0).unwrap());
        done += n;
    }
    plan.finish().map_err(|e| e.to_string())?;
    Ok(out)
}
