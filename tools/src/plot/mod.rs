//! PNG line and scatter plots for reports (work-precision diagrams, spectra,
//! fits), drawn with plotters.
//!
//! Text needs a TrueType font. evflow ships none: it uses the first of
//! `$EVFLOW_FONT` and the usual system paths of DejaVu Sans, Liberation Sans
//! and Noto Sans (Debian: `apt install fonts-dejavu-core`). Without one the
//! plot is still drawn — axes, grid and series — without its text, and
//! [`Written::labelled`] says so.

use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

pub use evflow_study::figure::{Legend, Plot, Series, Style};

mod legend;

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// The PNG file.
    pub path: PathBuf,
    /// Whether a font was found for the text.
    pub labelled: bool,
}

/// Why a plot could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// No series holds a point that can be drawn.
    #[error("{path}: nothing to plot (no finite point{log})", log = if *.log { " above 0 on a log axis" } else { "" })]
    Empty {
        /// The file that was to be written.
        path: String,
        /// Whether an axis was logarithmic.
        log: bool,
    },
    /// Drawing or writing failed.
    #[error("{path}: cannot draw the plot: {message}")]
    Draw {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

const SIZE: (u32, u32) = (960, 640);
const FONT: &str = "evflow-sans";

/// Registers a system font once; whether one was found.
fn font() -> bool {
    static FOUND: OnceLock<bool> = OnceLock::new();
    *FOUND.get_or_init(|| {
        let mut candidates: Vec<PathBuf> = std::env::var_os("EVFLOW_FONT").map(PathBuf::from).into_iter().collect();
        candidates.extend(
            [
                "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                "/usr/share/fonts/TTF/DejaVuSans.ttf",
                "/usr/share/fonts/dejavu/DejaVuSans.ttf",
                "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
                "/usr/share/fonts/truetype/noto/NotoSans-Regular.ttf",
                "/Library/Fonts/Arial.ttf",
                "/System/Library/Fonts/Supplemental/Arial.ttf",
                "C:\\Windows\\Fonts\\arial.ttf",
            ]
            .iter()
            .map(PathBuf::from),
        );
        candidates.into_iter().any(|p| match std::fs::read(&p) {
            // Fonts live for the whole program: plotters keeps a reference.
            Ok(bytes) => {
                plotters::style::register_font(FONT, FontStyle::Normal, Box::leak(bytes.into_boxed_slice())).is_ok()
            }
            Err(_) => false,
        })
    })
}

/// The drawable points of a series.
fn drawable(s: &Series, log_x: bool, log_y: bool) -> Vec<(f64, f64)> {
    s.points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log_x || *x > 0.0) && (!log_y || *y > 0.0))
        .collect()
}

/// The axis range covering `v`, padded, never empty.
fn range(v: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    if log {
        let (lo, hi) = (lo.log10(), hi.log10());
        let pad = ((hi - lo) * 0.05).max(0.05);
        (10f64.powf(lo - pad), 10f64.powf(hi + pad))
    } else {
        let pad = ((hi - lo) * 0.05).max(hi.abs().max(lo.abs()) * 0.05).max(1e-12);
        (lo - pad, hi + pad)
    }
}

