//! The suite's rows as a Markdown table, a CSV file and a summary line.

use super::{Group, Row};

/// `1.2346e300`, `0`, or `—` for nothing watched.
fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.4e}")
    }
}

/// One Markdown table cell: no `|`, no line breaks.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// The Markdown table of `rows`: case, what is extreme, largest |output|,
/// NaN/Inf count, invariant, verdict, detail.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| case | group | what is extreme | max \\|out\\| | NaN/Inf | invariant | verdict | detail |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            cell(&r.case),
            r.group.name(),
            cell(&r.extreme),
            num(r.max_abs),
            r.non_finite,
            cell(&r.invariant),
            cell(&r.verdict.text()),
            cell(&r.detail),
        );
    }
    s
}

/// A CSV field, quoted when it needs to be.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The rows as CSV (one header line), with the node types and family each
/// case covers and its seconds.
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from("case,group,covers,family,extreme,max_abs,non_finite,invariant,verdict,detail,seconds\n");
    for r in rows {
        let fields = [
            field(&r.case),
            r.group.name().into(),
            field(&r.covers.join(" ")),
            field(r.family.as_deref().unwrap_or("")),
            field(&r.extreme),
            format!("{:e}", r.max_abs),
            r.non_finite.to_string(),
            field(&r.invariant),
            field(&r.verdict.text()),
            field(&r.detail),
            format!("{:.3}", r.seconds),
        ];
        s += &fields.join(",");
        s.push('\n');
    }
    s
}

/// `stability: 250 cases (190 generated, 14 stiff, 11 graph families), 250 pass, 0 fail`.
pub fn summary(rows: &[Row]) -> String {
    let count = |g: Group| rows.iter().filter(|r| r.group == g).count();
    let failed = super::failures(rows);
    format!(
        "stability: {} cases ({} generated, {} stiff, {} graph families), {} pass, {} fail",
        rows.len(),
        count(Group::Generated),
        count(Group::Stiff),
        count(Group::Graph),
        rows.len() - failed,
        failed
    )
}

#[cfg(test)]
mod tests {
    use super::super::{Row, Verdict};
    use super::*;

    fn row(verdict: Verdict) -> Row {
        Row {
            case: "gain · steps ±1e300".into(),
            group: Group::Generated,
            covers: vec!["gain"],
            family: None,
            extreme: "a, b".into(),
            max_abs: 1e300,
            non_finite: 0,
            invariant: "bound |out| ≤ 1".into(),
            verdict,
            detail: "x | y".into(),
            seconds: 0.5,
        }
    }

    #[test]
    fn tables_quote_and_count() {
        let rows = [row(Verdict::Pass), row(Verdict::Fail("too big".into()))];
        let md = markdown(&rows);
        assert!(md.contains("| 1.0000e300 |") && md.contains("x \\| y") && md.contains("FAIL: too big"), "{md}");
        let c = csv(&rows);
        assert!(c.lines().nth(1).unwrap().contains("\"a, b\""), "{c}");
        assert_eq!(summary(&rows), "stability: 2 cases (2 generated, 0 stiff, 0 graph families), 1 pass, 1 fail");
    }
}
