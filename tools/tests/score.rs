//! `evflow score` (docs/score.md) end to end, on short strokes and few
//! floor iterations: the score of the shipped stroke (its first 3 s, the
//! `person` user of `report live`) on the nominal lab is `report live`'s
//! row for that user and sample — the same nothing, display floor, live
//! chain over the gain sweep, target's floor and stroke's floor, bit for
//! bit (both play the same actuation on the same display with the same
//! noise under the same finger against the same real force; the score
//! reads the finger and the force from 64-bit recordings of the very
//! numbers `sim.user` and `sim.texture` give `report live`); the command
//! writes its table, JSON and figure; bad inputs are refused naming the
//! file, with nothing written.
#![cfg(feature = "synth")]

use evflow_nodes::recording::format::Recording;
use evflow_study::graphs::{run_graph_for, Sets};
use evflow_study::live::row::{Chain, LiveRow};
use evflow_study::live::run::{run, LiveConfig};
use evflow_study::live::scope::{LiveScope, User};
use evflow_study::score::{self, inputs, Display, ScoreConfig};
use evflow_study::setup::Profile;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

const SECONDS: f64 = 3.0;
const GAINS: [f64; 2] = [0.6, 1.0];
const FLOOR_ITERATIONS: usize = 3;

/// The shipped stroke's first `SECONDS` and its truth on the plastic
/// sheet (graphs/record-stroke.toml as shipped: user 1), and the live
/// chain's actuation for it (graphs/texture-live-recorded.toml as shipped).
fn stroke(dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let graphs = root().join("graphs");
    run_graph_for(&graphs.join("record-stroke.toml"), &Sets::new(), dir, Some(SECONDS)).unwrap();
    let stroke = dir.join("stroke");
    // It is the shipped stroke, cut.
    let ours = Recording::open(&stroke).unwrap();
    let shipped = Recording::open(&graphs.join("data/strokes/person")).unwrap();
    assert_eq!(ours.frames(), 120);
    // The sidecar says which virtual user it holds (issue 37, point 9).
    assert!(ours.meta().source.ends_with("virtual user of seed 1"), "{}", ours.meta().source);
    assert_eq!(ours.meta().source, shipped.meta().source);
    for c in ["ir_x", "load_cell"] {
        let (a, b) = (ours.channel(c).unwrap(), shipped.channel(c).unwrap());
        assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()), "{c} differs from the shipped stroke");
    }
    run_graph_for(&graphs.join("texture-live-recorded.toml"), &Sets::new().path("stroke", &stroke), dir, None).unwrap();
    (stroke, dir.join("actuation-plastic-sheet"), dir.join("stroke-truth"))
}

/// `report live`'s row for `person` on the plastic sheet on the nominal
/// lab, the live synthesis alone, its library the shipped one (the files
/// graphs/texture-live-recorded.toml reads).
fn report_live_row(work: &Path) -> LiveRow {
    let mut scope = LiveScope::defaults();
    scope.profiles = vec!["nominal".into()];
    scope.samples = vec!["plastic-sheet".into()];
    scope.users = vec![User::defaults().into_iter().find(|u| u.name == "person").unwrap()];
    scope.gains = GAINS.to_vec();
    scope.seconds = SECONDS;
    scope.floor_iterations = FLOOR_ITERATIONS;
    scope.chains = vec![Chain::Live];
    let graphs = root().join("graphs");
    let cfg = LiveConfig {
        scope,
        graphs: graphs.clone(),
        work: work.to_path_buf(),
        shard: evflow_engine::batch::Shard::ALL,
        jobs: 1,
    };
    let lib = cfg.library(&Profile::nominal());
    for (from, to) in [("models", "models"), ("forces-plastic-sheet", "forces-plastic-sheet")] {
        std::fs::create_dir_all(lib.join(to)).unwrap();
        for e in std::fs::read_dir(graphs.join("data").join(from)).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with("forward-") || from != "models" {
                std::fs::copy(&p, lib.join(to).join(&name)).unwrap();
            }
        }
    }
    let study = run(&cfg, &mut |_| {}).unwrap();
    assert!(study.failures.is_empty(), "{:?}", study.failures);
    assert_eq!(study.rows.len(), 1);
    study.rows.into_iter().next().unwrap()
}

