//! Reading a lab profile file: TOML with spans, so every error names the
//! file, the line and the key, and a misspelt key gets "did you mean …?".

use super::profile::{LabProfile, KEYS};
use evflow_engine::diag::LineIndex;
use evflow_engine::suggest;
use std::fmt;
use std::path::{Path, PathBuf};
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// One problem in a profile file.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileIssue {
    /// Line (1-based; 0 when the problem is not at one place).
    pub line: usize,
    /// Column (1-based).
    pub col: usize,
    /// The key concerned, as a dotted path (empty for the whole file).
    pub key: String,
    /// What is wrong.
    pub message: String,
    /// What would fix it.
    pub help: Option<String>,
}

/// Every problem found in one profile file.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileError {
    /// The file.
    pub file: PathBuf,
    /// The problems, in file order.
    pub issues: Vec<ProfileIssue>,
}

impl fmt::Display for ProfileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.issues.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{}", self.file.display())?;
            if d.line > 0 {
                write!(f, ":{}:{}", d.line, d.col)?;
            }
            write!(f, ": ")?;
            if !d.key.is_empty() {
                write!(f, "`{}`: ", d.key)?;
            }
            write!(f, "{}", d.message)?;
            if let Some(h) = &d.help {
                write!(f, "\n  help: {h}")?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for ProfileError {}

impl ProfileError {
    /// The problems without the file name (for errors that name the file already).
    pub fn issues_text(&self) -> String {
        let mut s = String::new();
        for (i, d) in self.issues.iter().enumerate() {
            if i > 0 {
                s.push('\n');
            }
            if d.line > 0 {
                s += &format!("line {}, column {}: ", d.line, d.col);
            }
            if !d.key.is_empty() {
                s += &format!("`{}`: ", d.key);
            }
            s += &d.message;
            if let Some(h) = &d.help {
                s += &format!(" (help: {h})");
            }
        }
        s
    }
}

/// The sections of a profile (tables that hold keys).
const SECTIONS: [&str; 6] =
    ["display.amplifier", "display.electrical", "display.friction", "display.contact", "tribometer", "sensor"];
/// Top-level tables.
const TOP: [&str; 4] = ["lab", "display", "tribometer", "sensor"];
/// Sub-tables of `display`.
const DISPLAY_SUBS: [&str; 4] = ["amplifier", "electrical", "friction", "contact"];
/// Keys of `[lab]`.
const LAB_KEYS: [&str; 2] = ["name", "description"];

struct Reader<'t> {
    text: &'t str,
    lines: LineIndex,
    issues: Vec<ProfileIssue>,
}

impl Reader<'_> {
    fn err(&mut self, span: std::ops::Range<usize>, key: &str, message: impl Into<String>, help: Option<String>) {
        let loc = self.lines.loc(self.text, span.start);
        self.issues.push(ProfileIssue {
            line: loc.line,
            col: loc.col,
            key: key.to_string(),
            message: message.into(),
            help,
        });
    }
}

impl LabProfile {
    /// Reads a profile file. Keys not given keep their nominal value.
    pub fn load(path: &Path) -> Result<LabProfile, ProfileError> {
        let text = evflow_engine::files::read_regular_to_string(path).map_err(|e| ProfileError {
            file: path.to_path_buf(),
            issues: vec![ProfileIssue {
                line: 0,
                col: 0,
                key: String::new(),
                message: format!("cannot read the lab profile: {e}"),
                help: Some(
                    "`profile` takes a path relative to the graph file; graphs/lab/ holds the shipped profiles".into(),
                ),
            }],
        })?;
        Self::parse(path, &text)
    }

