//! The display family: virtual displays drawn from seeded, documented
//! ranges of every physical constant the lab's display models, split once
//! and for all into a **tuning** set (where the defaults of the synthesis
//! are chosen) and a **held-out** set (where the figures the docs quote are
//! measured). A display built by a lab independently of the project meets
//! evflow's defaults the way a held-out display does.
//!
//! Every member differs from the nominal lab only in `[display.*]`: the
//! tribometer, the force sensor and the texture samples stay the lab's, so
//! a family member is a lab that replaced its display.
//!
//! What is drawn ([`RANGES`], each with its source in docs/simulated-lab.md
//! §6.2): the amplifier's offset, bandwidth and latency; the circuit's
//! coating, gap, leaks, tip and return (its high-pass shelf) and the charge
//! relaxation before the square law (an electrical high-pass from a few Hz
//! to 100 Hz); the contact lag and its speed dependence; the friction of the
//! pen on the glass; the pen tip's lateral resonance (80–400 Hz) and its
//! damping ratio; one scale on every noise term (0.5–3×); and the display's
//! **force range** against the textures' (⅓–3×), which sets the amplifier
//! gain: the friction a unit carrier adds at 85 g and 5 cm/s is made that
//! many times the textures' force range ([`texture_range`]).
//!
//! The files in `graphs/lab/family/` are this module's output
//! (`evflow family --out graphs/lab/family`); a test holds them to it.

use super::display_model::DisplayModel;
use super::integrator::Method;
use super::profile::{LabProfile, G, KEYS};
use super::texture::{samples, TextureScan};
use crate::rng::Rng;
use std::fmt::Write as _;

/// The family's seed.
pub const SEED: u64 = 33;
/// Members of the tuning set (drawn first).
pub const TUNING: usize = 10;
/// Members of the held-out set (drawn after the tuning set).
pub const HELD_OUT: usize = 34;

// Issue 33: at most 10 tuning displays, at least 30 held out, at least 40 in all.
const _: () = assert!(TUNING <= 10 && HELD_OUT >= 30 && TUNING + HELD_OUT >= 40);

/// The six texture samples of dissertation §5.3 whose force range the
/// displays' ranges are drawn against.
pub const SAMPLES: [&str; 6] =
    ["dotted-sheet", "chair-fabric", "felt-fabric", "painting-canvas", "plastic-sheet", "scrunched-paper"];

/// Which set a member belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Split {
    /// Where defaults are chosen.
    Tuning,
    /// Where figures are quoted.
    HeldOut,
}

impl Split {
    /// The word a member's name starts with: `tuning` or `held-out`.
    pub fn word(self) -> &'static str {
        match self {
            Split::Tuning => "tuning",
            Split::HeldOut => "held-out",
        }
    }
}

/// How a range is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Uniform between the ends.
    Linear,
    /// Uniform in the logarithm (for constants known to an order of magnitude).
    Log,
    /// A whole number, uniform over the ends inclusive.
    Whole,
}

/// One drawn quantity.
#[derive(Debug, Clone, Copy)]
pub struct Range {
    /// Its name (a profile key's dotted path, or a derived quantity's name).
    pub name: &'static str,
    /// Smallest value.
    pub lo: f64,
    /// Largest value.
    pub hi: f64,
    /// Unit.
    pub unit: &'static str,
    /// How it is drawn.
    pub scale: Scale,
    /// What sets the profile from it.
    pub sets: &'static str,
}

const fn r(name: &'static str, lo: f64, hi: f64, unit: &'static str, scale: Scale, sets: &'static str) -> Range {
    Range { name, lo, hi, unit, scale, sets }
}

