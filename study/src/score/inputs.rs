//! The three files a stroke's score is made from, read and checked
//! together: the recorded stroke (what the chain was given), the chain's
//! actuation (what it played) and the real force along the same path
//! (what the finger should have felt). Every error names the file, and the
//! channel or the figure that is wrong.

use crate::live::stroke::Stroke;
use crate::StudyError;
use evflow_nodes::lab::texture::samples;
use evflow_nodes::lab::texture::surface::V_SIGN;
use evflow_nodes::recording::format::Recording;
use std::path::{Path, PathBuf};

/// The shortest scorable stroke, s: E_s is read over whole one-second
/// segments, and Welch's reading needs two of them to overlap.
pub const MIN_SECONDS: f64 = 2.0;

/// The stroke's channels: the IR frame's touch position (m) and the load cell (N).
pub const STROKE_CHANNELS: [(&str, &str); 2] = [("ir_x", "m"), ("load_cell", "N")];
/// The actuation's channels: the actuation after the gain and `limit` (1 = 50 V) and the force the chain aimed at (N).
pub const ACTUATION_CHANNELS: [(&str, &str); 2] = [("u", "1"), ("target", "N")];
/// The real recording's channels: the finger's true velocity (m/s) and load (N), and the real force (N).
pub const REAL_CHANNELS: [(&str, &str); 3] = [("velocity", "m/s"), ("load", "N"), ("force", "N")];

/// How the texture's own force modulation (the display floor adds it) is
/// taken out of the real force.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Base {
    /// The lab's sample: its base friction μ₀·N·tanh(v/v_s) exactly, as
    /// `report live` takes it.
    Sample(String),
    /// A material the lab does not model: the base friction μ̂·N·tanh(v/v_s)
    /// with μ̂ fitted to the real force by least squares (v_s the lab's
    /// 0.5 mm/s).
    Fitted {
        /// The fitted friction coefficient.
        mu: f64,
    },
}

impl Base {
    /// A short description for the report.
    pub fn describe(&self) -> String {
        match self {
            Base::Sample(s) => format!("the lab sample {s}'s base friction"),
            Base::Fitted { mu } => format!("a base friction μ̂ = {mu:.3} fitted to the real force"),
        }
    }
}

/// A stroke's three files, checked.
#[derive(Debug, Clone)]
pub struct Inputs {
    /// The recorded stroke (ir_x, load_cell).
    pub stroke_file: PathBuf,
    /// The chain's actuation (u, target).
    pub actuation_file: PathBuf,
    /// The real force along the path (velocity, load, force).
    pub real_file: PathBuf,
    /// The stroke's frame rate, Hz, and its frames.
    pub frame_rate: f64,
    /// Frames in the stroke.
    pub frames: usize,
    /// The finger's true path and the real force at the actuation's rate,
    /// with the texture's own modulation, as the live study holds a stroke.
    pub path: Stroke,
    /// The chain's actuation, |u| ≤ 1 as played at gain 1.
    pub u: Vec<f64>,
    /// The force the chain aimed at, tick by tick (N, a friction magnitude).
    pub target: Vec<f64>,
    /// The material, for the report: the lab sample, or what the real
    /// recording's sidecar calls it (empty: not recorded).
    pub material: String,
    /// How the modulation was taken out.
    pub base: Base,
}

impl Inputs {
    /// Seconds of stroke.
    pub fn seconds(&self) -> f64 {
        self.path.len() as f64 / self.path.rate
    }

    /// A name for the stroke: the stroke file's name.
    pub fn name(&self) -> String {
        self.stroke_file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "stroke".into())
    }
}

fn bad(file: &Path, message: impl std::fmt::Display) -> StudyError {
    StudyError::Recording(format!("{}: {message}", file.display()))
}

/// Opens `file` with `channels`, whole, each in its unit (an empty unit is
/// taken on trust); `what` says what the file should be.
fn open(file: &Path, channels: &[(&str, &str)], what: &str) -> Result<Recording, StudyError> {
    let names: Vec<&str> = channels.iter().map(|c| c.0).collect();
    let rec = Recording::open_channels(file, &names)
        .map_err(|e| StudyError::Recording(format!("{e} — {what} needs the channels {}", names.join(", "))))?;
    if let Some(s) = rec.shortfall() {
        return Err(bad(
            file,
            format!(
                "truncated: {} of {} frames present (was its writer stopped?); record it again",
                s.present, s.claimed
            ),
        ));
    }
    for (name, unit) in channels {
        let k = rec.meta().channel_index(name).expect("opened by name");
        let has = &rec.meta().channels[k].unit;
        if !has.is_empty() && has != unit {
            return Err(bad(file, format!("channel `{name}` is in `{has}`; {what} needs it in `{unit}`")));
        }
    }
    Ok(rec)
}

