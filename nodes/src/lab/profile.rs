//! Lab profiles: every physical parameter of the simulated lab, in one
//! struct with nested sections. The defaults are the nominal lab
//! (`graphs/lab/nominal.toml`); `docs/simulated-lab.md` gives each value's
//! source. Files are read by [`LabProfile::load`] (see `profile_load.rs`).

/// The high-voltage amplifier between the actuation signal and the panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Amplifier {
    /// Output volts per unit of actuation (50 V: u = ±1 gives 100 Vpp).
    pub gain_v: f64,
    /// Output limit in volts (±).
    pub max_v: f64,
    /// First-order small-signal bandwidth in Hz.
    pub bandwidth_hz: f64,
    /// DC offset at the output in volts.
    pub offset_v: f64,
    /// White output noise, V rms (per sample).
    pub noise_v: f64,
    /// Latency of the actuation path (DAQ output buffer, link, driver) in
    /// ms, rounded to whole samples of the node's rate.
    pub delay_ms: f64,
}

/// The series circuit amplifier → insulator → air gap → pen tip/skin → return.
#[derive(Debug, Clone, PartialEq)]
pub struct Electrical {
    /// Apparent contact area in mm².
    pub contact_area_mm2: f64,
    /// Insulating coating thickness in µm.
    pub insulator_thickness_um: f64,
    /// Relative permittivity of the coating.
    pub insulator_permittivity: f64,
    /// Leakage resistance through the coating in MΩ (Johnsen–Rahbek path).
    pub insulator_leak_mohm: f64,
    /// Effective air-gap thickness in µm.
    pub gap_um: f64,
    /// Leakage resistance across the air gap in MΩ.
    pub gap_leak_mohm: f64,
    /// Resistance of the pen tip (or stratum corneum) in kΩ.
    pub tip_resistance_kohm: f64,
    /// Capacitance of the pen tip (or stratum corneum) in nF.
    pub tip_capacitance_nf: f64,
    /// Return path resistance (pen body, stylus, ground) in kΩ.
    pub return_kohm: f64,
    /// Corner of the charge-relaxation high-pass between the gap voltage and
    /// the square law, Hz (0 = no relaxation). See `electrical.rs`.
    pub relaxation_hz: f64,
}

/// Friction at the sliding contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Friction {
    /// Static friction coefficient.
    pub mu_static: f64,
    /// Kinetic (Coulomb) friction coefficient.
    pub mu_kinetic: f64,
    /// Stribeck velocity in m/s.
    pub stribeck_velocity: f64,
    /// Viscous friction in N·s/m.
    pub viscous: f64,
    /// Cutoff of the electroadhesion lag at rest, in Hz.
    pub lag_cutoff_hz: f64,
    /// Increase of that cutoff with sliding speed, in Hz per mm/s.
    pub lag_slope_hz_per_mm_s: f64,
    /// Relative rms fluctuation of the friction coefficient (surface noise).
    pub noise: f64,
    /// Bandwidth of that fluctuation in Hz.
    pub noise_bandwidth_hz: f64,
    /// Relative rms slow drift of the friction coefficient.
    pub drift: f64,
    /// Correlation time of the drift in s.
    pub drift_time_s: f64,
}

/// Lateral mechanics of the pen tip (or finger pad) against its holder.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Moving mass of the tip in g.
    pub tip_mass_g: f64,
    /// Lateral contact stiffness in N/m.
    pub stiffness_n_per_m: f64,
    /// Lateral contact damping in N·s/m.
    pub damping_ns_per_m: f64,
}

/// The display: amplifier, circuit, friction and contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Display {
    /// Amplifier.
    pub amplifier: Amplifier,
    /// Electrical circuit.
    pub electrical: Electrical,
    /// Friction.
    pub friction: Friction,
    /// Contact mechanics.
    pub contact: Contact,
}

