//! The house's rule on length (issue 35, point 3): no function outside
//! tests is longer than [`MAX_LINES`] lines, in engine/src, nodes/src,
//! study/src and tools/src. A long function is split into named steps
//! with one job each (a command's main: the library computes, the command
//! prints).
//!
//! The reading is textual: a function is a line that starts (after any
//! `pub`, `pub(…)`, `const`, `async`, `unsafe`) with `fn name`, and runs to
//! the line where its braces balance again (braces in string and character
//! literals and after `//` not counted); its length counts both lines. A
//! file is read up to its first `#[cfg(test)]`; files named `*tests.rs`
//! and files under a `tests` folder are tests. It is checked on small
//! made-up sources below, so that it can fail.

use std::path::{Path, PathBuf};

/// The longest a function outside tests may be, in lines.
const MAX_LINES: usize = 100;

/// The source folders the rule holds in.
const ROOTS: &[&str] = &["engine/src", "nodes/src", "study/src", "tools/src"];

/// If `line` starts a function (`pub(crate) unsafe fn name…`), its name.
fn fn_name(line: &str) -> Option<&str> {
    /// `rest` after `word` and at least one whitespace character.
    fn after<'a>(rest: &'a str, word: &str) -> Option<&'a str> {
        let r = rest.strip_prefix(word)?;
        let t = r.trim_start();
        (t.len() < r.len()).then_some(t)
    }
    let mut rest = line.trim_start();
    if let Some(r) = rest.strip_prefix("pub") {
        let r = match r.strip_prefix('(') {
            Some(inner) => &inner[inner.find(')')? + 1..],
            None => r,
        };
        let t = r.trim_start();
        if t.len() < r.len() {
            rest = t;
        }
    }
    for word in ["const", "async", "unsafe"] {
        if let Some(r) = after(rest, word) {
            rest = r;
        }
    }
    let r = after(rest, "fn")?;
    let end = r.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(r.len());
    (end > 0).then_some(&r[..end])
}

/// `s` with each closed literal between `quote`s emptied (its escapes
/// skipped): `"a{b"` → `""`, `'{'` → `''`. With `one_char`, a literal
/// holds exactly one character or escape (character literals; a lifetime
/// `'a` is left alone).
fn empty_literals(s: &str, quote: char, one_char: bool) -> String {
    let c: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len());
    let mut p = 0;
    while p < c.len() {
        if c[p] == quote {
            if let Some(end) = literal_end(&c, p, quote, one_char) {
                out.push(quote);
                out.push(quote);
                p = end;
                continue;
            }
        }
        out.push(c[p]);
        p += 1;
    }
    out
}

/// Where the literal opened by the `quote` at `p` ends (one past its
/// closing quote), if it is closed on this line.
fn literal_end(c: &[char], p: usize, quote: char, one_char: bool) -> Option<usize> {
    let mut q = p + 1;
    let mut items = 0;
    loop {
        let ch = *c.get(q)?;
        if ch == quote {
            return (!one_char || items == 1).then_some(q + 1);
        }
        if one_char && items == 1 {
            return None;
        }
        q += if ch == '\\' {
            c.get(q + 1).filter(|n| **n != '\n')?;
            2
        } else {
            1
        };
        items += 1;
    }
}

/// The code of a line whose braces count: literals emptied, a `//` comment cut.
fn code(line: &str) -> String {
    let s = empty_literals(line, '"', false);
    let s = match s.find("//") {
        Some(k) => s[..k].to_string(),
        None => s,
    };
    empty_literals(&s, '\'', true)
}

/// `(line, name, length)` of every function of `text` outside its tests
/// longer than `max` lines.
fn long_functions(text: &str, max: usize) -> Vec<(usize, String, usize)> {
    let lines: Vec<&str> = text.split('\n').collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let Some(name) = fn_name(line) else {
            i += 1;
            continue;
        };
        let (mut depth, mut started, mut j) = (0i64, false, i);
        while j < lines.len() {
            let s = code(lines[j]);
            depth += s.matches('{').count() as i64 - s.matches('}').count() as i64;
            started |= s.contains('{');
            if (started && depth <= 0) || (!started && s.trim_end().ends_with(';')) {
                break;
            }
            j += 1;
        }
        let n = j - i + 1;
        if n > max {
            found.push((i + 1, name.to_string(), n));
        }
        i = if started { j + 1 } else { i + 1 };
    }
    found
}

/// The Rust files under `dir` that are not tests.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("a readable folder").path())
        .collect();
    entries.sort();
    for p in entries {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if p.is_dir() {
            if name != "tests" {
                sources(&p, out);
            }
        } else if name.ends_with(".rs") && !name.ends_with("tests.rs") {
            out.push(p);
        }
    }
}

#[test]
fn no_function_outside_tests_is_longer_than_the_rule() {
    let root = evflow_tests::root();
    let mut files = Vec::new();
    for r in ROOTS {
        sources(&root.join(r), &mut files);
    }
    assert!(files.len() > 200, "{} source files: is the root right?", files.len());
    let mut long = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        for (line, name, n) in long_functions(&text, MAX_LINES) {
            let shown = f.strip_prefix(&root).unwrap_or(f).display();
            long.push(format!("{shown}:{line} `{name}`: {n} lines"));
        }
    }
    assert!(
        long.is_empty(),
        "functions longer than {MAX_LINES} lines (split each into named steps with one job each):\n{}",
        long.join("\n")
    );
}

/// A function of `body_lines` lines between its `fn` line and its `}`.
fn function(head: &str, body_lines: usize) -> String {
    let mut s = format!("{head} {{\n");
    for k in 0..body_lines {
        s += &format!("    let x{k} = \"{{\"; // {{\n");
    }
    s + "}\n"
}

#[test]
fn the_reading_counts_a_function_from_its_fn_line_to_its_closing_brace() {
    // 1 + 99 + 1 = 101 lines: too long; 100: not.
    let long = function("pub(crate) unsafe fn long(a: u8) -> u8", 99);
    assert_eq!(long_functions(&long, 100), [(1, "long".to_string(), 101)]);
    assert!(long_functions(&function("fn fits()", 98), 100).is_empty());
    // Braces in strings, character literals and comments do not count;
    // a lifetime is no character literal.
    let tricky =
        "fn f<'a>(x: &'a str) -> char {\n    let _ = \"}}\\\"}\";\n    let c = '}'; // }\n    '{'\n}\nfn g() {\n}\n";
    assert_eq!(long_functions(tricky, 4), [(1, "f".to_string(), 5)]);
    // A declaration without a body ends at its `;`.
    let decl = format!("trait T {{\n    fn a(&self);\n}}\n{}", function("fn b()", 3));
    assert_eq!(long_functions(&decl, 4), [(4, "b".to_string(), 5)]);
    // Tests are not held to it.
    let tested = format!("fn short() {{}}\n#[cfg(test)]\nmod tests {{\n{}}}\n", function("    fn long_test()", 200));
    assert!(long_functions(&tested, 100).is_empty());
    assert_eq!(fn_name("    pub(super) const fn k() {}"), Some("k"));
    assert_eq!(fn_name("    pub fnord() {}"), None);
    assert_eq!(fn_name("let f = fn_ptr;"), None);
}
