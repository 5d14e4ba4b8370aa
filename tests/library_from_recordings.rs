//! `evflow library from-recordings` end to end (issue 33, points 4 and 5):
//! the shipped rig recordings (PRBS at 60 g, 3 cm/s and 85 g, 5 cm/s) and a
//! stepped multilevel excitation the test records at the two other corners
//! (1 kHz), with texture recordings at 10 kHz made as a rig makes them (the
//! force as measured, offset and both stroke directions, low-passed at
//! 500 Hz), go through the route; the library it writes is read by the
//! library's own index reader and played by graphs/texture-live-recorded.toml
//! over the shipped stroke to a finite actuation. Beside it: the forces cell
//! against the simulated lab's own high-passed recording, every refusal of
//! bad input naming its file, and the guard of the force-rendering chains.

use evflow_nodes::recording::format::{Channel, Recording, RecordingMeta, RecordingWriter};
use evflow_nodes::texture::grid::{offset_ratio, OFFSET_RATIO_MAX};
use evflow_study::from_recordings::survey::{survey, Texture};
use evflow_study::from_recordings::{build, forces, Inputs};
use evflow_study::graphs::{run_graph, Sets};
use evflow_study::library::{is_library, Index};
use evflow_study::setup::Cond;
use std::path::{Path, PathBuf};

fn graphs() -> PathBuf {
    evflow_tests::root().join("graphs")
}

/// Writes `text` as a graph file in `dir` and runs it with `sets` into `out`.
fn run_text(dir: &Path, name: &str, text: &str, sets: Sets, out: &Path) {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    run_graph(&file, &sets, out).unwrap_or_else(|e| panic!("{e}"));
}

/// The stepped multilevel excitation of graphs/forward-build.toml, recorded
/// as a rig records it: `u`, the force as measured, the velocity; 4 passes.
const MULTILEVEL: &str = r#"[graph]
format = 1
rate = 1000.0
seed = 1
connections = [
    "excite.out -> stepped.a", "steps.out -> levels.in", "levels.out -> stepped.b",
    "stepped.out -> display.u", "tribometer.load -> display.load", "tribometer.velocity -> display.velocity",
    "display.force -> sensor.surface_force", "tribometer.velocity -> sensor.velocity",
    "stepped.out -> record.u", "sensor.force -> record.force", "tribometer.velocity -> record.velocity",
]
[vars]
mass = 85.0
speed = 5.0
[nodes.excite]
type = "prms"
q = 5
order = 9
clock = 1
level = 0.5
[nodes.steps]
type = "prms"
q = 3
order = 9
clock = 250
level = 1.0
[nodes.levels]
type = "normalize"
min = -3.0
max = 1.0
clamp = false
[nodes.stepped]
type = "mul"
[nodes.tribometer]
type = "sim.tribometer"
speed = "$speed"
mass = "$mass"
passes = 4
[nodes.display]
type = "sim.display"
[nodes.sensor]
type = "sim.forcesensor"
[nodes.record]
type = "recording.out"
path = "multilevel-${mass}g-${speed}cms"
channels = ["u", "force", "velocity"]
units = ["1", "N", "m/s"]
load_g = "$mass"
velocity_cm_s = "$speed"
gain = 1.0
"#;

