//! `evflow` — run, check and inspect evflow graph files.

mod cli;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// evflow: a dataflow signal-processing engine for electrovibration haptics.
///
/// Graph files (TOML) wire nodes — sources, filters, models, the simulated
/// lab, sinks — into chains that run offline as fast as the machine allows
/// or live at 1 kHz. See docs/graph-format.md and `evflow nodes`.
#[derive(Parser)]
#[command(name = "evflow", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a graph offline over its finite sources, as fast as possible.
    ///
    /// Prints what each sink reports (metrics, files written) next to the run
    /// time per node and in total. With a `[sweep]` table in the graph or
    /// `--sweep` options, runs every combination of the swept variables and
    /// ends with a table of the reported values (`evflow sweep` is the same
    /// command).
    ///
    /// Examples:
    ///   evflow run graphs/excitation.toml --set mass=110 --out recordings
    ///   evflow run graphs/excitation.toml --sweep mass=60,85,110 --sweep speed=3,4,5 --csv grid.csv
    #[command(visible_alias = "sweep")]
    Run(cli::run::Args),
    /// Join the outputs of the shards of a sweep (`run --shard K/N`) into
    /// what one run would have written: the files the graphs wrote, and
    /// the --csv / --json tables in sweep order. Checks that the folders
    /// are every K of N of one sweep; lists the shards' failed runs. The
    /// shards of a model library (`library build --shard`) and of the
    /// reports `report textures --shard` (textures.md and rows.csv written
    /// from every shard's rows) and `report narx --shard` (narx.md) merge
    /// alike. A shard missing, or a folder without its record (a task
    /// killed mid-run), refuses the merge, each named with the commands
    /// that rerun it; `--partial` merges the shards there are into an
    /// output marked PARTIAL.txt and exits with status 3.
    ///
    /// Example (docs/scale.md):
    ///   for k in 1 2 3; do evflow run graphs/excitation.toml --shard $k/3 --out part$k --csv part$k/grid.csv; done
    ///   evflow merge grid part1 part2 part3
    Merge(cli::merge::Args),
    /// The model library: on the simulated lab (`build`), models, recorded
    /// forces and actuation cells for every texture sample × the 3×3 grid,
    /// with an index, resumable; from a lab's own recordings
    /// (`from-recordings`), the forces and models the live chains play.
    ///
    /// Examples:
    ///   cargo run --release -p evflow -- library build --out library --jobs 2
    ///   evflow library from-recordings --excitation /lab/excitation --textures /lab/textures --out /lab/library
    #[cfg(feature = "synth")]
    Library(cli::library::Args),
    /// Validate a graph and print its plan: execution order, rates, buffer
    /// block size, and which nodes were left out and why.
    ///
    /// Then, unless --no-build, the plan of every run is built as `run`
    /// builds it — files are opened and checked, meshes loaded — but nothing
    /// is run and nothing is written.
    ///
    /// Example: evflow check graphs/excitation.toml
    Check(cli::check::Args),
    /// List node types, or describe one: ports, rates, parameters with units
    /// and limits, and a working example.
    ///
    /// Example: evflow nodes butterworth
    Nodes(cli::nodes::Args),
    /// Import a lab's .npy or CSV file as an evflow recording (WAV + JSON).
    ///
    /// Reads NAME.npy (NumPy: 1-D, or frames × channels; float or integer)
    /// or NAME.csv / .tsv / .txt (numbers in columns; an optional header row
    /// of names with units in brackets, `time [s],force [N],u`) and writes
    /// the recording NAME.wav + NAME.json beside it, or at --out. The rate is
    /// --rate, or comes from a `time` or `t` column whose steps are uniform
    /// (the column is then dropped). The condition (--load-g,
    /// --velocity-cm-s, --material, --gain, --condition KEY=VALUE) goes into
    /// the sidecar, where graphs read it. Nothing is written when anything
    /// is wrong; an existing recording is replaced only with --force.
    /// docs/rig.md says what to record and how.
    ///
    /// Examples — a CSV with a `time [s]` column, then an .npy array of two
    /// columns (u, force) sampled at 10 kHz:
    ///
    ///   evflow import prbs-85g-4cms.csv --load-g 85 --velocity-cm-s 4 --material display-a
    ///
    ///   evflow import force.npy --rate 10000 --channels u,force --units ,N --out recordings/prbs-85g-4cms
    Import(cli::import::Args),
    /// Run a graph live, in real time (1 tick per base-rate period), and
    /// record the session (inputs, outputs, parameter changes) for replay.
    ///
    /// Example: evflow live graphs/display-live.toml --duration 60
    Live(cli::live::Args),
    /// Run a graph offline over a recorded session and compare its outputs
    /// with the live ones (bit for bit with the session's own graph).
    ///
    /// Exit status with --check: 0 proven, 1 something differs (or the
    /// replay failed), 3 nothing differs but something could not be checked
    /// (a session killed before it ended).
    ///
    /// Example: evflow replay sessions/display-live-20250101-120000 --check
    Replay(cli::replay::Args),
    /// Measure how well a method renders against ground truth, next to its
    /// run time, with tables and PNG figures.
    ///
    /// Example: evflow report mesh --out report
    Report(cli::report::ReportArgs),
    /// Score the live chain's actuation for a recorded stroke: played on a
    /// display (a lab profile, or the display made of a library's forward
    /// models) under the finger's true path, E_s (Welch, 2–200 Hz) against
    /// the real force along that path, beside nothing, the display floor,
    /// the target's floor and the stroke's floor, as `report live` scores
    /// its rows; score.md, score.json and a PNG of the spectra
    /// (docs/score.md).
    ///
    /// Example, on the shipped stroke (graphs/data/strokes/person, the
    /// `person` user of `report live`): its truth and the plastic sheet's
    /// force along it, the live chain's actuation for it, its score:
    ///
    ///   evflow run graphs/record-stroke.toml --out s
    ///
    ///   evflow run graphs/texture-live-recorded.toml --out s
    ///
    ///   evflow score graphs/data/strokes/person --real s/stroke-truth --actuation s/actuation-plastic-sheet
    #[cfg(feature = "synth")]
    Score(cli::score::Args),
    /// Benchmarks with distributions and baselines (the figures of
    /// docs/benchmarks.md). Build with --release.
    ///
    /// Example: cargo run --release -p evflow -- bench mesh
    Bench(cli::bench::BenchArgs),
    /// Write the display family: lab profiles drawn from seeded, documented
    /// ranges of every constant of the virtual display, split into a tuning
    /// set and a held-out set (docs/simulated-lab.md §6.2). The shipped
    /// family is graphs/lab/family, which `report live --displays` and
    /// `report textures --displays` run on.
    ///
    /// Example: evflow family --out graphs/lab/family
    #[cfg(feature = "lab")]
    Family(cli::family::Args),
    /// Print a graph in Graphviz dot syntax (pruned nodes dashed).
    ///
    /// Example: evflow dot graphs/excitation.toml | dot -Tpng > graph.png
    Dot(cli::dot::Args),
    /// Open a recorded session in the studio (a local web page): every
    /// recording over the whole session with scrubbing, the events on the
    /// time axis, the limiter's states, the timing figures and the replay
    /// check (docs/studio.md). `evflow live --studio` shows a running one.
    ///
    /// Example: evflow studio sessions/texture-live-20250101-120000
    #[cfg(feature = "studio")]
    Studio(cli::studio::Args),
    /// Emulate a friction-display device on a pseudo-terminal: it speaks
    /// the serial protocol (docs/serial-protocol.md) with the simulated lab
    /// inside, so serial graphs run without hardware.
    ///
    /// The emulator prints the pty's path; give it to a graph's `port`. A
    /// virtual finger scans side to side (touch x, y and load at 40 Hz); the
    /// actuation the host sends drives the virtual display (the model of
    /// `sim.display`), whose friction force goes back at 1 kHz. It answers
    /// HELLO, sends heartbeats, and its watchdog ramps the output to zero
    /// when the host goes quiet for 100 ms. `--link` keeps a fixed path
    /// pointing at the pty, so a restarted emulator is found again;
    /// `--corrupt` damages frames to test the host's receiver; `--log`
    /// records what it received and rendered.
    ///
    /// Example, in two terminals:
    ///
    ///   evflow devsim --link /tmp/evflow-device
    ///
    ///   evflow live graphs/display-serial.toml --set port=/tmp/evflow-device --duration 30
    ///
    /// Example, damaging 5 % of the frames and logging for a minute:
    ///
    ///   evflow devsim --corrupt 0.05 --log devsim-log --duration 60
    #[cfg(all(feature = "serial", feature = "lab"))]
    Devsim(cli::devsim::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(a) => cli::run::main(a),
        Command::Check(a) => cli::check::main(a),
        Command::Nodes(a) => cli::nodes::main(a),
        Command::Dot(a) => cli::dot::main(a),
        #[cfg(feature = "lab")]
        Command::Family(a) => cli::family::main(a),
        #[cfg(feature = "studio")]
        Command::Studio(a) => cli::studio::main(a),
        Command::Import(a) => cli::import::main(a),
        Command::Live(a) => cli::live::main(a),
        Command::Replay(a) => cli::replay::main(a),
        Command::Merge(a) => cli::merge::main(a),
        #[cfg(feature = "synth")]
        Command::Library(a) => cli::library::main(a),
        Command::Report(a) => cli::report::main(a),
        #[cfg(feature = "synth")]
        Command::Score(a) => cli::score::main(a),
        Command::Bench(a) => cli::bench::main(a),
        #[cfg(all(feature = "serial", feature = "lab"))]
        Command::Devsim(a) => cli::devsim::main(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Whatever value reached the message, a person reads it cut.
            eprintln!("{}", evflow_engine::diag::cut_words(&format!("{e:#}"), evflow_engine::diag::MAX_WORD));
            if e.downcast_ref::<cli::replay::Unproven>().is_some() {
                ExitCode::from(cli::replay::UNPROVEN_EXIT)
            } else if e.downcast_ref::<cli::merge::Partial>().is_some() {
                ExitCode::from(cli::merge::PARTIAL_EXIT)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
