//! What a texture study covers: lab profiles, texture samples, conditions,
//! gains, and where its graphs and work files live.

use super::StudyError;
use std::path::{Path, PathBuf};

/// A (load, velocity) condition.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Cond {
    /// Stylus mass, g.
    #[serde(with = "super::exact")]
    pub mass: f64,
    /// Scanning speed, cm/s.
    #[serde(with = "super::exact")]
    pub speed: f64,
}

impl Cond {
    /// Parses `MASS:SPEED` (g and cm/s).
    pub fn parse(s: &str) -> Result<Self, StudyError> {
        let bad = |m: String| StudyError::Config(format!("condition `{s}`: {m}"));
        let (m, v) = s.split_once(':').ok_or_else(|| bad("not MASS:SPEED".into()))?;
        let mass: f64 = m.trim().parse().map_err(|_| bad(format!("mass `{m}` is not a number")))?;
        let speed: f64 = v.trim().parse().map_err(|_| bad(format!("speed `{v}` is not a number")))?;
        if !(mass > 0.0 && speed > 0.0 && mass.is_finite() && speed.is_finite()) {
            return Err(bad("mass and speed must be positive".into()));
        }
        Ok(Self { mass, speed })
    }

    /// The shipped graphs' `mass` (g) and `speed` (cm/s).
    pub fn sets(&self) -> super::graphs::Sets {
        super::graphs::Sets::new().num("mass", self.mass).num("speed", self.speed)
    }

    /// "60 g, 3 cm/s".
    pub fn label(&self) -> String {
        format!("{} g, {} cm/s", self.mass, self.speed)
    }

    /// "60g-3cms", as the shipped graphs name their outputs.
    pub fn tag(&self) -> String {
        format!("{}g-{}cms", self.mass, self.speed)
    }

    /// The corners of dissertation Fig. 5.6: 60/110 g × 3/5 cm/s.
    pub fn corners() -> Vec<Cond> {
        vec![
            Cond { mass: 60.0, speed: 3.0 },
            Cond { mass: 60.0, speed: 5.0 },
            Cond { mass: 110.0, speed: 3.0 },
            Cond { mass: 110.0, speed: 5.0 },
        ]
    }
}

/// A lab profile: the nominal display or a profile file.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Short name ("nominal", "display-b", …).
    pub name: String,
    /// The file; None for the built-in nominal lab.
    pub path: Option<PathBuf>,
}

impl Profile {
    /// The built-in nominal lab.
    pub fn nominal() -> Self {
        Self { name: "nominal".into(), path: None }
    }

    /// A profile by name: "nominal", or `graphs/lab/NAME.toml`, or a path.
    pub fn resolve(name: &str, graphs: &Path) -> Result<Self, StudyError> {
        if name == "nominal" || name.is_empty() {
            return Ok(Self::nominal());
        }
        let as_path = Path::new(name);
        let file = if as_path.extension().is_some() {
            as_path.to_path_buf()
        } else {
            graphs.join("lab").join(format!("{name}.toml"))
        };
        let file = std::fs::canonicalize(&file)
            .map_err(|e| StudyError::Config(format!("lab profile `{name}`: {}: {e}", file.display())))?;
        let short = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| name.to_string());
        Ok(Self { name: short, path: Some(file) })
    }

    /// The `profile` value the shipped graphs take (empty for nominal).
    pub fn sets(&self) -> super::graphs::Sets {
        let file = self.path.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
        super::graphs::Sets::new().text("profile", &file)
    }
}