/// A texture scanned as a rig records it at `rate` Hz: the force as the
/// sensor measured it (friction, bias; low-passed at 500 Hz at 10 kHz),
/// the velocity; two passes (right, then left). The node names and seeds
/// are graphs/record-textures.toml's, so at 1 kHz without the low-pass its
/// force is that graph's before its 10 Hz high-pass.
fn texture_graph(rate: f64) -> String {
    let lowpass = rate > 1000.0;
    format!(
        r#"[graph]
format = 1
rate = {rate}
seed = 1
connections = [
    "tribometer.position -> texture.position", "tribometer.velocity -> texture.velocity",
    "tribometer.load -> texture.load", "texture.force -> sensor.surface_force",
    "tribometer.velocity -> sensor.velocity", {force}
    "tribometer.velocity -> record.velocity",
]
[vars]
sample = "felt-fabric"
mass = 85.0
speed = 5.0
rep = 1
[nodes.tribometer]
type = "sim.tribometer"
rate = {rate}
speed = "$speed"
mass = "$mass"
passes = 2
[nodes.texture]
type = "sim.texture"
sample = "$sample"
[nodes.sensor]
type = "sim.forcesensor"
seed = "$rep"
{lowpass_node}
[nodes.record]
type = "recording.out"
path = "${{sample}}-${{mass}}g-${{speed}}cms-r${{rep}}"
channels = ["force", "velocity"]
units = ["N", "m/s"]
load_g = "$mass"
velocity_cm_s = "$speed"
material = "$sample"
"#,
        force = if lowpass {
            r#""sensor.force -> lowpass.in", "lowpass.out -> record.force","#
        } else {
            r#""sensor.force -> record.force","#
        },
        lowpass_node = if lowpass {
            "[nodes.lowpass]\ntype = \"butterworth\"\nkind = \"lowpass\"\norder = 4\ncutoff = 500.0"
        } else {
            ""
        },
    )
}

fn cond(mass: f64, speed: f64) -> Sets {
    Sets::new().num("mass", mass).num("speed", speed)
}