#[test]
fn the_shipped_stroke_scores_what_report_live_computes_for_its_user_and_sample() {
    let dir = tempfile::tempdir().unwrap();
    let (s, a, r) = stroke(dir.path());
    let inputs = inputs::read(&s, &a, &r, None).unwrap();
    assert_eq!(inputs.material, "plastic-sheet");
    let cfg = ScoreConfig {
        display: Display::Lab(Profile::nominal()),
        work: dir.path().join("score"),
        gains: GAINS.to_vec(),
        floors: true,
        floor_iterations: FLOOR_ITERATIONS,
    };
    let ours = score::score(&inputs, &cfg, &mut |_| {}).unwrap();
    let theirs = report_live_row(&dir.path().join("live"));
    let (o, t) = (&ours.row, &theirs);
    // The same computation: equal to the last bit (the tolerance is 0).
    assert_eq!(o.nothing, t.nothing, "nothing");
    assert_eq!(o.display_floor, t.display_floor, "display floor");
    let (oc, tc) = (&o.chains[0], t.chain(Chain::Live).unwrap());
    assert_eq!(oc.sweep, tc.sweep, "the live chain over the sweep");
    assert_eq!(oc.chosen, tc.chosen);
    let (oa, ta) = (o.achievable.as_ref().unwrap(), t.achievable.as_ref().unwrap());
    assert_eq!((&oa.sweep, oa.reached, oa.objective), (&ta.sweep, ta.reached, ta.objective), "stroke's floor");
    assert_eq!(oa.sliding_only, ta.sliding_only);
    assert_eq!(oa.start, ta.start);
    let (ot, tt) = (o.target_floor.as_ref().unwrap(), t.target_floor.as_ref().unwrap());
    assert_eq!((&ot.sweep, ot.reached, ot.objective), (&tt.sweep, tt.reached, tt.objective), "target's floor");
    assert_eq!(o.floor(), t.floor());
    assert_eq!(o.target_floor(), t.target_floor());
    // What the score is made of holds together: the floors are never above
    // the chain they start from, the live chain renders closer than nothing.
    let chain = oc.chosen.best_welch.welch;
    assert!(o.floor().unwrap().welch <= chain && o.target_floor().unwrap().welch <= chain);
    assert!(ours.at_gain_1().unwrap().welch < o.nothing.welch);
    assert!(ours.spectra.floor.is_some() && ours.spectra.real.len() == 199);
}

fn evflow(args: &[&str]) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).current_dir(root()).output().expect("evflow runs");
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn the_command_writes_its_score_and_refuses_bad_input_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (s, a, _) = stroke(dir.path());
    let out = dir.path().join("out");
    let (s, a, o) = (s.to_str().unwrap(), a.to_str().unwrap(), out.to_str().unwrap());
    // On the display made of the shipped library's forward models, the real force read from STROKE-truth.
    let (ok, stdout, stderr) = evflow(&[
        "score",
        s,
        "--actuation",
        a,
        "--models",
        "graphs/data",
        "--gains",
        "0.8",
        "--floor-iterations",
        "2",
        "--out",
        o,
    ]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("forward-85g-5cms.json: off the grid"), "{stderr}");
    // Gain 1, the actuation as recorded, is played even where --gains leaves it out.
    for want in [
        "nothing (no actuation)",
        "display floor",
        "as recorded",
        "target's floor",
        "stroke's floor",
        "floors know the display exactly",
        "the chain (gain 1) / nothing",
    ] {
        assert!(stdout.contains(want), "{want} missing from:\n{stdout}");
    }
    for f in ["score.md", "score.json", "spectra.png"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let back: score::Score = serde_json::from_str(&std::fs::read_to_string(out.join("score.json")).unwrap()).unwrap();
    assert!(back.display.starts_with("forward models"), "{}", back.display);
    // Nothing on a display made of forward models is no force at all: E_s 1.
    let nothing = back.row.nothing.welch;
    assert!((nothing - 1.0).abs() < 1e-12, "{nothing}");

    // A real force at another rate: refused naming the file; nothing written.
    let bad = dir.path().join("bad");
    let rec = Recording::open(&dir.path().join("stroke-truth")).unwrap();
    let mut meta = rec.meta().clone();
    meta.rate = 500.0;
    let mut w = evflow_nodes::recording::format::RecordingWriter::create(&bad, meta).unwrap();
    let n = rec.frames();
    let frames: Vec<f64> = (0..n)
        .flat_map(|k| rec.meta().channels.iter().map(move |c| (k, c.name.clone())))
        .map(|(k, c)| rec.channel(&c).unwrap()[k])
        .collect();
    w.write_interleaved(&frames).unwrap();
    w.finish().unwrap();
    let out2 = dir.path().join("out2");
    let (ok, _, stderr) =
        evflow(&["score", s, "--actuation", a, "--real", bad.to_str().unwrap(), "--out", out2.to_str().unwrap()]);
    assert!(!ok);
    assert!(stderr.contains("bad.json") || stderr.contains("bad"), "{stderr}");
    assert!(stderr.contains("500 Hz") && stderr.contains("1000 Hz"), "{stderr}");
    assert!(!out2.exists(), "nothing is written for a refused input");
    // A display that does not exist.
    let (ok, _, stderr) = evflow(&["score", s, "--actuation", a, "--profile", "no-such-display", "--out", o]);
    assert!(!ok && stderr.contains("no-such-display"), "{stderr}");
}
