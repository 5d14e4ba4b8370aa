//! A gain sweep run as one shared sweep gives every point exactly what its
//! own run gives: the live chains of graphs/texture-live-quality.toml at
//! two gains, each chain computed once, every reported value and every
//! recorded actuation the same bits as two separate runs.

use evflow_engine::{check, read_graph, sweep_shared};
use evflow_study::graphs::{run_graph_for, run_sweep_for, Sets};

const GAINS: [f64; 2] = [0.6, 1.0];

fn point(gain: f64) -> Sets {
    Sets::new().num("gain", gain).text("record", &format!("actuations-g{gain:?}"))
}

#[test]
fn a_shared_gain_sweep_of_the_live_chains_is_the_separate_runs_bit_for_bit() {
    let graph = evflow_tests::root().join("graphs/texture-live-quality.toml");
    let points: Vec<Sets> = GAINS.iter().map(|&g| point(g)).collect();
    // What is shared: every chain up to its gain; what is copied: from the gains on.
    let parsed = read_graph(&graph).unwrap();
    let checked: Vec<_> =
        points.iter().map(|p| check(&parsed, &evflow_nodes::registry(), p.overrides()).unwrap()).collect();
    let merged = sweep_shared::merge(&checked).unwrap();
    let copied: Vec<&str> = merged.copied().collect();
    for shared in ["user", "sample", "live_synth", "ff_models", "narx_interp", "nothing_display", "nothing_es"] {
        assert!(!copied.contains(&shared), "{shared} is the same at every gain: {copied:?}");
    }
    for each in ["live_gain", "live_display", "live_es", "narx_limit", "record"] {
        assert!(copied.contains(&each), "{each} differs between gains: {copied:?}");
    }

    let (apart, together) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let seconds = Some(3.0);
    let alone: Vec<_> = points.iter().map(|p| run_graph_for(&graph, p, apart.path(), seconds).unwrap()).collect();
    let shared = run_sweep_for(&graph, &points, together.path(), seconds).unwrap();
    assert_eq!(shared.len(), GAINS.len());
    for (k, (a, s)) in alone.iter().zip(&shared).enumerate() {
        assert_eq!(a.ticks, s.ticks);
        assert_eq!(a.summaries.len(), s.summaries.len(), "gain {}", GAINS[k]);
        for ((na, sa), (ns, ss)) in a.summaries.iter().zip(&s.summaries) {
            assert_eq!(na, ns, "gain {}: the same nodes report, in the same order", GAINS[k]);
            assert_eq!(sa.values.len(), ss.values.len());
            for ((ka, va, _), (ks, vs, _)) in sa.values.iter().zip(&ss.values) {
                assert_eq!(ka, ks);
                assert_eq!(va.to_bits(), vs.to_bits(), "gain {}: {na}.{ka}: {va} vs {vs}", GAINS[k]);
            }
        }
        assert!(a.value("live_es", "E_s").is_some_and(f64::is_finite));
    }
    let mut files: Vec<_> = std::fs::read_dir(apart.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    files.sort();
    assert_eq!(files.len(), 2 * GAINS.len(), "a recording (wav + json) per gain: {files:?}");
    for f in files {
        let a = std::fs::read(apart.path().join(&f)).unwrap();
        let s = std::fs::read(together.path().join(&f)).unwrap_or_else(|e| panic!("{f:?}: {e}"));
        assert!(a == s, "{f:?} differs");
    }
}