/// Every drawn quantity, in drawing order (a member's draws come from its
/// own random stream in this order, so adding a range at the end keeps the
/// earlier draws). Sources: docs/simulated-lab.md §6.2.
pub static RANGES: &[Range] = &[
    r("display.amplifier.offset_v", -8.0, 8.0, "V", Scale::Linear, "the key"),
    r("display.amplifier.bandwidth_hz", 1000.0, 50_000.0, "Hz", Scale::Log, "the key"),
    r("display.amplifier.delay_ms", 0.0, 3.0, "ms", Scale::Whole, "the key"),
    r(
        "noise_scale",
        0.5,
        3.0,
        "×",
        Scale::Log,
        "noise_v, friction noise and drift × the value (nominal 0.05 V, 0.03, 0.05)",
    ),
    r(
        "force_range",
        1.0 / 3.0,
        3.0,
        "×",
        Scale::Log,
        "gain_v (max_v = 2 gain_v): a unit carrier adds this many textures' ranges",
    ),
    r("display.electrical.contact_area_mm2", 30.0, 80.0, "mm²", Scale::Linear, "the key"),
    r("display.electrical.insulator_thickness_um", 0.5, 5.0, "µm", Scale::Log, "the key"),
    r("display.electrical.insulator_permittivity", 3.0, 8.0, "1", Scale::Linear, "the key"),
    r("display.electrical.insulator_leak_mohm", 2.0, 100.0, "MΩ", Scale::Log, "the key"),
    r("display.electrical.gap_um", 0.5, 1.2, "µm", Scale::Linear, "the key"),
    r("display.electrical.gap_leak_mohm", 0.3, 10.0, "MΩ", Scale::Log, "the key"),
    r("display.electrical.tip_resistance_kohm", 50.0, 500.0, "kΩ", Scale::Log, "the key"),
    r("display.electrical.tip_capacitance_nf", 2.0, 20.0, "nF", Scale::Log, "the key"),
    r("display.electrical.return_kohm", 5.0, 50.0, "kΩ", Scale::Log, "the key"),
    r("display.electrical.relaxation_hz", 2.0, 100.0, "Hz", Scale::Log, "the key"),
    r("display.friction.mu_kinetic", 0.25, 0.5, "1", Scale::Linear, "the key"),
    r("static_ratio", 1.1, 1.45, "×", Scale::Linear, "mu_static = mu_kinetic × the value"),
    r("display.friction.stribeck_velocity", 0.002, 0.01, "m/s", Scale::Log, "the key"),
    r("display.friction.viscous", 0.05, 0.3, "N·s/m", Scale::Log, "the key"),
    r("display.friction.lag_cutoff_hz", 30.0, 200.0, "Hz", Scale::Log, "the key"),
    r("display.friction.lag_slope_hz_per_mm_s", 3.0, 20.0, "Hz/(mm/s)", Scale::Log, "the key"),
    r("display.contact.tip_mass_g", 0.5, 3.0, "g", Scale::Log, "the key"),
    r("contact_resonance_hz", 80.0, 400.0, "Hz", Scale::Log, "stiffness_n_per_m = m (2π f)²"),
    r("contact_damping_ratio", 0.1, 0.6, "1", Scale::Log, "damping_ns_per_m = 2 ζ √(k m)"),
];

/// One member of the family.
#[derive(Debug, Clone)]
pub struct Member {
    /// `tuning-01` … or `held-out-01` …
    pub name: String,
    /// Its set.
    pub split: Split,
    /// Its lab profile.
    pub profile: LabProfile,
    /// Each range's drawn value, in [`RANGES`] order.
    pub draws: Vec<f64>,
    /// The friction a unit carrier adds at 85 g and 5 cm/s
    /// ([`carrier_range`]) over the textures' force range, as built (the
    /// drawn `force_range` up to the offset's share).
    pub realized_range: f64,
}

/// `x` to four significant digits (the files stay readable; the profile
/// holds exactly what its file says).
fn round4(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let e = x.abs().log10().floor() as i32 - 3;
    let s = 10f64.powi(-e);
    let v = (x * s).round() / s;
    // Through text, so that the value is the one its shortest form names.
    format!("{v:.*}", (-e).max(0) as usize).parse().unwrap_or(v)
}

fn draw(rng: &mut Rng, range: &Range) -> f64 {
    let u = rng.uniform();
    match range.scale {
        Scale::Linear => round4(range.lo + u * (range.hi - range.lo)),
        Scale::Log => round4((range.lo.ln() + u * (range.hi.ln() - range.lo.ln())).exp()),
        Scale::Whole => (range.lo + (u * (range.hi - range.lo + 1.0)).floor()).min(range.hi),
    }
}