/// The linear tribometer of dissertation §5.1.1.
#[derive(Debug, Clone, PartialEq)]
pub struct Tribometer {
    /// Travel of one pass in cm.
    pub travel_cm: f64,
    /// Acceleration of the trapezoidal profile in m/s².
    pub accel_m_s2: f64,
    /// Rest at each end in s.
    pub dwell_s: f64,
    /// Coulomb friction of the stylus shaft in its linear bearing, N.
    pub bearing_friction_n: f64,
    /// Viscous damping of the shaft in the bearing, N·s/m.
    pub bearing_damping_ns_per_m: f64,
    /// Normal stiffness of the pen tip on the sample, N/m.
    pub normal_stiffness_n_per_m: f64,
    /// Normal damping of the pen tip on the sample, N·s/m.
    pub normal_damping_ns_per_m: f64,
    /// Height change of the sample over the travel (seat not level), mm.
    pub tilt_mm: f64,
    /// Amplitude of the sample's waviness, µm.
    pub waviness_um: f64,
    /// Wavelength of that waviness, mm.
    pub waviness_mm: f64,
}

/// The force sensor and its data acquisition.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    /// Resonance of the sensor with the tip mass on it, Hz.
    pub resonance_hz: f64,
    /// Damping ratio of that resonance.
    pub damping_ratio: f64,
    /// Full scale (±) of the acquired lateral force, N.
    pub full_scale_n: f64,
    /// Converter resolution in bits.
    pub bits: f64,
    /// White noise, N rms.
    pub noise_n: f64,
    /// DC bias while moving right (+x), N.
    pub bias_right_n: f64,
    /// DC bias while moving left (−x), N.
    pub bias_left_n: f64,
    /// Time constant of the change of bias after a reversal, s.
    pub bias_time_s: f64,
    /// Rms of the slow (thermal) bias drift, N.
    pub drift_n: f64,
    /// Correlation time of that drift, s.
    pub drift_time_s: f64,
}

/// A whole lab: display, tribometer and sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct LabProfile {
    /// Short name.
    pub name: String,
    /// What this lab stands for.
    pub description: String,
    /// The display.
    pub display: Display,
    /// The tribometer.
    pub tribometer: Tribometer,
    /// The force sensor.
    pub sensor: Sensor,
}

impl Default for LabProfile {
    /// The nominal lab.
    fn default() -> Self {
        Self {
            name: "nominal".into(),
            description: "3M-like surface-capacitive panel driven at 100 Vpp, touch-pen stylus on the linear tribometer of §5.1.1".into(),
            display: Display {
                amplifier: Amplifier {
                    gain_v: 50.0,
                    max_v: 100.0,
                    bandwidth_hz: 20_000.0,
                    offset_v: 2.0,
                    noise_v: 0.05,
                    delay_ms: 0.0,
                },
                electrical: Electrical {
                    contact_area_mm2: 50.0,
                    insulator_thickness_um: 1.0,
                    insulator_permittivity: 3.9,
                    insulator_leak_mohm: 10.0,
                    gap_um: 0.8,
                    gap_leak_mohm: 2.5,
                    tip_resistance_kohm: 100.0,
                    tip_capacitance_nf: 10.0,
                    return_kohm: 10.0,
                    relaxation_hz: 0.0,
                },
                friction: Friction {
                    mu_static: 0.45,
                    mu_kinetic: 0.35,
                    stribeck_velocity: 0.005,
                    viscous: 0.1,
                    lag_cutoff_hz: 100.0,
                    lag_slope_hz_per_mm_s: 13.8,
                    noise: 0.03,
                    noise_bandwidth_hz: 200.0,
                    drift: 0.05,
                    drift_time_s: 20.0,
                },
                contact: Contact { tip_mass_g: 0.5, stiffness_n_per_m: 10_000.0, damping_ns_per_m: 1.5 },
            },
            tribometer: Tribometer {
                travel_cm: 8.0,
                accel_m_s2: 1.0,
                dwell_s: 0.5,
                bearing_friction_n: 0.02,
                bearing_damping_ns_per_m: 0.5,
                normal_stiffness_n_per_m: 20_000.0,
                normal_damping_ns_per_m: 10.0,
                tilt_mm: 0.5,
                waviness_um: 20.0,
                waviness_mm: 20.0,
            },
            sensor: Sensor {
                resonance_hz: 1500.0,
                damping_ratio: 0.05,
                full_scale_n: 12.0,
                bits: 16.0,
                noise_n: 0.003,
                bias_right_n: 0.02,
                bias_left_n: -0.035,
                bias_time_s: 0.05,
                drift_n: 0.005,
                drift_time_s: 60.0,
            },
        }
    }
}

