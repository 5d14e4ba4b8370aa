//! The texture study end to end (issue 13; docs/synthesis.md): on two lab
//! profiles, the plastic sheet at one condition, every model built from
//! scratch by the shipped graphs, every method scored by the study module
//! that `evflow report textures` runs. The ordering that the report claims
//! must hold here too: the best method renders closer to the real texture
//! than the fair record-and-playback baseline, and the achievable floor —
//! found by optimizing through the display itself — is never above the
//! best method (by its definition) nor below the repeat baseline.

use evflow_study::row::Method;
use evflow_study::run::{run, StudyConfig};
use evflow_study::scope::Scope;
use evflow_study::setup::Cond;
use evflow_study::summary::{es, Basis};

#[test]
fn the_best_method_beats_fair_playback_on_two_profiles() {
    let root = evflow_tests::root();
    let graphs = root.join("graphs");
    let work = tempfile::tempdir().unwrap();
    let scope = Scope {
        profiles: vec!["nominal".into(), "stiff".into()],
        samples: vec!["plastic-sheet".into()],
        conds: vec![Cond { mass: 60.0, speed: 5.0 }],
        gains: vec![0.6, 1.0, 1.4],
        epochs: 30,
        iterations: 60,
        multilevel: false,
        floor: true,
        objective: "expected".into(),
        times: true,
    };
    let cfg =
        StudyConfig::new(scope, graphs.clone(), work.path().to_path_buf(), evflow_engine::batch::Shard::ALL).unwrap();
    let study = run(&cfg, &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(study.rows.len(), 2);
    for row in &study.rows {
        let at = |m| es(row, m, Basis::Table51Welch).unwrap();
        let (narx, opt, play) = (at(Method::NarxBinary), at(Method::Optimized), at(Method::Playback));
        for v in [narx, opt, play, row.repeat.welch, row.display_floor.welch] {
            assert!(v.is_finite() && v > 0.0, "{}: {v}", row.profile);
        }
        let best = narx.min(opt);
        assert!(best < play, "{}: best method {best} vs fair playback {play}", row.profile);
        // The optimized synthesis renders within 1.5× of the display floor on these rows.
        assert!(
            opt < 1.5 * row.display_floor.welch,
            "{}: optimized {opt} vs display floor {}",
            row.profile,
            row.display_floor.welch
        );
        let floor = row.floor().expect("the achievable floor was asked for");
        let best_gain = |m| row.method(m).unwrap().chosen.best_welch.welch;
        assert!(
            floor.welch <= best_gain(Method::Optimized) + 1e-12,
            "{}: the floor takes a better method's value",
            row.profile
        );
        assert!(floor.welch > row.repeat.welch, "{}: no rendering reaches the repeat baseline", row.profile);
    }
}
