//! `evflow import SRC`: a lab's `.npy` or CSV file as an evflow recording.
//!
//! Parses the options, calls [`evflow_nodes::recording::import`] (which
//! reads, checks and writes) and prints what was written.

use anyhow::Result;
use evflow_nodes::recording::import::{self, Delimiter, ImportOptions};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Arguments of `evflow import`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The file to import: NAME.npy, NAME.csv, NAME.tsv or NAME.txt.
    src: PathBuf,
    /// Where to write the recording: NAME (gives NAME.wav + NAME.json), or
    /// an existing folder (or one ending in /) to write it there under
    /// SRC's name. Default: beside SRC, under its name.
    #[arg(long, short, value_name = "DEST")]
    out: Option<PathBuf>,
    /// Sample rate in Hz. Needed unless the file has a time column (`time`
    /// or `t`, in s, ms, us or ns), whose uniform steps give it.
    #[arg(long, value_name = "HZ")]
    rate: Option<f64>,
    /// Channel names, one per column of the file (a column named time or t
    /// is the time column). Default: the CSV header, else ch0, ch1, ….
    #[arg(long, value_name = "A,B,…", value_delimiter = ',')]
    channels: Option<Vec<String>>,
    /// Units, one per column of the file (may be empty: `--units ,N`).
    /// Default: the CSV header's `name [unit]`, else none.
    #[arg(long, value_name = "U1,U2,…", value_delimiter = ',', allow_hyphen_values = true)]
    units: Option<Vec<String>>,
    /// Condition: normal load in grams.
    #[arg(long = "load-g", value_name = "G")]
    load_g: Option<f64>,
    /// Condition: scanning velocity in cm/s.
    #[arg(long = "velocity-cm-s", value_name = "V")]
    velocity_cm_s: Option<f64>,
    /// Condition: the texture material (or display) recorded.
    #[arg(long, value_name = "M")]
    material: Option<String>,
    /// Condition: the display gain (1.0 = 100 Vpp through the amplifier).
    #[arg(long, value_name = "X")]
    gain: Option<f64>,
    /// A further condition entry, KEY=VALUE (a number, true/false or text);
    /// may be repeated, e.g. --condition trial=2 --condition excitation=prbs9.
    #[arg(long = "condition", value_name = "KEY=VALUE")]
    condition: Vec<String>,
    /// Text delimiter: comma, semicolon, tab or space. Default: detected.
    #[arg(long, value_name = "D")]
    delimiter: Option<Delimiter>,
    /// Keep the time column as a channel once it gave the rate.
    #[arg(long)]
    keep_time: bool,
    /// How far a time step may stray from the median step, as a fraction of
    /// it (also how far --rate and the time column may disagree).
    #[arg(long, value_name = "FRACTION", default_value_t = 0.01)]
    time_tolerance: f64,
    /// Replace an existing recording at the destination.
    #[arg(long)]
    force: bool,
}

/// Runs `evflow import`.
pub fn main(a: Args) -> Result<()> {
    let mut opts = ImportOptions {
        rate: a.rate,
        channels: a.channels,
        units: a.units,
        delimiter: a.delimiter,
        keep_time: a.keep_time,
        time_tolerance: a.time_tolerance,
        force: a.force,
        ..ImportOptions::default()
    };
    opts.condition.load_g = a.load_g;
    opts.condition.velocity_cm_s = a.velocity_cm_s;
    opts.condition.material = a.material;
    opts.condition.gain = a.gain;
    for entry in &a.condition {
        opts.add_condition(entry)?;
    }
    // Ctrl-C, SIGTERM or SIGHUP stop the write between pieces, and the
    // temporary files go with it (the flag is read before writing starts,
    // so a signal while reading stops there too).
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let imported = import::read(&a.src, &opts)?;
    let written = imported.write_until(&import::destination(&a.src, a.out.as_deref()), opts.force, &stop)?;

    let m = &imported.meta;
    println!("wrote {} + {}", written.paths.wav.display(), written.paths.json.display());
    println!("  rate       {} Hz", m.rate);
    println!("  frames     {} ({} s)", written.frames, imported.duration());
    let channels: Vec<String> = m
        .channels
        .iter()
        .map(|c| if c.unit.is_empty() { c.name.clone() } else { format!("{} [{}]", c.name, c.unit) })
        .collect();
    println!("  channels   {}", channels.join(", "));
    let c = &m.condition;
    let mut entries: Vec<String> = [("load_g", c.load_g), ("velocity_cm_s", c.velocity_cm_s)]
        .into_iter()
        .filter_map(|(k, v)| v.map(|x| format!("{k}={x}")))
        .collect();
    entries.extend(c.material.as_ref().map(|m| format!("material={m}")));
    entries.extend(c.gain.map(|x| format!("gain={x}")));
    entries.extend(c.extra.iter().map(|(k, v)| match v {
        serde_json::Value::String(s) => format!("{k}={s}"),
        v => format!("{k}={v}"),
    }));
    if !entries.is_empty() {
        println!("  condition  {}", entries.join(", "));
    }
    println!("  source     {}", m.source);
    for note in &imported.notes {
        println!("note: {note}");
    }
    Ok(())
}