/// The textures' force range, N: the mean over [`SAMPLES`] of the spread
/// between the 2nd and 98th percentiles of the texture's own force
/// modulation (the friction less its base μ₀·N) over 20 cm at 85 g and
/// 5 cm/s.
pub fn texture_range() -> f64 {
    let (v, load, rate) = (0.05, 0.085 * G, 1000.0);
    let n = (0.2 / v * rate) as usize;
    let mut sum = 0.0;
    for name in SAMPLES {
        let surface = samples::lookup(name).expect("a shipped sample");
        let mut scan = TextureScan::new(surface);
        let mut m: Vec<f64> = (0..n)
            .map(|k| {
                let x = v * k as f64 / rate;
                scan.force(x, v, load) - scan.surface().base_force(v, load)
            })
            .collect();
        m.sort_by(f64::total_cmp);
        sum += m[(0.98 * n as f64) as usize] - m[(0.02 * n as f64) as usize];
    }
    sum / SAMPLES.len() as f64
}

/// The friction a held Nyquist-rate carrier of amplitude 1 adds on
/// `profile` at 85 g and 5 cm/s, N: μ_k × the electrostatic normal force
/// it adds (noise off; the mean over the second half of one second). The
/// normal force, not the lateral force, is averaged: on a soft contact the
/// lateral force sticks and slips, and its mean over a second is not the
/// display's range.
pub fn carrier_range(profile: &LabProfile) -> Result<f64, String> {
    let (v, load, rate) = (0.05, 0.085 * G, 1000.0);
    let run = |carrier: bool| -> Result<f64, String> {
        let mut d = DisplayModel::new(profile, rate, Method::Exact, 4, 0.0, 1)?;
        let n = 1000;
        let mut s = 0.0;
        for k in 0..n {
            let u = if carrier {
                if k % 2 == 0 {
                    1.0
                } else {
                    -1.0
                }
            } else {
                0.0
            };
            d.step(u, load, v);
            if k >= n / 2 {
                s += d.normal_force();
            }
        }
        Ok(s / (n / 2) as f64)
    };
    Ok(profile.display.friction.mu_kinetic * (run(true)? - run(false)?))
}

/// Sets the named key of `p` (a dotted path of [`KEYS`]).
fn set(p: &mut LabProfile, path: &str, v: f64) {
    let key = KEYS.iter().find(|k| k.path() == path).expect("a profile key");
    (key.set)(p, v);
}

/// The member drawn `index`-th (0-based over the whole family).
fn member(index: usize, textures: f64) -> Result<Member, String> {
    let split = if index < TUNING { Split::Tuning } else { Split::HeldOut };
    let number = if index < TUNING { index + 1 } else { index - TUNING + 1 };
    let name = format!("{}-{number:02}", split.word());
    let mut rng = Rng::substream(SEED, index as u64);
    let draws: Vec<f64> = RANGES.iter().map(|r| draw(&mut rng, r)).collect();
    let at = |n: &str| draws[RANGES.iter().position(|r| r.name == n).expect("a range")];
    let mut p = LabProfile { name: name.clone(), ..LabProfile::default() };
    for (r, v) in RANGES.iter().zip(&draws) {
        if r.name.starts_with("display.") {
            set(&mut p, r.name, *v);
        }
    }
    let nominal = LabProfile::default();
    let noise = at("noise_scale");
    let a = &mut p.display.amplifier;
    a.noise_v = round4(nominal.display.amplifier.noise_v * noise);
    let f = &mut p.display.friction;
    f.noise = round4(nominal.display.friction.noise * noise);
    f.drift = round4(nominal.display.friction.drift * noise);
    f.mu_static = round4(f.mu_kinetic * at("static_ratio"));
    let c = &mut p.display.contact;
    let m = c.tip_mass_g * 1e-3;
    let w = 2.0 * std::f64::consts::PI * at("contact_resonance_hz");
    c.stiffness_n_per_m = round4(m * w * w);
    c.damping_ns_per_m = round4(2.0 * at("contact_damping_ratio") * (c.stiffness_n_per_m * m).sqrt());
    // The gain that gives the drawn force range: the carrier's friction is
    // quadratic in the gain (the offset's share is small at a Nyquist carrier).
    let probe = carrier_range(&p)?;
    if !(probe.is_finite() && probe > 0.0) {
        return Err(format!("{name}: a unit carrier adds no friction ({probe} N)"));
    }
    let gain = round4((50.0 * (at("force_range") * textures / probe).sqrt()).clamp(5.0, 450.0));
    p.display.amplifier.gain_v = gain;
    p.display.amplifier.max_v = round4((2.0 * gain).max(2.0 * p.display.amplifier.offset_v.abs() + 1.0));
    p.description = format!(
        "display family member {name} ({} set): drawn by evflow's display family (seed {SEED}), docs/simulated-lab.md §6.2",
        split.word()
    );
    p.validate().map_err(|e| format!("{name}: {e}"))?;
    let realized_range = carrier_range(&p)? / textures;
    Ok(Member { name, split, profile: p, draws, realized_range })
}

