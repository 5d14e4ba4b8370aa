//! The live synthesis' own library: what `synth.live` renders from and
//! nothing else — the forward model of every trained condition
//! (`models/forward-TAG.json`, graphs/forward-build.toml's stepped
//! multilevel excitation) and each texture's recorded force at it
//! (`forces-SAMPLE/u-SAMPLE-TAG`, the high-passed sensor force over the
//! constant-speed stretch, repetition 1). The same files, made the same
//! way, as the model library of [`crate::library`] writes beside its
//! inverse models and cells; a live study that plays only the live
//! synthesis (a display family) builds this instead, in a fraction of the
//! time.
//!
//! Resumable like the model library: each file is made in `DIR/.partial/`
//! and moved into place when whole; a rerun skips the files that are there.

use crate::cells::{self, write_force};
use crate::graphs::run_graph;
use crate::models;
use crate::recordings::{self, Condition};
use crate::setup::{Cond, Profile};
use crate::StudyError;
use evflow_engine::batch::for_each_ordered;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::error::io;

/// What a live library covers.
#[derive(Debug, Clone)]
pub struct LivePlan {
    /// The library folder.
    pub dir: PathBuf,
    /// The folder of the shipped graphs (absolute).
    pub graphs: PathBuf,
    /// The lab profile the models and forces are made on.
    pub profile: Profile,
    /// Texture samples.
    pub samples: Vec<String>,
    /// The trained conditions.
    pub conds: Vec<Cond>,
    /// Runs at once.
    pub jobs: usize,
}

/// One file of the library to make.
#[derive(Debug, Clone)]
enum Item {
    /// The forward model of a condition.
    Forward(Cond),
    /// A texture's recorded force at a condition.
    Force(String, Cond),
}

impl Item {
    /// Where the item lives in the library (without extension for a recording).
    fn target(&self, dir: &Path) -> PathBuf {
        match self {
            Item::Forward(c) => dir.join("models").join(format!("forward-{}.json", c.tag())),
            Item::Force(s, c) => dir.join(format!("forces-{s}")).join(cells::name(s, c)),
        }
    }

    fn done(&self, dir: &Path) -> bool {
        let t = self.target(dir);
        match self {
            Item::Forward(_) => t.is_file(),
            Item::Force(..) => t.with_extension("json").is_file() && t.with_extension("wav").is_file(),
        }
    }

    fn label(&self) -> String {
        match self {
            Item::Forward(c) => format!("forward model at {}", c.label()),
            Item::Force(s, c) => format!("{s}'s force at {}", c.label()),
        }
    }
}

/// Moves `from` to `to`, making `to`'s folder.
fn move_into(from: &Path, to: &Path) -> Result<(), StudyError> {
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent).map_err(|e| io(parent, format!("cannot create: {e}")))?;
    }
    std::fs::rename(from, to).map_err(|e| io(to, format!("cannot move into the library: {e}")))
}

fn make(plan: &LivePlan, item: &Item, k: usize) -> Result<(), StudyError> {
    let partial = plan.dir.join(".partial").join(format!("item-{k}"));
    let _ = std::fs::remove_dir_all(&partial);
    match item {
        Item::Forward(c) => {
            let built = models::forward(&plan.graphs, &plan.profile, c, false, &partial)?;
            move_into(&built, &item.target(&plan.dir))?;
        }
        Item::Force(sample, c) => {
            let at = Condition { sample, mass: c.mass, speed: c.speed, passes: 1, rep: 1 };
            let rec = partial.join("recordings");
            run_graph(&plan.graphs.join("record-textures.toml"), &at.sets().and(plan.profile.sets()), &rec)?;
            let staged = write_force(&rec.join(recordings::name(sample, c, 1)), &partial.join("grid"), sample, c)?;
            let to = item.target(&plan.dir);
            // The samples first: a reader never finds a sidecar without them.
            for ext in ["wav", "json"] {
                move_into(&staged.with_extension(ext), &to.with_extension(ext))?;
            }
        }
    }
    let _ = std::fs::remove_dir_all(&partial);
    Ok(())
}

/// What a build did.
#[derive(Debug, Default)]
pub struct LiveOutcome {
    /// Files made now.
    pub built: usize,
    /// Files found and kept.
    pub skipped: usize,
    /// The items that failed, `(what, why)`.
    pub failures: Vec<(String, String)>,
}

/// Builds (or completes) the live library of `plan`.
pub fn build(plan: &LivePlan) -> Result<LiveOutcome, StudyError> {
    std::fs::create_dir_all(&plan.dir).map_err(|e| io(&plan.dir, format!("cannot create: {e}")))?;
    let mut items: Vec<Item> = plan.conds.iter().map(|c| Item::Forward(*c)).collect();
    for s in &plan.samples {
        items.extend(plan.conds.iter().map(|c| Item::Force(s.clone(), *c)));
    }
    let mut out = LiveOutcome::default();
    let todo: Vec<(usize, Item)> = items.into_iter().enumerate().filter(|(_, i)| !i.done(&plan.dir)).collect();
    out.skipped = plan.conds.len() * (1 + plan.samples.len()) - todo.len();
    let never = AtomicBool::new(false);
    for_each_ordered(
        todo.clone(),
        plan.jobs,
        &never,
        |_, (k, item)| make(plan, &item, k),
        |j, r| match r.map_err(|p| StudyError::Config(format!("panicked: {p}"))).and_then(|r| r) {
            Ok(()) => out.built += 1,
            Err(e) => out.failures.push((todo[j].1.label(), e.to_string())),
        },
    );
    let _ = std::fs::remove_dir(plan.dir.join(".partial"));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_nodes::recording::format::Recording;

    #[test]
    fn the_live_library_holds_the_forward_models_and_the_high_passed_forces() {
        let dir = tempfile::tempdir().unwrap();
        let graphs = std::fs::canonicalize(Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs")).unwrap();
        let plan = LivePlan {
            dir: dir.path().join("lib"),
            graphs,
            profile: Profile::nominal(),
            samples: vec!["plastic-sheet".into()],
            conds: vec![Cond { mass: 60.0, speed: 7.0 }],
            jobs: 2,
        };
        let out = build(&plan).unwrap();
        assert!(out.failures.is_empty(), "{:?}", out.failures);
        assert_eq!((out.built, out.skipped), (2, 0));
        assert!(plan.dir.join("models/forward-60g-7cms.json").is_file());
        let rec = Recording::open(&plan.dir.join("forces-plastic-sheet/u-plastic-sheet-60g-7cms")).unwrap();
        let f = rec.channel("u").unwrap();
        assert_eq!(rec.meta().channels[0].unit, "N");
        // High-passed: no offset of the friction (0.13 × 0.6 N) is left.
        let mean = f.iter().sum::<f64>() / f.len() as f64;
        let rms = (f.iter().map(|x| x * x).sum::<f64>() / f.len() as f64).sqrt();
        assert!(mean.abs() < 0.2 * rms, "mean {mean}, rms {rms}");
        assert!(rms > 1e-3);
        // A rerun keeps what is there.
        let again = build(&plan).unwrap();
        assert_eq!((again.built, again.skipped), (0, 2));
        assert!(!plan.dir.join(".partial").exists());
    }
}
