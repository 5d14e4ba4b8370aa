//! The legend and the note of a plot: each series' glyph, and the band
//! under the chart that holds the note and a legend set outside the data.

use super::{colour, Area, Pts, FONT, SIZE};
use evflow_study::figure::{Legend, Plot, Style};
use plotters::prelude::*;

/// Characters per line of the note (about 820 px at 14 px).
const NOTE_WIDTH: usize = 115;
/// Heights of a note line and a legend row, and the band's padding, in px.
const NOTE_LINE: u32 = 18;
const LEGEND_ROW: u32 = 22;
const PAD: u32 = 10;

/// A series' glyph in a legend, relative to its place: the path of its line
/// (empty for points alone) with its style, and its marker's style
/// (transparent for a line alone). A level is a thick bar.
pub(super) fn glyph(style: Style, c: RGBColor) -> (Vec<(i32, i32)>, ShapeStyle, ShapeStyle) {
    let none = ShapeStyle { color: c.mix(0.0), filled: true, stroke_width: 0 };
    let bar = vec![(0, 0), (20, 0)];
    match style {
        Style::Line => (bar, c.stroke_width(2), none),
        Style::Points => (vec![], none, c.filled()),
        Style::LinePoints => (bar, c.stroke_width(2), c.filled()),
        Style::Level => (bar, c.stroke_width(3), none),
    }
}

/// The note broken into lines of at most [`NOTE_WIDTH`] characters, at spaces.
pub(super) fn note_lines(note: &str) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in note.split_whitespace() {
        match lines.last_mut() {
            Some(l) if l.chars().count() + 1 + word.chars().count() <= NOTE_WIDTH => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// Legend columns: two when a name is long, else three.
fn columns(series: &Pts<'_>) -> usize {
    if series.iter().any(|(_, s, _)| s.name.chars().count() > 34) {
        2
    } else {
        3
    }
}

/// The band under the chart, in px: none without text, or with neither a
/// note nor a legend below.
fn band(plot: &Plot, series: &Pts<'_>, text: bool) -> u32 {
    let legend_rows = if plot.legend == Legend::Below { series.len().div_ceil(columns(series)) } else { 0 };
    let notes = note_lines(&plot.note).len();
    if !text || legend_rows + notes == 0 {
        return 0;
    }
    2 * PAD + notes as u32 * NOTE_LINE + legend_rows as u32 * LEGEND_ROW
}

/// Splits the image into the chart and, when the plot has one, the band
/// under it for the note and the legend.
pub(super) fn split<'a>(root: &Area<'a>, plot: &Plot, series: &Pts<'_>, text: bool) -> (Area<'a>, Option<Area<'a>>) {
    let h = band(plot, series, text).min(SIZE.1 / 3);
    if h == 0 {
        return (root.clone(), None);
    }
    let (top, bottom) = root.split_vertically(SIZE.1 - h);
    (top, Some(bottom))
}

/// Draws the note, then (with [`Legend::Below`]) the legend in columns.
pub(super) fn draw_below(area: &Area<'_>, plot: &Plot, series: &Pts<'_>) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    let mut y = PAD as i32;
    for line in note_lines(&plot.note) {
        area.draw(&Text::new(line, (30, y), (FONT, 14))).map_err(err)?;
        y += NOTE_LINE as i32;
    }
    if plot.legend != Legend::Below {
        return Ok(());
    }
    let cols = columns(series);
    let width = (SIZE.0 as i32 - 60) / cols as i32;
    for (k, (i, s, _)) in series.iter().enumerate() {
        let (x, row_y) = (30 + (k % cols) as i32 * width, y + (k / cols) as i32 * LEGEND_ROW as i32);
        let (path, line, marker) = glyph(s.style, colour(*i));
        let at = EmptyElement::at((x, row_y + 8)) + PathElement::new(path, line) + Circle::new((10, 0), 4, marker);
        area.draw(&at).map_err(err)?;
        area.draw(&Text::new(s.name.clone(), (x + 28, row_y), (FONT, 15))).map_err(err)?;
    }
    Ok(())
}