/// Reads and checks a stroke's files: the recorded `stroke` (ir_x in m and
/// load_cell in N at the frame's rate, e.g. 40 Hz), the chain's
/// `actuation` (u and target at the chain's rate, e.g. 1 kHz) and the
/// `real` force along the same path (velocity in m/s, load in N and force
/// in N at the actuation's rate, as many samples). `sample` names the lab
/// sample whose base friction the display floor takes off the real force;
/// `None` takes the real recording's `material` when it is a lab sample,
/// and fits a base friction otherwise.
pub fn read(stroke: &Path, actuation: &Path, real: &Path, sample: Option<&str>) -> Result<Inputs, StudyError> {
    let s = open(stroke, &STROKE_CHANNELS, "a recorded stroke (the IR frame and the load cell)")?;
    let a = open(actuation, &ACTUATION_CHANNELS, "the chain's actuation (graphs/texture-live-recorded.toml's output)")?;
    let r = open(real, &REAL_CHANNELS, "the real force along the stroke (the path and the force)")?;
    let (rate, frame_rate) = check_timing((stroke, &s), (actuation, &a), (real, &r))?;
    let ch = |rec: &Recording, name: &str| rec.channel(name).expect("opened by name").to_vec();
    let (velocity, load, force) = (ch(&r, "velocity"), ch(&r, "load"), ch(&r, "force"));
    check_same_path(stroke, &ch(&s, "ir_x"), frame_rate, real, &r, rate)?;
    let material = match sample {
        Some(name) => name.to_string(),
        None => r.meta().condition.material.clone().unwrap_or_default(),
    };
    let (base_force, base) = base_friction(&material, sample, real, (&velocity, &load, &force))?;
    let modulation = force.iter().zip(&base_force).map(|(f, b)| f - b).collect();
    // The path's position is not needed to play a display (it takes the
    // load and the velocity); it is integrated from the IR frame's first reading.
    let mut x = s.channel("ir_x").expect("opened").first().copied().unwrap_or(0.0);
    let position = velocity
        .iter()
        .map(|v| {
            let here = x;
            x += v / rate;
            here
        })
        .collect();
    let path = Stroke { rate, position, velocity, load, real: force, modulation };
    Ok(Inputs {
        stroke_file: stroke.to_path_buf(),
        actuation_file: actuation.to_path_buf(),
        real_file: real.to_path_buf(),
        frame_rate,
        frames: s.frames(),
        path,
        u: ch(&a, "u"),
        target: ch(&a, "target"),
        material,
        base,
    })
}

/// The three recordings cover one stroke: the real force at the
/// actuation's rate, sample for sample; the stroke (slower, at the
/// frame's rate) as long; both long enough to score. Returns the
/// actuation's rate and the stroke's frame rate.
fn check_timing(
    (stroke, s): (&Path, &Recording),
    (actuation, a): (&Path, &Recording),
    (real, r): (&Path, &Recording),
) -> Result<(f64, f64), StudyError> {
    let rate = a.rate();
    if r.rate() != rate {
        return Err(bad(
            real,
            format!(
                "at {} Hz, but the actuation {} is at {rate} Hz: record the real force at the actuation's rate",
                r.rate(),
                actuation.display()
            ),
        ));
    }
    let stroke_seconds = s.frames() as f64 / s.rate();
    if stroke_seconds < MIN_SECONDS {
        return Err(bad(
            stroke,
            format!(
                "a stroke of {stroke_seconds:.3} s ({} frames at {} Hz); a score needs at least {MIN_SECONDS} s \
                 (E_s is read over whole one-second segments)",
                s.frames(),
                s.rate()
            ),
        ));
    }
    if r.frames() != a.frames() {
        return Err(bad(
            real,
            format!(
                "{} samples ({:.3} s), but the actuation {} has {} ({:.3} s): the two must cover the same stroke, sample for sample",
                r.frames(),
                r.frames() as f64 / rate,
                actuation.display(),
                a.frames(),
                a.frames() as f64 / rate
            ),
        ));
    }
    let seconds = a.frames() as f64 / rate;
    if seconds < MIN_SECONDS {
        return Err(bad(
            actuation,
            format!(
                "{seconds:.3} s of actuation; a score needs at least {MIN_SECONDS} s (E_s is read over whole one-second segments)"
            ),
        ));
    }
    let frame_rate = s.rate();
    if frame_rate >= rate {
        return Err(bad(
            stroke,
            format!(
                "at {frame_rate} Hz, not slower than the actuation's {rate} Hz: is it the stroke the IR frame \
                 and the load cell recorded (40 Hz on the dissertation's rig)?"
            ),
        ));
    }
    if (stroke_seconds - seconds).abs() > 1.0 / frame_rate + 0.5 / rate {
        return Err(bad(
            stroke,
            format!(
                "{} frames at {frame_rate} Hz ({stroke_seconds:.3} s), but the actuation {} lasts {seconds:.3} s: \
                 was the actuation made from this stroke?",
                s.frames(),
                actuation.display()
            ),
        ));
    }
    Ok((rate, frame_rate))
}

