//! Delimited text (`.csv`, `.tsv`, `.txt`): numeric rows under an optional
//! header row of channel names.
//!
//! * The delimiter is a comma, a semicolon, a tab or runs of spaces: given,
//!   or detected as the first of tab, semicolon, comma that splits the first
//!   lines into the same number (more than one) of cells, then whitespace;
//!   a file none of them splits is one column.
//! * Empty lines and lines starting with `#` are skipped.
//! * The first remaining line is a header when none of its cells is a
//!   number. Without one, a `#` comment line right above the first row
//!   that holds one name per column is the header (`np.savetxt` writes
//!   its `header` argument so). A header cell is a name with an optional unit in brackets or
//!   parentheses: `force [N]`, `time (s)`.
//! * The text is UTF-8, or UTF-16 with a byte-order mark, or else Latin-1
//!   (decoded by the caller).
//! * Every other cell must be a finite number (`1.5`, `-2e-3`; with a
//!   semicolon, tab or space delimiter also the decimal comma `1,5`). Cells
//!   may be quoted (`"1.5"`, RFC 4180 quoting).

use super::error::{non_finite_word, ImportError};
use std::path::Path;

/// How the cells of a row are separated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delimiter {
    /// `,`
    Comma,
    /// `;` (spreadsheets in locales with a decimal comma)
    Semicolon,
    /// a tab (`.tsv`)
    Tab,
    /// one or more spaces or tabs (`np.savetxt`'s default)
    Whitespace,
}

impl Delimiter {
    /// The character, or `None` for whitespace runs.
    fn char(self) -> Option<char> {
        match self {
            Delimiter::Comma => Some(','),
            Delimiter::Semicolon => Some(';'),
            Delimiter::Tab => Some('\t'),
            Delimiter::Whitespace => None,
        }
    }

    /// A word for messages: `comma`, `semicolon`, `tab`, `whitespace`.
    pub fn name(self) -> &'static str {
        match self {
            Delimiter::Comma => "comma",
            Delimiter::Semicolon => "semicolon",
            Delimiter::Tab => "tab",
            Delimiter::Whitespace => "whitespace",
        }
    }
}

impl std::str::FromStr for Delimiter {
    type Err = String;
    /// `,` / `comma`, `;` / `semicolon`, `tab` / `\t`, `space` /
    /// `whitespace`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "," | "comma" => Ok(Delimiter::Comma),
            ";" | "semicolon" => Ok(Delimiter::Semicolon),
            "\t" | "\\t" | "tab" => Ok(Delimiter::Tab),
            " " | "space" | "whitespace" => Ok(Delimiter::Whitespace),
            other => Err(format!("delimiter `{other}` is not one of comma, semicolon, tab, space")),
        }
    }
}

/// A header cell: the name and unit as written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Head {
    /// The name (the cell without its bracketed unit), trimmed.
    pub name: String,
    /// The unit inside `[…]` or `(…)`, or empty.
    pub unit: String,
}

/// A parsed table: every cell a finite number.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Table {
    /// The header, one entry per column, if the file has one.
    pub header: Option<Vec<Head>>,
    /// Columns per row.
    pub columns: usize,
    /// Rows, interleaved (`row0col0, row0col1, …`).
    pub samples: Vec<f64>,
    /// The file's line number (from 1) of each row.
    pub lines: Vec<usize>,
    /// The delimiter used.
    pub delimiter: Delimiter,
    /// Whether the delimiter was detected (not given).
    pub detected: bool,
    /// The line of a `#` comment taken as the header (`np.savetxt` writes
    /// its `header` so), if that is where the header came from.
    pub header_from_comment: Option<usize>,
}

impl Table {
    /// Rows read.
    pub fn rows(&self) -> usize {
        self.lines.len()
    }
}

/// How many lines delimiter detection looks at.
const SNIFF_LINES: usize = 50;

