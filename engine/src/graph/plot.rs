//! `[[plot]]` tables: figures drawn from a run's or a sweep's results.

use crate::diag::Loc;

/// A curve fitted to each series of a plot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fit {
    /// No fit.
    None,
    /// y = a + b·x, least squares.
    Linear,
    /// y = a + b·x + c·x², least squares.
    Quadratic,
    /// y = a + b·x², least squares: the square law of electrovibration.
    Square,
}

impl Fit {
    /// The names accepted in a graph file.
    pub const NAMES: [&'static str; 4] = ["none", "linear", "quadratic", "square"];

    /// The fit of that name.
    pub fn from_name(s: &str) -> Option<Self> {
        match s {
            "none" => Some(Fit::None),
            "linear" => Some(Fit::Linear),
            "quadratic" => Some(Fit::Quadratic),
            "square" => Some(Fit::Square),
            _ => None,
        }
    }

    /// Its name in a graph file.
    pub fn name(self) -> &'static str {
        match self {
            Fit::None => "none",
            Fit::Linear => "linear",
            Fit::Quadratic => "quadratic",
            Fit::Square => "square",
        }
    }
}

/// One `[[plot]]` table.
///
/// A quantity is a graph variable (`intensity`), a value a sink reports
/// (`vib.pp_mean`), the run time of a node in seconds (`display.time`) or
/// of the whole run (`seconds`).
#[derive(Debug, Clone, PartialEq)]
pub struct PlotDecl {
    /// The PNG file, relative to the output folder.
    pub file: String,
    /// Title (default: the graph's name).
    pub title: String,
    /// The quantity on the x axis.
    pub x: String,
    /// The quantities on the y axis, one series each.
    pub y: Vec<String>,
    /// A variable whose values split each quantity into series (e.g. the
    /// integrator of a work-precision diagram); empty for none.
    pub series: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Curve fitted to each series, reported with its R².
    pub fit: Fit,
    /// Where the table starts.
    pub loc: Loc,
}

impl PlotDecl {
    /// The keys a `[[plot]]` table may hold.
    pub const KEYS: [&'static str; 8] = ["file", "title", "x", "y", "series", "log_x", "log_y", "fit"];
}
