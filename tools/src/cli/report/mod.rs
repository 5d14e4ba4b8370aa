//! `evflow report`: how well a method renders against ground truth, next
//! to its run time, as tables and PNG figures.

pub mod foaw;
pub mod freqvel;
pub mod interp;
pub mod interp_cells;
pub mod interp_cells_table;
pub mod lab_recording;
pub mod mesh;
pub mod narx;
pub mod resample;
pub mod textures;
pub mod textures_table;

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
    Interp(interp::Args),
    /// Re-sampling for the texture chain (§6.2): error against run time
    /// of rubato's sinc, polynomial and FFT resamplers and the live
    /// kernel of `interp`, a table and a work-precision PNG.
    ///
    /// Example: cargo run --release -p evflow -- report resample --out report
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
    Textures(textures::Args),
    /// Error against run time of the inverse NARX model (issue 6, point
    /// 10): several network sizes, tap delays and both trainers, each
    /// trained at one condition and scored on the texture study (as
    /// `report textures` scores every method: gain sweep, Table 5.1 rule and
    /// best gain) by the mean E_s of the textures it synthesizes; a table
    /// with the Pareto front and a PNG.
    ///
    /// Example: cargo run --release -p evflow -- report narx --out report
    Narx(narx::Args),
}

/// Writes `plot` to `path` and says so (unlabelled without a font); a plot
/// that cannot be drawn is a warning, not a failed report.
fn save_png(plot: &evflow_tools::plot::Plot, path: &std::path::Path) {
    match evflow_tools::plot::write_png(plot, path) {
        Ok(w) => println!("wrote {}{}", w.path.display(), if w.labelled { "" } else { " (no font found: unlabelled)" }),
        Err(e) => eprintln!("warning: {e}"),
    }
}

/// Writes a report's Markdown `text` to `path` (through a temporary file,
/// so an interrupted run leaves no half table) and says so.
fn save_markdown(path: &std::path::Path, text: &str) -> anyhow::Result<()> {
    use anyhow::Context;
    let tmp = path.with_extension("md.tmp");
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .with_context(|| format!("{}: cannot write", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Runs the chosen report.
pub fn main(a: ReportArgs) -> anyhow::Result<()> {
    match a.which {
        Which::Mesh(m) => mesh::main(m),
        Which::Foaw(f) => foaw::main(f),
        Which::Freqvel(f) => freqvel::main(f),
        Which::Interp(i) => interp::main(i),
        Which::Resample(r) => resample::main(r),
        Which::Textures(t) => textures::main(t),
        Which::Narx(n) => narx::main(n),
    }
}
