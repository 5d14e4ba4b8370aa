//! `evflow report stability` at CI size (issue 26, point 1): at least 60
//! cases, every node type and every shipped graph family covered, and
//! every verdict as it should be — a pass, except the findings listed in
//! [`FINDINGS`], which must still fail (fix one and this test says to
//! strike it off the list).

use evflow_study::stability::{self, graphs, Size};

/// Cases that fail today: real findings of the suite, left for the nodes'
/// owners (docs/numerics.md, "Findings"). Empty since issue 37, point 6
/// fixed the last thirteen (the analysis sinks' sums overflowing near
/// ±f64::MAX, `forward.train`'s NaN relative errors).
const FINDINGS: &[&str] = &[];

#[test]
fn the_ci_suite_covers_every_node_type_and_graph_family_and_passes_but_for_its_findings() {
    let dir = tempfile::tempdir().unwrap();
    let root = evflow_tests::root();
    let env = stability::prepare(dir.path(), &root.join("graphs"), Size::Ci).unwrap_or_else(|e| panic!("{e}"));
    let rows = stability::run(&env, "", 2, &mut |_| {});
    assert!(rows.len() >= 60, "{} cases", rows.len());
    let mut names: Vec<&str> = rows.iter().map(|r| r.case.as_str()).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), rows.len(), "case names are unique");
    for spec in evflow_nodes::all_specs() {
        assert!(rows.iter().any(|r| r.covers.contains(&spec.name)), "node type `{}` is not covered", spec.name);
    }
    for (family, _) in graphs::families(&root.join("graphs")) {
        assert!(
            rows.iter().any(|r| r.family.as_deref() == Some(family.as_str())),
            "graph family `{family}` is not covered"
        );
    }
    let mut wrong = Vec::new();
    for r in &rows {
        let finding = FINDINGS.contains(&r.case.as_str());
        if r.verdict.passed() == finding {
            wrong.push(format!(
                "{}: {}{}",
                r.case,
                r.verdict.text(),
                if finding { " — fixed? strike it off FINDINGS" } else { "" }
            ));
        }
    }
    for f in FINDINGS {
        assert!(names.contains(f), "finding `{f}` is no case of the suite");
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
