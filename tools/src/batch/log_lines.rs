//! A batch's progress as plain lines, for a stderr that is not a terminal
//! (a log file, a cluster's job log): where a terminal shows a redrawn bar,
//! a log gets `done/total what, elapsed, estimate` at most once every
//! [`EVERY`] and at least that often while the batch runs (the bar's steady
//! tick redraws it), plus the line of the last item ([`super::finish`]
//! draws it).

use indicatif::TermLike;
use std::io::{self, Write};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How often a line is written while a batch runs.
pub const EVERY: Duration = Duration::from_secs(60);

/// How often the bar is redrawn while nothing moves, so that a line is due
/// within [`EVERY`] of the last even during one long item.
pub const REDRAW: Duration = Duration::from_secs(10);

/// The template of a line: it starts with `pos/len`, which tells the last
/// item's line from the others.
pub const TEMPLATE: &str = "{pos}/{len} {what}, {elapsed} elapsed, about {eta} to go {msg}";

/// Collects what the bar draws and writes it as one line when due.
#[derive(Debug)]
pub struct LogLines<W: Write + Send + std::fmt::Debug> {
    state: Mutex<State<W>>,
}

#[derive(Debug)]
struct State<W> {
    out: W,
    line: String,
    last: Option<Instant>,
    /// The last line written, not to repeat it.
    written: String,
}

impl<W: Write + Send + std::fmt::Debug> LogLines<W> {
    /// Lines written to `out`.
    pub fn new(out: W) -> Self {
        Self { state: Mutex::new(State { out, line: String::new(), last: None, written: String::new() }) }
    }

    /// The writer, when done (for tests).
    pub fn into_inner(self) -> W {
        match self.state.into_inner() {
            Ok(s) => s.out,
            Err(poisoned) => poisoned.into_inner().out,
        }
    }
}

/// Whether a line that starts with `pos/len` has every item done.
fn is_last(line: &str) -> bool {
    let head = line.split_whitespace().next().unwrap_or("");
    match head.split_once('/') {
        Some((pos, len)) => !pos.is_empty() && pos == len,
        None => false,
    }
}

impl<W: Write + Send + std::fmt::Debug> State<W> {
    fn flush_line(&mut self, now: Instant) -> io::Result<()> {
        let line = self.line.trim().to_string();
        self.line.clear();
        if line.is_empty() || line == self.written {
            return Ok(());
        }
        let due = match self.last {
            None => true,
            Some(t) => now.duration_since(t) >= EVERY,
        };
        if due || (is_last(&line) && !is_last(&self.written)) {
            writeln!(self.out, "{line}")?;
            self.out.flush()?;
            self.last = Some(now);
            self.written = line;
        }
        Ok(())
    }
}

impl<W: Write + Send + std::fmt::Debug> TermLike for LogLines<W> {
    fn width(&self) -> u16 {
        // Wide enough that no line wraps.
        400
    }

    fn move_cursor_up(&self, _: usize) -> io::Result<()> {
        Ok(())
    }

    fn move_cursor_down(&self, _: usize) -> io::Result<()> {
        Ok(())
    }

    fn move_cursor_right(&self, _: usize) -> io::Result<()> {
        Ok(())
    }

    fn move_cursor_left(&self, _: usize) -> io::Result<()> {
        Ok(())
    }

    fn write_line(&self, s: &str) -> io::Result<()> {
        self.write_str(s)
    }

    fn write_str(&self, s: &str) -> io::Result<()> {
        if let Ok(mut st) = self.state.lock() {
            if !s.trim().is_empty() {
                st.line.push_str(s);
            }
        }
        Ok(())
    }

    fn clear_line(&self) -> io::Result<()> {
        Ok(())
    }

    fn flush(&self) -> io::Result<()> {
        match self.state.lock() {
            Ok(mut st) => st.flush_line(Instant::now()),
            Err(_) => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_line_and_the_last_are_written_the_others_once_a_minute() {
        let log = LogLines::new(Vec::<u8>::new());
        for line in ["1/4 runs, 0s", "2/4 runs, 1s", "3/4 runs, 2s", "4/4 runs, 3s", "4/4 runs, 4s"] {
            log.write_str("\r").unwrap();
            log.write_str(line).unwrap();
            log.write_str("      ").unwrap();
            log.flush().unwrap();
        }
        let out = String::from_utf8(log.into_inner()).unwrap();
        assert_eq!(out, "1/4 runs, 0s\n4/4 runs, 3s\n");
    }

    #[test]
    fn a_line_is_due_a_minute_after_the_last() {
        let mut st = State { out: Vec::<u8>::new(), line: String::new(), last: None, written: String::new() };
        let t0 = Instant::now();
        for (s, line) in [(0, "1/9 a"), (30, "2/9 a"), (61, "3/9 a"), (62, "3/9 a b"), (125, "3/9 a b c")] {
            st.line.push_str(line);
            st.flush_line(t0 + Duration::from_secs(s)).unwrap();
        }
        assert_eq!(String::from_utf8(st.out).unwrap(), "1/9 a\n3/9 a\n3/9 a b c\n");
    }

    #[test]
    fn only_a_complete_count_is_last() {
        assert!(is_last("7/7 steps, 3m"));
        assert!(!is_last("6/7 steps"));
        assert!(!is_last("/ steps"));
        assert!(!is_last("steps"));
    }
}