/// One numeric key of a profile: where it lives, its unit, limits and doc,
/// and how to read and write it. [`KEYS`] lists them all; the loader, the
/// validator and the documentation test read that one list.
#[derive(Clone, Copy)]
pub struct Key {
    /// Section path, e.g. `display.friction`.
    pub section: &'static str,
    /// Key name inside the section.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Smallest accepted value.
    pub min: f64,
    /// Largest accepted value.
    pub max: f64,
    /// One-line description.
    pub doc: &'static str,
    /// Reads the value.
    pub get: fn(&LabProfile) -> f64,
    /// Writes the value.
    pub set: fn(&mut LabProfile, f64),
}

impl Key {
    /// `section.name`.
    pub fn path(&self) -> String {
        format!("{}.{}", self.section, self.name)
    }
}

macro_rules! key {
    ($section:literal, $name:ident, $($field:ident).+, $unit:literal, $min:expr, $max:expr, $doc:literal) => {
        Key {
            section: $section,
            name: stringify!($name),
            unit: $unit,
            min: $min,
            max: $max,
            doc: $doc,
            get: |p| p.$($field).+.$name,
            set: |p, v| p.$($field).+.$name = v,
        }
    };
}

/// Every numeric key of a profile with its limits.
pub static KEYS: &[Key] = &[
    key!("display.amplifier", gain_v, display.amplifier, "V", 0.0, 1000.0, "output volts per unit of actuation"),
    key!("display.amplifier", max_v, display.amplifier, "V", 1.0, 1000.0, "output limit (±)"),
    key!("display.amplifier", bandwidth_hz, display.amplifier, "Hz", 10.0, 1e7, "first-order bandwidth"),
    key!("display.amplifier", offset_v, display.amplifier, "V", -100.0, 100.0, "DC offset at the output"),
    key!("display.amplifier", noise_v, display.amplifier, "V", 0.0, 100.0, "white output noise, rms"),
    key!(
        "display.amplifier",
        delay_ms,
        display.amplifier,
        "ms",
        0.0,
        100.0,
        "latency of the actuation path, rounded to whole samples"
    ),
    key!("display.electrical", contact_area_mm2, display.electrical, "mm²", 0.1, 1e4, "apparent contact area"),
    key!("display.electrical", insulator_thickness_um, display.electrical, "µm", 0.01, 1e4, "coating thickness"),
    key!(
        "display.electrical",
        insulator_permittivity,
        display.electrical,
        "1",
        1.0,
        1e4,
        "coating relative permittivity"
    ),
    key!(
        "display.electrical",
        insulator_leak_mohm,
        display.electrical,
        "MΩ",
        1e-3,
        1e9,
        "leakage through the coating (Johnsen–Rahbek path)"
    ),
    key!("display.electrical", gap_um, display.electrical, "µm", 0.01, 1e3, "effective air-gap thickness"),
    key!("display.electrical", gap_leak_mohm, display.electrical, "MΩ", 1e-3, 1e9, "leakage across the air gap"),
    key!(
        "display.electrical",
        tip_resistance_kohm,
        display.electrical,
        "kΩ",
        1e-3,
        1e9,
        "pen tip / stratum corneum resistance"
    ),
    key!(
        "display.electrical",
        tip_capacitance_nf,
        display.electrical,
        "nF",
        1e-3,
        1e6,
        "pen tip / stratum corneum capacitance"
    ),
    key!("display.electrical", return_kohm, display.electrical, "kΩ", 1e-3, 1e6, "return path resistance"),
    key!(
        "display.electrical",
        relaxation_hz,
        display.electrical,
        "Hz",
        0.0,
        1e5,
        "charge-relaxation high-pass corner before the square law (0 = off)"
    ),
    key!("display.friction", mu_static, display.friction, "1", 0.0, 5.0, "static friction coefficient"),
    key!("display.friction", mu_kinetic, display.friction, "1", 0.0, 5.0, "kinetic friction coefficient"),
    key!("display.friction", stribeck_velocity, display.friction, "m/s", 1e-6, 10.0, "Stribeck velocity"),
    key!("display.friction", viscous, display.friction, "N·s/m", 0.0, 1e3, "viscous friction"),
    key!("display.friction", lag_cutoff_hz, display.friction, "Hz", 0.1, 1e6, "electroadhesion lag cutoff at rest"),
    key!(
        "display.friction",
        lag_slope_hz_per_mm_s,
        display.friction,
        "Hz/(mm/s)",
        0.0,
        1e4,
        "increase of the lag cutoff with speed"
    ),
    key!("display.friction", noise, display.friction, "1", 0.0, 10.0, "relative rms fluctuation of μ"),
    key!("display.friction", noise_bandwidth_hz, display.friction, "Hz", 0.1, 1e6, "bandwidth of that fluctuation"),
    key!("display.friction", drift, display.friction, "1", 0.0, 10.0, "relative rms slow drift of μ"),
    key!("display.friction", drift_time_s, display.friction, "s", 1e-3, 1e6, "correlation time of the drift"),
    key!("display.contact", tip_mass_g, display.contact, "g", 1e-4, 1e4, "moving mass of the tip"),
    key!("display.contact", stiffness_n_per_m, display.contact, "N/m", 1.0, 1e10, "lateral contact stiffness"),
    key!("display.contact", damping_ns_per_m, display.contact, "N·s/m", 0.0, 1e6, "lateral contact damping"),
    key!("tribometer", travel_cm, tribometer, "cm", 0.1, 100.0, "travel of one pass"),
    key!("tribometer", accel_m_s2, tribometer, "m/s²", 0.01, 1e3, "acceleration of the trapezoidal profile"),
    key!("tribometer", dwell_s, tribometer, "s", 0.0, 60.0, "rest at each end"),
    key!("tribometer", bearing_friction_n, tribometer, "N", 0.0, 10.0, "Coulomb friction of the shaft in its bearing"),
    key!("tribometer", bearing_damping_ns_per_m, tribometer, "N·s/m", 0.0, 1e4, "viscous damping of the shaft"),
    key!(
        "tribometer",
        normal_stiffness_n_per_m,
        tribometer,
        "N/m",
        1.0,
        1e10,
        "normal stiffness of the tip on the sample"
    ),
    key!(
        "tribometer",
        normal_damping_ns_per_m,
        tribometer,
        "N·s/m",
        0.0,
        1e6,
        "normal damping of the tip on the sample"
    ),
    key!("tribometer", tilt_mm, tribometer, "mm", -10.0, 10.0, "height change of the sample over the travel"),
    key!("tribometer", waviness_um, tribometer, "µm", 0.0, 1e3, "waviness amplitude of the sample"),
    key!("tribometer", waviness_mm, tribometer, "mm", 0.1, 1e3, "waviness wavelength"),
    key!("sensor", resonance_hz, sensor, "Hz", 1.0, 1e8, "resonance of the sensor with the tip on it"),
    key!("sensor", damping_ratio, sensor, "1", 1e-4, 10.0, "damping ratio of that resonance"),
    key!("sensor", full_scale_n, sensor, "N", 0.01, 1e4, "full scale (±) of the lateral channel"),
    key!("sensor", bits, sensor, "bit", 4.0, 32.0, "converter resolution (an integer)"),
    key!("sensor", noise_n, sensor, "N", 0.0, 100.0, "white noise, rms"),
    key!("sensor", bias_right_n, sensor, "N", -100.0, 100.0, "DC bias while moving right"),
    key!("sensor", bias_left_n, sensor, "N", -100.0, 100.0, "DC bias while moving left"),
    key!("sensor", bias_time_s, sensor, "s", 1e-6, 100.0, "time constant of the bias change after a reversal"),
    key!("sensor", drift_n, sensor, "N", 0.0, 100.0, "rms of the slow bias drift"),
    key!("sensor", drift_time_s, sensor, "s", 1e-3, 1e6, "correlation time of the drift"),
];