/// Parses `text`, the contents of `path` (only used in messages).
pub(super) fn parse(text: &str, path: &Path, delimiter: Option<Delimiter>) -> Result<Table, ImportError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text); // a UTF-8 byte-order mark (Excel)
    let content: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .collect();
    if content.is_empty() {
        return Err(ImportError::Empty { path: path.to_path_buf(), what: "no rows (only empty or # lines)".into() });
    }
    let (delimiter, detected) = match delimiter {
        Some(d) => (d, false),
        None => (detect(content.iter().take(SNIFF_LINES).map(|(_, l)| *l)), true),
    };
    let text_err = |line: usize, message: String| ImportError::Text { path: path.to_path_buf(), line, message };

    let mut rows = content.iter();
    let mut header = None;
    let mut first_data = None;
    if let Some(&(line, l)) = rows.next() {
        let cells = split(l, delimiter).map_err(|m| text_err(line, m))?;
        if cells.iter().all(|c| number(c, delimiter).is_none()) {
            header = Some(cells.iter().map(|c| head(c)).collect::<Vec<_>>());
        } else {
            first_data = Some((line, cells));
        }
    }
    let columns = match (&header, &first_data) {
        (Some(h), _) => h.len(),
        (None, Some((_, cells))) => cells.len(),
        (None, None) => 0,
    };

    let mut samples = Vec::new();
    let mut lines = Vec::new();
    let mut push = |line: usize, cells: Vec<String>| -> Result<(), ImportError> {
        if cells.len() != columns {
            let against = if header.is_some() { "the header has" } else { "the first row has" };
            return Err(text_err(
                line,
                format!(
                    "{} cell(s) where {against} {columns} ({} delimiter{})",
                    cells.len(),
                    delimiter.name(),
                    if detected { ", detected; give another with --delimiter" } else { "" }
                ),
            ));
        }
        for (k, c) in cells.iter().enumerate() {
            let name = header.as_ref().map(|h| h[k].name.clone()).filter(|n| !n.is_empty());
            let cell_err = |message: String| ImportError::Cell {
                path: path.to_path_buf(),
                line,
                column: k + 1,
                name: name.clone(),
                message,
            };
            match number(c, delimiter) {
                Some(x) if x.is_finite() => samples.push(x),
                Some(x) => return Err(cell_err(format!("`{c}` is {}", non_finite_word(x)))),
                None if c.is_empty() => return Err(cell_err("is empty".into())),
                None if header.is_none() && lines.is_empty() => {
                    return Err(cell_err(format!(
                        "`{c}` is not a number (a header row, when there is one, holds only names)"
                    )))
                }
                None => return Err(cell_err(format!("`{c}` is not a number"))),
            }
        }
        lines.push(line);
        Ok(())
    };
    if let Some((line, cells)) = first_data {
        push(line, cells)?;
    }
    for &(line, l) in rows {
        let cells = split(l, delimiter).map_err(|m| text_err(line, m))?;
        push(line, cells)?;
    }
    if lines.is_empty() {
        return Err(ImportError::Empty { path: path.to_path_buf(), what: "a header row and no data rows".into() });
    }
    // No header row: the comment line right above the first row is the
    // header if it holds one name per column (`np.savetxt(…, header=…)`).
    let mut header_from_comment = None;
    if header.is_none() {
        let above = lines[0].checked_sub(2).and_then(|i| text.lines().nth(i)).map(|l| l.trim_end_matches('\r'));
        if let Some(names) = above.and_then(|l| l.trim_start().strip_prefix('#')) {
            if let Ok(cells) = split(names.trim(), delimiter) {
                if cells.len() == columns && cells.iter().all(|c| !c.is_empty() && number(c, delimiter).is_none()) {
                    header = Some(cells.iter().map(|c| head(c)).collect());
                    header_from_comment = Some(lines[0] - 1);
                }
            }
        }
    }
    Ok(Table { header, columns, samples, lines, delimiter, detected, header_from_comment })
}

