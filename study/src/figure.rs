//! What a study draws: plots as data — title, axes, named series — that
//! the program renders to PNG (`evflow_tools::plot::write_png`) and tests
//! can read without drawing.

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Points joined by a line.
    Line,
    /// Points only.
    Points,
    /// Points joined by a line, each marked.
    LinePoints,
    /// Each point a short horizontal bar, 0.8 x units wide centred on it: a
    /// level per category on a category axis (a floor, a target).
    Level,
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// Inside the plotting area, at its right (plotters' default).
    #[default]
    Inside,
    /// Under the plot, outside the data: it hides no point.
    Below,
}

/// One named series of (x, y) points.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// The points; non-finite ones (and non-positive ones on a log axis) are
    /// left out.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub style: Style,
}

impl Series {
    /// A series drawn with a line.
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self { name: name.into(), points, style: Style::Line }
    }
    /// A series drawn as marked points joined by a line.
    pub fn line_points(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self { name: name.into(), points, style: Style::LinePoints }
    }
    /// A series drawn as points.
    pub fn points(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self { name: name.into(), points, style: Style::Points }
    }
    /// A series drawn as a level (a short horizontal bar) at each point.
    pub fn level(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self { name: name.into(), points, style: Style::Level }
    }
}

/// A plot: title, axis labels and scales, series.
#[derive(Debug, Clone, Default)]
pub struct Plot {
    /// Title above the plot.
    pub title: String,
    /// Label of the x axis, with its unit.
    pub x_label: String,
    /// Label of the y axis, with its unit.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The series.
    pub series: Vec<Series>,
    /// A category axis when not empty: category k (from 0) sits at x = k + 1
    /// and is labelled with its name; the axis spans 0.5 … n + 0.5.
    pub categories: Vec<String>,
    /// Where the legend goes.
    pub legend: Legend,
    /// A note under the plot (a definition of a quantity); empty for none.
    pub note: String,
}
