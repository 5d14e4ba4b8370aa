//! `evflow report interp`: cross-validation of the interpolation schemes
//! (dissertation Fig. 5.6, 5.9, 6.8) on the simulated lab. Each sample is
//! recorded over a grid; the corners (or the rows) are the trained cells;
//! every untrained condition is interpolated from them by the basic scheme
//! (§5.3.3) and the improved one (Eq. 6.4) and compared with the real
//! recording at that condition by E_s (Eq. 5.2), beside the repeat baseline
//! (a second recording of the same condition). With `--cells recorded` (the
//! default) the cells are the recorded forces themselves (record-and-
//! playback, §6.5.2), compared directly: this isolates the interpolation
//! from the models and the display. `--cells narx|optimized|playback` runs
//! the whole chain instead, on the texture study: the cells are one
//! method's actuation, played on the virtual display, in the dissertation's
//! order and forces first ([`cells`]).

pub mod cells;
pub mod cells_table;
pub mod recorded;

pub use recorded::main;

use evflow_tools::batch::JobsArg;
use std::path::PathBuf;

/// What the grid cells are.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cells {
    /// The recorded forces at the trained conditions, interpolated and
    /// compared with the recording directly (no models, no display).
    Recorded,
    /// The actuation signals inverse NARX models synthesize at the trained
    /// conditions (each at its Table 5.1 gain), interpolated and played on
    /// the virtual display at the untrained condition
    /// (graphs/texture-cross-validation.toml); forces first with the
    /// nearest trained condition's inverse model.
    Narx,
    /// The optimized synthesis' actuation (through a forward model of each
    /// trained condition, `report textures`' best method), interpolated and
    /// played the same way; forces first optimizes offline through the
    /// nearest trained condition's forward model.
    Optimized,
    /// Record-and-playback's cells (the forces normalized per recording),
    /// interpolated and played the same way.
    Playback,
}

/// Arguments of `evflow report interp`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the table and the PNG figures (and, with synthesized
    /// cells, the models and the grids: `grids/METHOD-SAMPLE`,
    /// `grids/playback-SAMPLE`, `grids/forces-SAMPLE`).
    #[arg(long, default_value = ".")]
    pub(super) out: PathBuf,
    /// Texture samples (default: all seven; the rippled paper uses the grid of Fig. 6.8; `generated-<seed>` for a generated one).
    #[arg(long, value_delimiter = ',')]
    pub(super) samples: Vec<String>,
    /// What the grid cells are: the recorded forces, or one synthesis
    /// method's actuation played on the virtual display (narx, optimized,
    /// playback).
    #[arg(long, value_enum, default_value_t = Cells::Recorded)]
    pub(super) cells: Cells,
    /// Tribometer passes per recording (--cells recorded; the synthesized
    /// cells record one pass, as graphs/synthesize.toml plays).
    #[arg(long, default_value_t = 4)]
    pub(super) passes: u32,
    /// Band of E_s, Hz.
    #[arg(long, value_delimiter = ',', default_value = "2,200")]
    pub(super) band: Vec<f64>,
    /// The recording graph (--cells recorded).
    #[arg(long, default_value = "graphs/record-textures.toml")]
    pub(super) graph: PathBuf,
    /// Gains of the sweep that chooses each cell's gain (synthesized cells, §5.3.2).
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.8,1.0,1.2,1.4")]
    pub(super) gains: Vec<f64>,
    /// Levenberg–Marquardt epochs at most per inverse model (synthesized cells).
    #[arg(long, default_value_t = 200)]
    pub(super) epochs: u32,
    /// Iterations at most of the optimized synthesis (synthesized cells).
    #[arg(long, default_value_t = 100)]
    pub(super) iterations: usize,
    /// Use the models in this folder (narx-MASSg-SPEEDcms.json and
    /// forward-MASSg-SPEEDcms.json) instead of building them (synthesized cells).
    #[arg(long)]
    pub(super) models: Option<PathBuf>,
    /// The folder of the shipped graphs (synthesized cells).
    #[arg(long, default_value = "graphs")]
    pub(super) graphs: PathBuf,
    /// The lab profile the synthesized cells are recorded, trained and
    /// played on: `nominal`, a name of graphs/lab/*.toml, or a profile file.
    #[arg(long, default_value = "nominal")]
    pub(super) profile: String,
    /// Samples at once (--cells recorded; default: the cores available).
    #[command(flatten)]
    pub(super) jobs: JobsArg,
}