/// The names of the members of `split` (`None`: every member), in
/// drawing order, as the profile files in `graphs/lab/family/` are named.
pub fn names(split: Option<Split>) -> Vec<String> {
    let tuning = (1..=TUNING).map(|k| (Split::Tuning, k));
    let held = (1..=HELD_OUT).map(|k| (Split::HeldOut, k));
    tuning
        .chain(held)
        .filter(|(s, _)| split.is_none_or(|w| w == *s))
        .map(|(s, k)| format!("{}-{k:02}", s.word()))
        .collect()
}

/// The whole family: [`TUNING`] tuning members, then [`HELD_OUT`] held-out ones.
pub fn members() -> Result<Vec<Member>, String> {
    let textures = texture_range();
    (0..TUNING + HELD_OUT).map(|i| member(i, textures)).collect()
}

/// A member's profile file: every key of the profile, with what was drawn
/// in the header.
pub fn profile_file(m: &Member) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Display family member `{}` — {} set (docs/simulated-lab.md §6.2).", m.name, m.split.word());
    let _ = writeln!(s, "# Generated by `evflow family --out graphs/lab/family` (seed {SEED}); do not edit:");
    let _ = writeln!(s, "# a test holds this file to the generator. Drawn:");
    for (r, v) in RANGES.iter().zip(&m.draws) {
        let _ = writeln!(s, "#   {} = {v} {}", r.name, r.unit);
    }
    let _ = writeln!(
        s,
        "# The friction a unit carrier adds at 85 g, 5 cm/s: {:.3} × the textures' range.",
        m.realized_range
    );
    let _ = writeln!(s, "\n[lab]\nname = \"{}\"\ndescription = \"{}\"", m.name, m.profile.description);
    let mut section = "";
    for k in KEYS {
        if k.section != section {
            section = k.section;
            let _ = writeln!(s, "\n[{section}]");
        }
        let _ = writeln!(s, "{} = {:?}", k.name, (k.get)(&m.profile));
    }
    s
}

