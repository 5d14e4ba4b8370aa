//! The rendering-quality graph: under the virtual user, the improved
//! interpolation scheme (Eq. 6.4) renders the texture closer to the real
//! sample at the user's instantaneous condition than the basic one
//! (§5.3.3), with either playback mode — as `docs/texture.md` states — on a
//! grid of recorded forces and on NARX-synthesized cells played on the display.

use evflow_engine::{load_file, run_offline, Override, Plan, PlanOptions, RunOptions};

fn e_s_of(graph: &str, scheme: &str, mode: &str) -> f64 {
    metric_of(graph, "quality", scheme, mode)
}

/// E_s reported by the `metric` node `node` of `graph` with the scheme and playback mode given.
fn metric_of(graph: &str, node: &str, scheme: &str, mode: &str) -> f64 {
    let path = evflow_tests::root().join(graph);
    let overrides: Vec<Override> = [format!("scheme=\"{scheme}\""), format!("mode=\"{mode}\"")]
        .iter()
        .map(|s| Override::parse(s).unwrap())
        .collect();
    let checked = load_file(&path, &evflow_nodes::registry(), &overrides).unwrap_or_else(|e| panic!("{e}"));
    let mut plan = Plan::build(&checked, &PlanOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let report =
        run_offline(&mut plan, RunOptions { duration: None, progress: None }).unwrap_or_else(|e| panic!("{e}"));
    report.value(node, "E_s").unwrap_or_else(|| panic!("{node} reports E_s"))
}

fn e_s(scheme: &str, mode: &str) -> f64 {
    e_s_of("graphs/texture-quality.toml", scheme, mode)
}

#[test]
fn the_improved_scheme_renders_closer_to_the_real_sample_in_both_playback_modes() {
    for mode in ["time", "position"] {
        let (basic, improved) = (e_s("basic", mode), e_s("improved", mode));
        assert!(improved < basic, "{mode}: improved {improved} vs basic {basic}");
    }
}

#[test]
fn with_narx_synthesized_cells_on_the_display_the_improved_scheme_is_better_too() {
    // graphs/texture-render-quality.toml: the grid holds the actuation the
    // inverse NARX models synthesized; the display turns the interpolated
    // actuation into the force that is scored.
    for mode in ["time", "position"] {
        let g = "graphs/texture-render-quality.toml";
        let (basic, improved) = (e_s_of(g, "basic", mode), e_s_of(g, "improved", mode));
        assert!(improved < basic, "{mode}: improved {improved} vs basic {basic}");
    }
}

#[test]
fn forces_first_the_improved_scheme_is_better_too() {
    // The recorded forces interpolated, then the nearest corner's inverse
    // model (narx.grid) synthesizes the actuation played on the display.
    for mode in ["time", "position"] {
        let forces_first = |scheme| metric_of("graphs/texture-render-quality.toml", "forces_quality", scheme, mode);
        let (basic, improved) = (forces_first("basic"), forces_first("improved"));
        assert!(improved < basic, "{mode}: improved {improved} vs basic {basic}");
    }
}