    /// Reads a profile from text; `file` names it in errors.
    pub fn parse(file: &Path, text: &str) -> Result<LabProfile, ProfileError> {
        let mut r = Reader { text, lines: LineIndex::new(text), issues: Vec::new() };
        let mut p = LabProfile::default();
        let root = match DeTable::parse(text) {
            Ok(t) => t,
            Err(e) => {
                let span = e.span().unwrap_or(0..0);
                r.err(span, "", format!("not valid TOML: {}", e.message().trim()), None);
                return Err(ProfileError { file: file.to_path_buf(), issues: r.issues });
            }
        };
        for (k, v) in root.get_ref().iter() {
            let name = k.get_ref().as_ref();
            match name {
                "lab" => read_lab(&mut r, v, &mut p),
                "display" => match v.get_ref().as_table() {
                    Some(t) => {
                        for (sk, sv) in t.iter() {
                            let sub = sk.get_ref().as_ref();
                            if DISPLAY_SUBS.contains(&sub) {
                                read_section(&mut r, &format!("display.{sub}"), sv, &mut p);
                            } else {
                                let help = suggest::help(sub, DISPLAY_SUBS);
                                r.err(sk.span(), &format!("display.{sub}"), "unknown section", Some(help));
                            }
                        }
                    }
                    None => r.err(v.span(), "display", "must be a table of sections ([display.amplifier], …)", None),
                },
                "tribometer" | "sensor" => read_section(&mut r, name, v, &mut p),
                other => {
                    let cands = TOP.iter().copied().chain(SECTIONS.iter().copied());
                    r.err(k.span(), other, "unknown section", Some(suggest::help(other, cands)));
                }
            }
        }
        if r.issues.is_empty() {
            for (key, message) in p.cross_check() {
                let span = find_key_span(root.get_ref(), &key).unwrap_or(0..0);
                let (line, col) = if span == (0..0) {
                    (0, 0)
                } else {
                    let l = r.lines.loc(text, span.start);
                    (l.line, l.col)
                };
                r.issues.push(ProfileIssue { line, col, key, message, help: None });
            }
        }
        if r.issues.is_empty() {
            Ok(p)
        } else {
            Err(ProfileError { file: file.to_path_buf(), issues: r.issues })
        }
    }
}

fn read_lab(r: &mut Reader<'_>, v: &Spanned<DeValue<'_>>, p: &mut LabProfile) {
    let Some(t) = v.get_ref().as_table() else {
        r.err(v.span(), "lab", "must be a table ([lab] with name and description)", None);
        return;
    };
    for (k, val) in t.iter() {
        let key = k.get_ref().as_ref();
        let path = format!("lab.{key}");
        match (key, val.get_ref().as_str()) {
            ("name", Some(s)) => p.name = s.to_string(),
            ("description", Some(s)) => p.description = s.to_string(),
            ("name" | "description", None) => r.err(val.span(), &path, "must be text", None),
            _ => r.err(k.span(), &path, "unknown key", Some(suggest::help(key, LAB_KEYS))),
        }
    }
}

fn read_section(r: &mut Reader<'_>, section: &str, v: &Spanned<DeValue<'_>>, p: &mut LabProfile) {
    let Some(t) = v.get_ref().as_table() else {
        r.err(v.span(), section, format!("must be a table ([{section}])"), None);
        return;
    };
    for (k, val) in t.iter() {
        let name = k.get_ref().as_ref();
        let path = format!("{section}.{name}");
        let Some(key) = KEYS.iter().find(|x| x.section == section && x.name == name) else {
            let cands: Vec<&str> = KEYS.iter().filter(|x| x.section == section).map(|x| x.name).collect();
            let mut help = suggest::help(name, cands.iter().copied());
            if let Some(other) = KEYS.iter().find(|x| x.name == name) {
                help = format!("`{name}` belongs in [{}]", other.section);
            }
            r.err(k.span(), &path, "unknown key", Some(help));
            continue;
        };
        let x = match number(val.get_ref()) {
            Some(x) => x,
            None => {
                r.err(
                    val.span(),
                    &path,
                    format!("must be a number ({}), not {}", key.unit, val.get_ref().type_str()),
                    Some(key.doc.to_string()),
                );
                continue;
            }
        };
        if !(x.is_finite() && x >= key.min && x <= key.max) {
            r.err(
                val.span(),
                &path,
                format!("{x} is outside {} ..= {} {}", key.min, key.max, key.unit),
                Some(key.doc.to_string()),
            );
            continue;
        }
        (key.set)(p, x);
    }
}

fn number(v: &DeValue<'_>) -> Option<f64> {
    match v {
        DeValue::Integer(i) if i.radix() == 10 => i.as_str().replace('_', "").parse::<i64>().ok().map(|x| x as f64),
        DeValue::Float(f) => f.as_str().replace('_', "").parse::<f64>().ok(),
        _ => None,
    }
}