#[test]
fn a_labs_recordings_become_a_library_the_live_chain_plays() {
    let dir = tempfile::tempdir().unwrap();
    let (excitation, textures, lib) =
        (dir.path().join("excitation"), dir.path().join("textures"), dir.path().join("lib"));
    std::fs::create_dir_all(&excitation).unwrap();
    for f in ["prbs-60g-3cms", "prbs-85g-5cms"] {
        for ext in ["json", "wav"] {
            let name = format!("{f}.{ext}");
            std::fs::copy(graphs().join("data/rig").join(&name), excitation.join(&name)).unwrap();
        }
    }
    for (m, v) in [(60.0, 5.0), (85.0, 3.0)] {
        run_text(dir.path(), "multilevel", MULTILEVEL, cond(m, v), &excitation);
    }
    let tex = texture_graph(10_000.0);
    for (m, v) in [(60.0, 3.0), (60.0, 5.0), (85.0, 3.0), (85.0, 5.0)] {
        run_text(dir.path(), "texture", &tex, cond(m, v), &textures);
    }
    // A second repetition at one condition: kept out of the cell, and said so.
    run_text(dir.path(), "texture", &tex, cond(60.0, 3.0).int("rep", 2), &textures);

    let s = survey(&excitation, &textures).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.excitation.len(), 4);
    assert_eq!(s.textures.len(), 4);
    assert_eq!(s.samples(), ["felt-fabric"]);
    let inputs = Inputs {
        excitation: excitation.clone(),
        textures: textures.clone(),
        out: lib.clone(),
        graphs: graphs(),
        epochs: 3,
        jobs: 2,
    };
    let done = std::sync::atomic::AtomicUsize::new(0);
    let o = build(&inputs, &s, &|_| {
        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(done.into_inner(), 4 * 2 + 4, "progress once per item");
    assert_eq!(o.cells, 4);
    assert!(!lib.join(".partial").exists());

    // The index: the library's own type, read by its own reader.
    assert!(is_library(&lib));
    let index: Index = serde_json::from_str(&std::fs::read_to_string(lib.join("index.json")).unwrap()).unwrap();
    assert_eq!(index.conditions, ["60g-3cms", "60g-5cms", "85g-3cms", "85g-5cms"]);
    assert_eq!(index.entries.len(), 4);
    for e in &index.entries {
        assert!(lib.join(&e.forward_model).is_file() && lib.join(&e.model).is_file(), "{e:?}");
        assert!(e.training["validation_mse"].as_f64().is_some_and(f64::is_finite), "{}", e.training);
        let cell = Recording::open(&lib.join(&e.cells["forces"])).unwrap();
        // What the lab's library writes: 1 kHz, channel u in newtons, the
        // condition, gain 1; high-passed (the guard's ratio far below its limit).
        assert_eq!(cell.rate(), 1000.0);
        assert_eq!(cell.meta().channels, [Channel::new("u", "N")]);
        assert_eq!(cell.meta().condition.load_g, Some(e.condition.load_g));
        assert_eq!(cell.meta().condition.velocity_cm_s, Some(e.condition.velocity_cm_s));
        assert_eq!(cell.meta().condition.gain, Some(1.0));
        let u = cell.channel("u").unwrap();
        let ratio = offset_ratio(u, 1000.0);
        assert!(ratio < OFFSET_RATIO_MAX / 4.0, "{}: offset ratio {ratio}", e.tag);
        // One forward pass's constant-speed stretch: the 8 cm travel less
        // the speed-up and 100 ms of settling (2.54 s at 3 cm/s, 1.45 s at 5).
        let seconds = u.len() as f64 / 1000.0;
        let want = if e.condition.velocity_cm_s == 3.0 { 2.54 } else { 1.45 };
        assert!((seconds - want).abs() < 0.05, "{}: {seconds} s", e.tag);
    }
    // The multilevel excitation identifies the carrier gain (the lab's
    // graphs/forward-build.toml gives 0.14–0.17 N); the notes name the binary ones.
    for tag in ["60g-5cms", "85g-3cms"] {
        let m = evflow_nodes::synth::model_file::ForwardModel::load(&lib.join(format!("models/forward-{tag}.json")))
            .unwrap();
        assert!(m.carrier_gain_n > 0.08 && m.carrier_gain_n < 0.3, "{tag}: κ = {}", m.carrier_gain_n);
    }
    let notes = o.notes.join("\n");
    assert!(notes.contains("prbs-60g-3cms.json: a binary excitation"), "{notes}");
    assert!(notes.contains("felt-fabric-60g-3cms-r2"), "{notes}");

    // Played by the live chain over the shipped stroke.
    let models: Vec<String> = o.forward_models.iter().map(|p| p.display().to_string()).collect();
    let words: Vec<&str> = models.iter().map(String::as_str).collect();
    let sets = Sets::new().path("library", &lib).text("sample", "felt-fabric").words("forward_models", &words);
    let played = dir.path().join("played");
    run_graph(&graphs().join("texture-live-recorded.toml"), &sets, &played).unwrap_or_else(|e| panic!("{e}"));
    let rec = Recording::open(&played.join("actuation-felt-fabric")).unwrap();
    let u = rec.channel("u").unwrap();
    assert_eq!(u.len(), 8000);
    assert!(u.iter().all(|x| x.is_finite() && x.abs() <= 1.0));
    assert!(u.iter().any(|x| x.abs() > 0.05), "the chain played nothing");
    let target = rec.channel("target").unwrap();
    assert!(target.iter().any(|x| x.abs() > 0.005), "no force to render");

    // An existing library is never overwritten.
    let e = build(&inputs, &s, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("not empty") && e.contains("new folder"), "{e}");
}

#[test]
fn the_forces_cell_is_the_labs_own_high_passed_forward_stretch() {
    // At 1 kHz the route's cell and graphs/record-textures.toml's recording
    // (the same scan, high-passed at 10 Hz in the graph) cut to the same
    // forward stretch agree but for the resampler's low-pass above 448 Hz:
    // E_s (Eq. 5.2, 2–200 Hz) far below the repeat baseline (0.06).
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("raw");
    let sets = cond(60.0, 3.0).text("sample", "plastic-sheet");
    run_text(dir.path(), "texture", &texture_graph(1000.0), sets.clone(), &raw);
    let lab = dir.path().join("lab");
    run_graph(&graphs().join("record-textures.toml"), &sets.clone().int("passes", 2).int("rep", 1), &lab).unwrap();
    let t = Texture {
        path: raw.join("plastic-sheet-60g-3cms-r1.json"),
        cond: Cond { mass: 60.0, speed: 3.0 },
        rate: 1000.0,
        material: "plastic-sheet".into(),
        repeats: Vec::new(),
    };
    let (cell, seconds) = forces::cell(&graphs(), &t, &dir.path().join("work"), &dir.path().join("grid")).unwrap();
    let got = Recording::open(&cell).unwrap().channel("u").unwrap().to_vec();
    let rec = Recording::open(&lab.join("plastic-sheet-60g-3cms-r1")).unwrap();
    let gate = evflow_study::from_recordings::survey::forward_gate(rec.channel("velocity").unwrap(), 3.0, 1000.0);
    let run = evflow_study::from_recordings::survey::longest_run(&gate).unwrap();
    let want = &rec.channel("force").unwrap()[run];
    assert_eq!(got.len(), want.len(), "{seconds} s");
    use evflow_nodes::metric::spectral_error::{spectral_rms_error, Band};
    use evflow_nodes::metric::spectrum::{averaged_spectrum, SpectrumConfig, Window};
    let cfg = SpectrumConfig { rate: 1000.0, nfft: 1000, window: Window::Rect, overlap: 0.0 };
    let spectrum = |x: &[f64]| averaged_spectrum(x, cfg).unwrap().unwrap().magnitude;
    let band = Band::new(1000.0, 1000, 2.0, 200.0, false).unwrap();
    let es = spectral_rms_error(&spectrum(&got), &spectrum(want), &band).unwrap();
    assert!(es < 0.01, "E_s {es}");
    // Sample for sample, in time: within a few per cent of the force's rms.
    let rms = |x: &[f64]| (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
    let diff: Vec<f64> = got.iter().zip(want).map(|(a, b)| a - b).collect();
    assert!(rms(&diff) < 0.1 * rms(want), "{} against {}", rms(&diff), rms(want));
}

/// Writes a recording `dir/name` at `rate` with `channels` (name, unit,
/// samples) and the condition (load, speed, material).
fn write(dir: &Path, name: &str, rate: f64, channels: &[(&str, &str, Vec<f64>)], c: (f64, f64, Option<&str>)) {
    std::fs::create_dir_all(dir).unwrap();
    let mut meta = RecordingMeta::new(rate, channels.iter().map(|(n, u, _)| Channel::new(*n, *u)).collect());
    meta.condition.load_g = Some(c.0);
    meta.condition.velocity_cm_s = Some(c.1);
    meta.condition.material = c.2.map(String::from);
    let n = channels[0].2.len();
    let frames: Vec<f64> = (0..n).flat_map(|i| channels.iter().map(move |(_, _, x)| x[i])).collect();
    let mut w = RecordingWriter::create(&dir.join(name), meta).unwrap();
    w.write_interleaved(&frames).unwrap();
    w.finish().unwrap();
}

/// 1.5 s at 1 kHz of a pass at `speed` cm/s: (u, force, velocity).
fn pass(speed: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let u = (0..1500).map(|i| [0.5, -0.25, 0.0, 0.25][(i * 7 + i / 5) % 4]).collect();
    let f = (0..1500).map(|i| 0.3 + 0.01 * (i as f64 * 0.7).sin()).collect();
    (u, f, vec![speed / 100.0; 1500])
}

fn excitation(dir: &Path, name: &str, m: f64, v: f64) {
    let (u, f, vel) = pass(v);
    write(dir, name, 1000.0, &[("u", "1", u), ("force", "N", f), ("velocity", "m/s", vel)], (m, v, None));
}

fn texture(dir: &Path, name: &str, rate: f64, m: f64, v: f64, force_unit: &str) {
    let (_, f, vel) = pass(v);
    let k = (rate / 1000.0) as usize;
    let up = |x: Vec<f64>| x.into_iter().flat_map(|s| std::iter::repeat_n(s, k)).collect::<Vec<f64>>();
    write(dir, name, rate, &[("force", force_unit, up(f)), ("velocity", "m/s", up(vel))], (m, v, Some("felt")));
}

#[test]
fn bad_input_is_refused_naming_the_file_before_anything_is_built() {
    let dir = tempfile::tempdir().unwrap();
    let (ex, tx) = (dir.path().join("ex"), dir.path().join("tx"));
    excitation(&ex, "a-60g-3cms", 60.0, 3.0);
    excitation(&ex, "b-60g-5cms", 60.0, 5.0);
    texture(&tx, "felt-60g-3cms", 1000.0, 60.0, 3.0, "N");
    texture(&tx, "felt-60g-5cms", 1000.0, 60.0, 5.0, "N");
    let s = survey(&ex, &tx).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((s.excitation.len(), s.textures.len()), (2, 2));
    let refused = |what: &str| survey(&ex, &tx).expect_err(what).to_string();

    // A force in the wrong unit.
    texture(&tx, "felt-60g-5cms", 1000.0, 60.0, 5.0, "mN");
    let e = refused("unit");
    assert!(e.contains("felt-60g-5cms.json") && e.contains("unit `mN`, not `N`") && e.contains("newtons"), "{e}");
    // A missing channel.
    write(&tx, "felt-60g-5cms", 1000.0, &[("force", "N", pass(5.0).1)], (60.0, 5.0, Some("felt")));
    let e = refused("channel");
    assert!(e.contains("felt-60g-5cms.json") && e.contains("no channel `velocity`"), "{e}");
    // Mixed rates in one folder.
    std::fs::remove_file(tx.join("felt-60g-5cms.wav")).unwrap();
    std::fs::remove_file(tx.join("felt-60g-5cms.json")).unwrap();
    texture(&tx, "felt-60g-5cms", 10_000.0, 60.0, 5.0, "N");
    let e = refused("rates");
    assert!(e.contains("felt-60g-5cms.json: recorded at 10000 Hz but") && e.contains("felt-60g-3cms.json"), "{e}");
    // A rate that is no multiple of 1 kHz.
    texture(&tx, "felt-60g-5cms", 9999.87, 60.0, 5.0, "N");
    let e = refused("9999.87");
    assert!(e.contains("felt-60g-5cms.json: recorded at 9999.87 Hz") && e.contains("whole multiples of 1 kHz"), "{e}");
    texture(&tx, "felt-60g-5cms", 1000.0, 60.0, 5.0, "N");
    // A texture at a condition with no excitation.
    texture(&tx, "felt-85g-3cms", 1000.0, 85.0, 3.0, "N");
    let e = refused("no excitation");
    assert!(
        e.contains("felt-85g-3cms.json") && e.contains("no excitation recording") && e.contains("60 g, 5 cm/s"),
        "{e}"
    );
    // … with an excitation, still half a grid: 85 g, 5 cm/s is missing.
    excitation(&ex, "c-85g-3cms", 85.0, 3.0);
    let e = refused("grid");
    assert!(e.contains("`felt`") && e.contains("85 g, 5 cm/s") && e.contains("full grid"), "{e}");
    std::fs::remove_file(tx.join("felt-85g-3cms.json")).unwrap();
    std::fs::remove_file(tx.join("felt-85g-3cms.wav")).unwrap();
    // A non-finite sample (the WAV's last sample turned into NaN).
    let wav = tx.join("felt-60g-3cms.wav");
    let mut bytes = std::fs::read(&wav).unwrap();
    let n = bytes.len();
    bytes[n - 8..].copy_from_slice(&f64::NAN.to_le_bytes());
    std::fs::write(&wav, bytes).unwrap();
    let e = refused("NaN");
    assert!(e.contains("felt-60g-3cms.wav") && e.contains("NaN"), "{e}");
    texture(&tx, "felt-60g-3cms", 1000.0, 60.0, 3.0, "N");
    // Two excitations of one condition.
    excitation(&ex, "d-60g-3cms", 60.0, 3.0);
    let e = refused("twice");
    assert!(e.contains("d-60g-3cms.json: a second excitation at 60 g, 3 cm/s") && e.contains("a-60g-3cms.json"), "{e}");
    std::fs::remove_file(ex.join("d-60g-3cms.json")).unwrap();
    // A velocity that never holds the condition's speed (cm/s written as m/s).
    write(
        &tx,
        "felt-60g-5cms",
        1000.0,
        &[("force", "N", pass(5.0).1), ("velocity", "m/s", vec![5.0; 1500])],
        (60.0, 5.0, Some("felt")),
    );
    let e = refused("speed");
    assert!(e.contains("felt-60g-5cms.json") && e.contains("forward constant-speed stretch"), "{e}");
    texture(&tx, "felt-60g-5cms", 1000.0, 60.0, 5.0, "N");
    assert!(survey(&ex, &tx).is_ok());

    // A build that fails leaves nothing behind (here: no graphs to run).
    let out = dir.path().join("lib");
    let s = survey(&ex, &tx).unwrap();
    let inputs = Inputs {
        excitation: ex,
        textures: tx,
        out: out.clone(),
        graphs: dir.path().join("nowhere"),
        epochs: 1,
        jobs: 1,
    };
    let e = build(&inputs, &s, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("failed") && e.contains("nothing was written"), "{e}");
    assert!(!out.exists());
}

#[test]
fn a_force_rendering_chain_refuses_an_actuation_grid_and_the_raw_force_naming_the_fix() {
    // graphs/texture-live-recorded.toml over a library whose forces folder
    // holds (a) the shipped inverse-NARX cells (unit 1), (b) the raw force
    // (friction and bias, as measured) over its constant-speed stretch.
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let grid = lib.join("forces-felt-fabric");
    std::fs::create_dir_all(&grid).unwrap();
    let narx = graphs().join("data/narx-felt-fabric");
    for e in std::fs::read_dir(&narx).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, grid.join(p.file_name().unwrap())).unwrap();
    }
    let models: Vec<String> = ["60g-3cms", "60g-7cms", "110g-3cms", "110g-7cms"]
        .iter()
        .map(|t| graphs().join(format!("data/models/forward-{t}.json")).display().to_string())
        .collect();
    let models: Vec<&str> = models.iter().map(String::as_str).collect();
    let sets = Sets::new().path("library", &lib).text("sample", "felt-fabric").words("forward_models", &models);
    let play = |out: &str| {
        run_graph(&graphs().join("texture-live-recorded.toml"), &sets, &dir.path().join(out))
            .expect_err("refused")
            .to_string()
    };
    let e = play("a");
    assert!(e.contains("forces-felt-fabric") && e.contains("unit `1`, not `N`"), "{e}");
    assert!(e.contains("evflow library from-recordings") && e.contains("forces-SAMPLE"), "{e}");

    std::fs::remove_dir_all(&grid).unwrap();
    let raw = dir.path().join("raw");
    for (m, v) in [(60.0, 3.0), (60.0, 7.0), (110.0, 3.0), (110.0, 7.0)] {
        run_text(dir.path(), "texture", &texture_graph(1000.0), cond(m, v), &raw);
        let name = format!("felt-fabric-{m}g-{v}cms-r1");
        let rec = Recording::open(&raw.join(&name)).unwrap();
        let gate = evflow_study::from_recordings::survey::forward_gate(rec.channel("velocity").unwrap(), v, 1000.0);
        let run = evflow_study::from_recordings::survey::longest_run(&gate).unwrap();
        let force = rec.channel("force").unwrap()[run].to_vec();
        write(&grid, &format!("u-felt-fabric-{m}g-{v}cms"), 1000.0, &[("u", "N", force)], (m, v, Some("felt-fabric")));
    }
    let e = play("b");
    assert!(e.contains("forces-felt-fabric") && e.contains("carries an offset"), "{e}");
    assert!(e.contains("evflow library from-recordings"), "{e}");
}