/// An axis label: at most four significant digits, no float noise
/// (0.30000000000000004 → 0.3), exponent form for very small or large values.
fn tick_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let mag = v.abs().log10().floor();
    if !(-3.0..6.0).contains(&mag) {
        return format!("{v:.1e}");
    }
    let decimals = (3.0 - mag).max(0.0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Key points of a log axis: multiples of the powers of ten inside the
/// range — 1, 2, 5 per decade, denser under one decade, only the powers
/// over more than four (values parsed from text so labels carry no float
/// noise).
fn log_keys((lo, hi): (f64, f64)) -> Vec<f64> {
    let decades = (hi / lo).log10();
    let mults: &[f64] = if decades < 1.0 {
        &[1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0]
    } else if decades > 4.0 {
        &[1.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    let mut v = Vec::new();
    for e in (lo.log10().floor() as i32)..=(hi.log10().ceil() as i32) {
        for &m in mults {
            let k: f64 = format!("{m}e{e}").parse().unwrap_or(f64::NAN);
            if k >= lo && k <= hi {
                v.push(k);
            }
        }
    }
    v
}

/// A colour per series, distinct for the first ten.
fn colour(i: usize) -> RGBColor {
    const C: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    let (r, g, b) = C[i % C.len()];
    RGBColor(r, g, b)
}

/// Draws `plot` into `path` (PNG, 960×640). Drawn in memory, then written
/// to a new temporary file and renamed (`evflow_engine::atomic_file`), so a
/// failure leaves no half-written image and nothing is written through a
/// link.
pub fn write_png(plot: &Plot, path: &Path) -> Result<Written, PlotError> {
    let shown = path.display().to_string();
    let log_x = plot.log_x && plot.categories.is_empty();
    let series: Vec<Drawable<'_>> =
        plot.series.iter().enumerate().map(|(i, s)| (i, s, drawable(s, log_x, plot.log_y))).collect();
    if series.iter().all(|(_, _, p)| p.is_empty()) {
        return Err(PlotError::Empty { path: shown, log: log_x || plot.log_y });
    }
    let all = || series.iter().flat_map(|(_, _, p)| p.iter().copied());
    let xr = if plot.categories.is_empty() {
        range(all().map(|p| p.0), log_x)
    } else {
        (0.5, plot.categories.len() as f64 + 0.5)
    };
    let yr = range(all().map(|p| p.1), plot.log_y);
    let labelled = font();
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| PlotError::Draw { path: shown.clone(), message: format!("cannot create its folder: {e}") })?;
    }
    let mut pixels = vec![0u8; SIZE.0 as usize * SIZE.1 as usize * 3];
    let result = draw(plot, &series, xr, yr, labelled, &mut pixels).and_then(|()| {
        evflow_engine::atomic_file::write_with(path, |f| encode_png(&pixels, f)).map_err(|e| e.to_string())
    });
    result.map_err(|message| PlotError::Draw { path: shown, message })?;
    Ok(Written { path: path.to_path_buf(), labelled })
}

/// Writes `pixels` (RGB, [`SIZE`]) to `out` as PNG with the settings
/// plotters' own file output uses (through the image crate's encoder:
/// fast compression, adaptive filtering starting from Sub): the same bytes.
fn encode_png(pixels: &[u8], out: &mut impl std::io::Write) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    let mut encoder = png::Encoder::new(&mut w, SIZE.0, SIZE.1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::FilterType::Sub);
    encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    writer.write_image_data(pixels).map_err(std::io::Error::other)?;
    writer.finish().map_err(std::io::Error::other)?;
    std::io::Write::flush(&mut w)
}

/// A series with its index (for its colour) and its drawable points.
type Drawable<'a> = (usize, &'a Series, Vec<(f64, f64)>);
type Pts<'a> = [Drawable<'a>];
type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// The name of the category at `v` (categories sit at 1, 2, …), if any.
fn category(names: &[String], v: f64) -> Option<&str> {
    let k = v.round();
    // NaN fails both tests.
    if !((v - k).abs() <= 1e-9 && k >= 1.0 && k <= names.len() as f64) {
        return None;
    }
    names.get(k as usize - 1).map(String::as_str)
}