/// Vacuum permittivity in F/m (CODATA 2018).
pub const EPS0: f64 = 8.854_187_812_8e-12;
/// Standard gravity in m/s².
pub const G: f64 = 9.806_65;

impl LabProfile {
    /// Problems no single key's limits can express, as (key path, message).
    pub fn cross_check(&self) -> Vec<(String, String)> {
        let mut v = Vec::new();
        let f = &self.display.friction;
        if f.mu_kinetic > f.mu_static {
            v.push((
                "display.friction.mu_kinetic".into(),
                format!("kinetic friction {} exceeds static friction {}", f.mu_kinetic, f.mu_static),
            ));
        }
        let s = &self.sensor;
        if s.bits.fract() != 0.0 {
            v.push(("sensor.bits".into(), format!("must be a whole number of bits, not {}", s.bits)));
        }
        let a = &self.display.amplifier;
        if a.offset_v.abs() >= a.max_v {
            v.push((
                "display.amplifier.offset_v".into(),
                format!("offset {} V reaches the output limit ±{} V", a.offset_v, a.max_v),
            ));
        }
        v
    }

    /// Checks every key against its limits and the cross-checks; the
    /// messages name the key. Used for profiles built in code.
    pub fn validate(&self) -> Result<(), String> {
        let mut errs = Vec::new();
        for k in KEYS {
            let x = (k.get)(self);
            if !(x.is_finite() && x >= k.min && x <= k.max) {
                errs.push(format!("`{}` = {x} is outside {} ..= {} {}", k.path(), k.min, k.max, k.unit));
            }
        }
        for (key, m) in self.cross_check() {
            errs.push(format!("`{key}`: {m}"));
        }
        if errs.is_empty() {
            Ok(())
        } else {
            Err(errs.join("\n"))
        }
    }