/// The family's table (Markdown): each member's split and the constants
/// that shape what a synthesis meets.
pub fn table(members: &[Member]) -> String {
    let mut s = String::from(
        "| display | set | force range (× textures') | offset V | delay ms | relaxation Hz | contact resonance Hz | ζ | lag Hz | noise × | amplifier kHz | gain V |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for m in members {
        let at = |n: &str| m.draws[RANGES.iter().position(|r| r.name == n).expect("a range")];
        let p = &m.profile.display;
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {:.1} | {} |",
            m.name,
            m.split.word(),
            m.realized_range,
            p.amplifier.offset_v,
            p.amplifier.delay_ms,
            p.electrical.relaxation_hz,
            at("contact_resonance_hz"),
            at("contact_damping_ratio"),
            p.friction.lag_cutoff_hz,
            at("noise_scale"),
            p.amplifier.bandwidth_hz * 1e-3,
            p.amplifier.gain_v,
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::profile_load::ProfileError;
    use std::path::Path;

    #[test]
    fn every_member_is_valid_inside_its_ranges_and_the_sets_are_split() {
        let ms = members().unwrap();
        assert_eq!(ms.len(), TUNING + HELD_OUT);
        assert_eq!(ms.iter().filter(|m| m.split == Split::Tuning).count(), TUNING);
        for m in &ms {
            m.profile.validate().unwrap();
            for (r, v) in RANGES.iter().zip(&m.draws) {
                assert!((r.lo * 0.9995..=r.hi * 1.0005).contains(v), "{}: {} = {v}", m.name, r.name);
            }
            // Only the display differs from the nominal lab.
            let n = LabProfile::default();
            assert_eq!(m.profile.tribometer, n.tribometer, "{}", m.name);
            assert_eq!(m.profile.sensor, n.sensor, "{}", m.name);
            // The contact resonance is the drawn one.
            let c = &m.profile.display.contact;
            let f = (c.stiffness_n_per_m / (c.tip_mass_g * 1e-3)).sqrt() / (2.0 * std::f64::consts::PI);
            let drawn = m.draws[RANGES.iter().position(|r| r.name == "contact_resonance_hz").unwrap()];
            assert!((f / drawn - 1.0).abs() < 1e-3, "{}: {f} vs {drawn}", m.name);
            // The gain gives the drawn force range to within the display's nonlinearity.
            let want = m.draws[RANGES.iter().position(|r| r.name == "force_range").unwrap()];
            assert!((m.realized_range / want - 1.0).abs() < 0.02, "{}: {} vs {want}", m.name, m.realized_range);
        }
        // The ranges are covered: each set reaches into both halves of every range.
        for (i, r) in RANGES.iter().enumerate() {
            let mid = match r.scale {
                Scale::Log => (r.lo * r.hi).sqrt(),
                _ => 0.5 * (r.lo + r.hi),
            };
            let held: Vec<f64> = ms.iter().filter(|m| m.split == Split::HeldOut).map(|m| m.draws[i]).collect();
            assert!(held.iter().any(|v| *v < mid) && held.iter().any(|v| *v >= mid), "{}", r.name);
        }
        // Names are unique, and `names` lists them.
        let mut all: Vec<&str> = ms.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names(None), all);
        assert_eq!(names(Some(Split::Tuning)).len(), TUNING);
        assert_eq!(names(Some(Split::HeldOut))[0], "held-out-01");
        all.dedup();
        assert_eq!(all.len(), ms.len());
    }

    #[test]
    fn the_shipped_files_are_the_generators_output_and_load_back() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/lab/family");
        for m in members().unwrap() {
            let file = dir.join(format!("{}.toml", m.name));
            let text = std::fs::read_to_string(&file).unwrap_or_else(|e| {
                panic!("{}: {e} (write the family with `evflow family --out graphs/lab/family`)", file.display())
            });
            assert_eq!(text, profile_file(&m), "{} is not the generator's output", file.display());
            let back = LabProfile::load(&file).map_err(|e: ProfileError| e.to_string()).unwrap();
            assert_eq!(back, m.profile, "{}", m.name);
        }
        let table_file = dir.join("family.md");
        let text = std::fs::read_to_string(&table_file).unwrap();
        assert!(text.contains(&table(&members().unwrap())), "{} lacks the generator's table", table_file.display());
    }

    #[test]
    fn draws_round_to_four_digits_and_whole_ranges_give_whole_numbers() {
        assert_eq!(round4(123.456_78), 123.5);
        assert_eq!(round4(0.000_123_456), 0.000_123_5);
        assert_eq!(round4(-7.777_77), -7.778);
        let mut rng = Rng::new(1);
        let whole = r("w", 0.0, 3.0, "ms", Scale::Whole, "");
        let mut seen = [false; 4];
        for _ in 0..200 {
            let v = draw(&mut rng, &whole);
            assert_eq!(v.fract(), 0.0);
            seen[v as usize] = true;
        }
        assert!(seen.iter().all(|s| *s), "{seen:?}");
    }
}