/// The first of tab, semicolon, comma that splits every sniffed line into
/// the same number (> 1) of cells; else whitespace if it does; else the
/// most frequent of the three in the first line (the row check then names
/// the line that disagrees); else comma (one column).
fn detect<'a>(lines: impl Iterator<Item = &'a str> + Clone) -> Delimiter {
    let consistent = |d: Delimiter| {
        let mut counts = lines.clone().map(|l| split(l, d).map(|c| c.len()).unwrap_or(0));
        let first = counts.next().unwrap_or(0);
        first > 1 && counts.all(|n| n == first)
    };
    for d in [Delimiter::Tab, Delimiter::Semicolon, Delimiter::Comma, Delimiter::Whitespace] {
        if consistent(d) {
            return d;
        }
    }
    let first = lines.clone().next().unwrap_or("");
    [Delimiter::Tab, Delimiter::Semicolon, Delimiter::Comma]
        .into_iter()
        .map(|d| (first.matches(d.char().unwrap_or(',')).count(), d))
        .filter(|(n, _)| *n > 0)
        .max_by_key(|(n, _)| *n)
        .map_or(Delimiter::Comma, |(_, d)| d)
}

/// The cells of a line, trimmed and unquoted. A line ending in a delimiter
/// (as some spreadsheets write) has no empty last cell.
fn split(line: &str, d: Delimiter) -> Result<Vec<String>, String> {
    let Some(sep) = d.char() else {
        return Ok(line.split_whitespace().map(|c| unquote(c).to_string()).collect());
    };
    let mut cells = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut was_quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(ch) = chars.next() {
        if quoted {
            if ch == '"' {
                if chars.peek() == Some(&'"') {
                    cur.push('"');
                    chars.next();
                } else {
                    quoted = false;
                }
            } else {
                cur.push(ch);
            }
        } else if ch == '"' && cur.trim().is_empty() && !was_quoted {
            quoted = true;
            was_quoted = true;
            cur.clear();
        } else if ch == sep {
            cells.push(std::mem::take(&mut cur).trim().to_string());
            was_quoted = false;
        } else {
            cur.push(ch);
        }
    }
    if quoted {
        return Err("a quoted cell is not closed on this line".into());
    }
    let last = cur.trim().to_string();
    if !(last.is_empty() && !was_quoted && !cells.is_empty()) {
        cells.push(last);
    }
    Ok(cells)
}

/// `'abc'` → `abc` (whitespace-delimited cells keep their quotes).
fn unquote(c: &str) -> &str {
    for q in ['"', '\''] {
        if let Some(inner) = c.strip_prefix(q).and_then(|r| r.strip_suffix(q)) {
            return inner;
        }
    }
    c
}

/// The number in a cell, or `None`. With a delimiter other than the comma,
/// a single comma and no point is a decimal comma (`1,5`).
fn number(cell: &str, d: Delimiter) -> Option<f64> {
    if let Ok(x) = cell.parse::<f64>() {
        return Some(x);
    }
    if d != Delimiter::Comma && cell.matches(',').count() == 1 && !cell.contains('.') {
        return cell.replace(',', ".").parse().ok();
    }
    None
}