    /// Insulator capacitance in F.
    pub fn insulator_capacitance(&self) -> f64 {
        let e = &self.display.electrical;
        EPS0 * e.insulator_permittivity * e.contact_area_mm2 * 1e-6 / (e.insulator_thickness_um * 1e-6)
    }

    /// Air-gap capacitance in F.
    pub fn gap_capacitance(&self) -> f64 {
        let e = &self.display.electrical;
        EPS0 * e.contact_area_mm2 * 1e-6 / (e.gap_um * 1e-6)
    }

    /// Electrostatic force per squared gap volt, k_e = ε0 A / (2 d²), in N/V².
    pub fn electrostatic_coefficient(&self) -> f64 {
        let e = &self.display.electrical;
        let d = e.gap_um * 1e-6;
        EPS0 * e.contact_area_mm2 * 1e-6 / (2.0 * d * d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_is_valid_and_keys_round_trip() {
        let p = LabProfile::default();
        p.validate().unwrap();
        let mut q = p.clone();
        for (i, k) in KEYS.iter().enumerate() {
            (k.set)(&mut q, i as f64 + 0.5);
            assert_eq!((k.get)(&q), i as f64 + 0.5, "{}", k.path());
        }
        // Every key distinct.
        for (i, a) in KEYS.iter().enumerate() {
            for b in &KEYS[i + 1..] {
                assert_ne!(a.path(), b.path());
            }
        }
    }

    #[test]
    fn derived_quantities_match_the_parallel_plate_formulas() {
        let p = LabProfile::default();
        // 50 mm², 0.8 µm air: C = ε0 A / d = 553.4 pF; k_e = C / (2d) = 3.459e-4 N/V².
        assert!((p.gap_capacitance() - 5.534e-10).abs() < 1e-13);
        assert!((p.electrostatic_coefficient() - 3.459e-4).abs() < 1e-7);
        // 50 mm² of εr 3.9 at 1 µm: 1.7265 nF.
        assert!((p.insulator_capacitance() - 1.7265e-9).abs() < 1e-12);
    }

    #[test]
    fn validate_names_bad_keys() {
        let mut p = LabProfile::default();
        p.display.friction.mu_kinetic = 0.9;
        p.sensor.bits = 15.5;
        p.display.contact.stiffness_n_per_m = f64::NAN;
        let e = p.validate().unwrap_err();
        assert!(e.contains("display.friction.mu_kinetic"), "{e}");
        assert!(e.contains("sensor.bits"), "{e}");
        assert!(e.contains("display.contact.stiffness_n_per_m"), "{e}");
    }
}

#[cfg(test)]
mod doc_tests {
    use super::KEYS;

    #[test]
    fn every_profile_key_is_documented_with_its_source() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/simulated-lab.md");
        let doc = std::fs::read_to_string(&path).unwrap();
        for k in KEYS {
            let row = format!("| `{}` |", k.name);
            assert!(doc.contains(&row), "docs/simulated-lab.md has no table row for `{}`", k.path());
        }
    }

    #[test]
    fn every_profile_key_is_in_the_nominal_file() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs/lab/nominal.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        for k in KEYS {
            assert!(text.contains(&format!("\n{} = ", k.name)), "nominal.toml lacks `{}`", k.path());
        }
    }
}