fn draw(
    plot: &Plot,
    series: &Pts<'_>,
    xr: (f64, f64),
    yr: (f64, f64),
    text: bool,
    pixels: &mut [u8],
) -> Result<(), String> {
    let root = BitMapBackend::with_buffer(pixels, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (chart, below) = legend::split(&root, plot, series, text);
    let lx = || (xr.0..xr.1).log_scale().with_key_points(log_keys(xr));
    let ly = || (yr.0..yr.1).log_scale().with_key_points(log_keys(yr));
    let log_x = plot.log_x && plot.categories.is_empty();
    match (log_x, plot.log_y) {
        (false, false) => body(&chart, plot, series, (xr.0..xr.1, yr.0..yr.1), text),
        (true, false) => body(&chart, plot, series, (lx(), yr.0..yr.1), text),
        (false, true) => body(&chart, plot, series, (xr.0..xr.1, ly()), text),
        (true, true) => body(&chart, plot, series, (lx(), ly()), text),
    }?;
    if let Some(area) = below {
        legend::draw_below(&area, plot, series)?;
    }
    root.present().map_err(|e| e.to_string())
}

fn body<X, Y>(root: &Area<'_>, plot: &Plot, series: &Pts<'_>, (x, y): (X, Y), text: bool) -> Result<(), String>
where
    X: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
    Y: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
    X::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
    Y::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let mut b = ChartBuilder::on(root);
    b.margin(20);
    if text {
        b.caption(&plot.title, (FONT, 24)).x_label_area_size(50).y_label_area_size(80);
    } else {
        b.x_label_area_size(10).y_label_area_size(10);
    }
    let mut chart = b.build_cartesian_2d(x, y).map_err(|e| e.to_string())?;
    let mut mesh = chart.configure_mesh();
    // On a category axis only the categories are named (a tick between two is blank).
    let x_tick = |v: &f64| match category(&plot.categories, *v) {
        Some(name) => name.to_string(),
        None if plot.categories.is_empty() => tick_label(*v),
        None => String::new(),
    };
    if !plot.categories.is_empty() {
        mesh.x_labels(plot.categories.len().max(2));
    }
    if text {
        mesh.x_desc(&plot.x_label)
            .y_desc(&plot.y_label)
            .label_style((FONT, 16))
            .x_label_formatter(&x_tick)
            .y_label_formatter(&|v| tick_label(*v));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(|e| e.to_string())?;
    // Lines and levels first, markers over them: no line hides a point.
    for (i, s, pts) in series {
        let c = colour(*i);
        match s.style {
            Style::Line | Style::LinePoints => {
                chart
                    .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
                    .map_err(|e| e.to_string())?;
            }
            Style::Level => {
                let bar = |&(x, y): &(f64, f64)| PathElement::new(vec![(x - 0.4, y), (x + 0.4, y)], c.stroke_width(3));
                chart.draw_series(pts.iter().map(bar)).map_err(|e| e.to_string())?;
            }
            Style::Points => {}
        }
    }
    for (i, s, pts) in series {
        if matches!(s.style, Style::Points | Style::LinePoints) {
            let c = colour(*i);
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled()))).map_err(|e| e.to_string())?;
        }
    }
    if text && series.len() > 1 && plot.legend == Legend::Inside {
        // The legend in the series' order: an empty series per entry.
        for (i, s, _) in series {
            let (path, line, marker) = legend::glyph(s.style, colour(*i));
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(|e| e.to_string())?
                .label(&s.name)
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y)) + PathElement::new(path.clone(), line) + Circle::new((10, 0), 4, marker)
                });
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 16))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(0.30000000000000004), "0.3");
        assert_eq!(tick_label(0.0125), "0.0125");
        assert_eq!(tick_label(1234.6), "1235");
        assert_eq!(tick_label(20.0), "20");
        assert_eq!(tick_label(2e-5), "2.0e-5");
        assert_eq!(tick_label(-0.5), "-0.5");
    }

    #[test]
    fn log_key_points_suit_the_span_and_stay_within_the_range() {
        assert_eq!(log_keys((0.11, 0.9)), vec![0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8]);
        assert_eq!(log_keys((1e-3, 1e3)), vec![1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 1e3]);
        let k = log_keys((0.004, 0.3));
        assert_eq!(k, vec![0.005, 0.01, 0.02, 0.05, 0.1, 0.2]);
    }

    #[test]
    fn writes_a_png_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("wp.png");
        let plot = Plot {
            title: "work-precision".into(),
            x_label: "run time (s)".into(),
            y_label: "error".into(),
            log_x: true,
            log_y: true,
            series: vec![
                Series::line_points("exact", (1..8).map(|k| (k as f64 * 1e-3, 10f64.powi(-k))).collect()),
                Series::points("rk4", vec![(1e-3, 1e-2), (f64::NAN, 1.0), (0.0, 1.0)]),
            ],
            ..Default::default()
        };
        let w = write_png(&plot, &path).unwrap();
        let bytes = std::fs::read(&w.path).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("wp.png")]);
    }

    #[test]
    fn the_png_is_byte_for_byte_what_plotters_writes_to_a_file() {
        // Plots are drawn in memory and written through a new temporary
        // (issue 37, point 2); the bytes are those plotters' file output
        // (`BitMapBackend::new`, plotters 0.3.7 through image 0.24.9) wrote
        // for this scene: its length and FNV-1a hash were taken from that
        // output before the image crate was dropped.
        let mut pixels = vec![0u8; SIZE.0 as usize * SIZE.1 as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
            root.fill(&WHITE).unwrap();
            let pts = (0..900).map(|x| (x + 30, 320 + ((x as f64 / 40.0).sin() * 250.0) as i32));
            root.draw(&PathElement::new(pts.collect::<Vec<_>>(), colour(1).stroke_width(2))).unwrap();
            root.present().unwrap();
        }
        let mut ours = Vec::new();
        encode_png(&pixels, &mut ours).unwrap();
        let fnv = ours.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
        assert_eq!((ours.len(), fnv), (18164, 0x8835_29ac_ec80_cdb5));
        // And it decodes to the pixels drawn.
        let mut reader = png::Decoder::new(std::io::Cursor::new(&ours)).read_info().unwrap();
        let mut back = vec![0u8; reader.output_buffer_size()];
        let info = reader.next_frame(&mut back).unwrap();
        assert_eq!((info.width, info.height, info.color_type), (SIZE.0, SIZE.1, png::ColorType::Rgb));
        assert_eq!(back, pixels);
    }

    #[test]
    fn categories_are_named_at_whole_positions_only() {
        let names: Vec<String> = ["felt", "paper"].map(String::from).to_vec();
        assert_eq!(category(&names, 1.0), Some("felt"));
        assert_eq!(category(&names, 2.0 + 1e-12), Some("paper"));
        assert_eq!(category(&names, 1.5), None);
        assert_eq!(category(&names, 0.0), None);
        assert_eq!(category(&names, 3.0), None);
        assert_eq!(category(&names, -1.0), None);
        assert_eq!(category(&names, f64::NAN), None);
    }

    #[test]
    fn a_note_wraps_at_spaces_within_its_width() {
        let note = "word ".repeat(60);
        let lines = legend::note_lines(&note);
        assert!(lines.len() >= 2 && lines.iter().all(|l| l.chars().count() <= 115), "{lines:?}");
        assert_eq!(lines.join(" "), note.trim_end());
        assert!(legend::note_lines("").is_empty());
    }

    #[test]
    fn a_category_plot_with_levels_a_note_and_the_legend_below_is_drawn() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.png");
        let plot = Plot {
            title: "categories".into(),
            y_label: "E_s".into(),
            series: vec![
                Series::points("nothing", vec![(0.9, 0.8), (1.9, 0.5)]),
                Series::level("floor", vec![(1.0, 0.3), (2.0, 0.4)]),
            ],
            categories: vec!["felt".into(), "paper".into()],
            legend: Legend::Below,
            note: "E_s: what it is.".into(),
            log_x: true,
            ..Plot::default()
        };
        let w = write_png(&plot, &path).unwrap();
        assert_eq!(&std::fs::read(&w.path).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
    }

    #[test]
    fn nothing_to_plot_is_an_error_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.png");
        let plot =
            Plot { log_y: true, series: vec![Series::line("s", vec![(1.0, 0.0), (2.0, -1.0)])], ..Plot::default() };
        let e = write_png(&plot, &path).unwrap_err();
        assert!(e.to_string().contains("nothing to plot"), "{e}");
        assert!(!path.exists());
    }
}