/// `force [N]` → (`force`, `N`); `time (s)` → (`time`, `s`); `x` → (`x`, ``).
fn head(cell: &str) -> Head {
    let cell = cell.trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(body) = cell.strip_suffix(close) {
            if let Some(at) = body.rfind(open) {
                let name = body[..at].trim();
                if !name.is_empty() {
                    return Head { name: name.to_string(), unit: body[at + 1..].trim().to_string() };
                }
            }
        }
    }
    Head { name: cell.to_string(), unit: String::new() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.csv")
    }

    #[test]
    fn detects_each_delimiter_and_reads_the_header_with_units() {
        for (text, d) in [
            ("time [s],force [N]\n0,1.5\n0.001,-2e-3\n", Delimiter::Comma),
            ("time [s];force [N]\n0;1,5\n0,001;-2e-3\n", Delimiter::Semicolon),
            ("time [s]\tforce [N]\n0\t1.5\n0.001\t-2e-3\n", Delimiter::Tab),
            ("# np.savetxt\n0.0 1.5\n1.0e-3   -2.0e-3\n", Delimiter::Whitespace),
        ] {
            let t = parse(text, p(), None).unwrap();
            assert_eq!(t.delimiter, d, "{text:?}");
            assert!(t.detected);
            assert_eq!(t.columns, 2);
            assert_eq!(t.samples, [0.0, 1.5, 0.001, -2e-3], "{text:?}");
            if d != Delimiter::Whitespace {
                let h = t.header.unwrap();
                assert_eq!(h[0], Head { name: "time".into(), unit: "s".into() });
                assert_eq!(h[1], Head { name: "force".into(), unit: "N".into() });
            } else {
                assert_eq!(t.header, None);
                assert_eq!(t.lines, [2, 3]);
            }
        }
    }

    #[test]
    fn comments_blank_lines_crlf_bom_quotes_and_a_trailing_delimiter() {
        let text = "\u{feff}# rig 2\r\n\r\n\"time (ms)\",\"force, lateral [N]\",\r\n# mid-file note\r\n\"0\",1,\r\n1,\"2\",\r\n\r\n";
        let t = parse(text, p(), None).unwrap();
        assert_eq!(t.delimiter, Delimiter::Comma);
        let h = t.header.unwrap();
        assert_eq!(h[0], Head { name: "time".into(), unit: "ms".into() });
        assert_eq!(h[1], Head { name: "force, lateral".into(), unit: "N".into() });
        assert_eq!(t.samples, [0.0, 1.0, 1.0, 2.0]);
        assert_eq!(t.lines, [5, 6]);
    }

    #[test]
    fn one_column_without_delimiter_and_a_given_delimiter() {
        let t = parse("force\n1\n2\n3\n", p(), None).unwrap();
        assert_eq!((t.columns, t.rows()), (1, 3));
        let t = parse("1;2\n3;4\n", p(), Some(Delimiter::Semicolon)).unwrap();
        assert!(!t.detected);
        assert_eq!(t.samples, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!("tab".parse::<Delimiter>(), Ok(Delimiter::Tab));
        assert!("|".parse::<Delimiter>().unwrap_err().contains("not one of"));
    }

    fn err(text: &str) -> String {
        parse(text, p(), None).unwrap_err().to_string()
    }

    #[test]
    fn bad_cells_name_file_line_and_column() {
        assert_eq!(err("a,b\n1,2\n3,x\n"), "t.csv:3: column 2 (`b`): `x` is not a number");
        assert_eq!(err("a,b\n1,2\n3,NaN\n"), "t.csv:3: column 2 (`b`): `NaN` is NaN");
        assert_eq!(err("1,2\n3,inf\n"), "t.csv:2: column 2: `inf` is +Inf");
        assert_eq!(err("1,2\n-Infinity,4\n"), "t.csv:2: column 1: `-Infinity` is -Inf");
        assert_eq!(err("a,b\n1,2\n,4\n"), "t.csv:3: column 1 (`a`): is empty");
        assert_eq!(
            err("1,b\n1,2\n"),
            "t.csv:1: column 2: `b` is not a number (a header row, when there is one, holds only names)"
        );
        assert_eq!(
            err("a,b\n1,2\n1,2,3\n"),
            "t.csv:3: 3 cell(s) where the header has 2 (comma delimiter, detected; give another with --delimiter)"
        );
        assert_eq!(err("a,b\n\"1,2\n"), "t.csv:2: a quoted cell is not closed on this line");
    }

    #[test]
    fn a_commented_header_right_above_the_rows_is_the_header() {
        let t = parse("# written by np.savetxt\n# time [s],force [N]\n0,1\n1,2\n", p(), None).unwrap();
        assert_eq!(t.header_from_comment, Some(2));
        assert_eq!(t.header.unwrap()[1], Head { name: "force".into(), unit: "N".into() });
        // Not right above, the wrong count, or numbers: a comment stays one.
        for text in ["# time,force\n\n0,1\n", "# time,force,u\n0,1\n", "# 1,2\n0,1\n", "# a note\n0,1\n"] {
            let t = parse(text, p(), None).unwrap();
            assert_eq!((t.header, t.header_from_comment), (None, None), "{text:?}");
        }
    }

    #[test]
    fn empty_and_header_only_files_are_refused() {
        assert_eq!(err(""), "t.csv: holds no samples: no rows (only empty or # lines)");
        assert_eq!(err("\n# only a comment\n  \n"), "t.csv: holds no samples: no rows (only empty or # lines)");
        assert_eq!(err("time,force\n"), "t.csv: holds no samples: a header row and no data rows");
    }
}
