//! `evflow report`: how well a method renders against ground truth, next
//! to its run time, as tables and PNG figures.

pub mod foaw;
#[cfg(feature = "synth")]
pub mod freqvel;
#[cfg(feature = "synth")]
pub mod interp;
#[cfg(feature = "synth")]
pub mod live;
#[cfg(feature = "mesh")]
pub mod mesh;
#[cfg(feature = "synth")]
pub mod narx;
pub mod precision;
#[cfg(feature = "texture")]
pub mod resample;
pub mod stability;
#[cfg(feature = "synth")]
pub mod textures;

/// Arguments of `evflow report`.
#[derive(clap::Args, Debug)]
pub struct ReportArgs {
    #[command(subcommand)]
    which: Which,
}

#[derive(clap::Subcommand, Debug)]
enum Which {
    /// Mesh-gradient rendering (dissertation chapter 4): gradient error
    /// against mesh resolution and run time; edge detection against
    /// dihedral ground truth.
    ///
    /// Example: evflow report mesh --out report
    #[cfg(feature = "mesh")]
    Mesh(mesh::Args),
    /// Velocity from IR-frame positions (§6.5.1): FOAW against finite
    /// differences and moving averages on known trajectories sampled at
    /// 40 Hz and quantized — RMS error and lag, a table and a PNG.
    ///
    /// Example: evflow report foaw --out report
    Foaw(foaw::Args),
    /// Frequency–velocity relation (§6.3, Fig. 6.6): each texture sample
    /// recorded on the simulated tribometer at several speeds, main
    /// spectral component against speed with a linear fit and R².
    ///
    /// Example: cargo run --release -p evflow -- report freqvel --out report
    #[cfg(feature = "synth")]
    Freqvel(freqvel::Args),
    /// Interpolation over the (load, velocity) grid (Fig. 5.6, 5.9, 6.8):
    /// the basic (§5.3.3) and improved (Eq. 6.4) schemes against the
    /// recording at every untrained condition, E_s beside the repeat
    /// baseline; a table and PNG spectra. The cells are the recorded
    /// forces, or (--cells narx|optimized|playback) one synthesis method's
    /// actuation played on the virtual display — interpolated in the
    /// dissertation's order and forces first (interpolate the forces, then
    /// synthesize with the nearest trained condition's model).
    ///
    /// Example: cargo run --release -p evflow -- report interp --cells optimized --out report
    #[cfg(feature = "synth")]
    Interp(interp::Args),
    /// Re-sampling for the texture chain (§6.2): error against run time
    /// of rubato's sinc, polynomial and FFT resamplers and the live
    /// kernel of `interp`, a table and a work-precision PNG.
    ///
    /// Example: cargo run --release -p evflow -- report resample --out report
    #[cfg(feature = "texture")]
    Resample(resample::Args),
    /// Virtual against real textures (Fig. 5.7/5.8, Table 5.1), on the
    /// texture study: every method (inverse NARX on binary and multilevel
    /// excitation, optimized synthesis through a forward model, fair
    /// playback) on every lab profile, played on the virtual display over
    /// the gain sweep; E_s beside the repeat baseline, the display floor and
    /// the achievable floor, Markdown tables, rows.csv and PNG spectra;
    /// `--grid` writes each method's cells for the live grids.
    ///
    /// Example: cargo run --release -p evflow -- report textures --out report
    #[cfg(feature = "synth")]
    Textures(textures::Args),
    /// Error against run time of the inverse NARX model (issue 6, point
    /// 10): several network sizes, tap delays and both trainers, each
    /// trained at one condition and scored on the texture study (as
    /// `report textures` scores every method: gain sweep, Table 5.1 rule and
    /// best gain) by the mean E_s of the textures it synthesizes; a table
    /// with the Pareto front and a PNG. A failed (setting, seed) or texture
    /// does not stop the others: it is left out, listed at the end, and
    /// the exit code is 1. `--shard K/N` runs a slice of the (setting, seed)
    /// items; `evflow merge` joins the slices (docs/scale.md).
    ///
    /// Example: cargo run --release -p evflow -- report narx --out report
    #[cfg(feature = "synth")]
    Narx(narx::Args),
    /// Live texture rendering under virtual users (docs/texture.md §9):
    /// per lab profile × texture sample × virtual user, every live chain —
    /// nothing, record-and-playback, NARX and optimized cells, forces
    /// first, the live synthesis (`synth.live`) — scored by E_s against
    /// the force the finger meets on the real sample, at Table 5.1's gain
    /// rule and its best gain, beside the display floor and the stroke's
    /// achievable floor (the actuation optimized through the display's twin
    /// knowing the user's path). Each profile's models and cells come from
    /// a model library built on it (under OUT/work). A failed step does not
    /// stop the others (exit 1). `--shard K/N` runs a slice of the items;
    /// `evflow merge` joins the slices.
    ///
    /// Example: cargo run --release -p evflow -- report live --out report-live
    #[cfg(feature = "synth")]
    Live(live::Args),
    /// Error against run time of every computation with a tolerance or a
    /// discretization (docs/numerics.md): the lab's integrators,
    /// `butterworth`, `decimate`, `resample`, `interp`'s kernel, FOAW, the
    /// mesh gradient, the forward model's memory, `synth.optimize`'s
    /// iterations on every lab profile, NARX sizes and trainers, and the
    /// live texture and mesh chains end to end, each against an exact
    /// reference (or one ≥ 10× more precise, or says why there is none):
    /// a log-log PNG each with the shipped default marked, table.md
    /// (default, its error and cost, the cheapest setting within 10 % of the
    /// best error) and rows.csv. `--size ci` runs in seconds.
    ///
    /// Example: cargo run --release -p evflow -- report precision --out report-precision
    Precision(precision::Args),
    /// Numerical stability (docs/numerics.md): every node type
    /// with each numeric parameter at its declared limits and every input
    /// at ±1e300, ±f64::MAX, subnormals, full-scale steps and impulses and
    /// a long constant run; the named stiff cases; every shipped graph
    /// family. Per case the largest |output|, the NaN/Inf count, the
    /// invariant checked and the verdict; table.md and rows.csv; exit 1
    /// when a case fails. `--size ci` is the suite CI runs.
    ///
    /// Example: cargo run --release -p evflow -- report stability --out report
    Stability(stability::Args),
}

