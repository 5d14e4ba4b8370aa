//! Diagnostics: errors that name the file, the line and the node.

use std::fmt;
use std::path::PathBuf;

/// A place in a graph file (1-based line and column).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Loc {
    /// Line, from 1 (0 when unknown, e.g. a command-line override).
    pub line: usize,
    /// Column, from 1.
    pub col: usize,
}

/// One problem found in a graph file.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnostic {
    /// The file (or `<command line>`).
    pub file: PathBuf,
    /// Where in it.
    pub loc: Loc,
    /// The node concerned, if any.
    pub node: Option<String>,
    /// What is wrong.
    pub message: String,
    /// What would fix it (e.g. the closest valid name).
    pub help: Option<String>,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if self.loc.line > 0 {
            write!(f, ":{}:{}", self.loc.line, self.loc.col)?;
        }
        write!(f, ": ")?;
        if let Some(n) = &self.node {
            write!(f, "node `{}`: ", cut_words(n, MAX_WORD))?;
        }
        write!(f, "{}", cut_words(&self.message, MAX_WORD))?;
        if let Some(h) = &self.help {
            write!(f, "\n  help: {}", cut_words(h, MAX_WORD))?;
        }
        Ok(())
    }
}

/// Every problem found in a graph file; loading stops before anything is built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "error: {d}")?;
        }
        if self.0.len() > 1 {
            write!(f, "\n{} errors", self.0.len())?;
        }
        Ok(())
    }
}

/// Maps byte offsets of a text to line and column.
pub struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    /// Indexes `text`.
    pub fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        Self { starts }
    }
    /// The location of byte offset `at`.
    pub fn loc(&self, text: &str, at: usize) -> Loc {
        let at = at.min(text.len());
        let line = match self.starts.binary_search(&at) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.starts[line];
        let col = text.get(start..at).map(|s| s.chars().count()).unwrap_or(0) + 1;
        Loc { line: line + 1, col }
    }
}

/// `s` for a message: whole when it is at most `max` characters, else its
/// first `max` and how long it was (a bad value of a megabyte must not fill
/// a terminal).
pub fn cut(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        s.to_string()
    } else {
        let head: String = s.chars().take(max).collect();
        format!("{head}… ({n} characters)")
    }
}

/// The longest run of characters without a space that a message prints
/// whole (a long path still fits; a megabyte of value does not).
pub const MAX_WORD: usize = 600;

/// `message` with every run of more than `max` characters without white
/// space shortened to its first and last `max / 3` characters and how long
/// it was: the guard every error message passes on its way to a person
/// (the CLI's error printer, [`Diagnostic`]'s display), whatever value
/// reached it.
pub fn cut_words(message: &str, max: usize) -> std::borrow::Cow<'_, str> {
    let long = |w: &str| w.chars().count() > max;
    if !message.split(char::is_whitespace).any(long) {
        return std::borrow::Cow::Borrowed(message);
    }
    let keep = (max / 3).max(1);
    let mut out = String::with_capacity(message.len().min(64 * 1024));
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        let n = word.chars().count();
        if n > max {
            let head: String = word.chars().take(keep).collect();
            let tail: String = word.chars().skip(n - keep).collect();
            out.push_str(&format!("{head}…{tail} ({n} characters)"));
        } else {
            out.push_str(word);
        }
        word.clear();
    };
    for c in message.chars() {
        if c.is_whitespace() {
            flush(&mut word, &mut out);
            out.push(c);
        } else {
            word.push(c);
        }
    }
    flush(&mut word, &mut out);
    std::borrow::Cow::Owned(out)
}

#[cfg(test)]
mod cut_tests {
    use super::{cut, cut_words};

    #[test]
    fn long_words_are_cut_in_the_middle_and_the_rest_kept() {
        assert_eq!(cut_words("a short message", 7), "a short message");
        let m = format!("bad value \"{}\" at line 3\n  help: {}", "x".repeat(1_000_000), "y".repeat(10));
        let c = cut_words(&m, 30);
        let x9 = "x".repeat(9);
        assert_eq!(c, format!("bad value \"{x9}…{x9}\" (1000002 characters) at line 3\n  help: yyyyyyyyyy"));
        assert!(c.len() < 200, "{c}");
    }

    #[test]
    fn long_values_are_cut_and_say_how_long_they_were() {
        assert_eq!(cut("short", 10), "short");
        let long = "é".repeat(1_000_000);
        let c = cut(&long, 8);
        assert_eq!(c, format!("{}… (1000000 characters)", "é".repeat(8)));
    }
}