/// The base friction under the path — (`velocity`, `load`), with the real
/// `force` — that the display floor takes off the real force: lab sample
/// `material`'s, or where it is none (and no `sample` was named) one
/// μ·load·tanh(v/v₀) fitted to the force.
fn base_friction(
    material: &str,
    sample: Option<&str>,
    real: &Path,
    (velocity, load, force): (&[f64], &[f64], &[f64]),
) -> Result<(Vec<f64>, Base), StudyError> {
    let surface = samples::lookup(material);
    Ok(match (&surface, sample) {
        (Ok(surface), _) => (
            velocity.iter().zip(load).map(|(v, l)| surface.base_force(*v, *l)).collect(),
            Base::Sample(material.to_string()),
        ),
        (Err(e), Some(_)) => return Err(StudyError::Config(format!("--sample: {e}"))),
        (Err(_), None) => {
            let b: Vec<f64> = velocity.iter().zip(load).map(|(v, l)| l.max(0.0) * (v / V_SIGN).tanh()).collect();
            let bb: f64 = b.iter().map(|x| x * x).sum();
            if bb <= 0.0 {
                return Err(bad(real, "the finger never moves under load: there is no friction to score"));
            }
            let mu = b.iter().zip(force).map(|(x, f)| x * f).sum::<f64>() / bb;
            (b.iter().map(|x| mu * x).collect(), Base::Fitted { mu })
        }
    })
}

/// The least correlation between the IR frame's position and the real
/// recording's `position` at the frame's instants for the two to be one path.
pub const MIN_PATH_CORRELATION: f64 = 0.9;

/// When the real recording holds the path's `position` too, the stroke's
/// IR frame must follow it: a stroke and a real force of two different
/// strokes are refused.
fn check_same_path(
    stroke: &Path,
    ir_x: &[f64],
    frame_rate: f64,
    real: &Path,
    r: &Recording,
    rate: f64,
) -> Result<(), StudyError> {
    if r.meta().channel_index("position").is_none() {
        return Ok(());
    }
    let all = Recording::open_channels(real, &["position"]).map_err(|e| StudyError::Recording(e.to_string()))?;
    let position = all.channel("position").expect("opened by name");
    let pairs: Vec<(f64, f64)> = ir_x
        .iter()
        .enumerate()
        .filter_map(|(k, x)| {
            let n = ((k as f64) * rate / frame_rate).round() as usize;
            position.get(n).map(|p| (*x, *p))
        })
        .collect();
    let c = correlation(&pairs);
    if c.is_nan() || c < MIN_PATH_CORRELATION {
        return Err(bad(
            stroke,
            format!(
                "its IR frame does not follow the path of {} (correlation {c:.2} of the positions, at least \
                 {MIN_PATH_CORRELATION} expected): the stroke and the real force must be the same stroke",
                real.display()
            ),
        ));
    }
    Ok(())
}

