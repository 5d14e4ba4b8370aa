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
    /// The square law above a measured floor: y = (f^p + (b·x²)^p)^(1/p),
    /// f the mean y at x = 0 (the sweep must hold x = 0), b and p ≥ 1 by
    /// least squares over the other points. For a measure that reads a
    /// floor with the effect off (noise, the tribometer's reversals) and
    /// the square law once the effect rises above it.
    SquareOverFloor,
}

impl Fit {
    /// The names accepted in a graph file.
    pub const NAMES: [&'static str; 5] = ["none", "linear", "quadratic", "square", "square-over-floor"];

    /// The fit of that name.
    pub fn from_name(s: &str) -> Option<Self> {
        match s {
            "none" => Some(Fit::None),
            "linear" => Some(Fit::Linear),
            "quadratic" => Some(Fit::Quadratic),
            "square" => Some(Fit::Square),
            "square-over-floor" => Some(Fit::SquareOverFloor),
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
            Fit::SquareOverFloor => "square-over-floor",
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

#[cfg(test)]
mod tests {
    use super::Fit;

    #[test]
    fn every_fit_name_round_trips_and_the_floor_fit_is_named() {
        for n in Fit::NAMES {
            assert_eq!(Fit::from_name(n).map(Fit::name), Some(n));
        }
        assert_eq!(Fit::from_name("square-over-floor"), Some(Fit::SquareOverFloor));
        assert_eq!(Fit::from_name("square_over_floor"), None);
    }
}