/// `--displays`: a set of the display family (docs/simulated-lab.md §6.2).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Displays {
    /// The tuning displays, where the defaults are chosen.
    Tuning,
    /// The held-out displays, where the figures the docs quote are measured.
    HeldOut,
    /// Both.
    All,
}

#[cfg(feature = "synth")]
impl Displays {
    /// The set's profiles as `--profiles` names them (`family/NAME`, the
    /// files of graphs/lab/family/).
    fn profiles(self) -> Vec<String> {
        use evflow_nodes::lab::family::{names, Split};
        let split = match self {
            Displays::Tuning => Some(Split::Tuning),
            Displays::HeldOut => Some(Split::HeldOut),
            Displays::All => None,
        };
        names(split).into_iter().map(|n| format!("family/{n}")).collect()
    }
}

/// Writes `plot` to `path` and says so (unlabelled without a font); a plot
/// that cannot be drawn is a warning, not a failed report.
fn save_png(plot: &evflow_tools::plot::Plot, path: &std::path::Path) {
    match evflow_tools::plot::write_png(plot, path) {
        Ok(w) => println!("wrote {}{}", w.path.display(), if w.labelled { "" } else { " (no font found: unlabelled)" }),
        Err(e) => eprintln!("warning: {e}"),
    }
}

#[cfg(feature = "synth")]
/// Writes a report's Markdown `text` to `path` (through a temporary file,
/// so an interrupted run leaves no half table) and says so.
fn save_markdown(path: &std::path::Path, text: &str) -> anyhow::Result<()> {
    use anyhow::Context;
    evflow_engine::atomic_file::write_atomically(path, text)
        .with_context(|| format!("{}: cannot write", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Runs the chosen report.
pub fn main(a: ReportArgs) -> anyhow::Result<()> {
    match a.which {
        #[cfg(feature = "mesh")]
        Which::Mesh(m) => mesh::main(m),
        Which::Foaw(f) => foaw::main(f),
        #[cfg(feature = "synth")]
        Which::Freqvel(f) => freqvel::main(f),
        #[cfg(feature = "synth")]
        Which::Interp(i) => interp::main(i),
        #[cfg(feature = "texture")]
        Which::Resample(r) => resample::main(r),
        #[cfg(feature = "synth")]
        Which::Textures(t) => textures::main(t),
        #[cfg(feature = "synth")]
        Which::Narx(n) => narx::main(n),
        #[cfg(feature = "synth")]
        Which::Live(l) => live::main(l),
        Which::Precision(p) => precision::main(p),
        Which::Stability(s) => stability::main(s),
    }
}