fn find_key_span(root: &DeTable<'_>, path: &str) -> Option<std::ops::Range<usize>> {
    let mut parts = path.split('.').peekable();
    let mut table = root;
    while let Some(part) = parts.next() {
        let (k, v) = table.iter().find(|(k, _)| k.get_ref().as_ref() == part)?;
        if parts.peek().is_none() {
            return Some(k.span());
        }
        table = v.get_ref().as_table()?;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<LabProfile, ProfileError> {
        LabProfile::parse(Path::new("lab.toml"), text)
    }

    #[test]
    fn empty_file_is_the_nominal_lab() {
        assert_eq!(parse("").unwrap(), LabProfile::default());
    }

    #[test]
    fn reads_nested_sections_and_integers() {
        let p = parse(
            "[lab]\nname = \"x\"\n[display.contact]\nstiffness_n_per_m = 200_000\n[sensor]\nresonance_hz = 1.5e5\n",
        )
        .unwrap();
        assert_eq!(p.name, "x");
        assert_eq!(p.display.contact.stiffness_n_per_m, 200_000.0);
        assert_eq!(p.sensor.resonance_hz, 150_000.0);
        assert_eq!(p.tribometer, LabProfile::default().tribometer);
    }

    #[test]
    fn unknown_key_names_line_and_suggests() {
        let e = parse("[display.friction]\nmu_statc = 0.4\n").unwrap_err();
        let s = e.to_string();
        assert_eq!(e.issues[0].line, 2, "{s}");
        assert!(s.contains("lab.toml:2:1"), "{s}");
        assert!(s.contains("display.friction.mu_statc"), "{s}");
        assert!(s.contains("did you mean `mu_static`?"), "{s}");
    }

    #[test]
    fn key_in_the_wrong_section_is_pointed_to_its_section() {
        let e = parse("[sensor]\ntravel_cm = 8\n").unwrap_err();
        assert!(e.to_string().contains("belongs in [tribometer]"), "{e}");
    }

    #[test]
    fn out_of_range_and_wrong_type_and_unknown_section() {
        let e = parse("[sensor]\nbits = 64\nnoise_n = \"lots\"\n[senser]\n[display.frction]\n").unwrap_err();
        assert_eq!(e.issues.len(), 4, "{e}");
        let s = e.to_string();
        assert!(s.contains("lab.toml:2:8: `sensor.bits`: 64 is outside 4 ..= 32 bit"), "{s}");
        assert!(s.contains("lab.toml:3:11: `sensor.noise_n`: must be a number"), "{s}");
        assert!(s.contains("did you mean `sensor`?"), "{s}");
        assert!(s.contains("did you mean `friction`?"), "{s}");
    }

    #[test]
    fn cross_checks_point_at_the_key() {
        let e = parse("[display.friction]\nmu_static = 0.2\nmu_kinetic = 0.3\n").unwrap_err();
        assert_eq!(e.issues[0].line, 3, "{e}");
        assert!(e.to_string().contains("exceeds static friction"), "{e}");
    }

    #[test]
    fn bad_toml_and_missing_file() {
        let e = parse("[sensor\n").unwrap_err();
        assert!(e.to_string().contains("not valid TOML"), "{e}");
        let e = LabProfile::load(Path::new("/nonexistent/lab.toml")).unwrap_err();
        assert!(e.to_string().contains("cannot read the lab profile"), "{e}");
    }
}

#[cfg(test)]
mod shipped_tests {
    use crate::lab::testutil::shipped;
    use crate::lab::LabProfile;

    #[test]
    fn nominal_file_is_the_builtin_default() {
        assert_eq!(shipped("nominal"), LabProfile::default());
    }

    #[test]
    fn stiff_raises_contact_stiffness_and_sensor_resonance_100x() {
        let (n, s) = (LabProfile::default(), shipped("stiff"));
        assert_eq!(s.display.contact.stiffness_n_per_m / n.display.contact.stiffness_n_per_m, 100.0);
        assert_eq!(s.sensor.resonance_hz / n.sensor.resonance_hz, 100.0);
        assert_eq!(s.tribometer.normal_stiffness_n_per_m / n.tribometer.normal_stiffness_n_per_m, 100.0);
        assert_eq!(s.display.electrical, n.display.electrical);
        assert_eq!(s.display.friction, n.display.friction);
    }

    #[test]
    fn display_b_differs_electrically_and_mechanically() {
        use crate::lab::electrical::Circuit;
        let (n, b) = (LabProfile::default(), shipped("display-b"));
        b.validate().unwrap();
        let (cn, cb) = (Circuit::of(&n), Circuit::of(&b));
        // Gap response at 20 Hz relative to 500 Hz: the fast-leaking gap of
        // display B is a much stronger high-pass.
        let shape = |c: &Circuit| c.gap_gain(20.0) / c.gap_gain(500.0);
        assert!(shape(&cb) < 0.5 * shape(&cn), "{} vs {}", shape(&cb), shape(&cn));
        let fr = |p: &LabProfile| {
            let c = &p.display.contact;
            (c.stiffness_n_per_m / (c.tip_mass_g * 1e-3)).sqrt() / (2.0 * std::f64::consts::PI)
        };
        assert!(fr(&n) > 2.0 * fr(&b), "lateral resonance {} vs {}", fr(&n), fr(&b));
        assert_eq!(b.tribometer, n.tribometer);
        assert_eq!(b.sensor, n.sensor);
    }
}