/// Pearson's correlation of the pairs (NaN when either side is constant).
fn correlation(pairs: &[(f64, f64)]) -> f64 {
    let n = pairs.len() as f64;
    let (ma, mb) = pairs.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in pairs {
        sab += (x - ma) * (y - mb);
        saa += (x - ma).powi(2);
        sbb += (y - mb).powi(2);
    }
    sab / (saa * sbb).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};

    /// Writes `channels` (name, unit, samples) at `rate` as `dir/name`, with `material`.
    fn write(dir: &Path, name: &str, rate: f64, channels: &[(&str, &str, Vec<f64>)], material: &str) -> PathBuf {
        let file = dir.join(name);
        let mut meta = RecordingMeta::new(rate, channels.iter().map(|c| Channel::new(c.0, c.1)).collect());
        meta.source = "test".into();
        if !material.is_empty() {
            meta.condition.material = Some(material.into());
        }
        let mut w = RecordingWriter::create(&file, meta).unwrap();
        let n = channels[0].2.len();
        let frames: Vec<f64> = (0..n).flat_map(|k| channels.iter().map(move |c| c.2[k])).collect();
        w.write_interleaved(&frames).unwrap();
        w.finish().unwrap();
        file
    }

    /// A stroke of `seconds`: back and forth at 5 cm/s over 2 cm under 0.8 N.
    struct Files {
        stroke: PathBuf,
        actuation: PathBuf,
        real: PathBuf,
    }

    /// The files of a good stroke in the new folder `dir/tag`.
    fn files_in(dir: &Path, tag: &str, seconds: f64, material: &str) -> Files {
        let sub = dir.join(tag);
        std::fs::create_dir_all(&sub).unwrap();
        files(&sub, seconds, material)
    }

    fn files(dir: &Path, seconds: f64, material: &str) -> Files {
        let n = (seconds * 1000.0) as usize;
        let v: Vec<f64> = (0..n).map(|k| if (k / 400) % 2 == 0 { 0.05 } else { -0.05 }).collect();
        let mut x = vec![0.0; n];
        for k in 1..n {
            x[k] = x[k - 1] + v[k] / 1000.0;
        }
        let load = vec![0.8; n];
        let force: Vec<f64> = (0..n).map(|k| v[k].signum() * 0.12 * (1.0 + 0.1 * (x[k] * 3000.0).sin())).collect();
        let frames = (seconds * 40.0) as usize;
        let ir: Vec<f64> = (0..frames).map(|k| x[k * 25]).collect();
        Files {
            stroke: write(dir, "stroke", 40.0, &[("ir_x", "m", ir), ("load_cell", "N", vec![0.8; frames])], ""),
            actuation: write(
                dir,
                "actuation",
                1000.0,
                &[("u", "1", vec![0.1; n]), ("target", "N", vec![0.01; n]), ("velocity", "cm/s", vec![5.0; n])],
                "",
            ),
            real: write(
                dir,
                "stroke-truth",
                1000.0,
                &[("position", "m", x), ("velocity", "m/s", v), ("load", "N", load), ("force", "N", force)],
                material,
            ),
        }
    }

    #[test]
    fn good_files_give_the_path_the_real_force_and_its_modulation() {
        let dir = tempfile::tempdir().unwrap();
        let f = files(dir.path(), 3.0, "felt-fabric");
        let i = read(&f.stroke, &f.actuation, &f.real, None).unwrap();
        assert_eq!((i.path.len(), i.frames, i.frame_rate), (3000, 120, 40.0));
        assert_eq!(i.base, Base::Sample("felt-fabric".into()));
        assert_eq!(i.seconds(), 3.0);
        let surface = samples::lookup("felt-fabric").unwrap();
        assert_eq!(i.path.modulation[5], i.path.real[5] - surface.base_force(0.05, 0.8));
        // A material the lab does not model: μ̂ fitted. The force is 0.12·N·(1 + 0.1 sin) in the direction of motion.
        let dir = tempfile::tempdir().unwrap();
        let f = files(dir.path(), 3.0, "oak");
        let i = read(&f.stroke, &f.actuation, &f.real, None).unwrap();
        let Base::Fitted { mu } = i.base else { panic!("{:?}", i.base) };
        assert!((mu - 0.15).abs() < 0.01, "{mu}");
        assert_eq!(i.material, "oak");
        assert!(read(&f.stroke, &f.actuation, &f.real, Some("oak")).unwrap_err().to_string().contains("--sample"));
        assert_eq!(
            read(&f.stroke, &f.actuation, &f.real, Some("felt-fabric")).unwrap().base,
            Base::Sample("felt-fabric".into())
        );
    }

    fn error(f: &Files) -> String {
        read(&f.stroke, &f.actuation, &f.real, None).unwrap_err().to_string()
    }

    #[test]
    fn bad_files_are_refused_naming_the_file_and_what_is_wrong() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let good = files_in(d, "good", 3.0, "felt-fabric");
        // Missing channels.
        let no_ir = Files {
            stroke: write(d, "no-ir", 40.0, &[("x", "m", vec![0.0; 120]), ("load_cell", "N", vec![0.8; 120])], ""),
            ..files_in(d, "c1", 3.0, "")
        };
        let e = error(&no_ir);
        assert!(e.contains("no-ir") && e.contains("ir_x"), "{e}");
        let no_target = Files {
            actuation: write(d, "no-target", 1000.0, &[("u", "1", vec![0.0; 3000])], ""),
            ..files_in(d, "c2", 3.0, "")
        };
        let e = error(&no_target);
        assert!(e.contains("no-target") && e.contains("target"), "{e}");
        let no_force = Files {
            real: write(
                d,
                "no-force",
                1000.0,
                &[("velocity", "m/s", vec![0.05; 3000]), ("load", "N", vec![0.8; 3000])],
                "",
            ),
            ..files_in(d, "c3", 3.0, "")
        };
        let e = error(&no_force);
        assert!(e.contains("no-force") && e.contains("force"), "{e}");
        // A unit that is not the one asked for.
        let grams = Files {
            real: write(
                d,
                "grams",
                1000.0,
                &[
                    ("velocity", "m/s", vec![0.05; 3000]),
                    ("load", "g", vec![80.0; 3000]),
                    ("force", "N", vec![0.1; 3000]),
                ],
                "",
            ),
            ..files_in(d, "c4", 3.0, "")
        };
        let e = error(&grams);
        assert!(e.contains("grams") && e.contains("`load` is in `g`"), "{e}");
        // Rates and lengths that disagree.
        let chans = |n: usize| {
            vec![("velocity", "m/s", vec![0.05; n]), ("load", "N", vec![0.8; n]), ("force", "N", vec![0.1; n])]
        };
        let slow = Files { real: write(d, "slow", 500.0, &chans(1500), ""), ..files_in(d, "c5", 3.0, "") };
        let e = error(&slow);
        assert!(e.contains("slow") && e.contains("500 Hz") && e.contains("1000 Hz"), "{e}");
        let short = Files { real: write(d, "short", 1000.0, &chans(2500), ""), ..files_in(d, "c6", 3.0, "") };
        let e = error(&short);
        assert!(e.contains("short") && e.contains("2500 samples") && e.contains("3000"), "{e}");
        let other = Files { stroke: files_in(d, "long", 5.0, "").stroke, ..files_in(d, "c7", 3.0, "") };
        let e = error(&other);
        assert!(e.contains("200 frames at 40 Hz") && e.contains("was the actuation made from this stroke"), "{e}");
        // Too short for E_s.
        let brief = files_in(d, "brief", 1.5, "");
        let e = error(&brief);
        assert!(e.contains("brief/stroke") && e.contains("1.500 s") && e.contains("at least 2 s"), "{e}");
        let brief_actuation = Files {
            actuation: write(
                d,
                "brief-actuation",
                1000.0,
                &[("u", "1", vec![0.0; 1500]), ("target", "N", vec![0.0; 1500])],
                "",
            ),
            real: write(d, "brief-real", 1000.0, &chans(1500), ""),
            ..files_in(d, "c11", 3.0, "")
        };
        let e = error(&brief_actuation);
        assert!(e.contains("brief-actuation") && e.contains("1.500 s of actuation"), "{e}");
        // A stroke at the actuation's rate is not a recorded stroke.
        let fast = Files {
            stroke: write(
                d,
                "fast",
                1000.0,
                &[("ir_x", "m", vec![0.0; 3000]), ("load_cell", "N", vec![0.8; 3000])],
                "",
            ),
            ..files_in(d, "c8", 3.0, "")
        };
        assert!(error(&fast).contains("not slower"), "{}", error(&fast));
        // The IR frame of one stroke, the real force of another.
        let mirrored: Vec<f64> =
            Recording::open(&good.stroke).unwrap().channel("ir_x").unwrap().iter().map(|x| -x).collect();
        let swapped = Files {
            stroke: write(d, "swapped", 40.0, &[("ir_x", "m", mirrored), ("load_cell", "N", vec![0.8; 120])], ""),
            ..files_in(d, "c9", 3.0, "")
        };
        let e = error(&swapped);
        assert!(e.contains("swapped") && e.contains("does not follow the path"), "{e}");
        // A recording that is not there.
        let gone = Files { real: d.join("gone"), ..files_in(d, "c10", 3.0, "") };
        assert!(error(&gone).contains("gone"), "{}", error(&gone));
    }
}
