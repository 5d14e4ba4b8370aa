//! The named stiff cases of issue 26: the lab's `stiff` profile and
//! harder, the integrators at their largest step, Butterworth at the ends
//! of its order and cut-off, decimation and re-sampling at extreme ratios,
//! NARX with saturated units, the Volterra model and `synth.optimize` far
//! outside their training range with bounds near zero, a mesh of slivers,
//! FOAW on a resting and a jumping finger, a live graph run long in
//! fast-forward, and NaN/Inf samples arriving from outside the graph.

use super::graphs::{check_text, run_checked, Running};
use super::invariant::{Invariant, Observed};
use super::{single, Case, Env, Group, Work};
use evflow_engine::params::toml_string;
use evflow_engine::NodeSpec;
use evflow_nodes::example_files as fixtures;
use evflow_nodes::lab::profile::{LabProfile, KEYS};
use std::path::Path;

fn spec(name: &str) -> &'static NodeSpec {
    evflow_nodes::registry().get(name).unwrap_or_else(|| panic!("no node type `{name}`"))
}

fn case(
    name: &str,
    covers: &[&'static str],
    extreme: &str,
    invariant: Invariant,
    body: impl Fn(&Env) -> Observed + Send + Sync + 'static,
) -> Case {
    Case {
        name: name.to_string(),
        group: Group::Stiff,
        covers: covers.to_vec(),
        family: None,
        extreme: extreme.to_string(),
        invariant,
        work: Work::Whole(Box::new(body)),
    }
}

/// The profile keys the harder-than-stiff lab sets to their largest value:
/// contact and normal stiffness, the electroadhesion bandwidths (amplifier,
/// relaxation, friction lag) and the sensor's resonance.
const HARDEST: &[&str] = &[
    "display.contact.stiffness_n_per_m",
    "display.amplifier.bandwidth_hz",
    "display.electrical.relaxation_hz",
    "display.friction.lag_cutoff_hz",
    "tribometer.normal_stiffness_n_per_m",
    "sensor.resonance_hz",
];

/// A lab profile (TOML) with every `HARDEST` key at its declared
/// maximum — but below half the sample rate `rate` for a corner frequency
/// the lab requires to be (the charge relaxation's).
pub fn hardest_profile(rate: f64) -> String {
    let mut s = String::from(
        "[lab]\nname = \"hardest\"\ndescription = \"stiffness and bandwidths at their limits (report stability)\"\n",
    );
    for k in KEYS.iter().filter(|k| HARDEST.contains(&k.path().as_str())) {
        let v = if k.name == "relaxation_hz" { k.max.min(0.45 * rate) } else { k.max };
        s += &format!("[{}]\n{} = {:?}\n", k.section, k.name, v);
    }
    s
}

/// The simulated lab chain: a sine drives the display while the tribometer
/// scans it; the force sensor acquires the force.
fn lab_graph(profile: &Path, rate: f64, integrator: &str, substeps: u32) -> String {
    let p = toml_string(&profile.display().to_string());
    let f = (rate * 0.08).min(80.0);
    format!(
        "[graph]\nformat = 1\nname = \"stiff\"\nrate = {rate:?}\nseed = 7\nconnections = [\
         \"drive.out -> display.u\", \"trib.load -> display.load\", \"trib.velocity -> display.velocity\", \
         \"display.force -> sensor.surface_force\", \"trib.velocity -> sensor.velocity\", \"sensor.force -> tap.in\"]\n\
         [nodes.drive]\ntype = \"sine\"\nfrequency = {f:?}\namplitude = 1.0\nrate = {rate:?}\n\
         [nodes.trib]\ntype = \"sim.tribometer\"\nprofile = {p}\npasses = 0\nrate = {rate:?}\nintegrator = \"{integrator}\"\nsubsteps = {substeps}\n\
         [nodes.display]\ntype = \"sim.display\"\nprofile = {p}\nintegrator = \"{integrator}\"\nsubsteps = {substeps}\n\
         [nodes.sensor]\ntype = \"sim.forcesensor\"\nprofile = {p}\nintegrator = \"{integrator}\"\nsubsteps = {substeps}\n\
         [nodes.tap]\ntype = \"harness.tap\"\n"
    )
}

/// Runs graph `text` for `seconds` from `env`'s folder.
fn run_text(env: &Env, text: &str, seconds: f64, block: usize) -> Observed {
    match check_text(&env.dir.join("stability.toml"), text) {
        Ok(c) => {
            run_checked(&c, &Running { base_dir: env.dir.clone(), out_dir: env.dir.join("stiff-out"), seconds, block })
        }
        Err(e) => Observed { error: Some(e), ..Observed::default() },
    }
}

fn lab_cases(v: &mut Vec<Case>, env: &Env) {
    let stiff = env.graphs.join("lab/stiff.toml");
    let hardest = env.dir.join("hardest.toml");
    let full_scale = |p: &Path| LabProfile::load(p).map(|l| l.sensor.full_scale_n).unwrap_or(f64::NAN);
    let sensor = |b: f64| Invariant::Bound {
        bound: b,
        port: Some("sensor.force".into()),
        why: "the sensor's full scale".into(),
    };
    let lab = ["sine", "sim.tribometer", "sim.display", "sim.forcesensor"];
    let secs = match env.size {
        super::Size::Ci => 2.0,
        super::Size::Full => 30.0,
    };
    for integ in ["exact", "rk4", "euler"] {
        let p = stiff.clone();
        v.push(case(
            &format!("lab · stiff profile, {integ}, 1 substep at 1 kHz"),
            &lab,
            &format!(
                "graphs/lab/stiff.toml (contact 1e6 N/m, sensor 150 kHz), {integ} at its largest step: \
                 one substep per 1 ms sample{}",
                if integ == "exact" { "" } else { " (explicit: diverges, the node resets and reports)" }
            ),
            sensor(full_scale(&stiff)),
            move |env| run_text(env, &lab_graph(&p, 1000.0, integ, 1), secs, 256),
        ));
    }
    let p = hardest.clone();
    v.push(case(
        "lab · harder than stiff: stiffness and bandwidths at their limits",
        &lab,
        &format!(
            "{} at their declared maxima (the relaxation corner below Nyquist), exact, 4 substeps at 1 kHz",
            HARDEST.join(", ")
        ),
        sensor(LabProfile::default().sensor.full_scale_n),
        move |env| {
            if let Err(e) = std::fs::write(&p, hardest_profile(1000.0)) {
                return Observed { error: Some(e.to_string()), ..Observed::default() };
            }
            run_text(env, &lab_graph(&p, 1000.0, "exact", 4), secs, 256)
        },
    ));
    let p = env.dir.join("hardest-1hz.toml");
    v.push(case(
        "lab · harder than stiff at 1 Hz, 1 substep",
        &lab,
        "the hardest profile with the exact integrators at the largest step they accept: \
         the lowest rate (1 Hz), one substep",
        sensor(LabProfile::default().sensor.full_scale_n),
        move |env| {
            if let Err(e) = std::fs::write(&p, hardest_profile(1.0)) {
                return Observed { error: Some(e.to_string()), ..Observed::default() };
            }
            run_text(env, &lab_graph(&p, 1.0, "exact", 1), secs * 100.0, 16)
        },
    ));
}

/// Butterworth: the highest order it accepts (8) at 1e-4 and 0.4999 of the
/// rate, and the order 16, which its declaration refuses.
fn butterworth_cases(v: &mut Vec<Case>, env: &Env) {
    let bw = spec("butterworth");
    let long = match env.size {
        super::Size::Ci => 100_000,
        super::Size::Full => 400_000,
    };
    let params =
        |kind: &str, cutoff: f64, order: u32| format!("kind = \"{kind}\"\norder = {order}\ncutoff = {cutoff:?}");
    // DC gain of the low-pass at 1e-4 of the rate: a step of 1 settles at 1.
    v.push(case(
        "butterworth · order 8 lowpass at 1e-4 of the rate: DC gain",
        &["butterworth"],
        &format!("order 8 (the largest accepted), cut-off 0.1 Hz at 1 kHz; a step of 1 held {long} samples"),
        Invariant::Reference { value: 1.0, tol: 1e-4, what: "mean of the last 1000 outputs".into() },
        move |env| {
            let mut o = single::run(bw, &params("lowpass", 0.1, 8), &|_| vec![1.0; long], long as u64, 4096, &env.dir);
            o.measured = last_mean(env, bw, &params("lowpass", 0.1, 8), &|_| vec![1.0; long], long);
            o
        },
    ));
    v.push(case(
        "butterworth · order 8 highpass at 0.4999 of the rate: gain at Nyquist",
        &["butterworth"],
        &format!("order 8, cut-off 499.9 Hz at 1 kHz; (−1)ⁿ held {long} samples"),
        Invariant::Reference { value: 1.0, tol: 1e-4, what: "|out| over the last 1000 samples".into() },
        move |env| {
            let alt = |_: usize| (0..long).map(|n| if n % 2 == 0 { 1.0 } else { -1.0 }).collect::<Vec<f64>>();
            let p = params("highpass", 499.9, 8);
            let mut o = Observed::default();
            match single_outputs(env, bw, &p, &alt, long) {
                Ok(y) => {
                    o.watch("out", &y);
                    let tail = &y[y.len() - 1000..];
                    o.measured = Some(tail.iter().map(|v| v.abs()).sum::<f64>() / 1000.0);
                }
                Err(e) => o.error = Some(e),
            }
            o
        },
    ));
    for (kind, cutoff) in [("lowpass", 499.9), ("highpass", 0.1)] {
        v.push(case(
            &format!("butterworth · order 8 {kind} at {} of the rate: energy", cutoff / 1000.0),
            &["butterworth"],
            &format!("order 8, cut-off {cutoff} Hz at 1 kHz, a chirp with noise, {} samples", env.size.long_run()),
            Invariant::Energy,
            move |env| {
                let n = env.size.long_run() as usize;
                let x = fixtures::signal(n, 3);
                let ein = x.iter().map(|v| v * v).sum::<f64>();
                let mut o = Observed::default();
                match single_outputs(env, bw, &params(kind, cutoff, 8), &|_| x.clone(), n) {
                    Ok(y) => {
                        o.watch("out", &y);
                        o.energy = Some((ein, y.iter().map(|v| v * v).sum()));
                    }
                    Err(e) => o.error = Some(e),
                }
                o
            },
        ));
    }
    v.push(case(
        "butterworth · order 16 is refused",
        &["butterworth"],
        "order 16 (issue 26 asks for it), above the declared 1 ..= 8",
        Invariant::Refused { naming: "order".into() },
        move |env| single::run(bw, &params("lowpass", 0.1, 16), &|_| vec![1.0; 100], 100, 64, &env.dir),
    ));
}

/// The outputs of a one-output node, or the error.
fn single_outputs(
    env: &Env,
    spec: &'static NodeSpec,
    params: &str,
    input: &dyn Fn(usize) -> Vec<f64>,
    ticks: usize,
) -> Result<Vec<f64>, String> {
    let (ins, outs) = single::ports(spec, params)?;
    evflow_engine::harness::Single::new(spec, params)
        .inputs(ins.iter().enumerate().map(|(k, n)| (n.as_str(), input(k), single::RATE)))
        .outputs(outs.iter().take(1).map(String::as_str))
        .base_rate(single::RATE)
        .ticks(ticks as u64)
        .block(4096)
        .base_dir(&env.dir)
        .run()
        .map(|mut o| o.remove(0))
}

fn last_mean(
    env: &Env,
    spec: &'static NodeSpec,
    params: &str,
    input: &dyn Fn(usize) -> Vec<f64>,
    ticks: usize,
) -> Option<f64> {
    let y = single_outputs(env, spec, params, input, ticks).ok()?;
    let tail = &y[y.len().saturating_sub(1000)..];
    Some(tail.iter().sum::<f64>() / tail.len().max(1) as f64)
}

/// Decimation and re-sampling at extreme ratios: a constant of 1 must come
/// out as 1 (their DC gain).
fn rate_cases(v: &mut Vec<Case>) {
    let cases: [(&str, &str, &str, usize, &str); 5] = [
        (
            "decimate",
            "rate = 2.0",
            "1 kHz → 2 Hz (÷500), the largest factor one stage takes at its defaults",
            60_000,
            "out",
        ),
        (
            "decimate",
            "rate = 10.0\npassband = 0.95\nattenuation = 200.0",
            "÷100 at 200 dB, passband 0.95",
            60_000,
            "out",
        ),
        (
            "decimate",
            "rate = 500.0\npassband = 0.05\nattenuation = 20.0",
            "÷2 at the loosest design (20 dB, passband 0.05)",
            4000,
            "out",
        ),
        ("resample", "rate = 10.0\nquality = \"best\"", "1 kHz → 10 Hz (÷100), 256-tap sinc", 60_000, "out"),
        ("resample", "rate = 1000000.0\nquality = \"best\"", "1 kHz → 1 MHz (×1000), 256-tap sinc", 2000, "out"),
    ];
    for (node, params, what, ticks, _) in cases {
        let s = spec(node);
        v.push(case(
            &format!("{node} · {what}"),
            &[node],
            &format!("{what}; a constant 1 for {ticks} input samples"),
            Invariant::Reference { value: 1.0, tol: 1e-6, what: "the last output (DC gain)".into() },
            move |env| {
                let mut o = Observed::default();
                match single_outputs(env, s, params, &|_| vec![1.0; ticks], ticks) {
                    Ok(y) => {
                        o.watch("out", &y);
                        o.measured = y.last().copied();
                        o.notes.push(format!("{} output samples", y.len()));
                    }
                    Err(e) => o.error = Some(e),
                }
                o
            },
        ));
    }
}

/// NARX with saturated units, the Volterra model and `synth.optimize` far
/// outside their training range.
fn model_cases(v: &mut Vec<Case>, env: &Env) {
    let narx = spec("narx");
    let model = env.dir.join("models/narx.json");
    let y = evflow_nodes::narx::model::Model::load(&model).map(|m| m.normalization.y);
    let b = y.map(|y| y.min.abs().max(y.max.abs())).unwrap_or(f64::NAN);
    let ticks = env.size.ticks() as usize;
    v.push(case(
        "narx · saturated units: force at ±1e300",
        &["narx"],
        "force steps 0 → +1e300 → −1e300 → 0: every hidden tanh saturated",
        Invariant::Bound { bound: b, port: Some("u".into()), why: "the model's trained actuation range".into() },
        move |env| {
            let s = super::signals::Extreme::Steps1e300;
            single::run(narx, "model = \"models/narx.json\"", &|k| s.samples(ticks, k), ticks as u64, 64, &env.dir)
        },
    ));
    v.push(case(
        "volterra · actuation 1e6 × the training range",
        &["forward.train"],
        "the forward model (trained within ±1) evaluated on a chirp scaled by 1e6",
        Invariant::Reference {
            value: 0.0,
            tol: 1e-9,
            what: "largest relative departure from its quadratic law".into(),
        },
        volterra_far,
    ));
    for (bound, scale) in [(1e-6, 1e6), (2.0, 1e6), (1e-6, 1e-6)] {
        v.push(case(
            &format!("synth.optimize · target ×{scale:e}, bound {bound:e}"),
            &["synth.optimize"],
            &format!("the felt force scaled by {scale:e} (far outside the model's training), |u| ≤ {bound:e}"),
            Invariant::Monotone,
            move |env| optimize_far(env, scale, bound),
        ));
    }
}

fn volterra_far(env: &Env) -> Observed {
    use evflow_nodes::synth::model_file::ForwardModel;
    let mut o = Observed::default();
    let m = match ForwardModel::load(&env.dir.join("models/forward.json")).and_then(|m| m.volterra()) {
        Ok(m) => m,
        Err(e) => {
            o.error = Some(e.to_string());
            return o;
        }
    };
    let u: Vec<f64> = fixtures::signal(2000, 11);
    let s = 1e6;
    let eval = |x: &[f64]| {
        let mut y = vec![0.0; x.len()];
        m.eval(x, &mut y);
        y
    };
    let neg: Vec<f64> = u.iter().map(|x| -x).collect();
    let big: Vec<f64> = u.iter().map(|x| s * x).collect();
    let (yp, yn, yb) = (eval(&u), eval(&neg), eval(&big));
    o.watch("y", &yb);
    // y(u) = c + L(u) + Q(u): L = (y(u) − y(−u))/2, Q = (y(u) + y(−u))/2 − c.
    let c = m.constant();
    let mut worst: f64 = 0.0;
    for n in 0..u.len() {
        let l = 0.5 * (yp[n] - yn[n]);
        let q = 0.5 * (yp[n] + yn[n]) - c;
        let want = c + s * l + s * s * q;
        let scale = want.abs().max(s * s * 1e-12);
        worst = worst.max((yb[n] - want).abs() / scale);
    }
    o.measured = Some(worst);
    o
}

fn optimize_far(env: &Env, scale: f64, bound: f64) -> Observed {
    use evflow_nodes::synth::lbfgsb::Options;
    use evflow_nodes::synth::model_file::ForwardModel;
    use evflow_nodes::synth::synthesize::{synthesize, SynthConfig};
    let mut o = Observed::default();
    let model = match ForwardModel::load(&env.dir.join("models/forward.json")) {
        Ok(m) => m,
        Err(e) => {
            o.error = Some(e.to_string());
            return o;
        }
    };
    let n = match env.size {
        super::Size::Ci => 1000,
        super::Size::Full => fixtures::RECORDING_SAMPLES,
    };
    let target: Vec<f64> = fixtures::signal(n, 99).iter().map(|x| scale * (0.2 + 0.05 * x)).collect();
    let iters = match env.size {
        super::Size::Ci => 15,
        super::Size::Full => 100,
    };
    let cfg =
        SynthConfig { bound, options: Options { max_iter: iters, ..Options::default() }, ..SynthConfig::default() };
    match synthesize(&model, &target, &vec![true; n], &vec![0.0; n], &cfg) {
        Ok(s) => {
            o.watch("u", &s.u);
            if let Some(x) = s.u.iter().find(|x| x.abs() > bound) {
                o.violations.push(format!("|u| = {x:e} above the bound {bound:e}"));
            }
            o.series = s.history;
            o.notes.push(format!("stopped: {}", s.stop.describe()));
        }
        Err(e) => o.error = Some(e.to_string()),
    }
    o
}

/// A finger scanning across the sliver mesh, through `mesh.gradient` and
/// `mesh.edges`.
fn mesh_cases(v: &mut Vec<Case>, env: &Env) {
    let ticks = env.size.ticks() as usize * 5;
    // Lines across the fan of needles (y = 1 cm + k·1e-11 m) and the knife
    // edge, x from −1 to 5 cm (off the mesh at both ends).
    let path = move |k: usize| -> Vec<f64> {
        (0..ticks)
            .map(|i| {
                let t = i as f64 / ticks as f64;
                if k == 0 {
                    -0.01 + 0.06 * ((t * 8.0) % 1.0)
                } else {
                    [0.01 + 3e-11, 0.01 + 1e-9 * 17.5, 0.02, 0.035, 0.03][(t * 8.0) as usize % 5]
                }
            })
            .collect()
    };
    for (node, extra, inv) in [
        (
            "mesh.gradient",
            "range = \"auto\"\ncalib_directions = 4\ncalib_lines = 8\ncache = \"none\"",
            Invariant::Bound {
                bound: 1.0,
                port: Some("intensity".into()),
                why: "an intensity in [i_min, i_max]".into(),
            },
        ),
        ("mesh.edges", "", Invariant::Finite { refusal_ok: false }),
    ] {
        let s = spec(node);
        let params = format!("file = \"meshes/slivers.obj\"\nunit = 0.01\n{extra}");
        v.push(case(
            &format!("{node} · slivers and near-degenerate triangles"),
            &[node],
            "a fan of needles 1e-9 cm wide, a 1e-24 m² triangle, a collinear one, a knife edge 1e-12 cm high; \
             scan lines across them and off the mesh",
            inv,
            move |env| single::run(s, &params, &path, ticks as u64, 64, &env.dir),
        ));
    }
}

/// FOAW on a resting finger (exactly 0) and a jumping one (bounded by the
/// jump over one sample).
fn foaw_cases(v: &mut Vec<Case>, env: &Env) {
    let foaw = spec("foaw");
    // A resting finger keeps every window at its longest: the estimator's
    // cost per sample grows with max_window² (see docs/numerics.md).
    let n = match env.size {
        super::Size::Ci => 2000,
        super::Size::Full => 10_000,
    };
    for fit in ["best", "end"] {
        v.push(case(
            &format!("foaw · resting finger ({fit} fit)"),
            &["foaw"],
            &format!("a position held at 12.3 mm for {n} samples, window up to 1024"),
            Invariant::Reference { value: 0.0, tol: 0.0, what: "largest |velocity|".into() },
            move |env| {
                let p = format!("noise = 0.0005\nmax_window = 1024\nfit = \"{fit}\"");
                let mut o = single::run(foaw, &p, &|_| vec![0.0123; n], n as u64, 256, &env.dir);
                o.measured = Some(o.max_abs);
                o
            },
        ));
        let jump = 0.05;
        v.push(case(
            &format!("foaw · jumping finger ({fit} fit)"),
            &["foaw"],
            "a finger lifted and put down 5 cm away between two samples, every 100 samples, at rest between",
            Invariant::Bound {
                bound: jump * single::RATE,
                port: Some("velocity".into()),
                why: "the jump over one sample".into(),
            },
            move |env| {
                let p = format!("noise = 0.0\nmax_window = 1024\nfit = \"{fit}\"");
                let x = |_: usize| (0..n).map(|i| if (i / 100) % 2 == 0 { 0.0 } else { jump }).collect();
                single::run(foaw, &p, &x, n as u64, 256, &env.dir)
            },
        ));
    }
}

/// The live graph run in fast-forward (offline, whole blocks: the same
/// `Plan::step` the live runner ticks) for the size's longest run.
fn live_case(v: &mut Vec<Case>, env: &Env) {
    let secs = env.size.live_seconds();
    let file = env.graphs.join("display-live.toml");
    v.push(case(
        "live · display-live.toml in fast-forward",
        &["sine", "gain", "limit", "sim.display", "sim.tribometer", "sim.forcesensor", "stats"],
        &format!(
            "the live scan run {secs} s in fast-forward (blocks of 4096 ticks; the engine's longest allowed run, \
             1e7 s, is 10¹⁰ ticks — out of reach, so the full size runs an hour)"
        ),
        Invariant::Finite { refusal_ok: false },
        move |env| match evflow_engine::load_file(&file, &super::graphs::registry(), &[]) {
            Ok(c) => run_checked(
                &c,
                &Running {
                    base_dir: env.graphs.clone(),
                    out_dir: env.dir.join("live-out"),
                    seconds: secs,
                    block: 4096,
                },
            ),
            Err(e) => Observed { error: Some(e.to_string()), ..Observed::default() },
        },
    ));
}

/// A recording whose frame `at` is `bad` (NaN or ±Inf): written with a
/// marker value there, then the marker's bytes replaced.
pub fn poisoned_recording(path: &Path, at: usize, bad: f64) -> Result<(), String> {
    const MARK: f64 = 12345.678;
    let mut x: Vec<f64> = fixtures::signal(500, 4).iter().map(|v| 0.2 + 0.05 * v).collect();
    x[at] = MARK;
    fixtures::write_recording(path, "force", 1000.0, &x)?;
    let mut bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    let mark = MARK.to_le_bytes();
    let i = bytes.windows(8).position(|w| w == mark).ok_or("marker not found")?;
    bytes[i..i + 8].copy_from_slice(&bad.to_le_bytes());
    std::fs::write(path, bytes).map_err(|e| e.to_string())
}

/// NaN and Inf samples arriving from outside the graph (a recording) are
/// an error naming the frame, never an output.
fn nan_cases(v: &mut Vec<Case>) {
    for (bad, at, word) in [(f64::NAN, 17usize, "NaN"), (f64::INFINITY, 42, "+Inf"), (f64::NEG_INFINITY, 499, "-Inf")] {
        let rec = spec("recording.in");
        v.push(case(
            &format!("recording.in · {word} at frame {at}"),
            &["recording.in"],
            &format!("a recording whose frame {at} is {word}"),
            Invariant::Refused { naming: format!("frame {at} is {word}") },
            move |env| {
                let path = env.dir.join(format!("recordings/poisoned-{at}.wav"));
                if let Err(e) = poisoned_recording(&path, at, bad) {
                    return Observed { panic: Some(format!("fixture: {e}")), ..Observed::default() };
                }
                let p = format!("path = \"recordings/poisoned-{at}.wav\"\nchannels = [\"force\"]\nrate = 1000.0");
                single::run(rec, &p, &|_| Vec::new(), 600, 64, &env.dir)
            },
        ));
    }
    let opt = spec("synth.optimize");
    v.push(case(
        "synth.optimize · NaN in its target recording",
        &["synth.optimize"],
        "the target recording's frame 17 is NaN",
        Invariant::Refused { naming: "frame 17 is NaN".into() },
        move |env| {
            let path = env.dir.join("recordings/poisoned-target.wav");
            if let Err(e) = poisoned_recording(&path, 17, f64::NAN) {
                return Observed { panic: Some(format!("fixture: {e}")), ..Observed::default() };
            }
            let p = "target = \"recordings/poisoned-target\"\nmodel = \"models/forward.json\"\niterations = 2";
            single::run(opt, p, &|_| Vec::new(), 100, 64, &env.dir)
        },
    ));
}

/// Every named stiff case.
pub fn cases(env: &Env) -> Vec<Case> {
    let mut v = Vec::new();
    lab_cases(&mut v, env);
    butterworth_cases(&mut v, env);
    rate_cases(&mut v);
    model_cases(&mut v, env);
    mesh_cases(&mut v, env);
    foaw_cases(&mut v, env);
    live_case(&mut v, env);
    nan_cases(&mut v);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hardest_profile_loads_with_every_key_at_its_maximum() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("hardest.toml");
        std::fs::write(&p, hardest_profile(1e6)).unwrap();
        let lab = LabProfile::load(&p).unwrap_or_else(|e| panic!("{e}"));
        let n = KEYS.iter().filter(|k| HARDEST.contains(&k.path().as_str())).count();
        assert_eq!(n, HARDEST.len(), "every key named exists");
        for k in KEYS.iter().filter(|k| HARDEST.contains(&k.path().as_str())) {
            assert_eq!((k.get)(&lab), k.max, "{}", k.path());
        }
    }

    #[test]
    fn a_poisoned_recording_is_refused_naming_its_frame() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.wav");
        poisoned_recording(&p, 17, f64::NAN).unwrap();
        let e = evflow_nodes::recording::format::Recording::open(&p).map(|_| ()).unwrap_err().to_string();
        assert!(e.contains("frame 17 is NaN"), "{e}");
    }
}
