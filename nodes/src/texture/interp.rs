//! `interp`: the interpolated actuation signal for the user's load and
//! velocity, recomputed at the update rate and sent to `playback` as frames.

use super::align::{self, Shift};
use super::frame::{at, CARRIER, HEADER, IMPROVED, MAGIC};
use super::grid::{Expect, Grid, GridError, GridSource};
use super::kernel::SincKernel;
use super::scheme::{Geometry, Mix, Scheme};
use crate::rate::clock::Clock;
use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::spec::Scene;
use evflow_engine::typed_params::{Choice, Flag, Float, Floats, Int, Text, Words};
use evflow_engine::{
    BuildContext, Change, Io, Node, NodeError, NodeSpec, Params, PortSpec, PrepareContext, RateSpec, Refused, Role,
    Summary,
};
use std::path::PathBuf;

/// `texture`: which of `textures` plays, changeable live.
const TEXTURE: Int =
    Int::new("texture", 0, 255, 0, "1", "index into `textures` of the texture played (0: the first)").live();

/// Declaration of `interp`.
pub static SPEC: NodeSpec = NodeSpec::new(
    "interp",
    "texture",
    Role::Filter,
    "Interpolates an actuation signal over the (load, velocity) grid (§5.3.3 basic, Eq. 6.4 improved) at the update rate.",
    build,
)
.doc(
    "Loads a grid of actuation signals U_ij — recordings whose sidecars set `condition.load_g` = m_i and \
`condition.velocity_cm_s` = v_j (`docs/recording-format.md`) — and, at every update (10 Hz in the user \
study, §6.5.1), computes the signal for the user's current load m_u and speed |v_u| from the four \
neighbouring cells:\n\n\
* `scheme = \"improved\"` (dissertation Eq. 6.4): weighted average over mass (Eq. 6.1), re-sampling of \
each velocity column by v_j/v_u (𝓡𝓢, §6.2–6.3: its main component moves to the frequency of v_u), \
weighted average over velocity;\n\
* `scheme = \"basic\"` (§5.3.3): the bilinear weighted average without re-sampling.\n\n\
Loads and velocities outside the grid are clamped to its extremes (§6.4); with `load_beyond = \
\"proportional\"` — for a grid of *forces* (friction is proportional to the normal load) — a load \
outside the grid takes the nearest load's table scaled by m_u/m_edge instead. A grid with one load or one \
velocity drops that step; a speed of 0 is clamped to v_min (no division by zero; `playback` makes rest \
silent).\n\n\
**Ports.** `load` (g) and `velocity` (cm/s, sign ignored) at any one rate (e.g. 40 Hz IR-frame rate or \
1 kHz); `table` at `stream_rate`: one frame of F = stream_rate/update_rate samples per update, holding a \
10-sample header and the table (layout in `nodes/src/texture/frame.rs`, `docs/texture.md`). Connect it \
to `playback.table`. The condition is latched at the first sample of each frame (the latest input at or \
before it), so a table is heard one update period after its condition was read.\n\n\
**Real time.** The table is computed sample by sample as the frame is sent, stream_rate/base-rate \
samples per tick (20 per 1 ms tick by default): the 10 Hz update costs the same small amount every tick \
instead of one large burst. Each sample costs two kernel evaluations of 2·W/c taps (W = `half_width`, c \
the anti-alias cutoff, smaller for larger velocity steps); nothing is allocated after `prepare`.\n\n\
**Textures.** `textures` lists several grids (one folder per texture) instead of `folder`; all are \
loaded when the node is built, and the live parameter `texture` (0-based index into the list) picks the \
one played: a change takes effect at the next frame (the next 10 Hz update), and `playback` crossfades \
into it like any new table — no click. Change it live with `interp.texture=1` (or a graph variable \
bound to it, `docs/live.md`).\n\n\
**Grid.** `folder` (every recording in it) or `paths`; `material` filters; `channel` picks the channel \
(default: the recording's only one). Only the cells that `load_range` × `velocity_range` can reach are \
loaded (the rest are never opened). A reachable cell without a recording, two recordings for one cell, \
a cell without a condition, or cells at different rates is an error at load naming the file or cell.\n\n\
**Alignment.** The schemes take every recording to start at the same place on the texture, as \
tribometer passes do. Cells cut to their constant-speed stretch, or recorded by a lab from where it \
started, do not: averaged, misaligned cells cancel part of a periodic texture's harmonics and smear a \
random one's, so the table holds less texture than any cell. `align` = S > 0 compares each cell with the \
first (lowest load and velocity) in position and trims its start so that every cell begins at the same \
place: the normalized cross-correlation of the two, read at the first cell's spatial step, is maximized \
over shifts up to S cm (`nodes/src/texture/align.rs`; the summary lists each cell's shift). The chains \
that render recorded forces set 1 cm.\n\n\
**Loop.** Every table covers the same stretch of texture, from a margin x₀ to x₀ + L: L = `loop` cm, or \
by default the longest the recordings allow (at most `stream_rate/update_rate − 10 − overlap` samples at \
v_min); a loop of a whole number of texture periods has no seam at all: `period` (the texture's main \
wavelength, e.g. 1/slope of `evflow report freqvel`) rounds the loop down to a whole number of it. At a \
seam that is not whole the main component jumps in phase, which a 1 Hz-bin spectrum (E_s, Eq. 5.2) sees as \
a lower, split peak. Each table holds `overlap` ms more, which `playback` crossfades into the loop's \
start so the loop has no seam click.\n\n\
**Carrier.** Cells whose sidecars say `condition.carrier = \"nyquist\"` (the optimized synthesis' \
cells, written by the texture study) ride a Nyquist-rate carrier, u[n] = (−1)ⁿ·a[n], with a slowly varying \
envelope a. Re-sampling removes everything near the Nyquist rate, so such cells are demodulated when loaded \
and their envelopes interpolated; the frame says so (flag 2) and `playback` multiplies the envelope by \
(−1)ᵐ at its own output sample m. `carrier = \"nyquist\"` or `\"none\"` overrides the sidecars; the cells of \
one grid must agree.\n\n\
**Forces.** A chain that renders the texture's *force* (`synth.live`: graphs/texture-live.toml) sets \
`expect = \"force\"`: every reachable cell must then hold newtons (its channel's unit `N`) with no offset \
the 10 Hz high-pass of §5.1.1 removes — the rms of its 250 ms means at most 0.4 times the rms of \
its variation around them (the lab's high-passed forces: ≤ 0.08; the raw force with its friction and \
sensor bias: ≥ 2.3). An actuation grid (`narx-SAMPLE`, unit `1`) or the force as the sensor measured it \
is refused at load, naming the cell and the command that makes a proper `forces-SAMPLE` folder \
(`evflow library from-recordings`, docs/rig.md), instead of playing a saturated carrier.\n\n\
**Checked against:** the sine examples of §6.1–6.2 (10 and 20 Hz → 15 Hz: one full-power peak; basic: \
two half-amplitude peaks; 19 Hz with weights 0.1/0.9 and 12 Hz with 0.8/0.2), clamping, single-row and \
single-column grids, a velocity ratio of 10, missing and duplicate cells, envelopes on a carrier \
(`nodes/tests/texture_*.rs`).",
)
.ports(PORTS)
.params(&[
    FOLDER.spec(),
    PATHS.spec(),
    TEXTURES.spec(),
    TEXTURE.spec(),
    MATERIAL.spec(),
    CHANNEL.spec(),
    SCHEME.spec(),
    LOAD_RANGE.spec(),
    VELOCITY_RANGE.spec(),
    UPDATE_RATE.spec(),
    STREAM_RATE.spec(),
    LOOP.spec(),
    PERIOD.spec(),
    OVERLAP.spec(),
    HALF_WIDTH.spec(),
    APPLY_GAIN.spec(),
    LOAD_BEYOND.spec(),
    CARRIER_MODE.spec(),
    EXPECT.spec(),
    ALIGN.spec(),
])
.scene(Scene::TextureGrid)
.example("folder = \"recordings/grid\"\nscheme = \"improved\"\nupdate_rate = 10.0\nstream_rate = 20000.0");

/// The ports: the user's load and velocity in, table frames out.
const PORTS: &[PortSpec] = &[
    PortSpec::input("load", "g", "user's normal load m_u").view(),
    PortSpec::input("velocity", "cm/s", "user's scanning velocity v_u (its magnitude is used)").view(),
    PortSpec::output("table", "frame", "table frames for `playback` (header + U_uu)")
        .at(RateSpec::Param(STREAM_RATE.name())),
];
/// `load`: the user's normal load.
const LOAD: InPort = InPort::named(PORTS, "load");
/// `velocity`: the user's scanning velocity.
const VELOCITY: InPort = InPort::named(PORTS, "velocity");
/// `table`: the table frames.
const TABLE: OutPort = OutPort::named(PORTS, "table");

/// Outside the grid's loads (`load_beyond`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LoadBeyond {
    /// The nearest load's table (§6.4).
    Clamp,
    /// The nearest load's table scaled by m_u/m_edge (a grid of forces).
    Proportional,
}

/// Whether the cells ride a Nyquist-rate carrier (`carrier`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum CarrierMode {
    /// As each grid's sidecars say.
    Auto,
    /// They do.
    Nyquist,
    /// They do not.
    None,
}

/// `folder`: a folder of grid recordings.
const FOLDER: Text =
    Text::new("folder", "", "folder of grid recordings (relative to the graph file); or use `paths` or `textures`");
/// `paths`: grid recordings, one per cell.
const PATHS: Words = Words::new("paths", "grid recordings, one per cell (instead of `folder`)");
/// `textures`: folders of grid recordings, one per texture.
const TEXTURES: Words =
    Words::new("textures", "folders of grid recordings, one per texture (instead of `folder`); `texture` picks one");
/// `material`: the recordings' material to use.
const MATERIAL: Text = Text::new("material", "", "use only recordings of this condition.material (empty: all)");
/// `channel`: the channel holding U_ij.
const CHANNEL: Text = Text::new("channel", "", "channel holding U_ij (empty: the recording's only channel)");
/// `scheme`: Eq. 6.4 or §5.3.3.
const SCHEME: Choice<Scheme> = Choice::new(
    "scheme",
    &["improved", "basic"],
    &[Scheme::Improved, Scheme::Basic],
    "improved",
    "Eq. 6.4 two-part scheme or §5.3.3 basic average",
);
/// `load_range`: the loads a session can reach.
const LOAD_RANGE: Floats =
    Floats::new("load_range", 0.0, 1e6, "g", "[lo, hi] loads a session can reach (empty: whole grid)");
/// `velocity_range`: the velocities a session can reach.
const VELOCITY_RANGE: Floats =
    Floats::new("velocity_range", 0.0, 1e6, "cm/s", "[lo, hi] velocities a session can reach (empty: whole grid)");
/// `update_rate`: table updates per second.
const UPDATE_RATE: Float =
    Float::new("update_rate", 0.01, 1000.0, 10.0, "Hz", "table updates per second (§6.5.1: 10 Hz)");
/// `stream_rate`: the rate of the `table` port.
const STREAM_RATE: Float = Float::new(
    "stream_rate",
    1.0,
    1e7,
    20_000.0,
    "Hz",
    "rate of the `table` port; frame length = stream_rate/update_rate",
);
/// `loop`: the length of texture each table covers.
const LOOP: Float = Float::new(
    "loop",
    0.0,
    1e4,
    0.0,
    "cm",
    "length of texture each table covers (0: the longest the recordings allow)",
);
/// `align`: the largest shift searched when aligning the cells in position.
const ALIGN: Float = Float::new(
    "align",
    0.0,
    100.0,
    0.0,
    "cm",
    "align the cells in position by cross-correlation, searching shifts up to this far (0: take every recording to start at the same place)",
);
/// `period`: the spatial period the loop is a whole number of.
const PERIOD: Float = Float::new(
    "period",
    0.0,
    1e3,
    0.0,
    "cm",
    "round the loop down to a whole number of this spatial period (0: off; with `textures`, the same for each)",
);
/// `overlap`: the seam overlap.
const OVERLAP: Float = Float::new("overlap", 0.0, 1000.0, 10.0, "ms", "seam overlap read past the loop's end");
/// `half_width`: the re-sampling kernel's half-width W.
const HALF_WIDTH: Int = Int::new("half_width", 2, 64, 16, "1", "re-sampling kernel half-width W (zero crossings)");
/// `apply_gain`: multiply each cell by its gain.
const APPLY_GAIN: Flag = Flag::new("apply_gain", false, "multiply each cell by its condition.gain (Table 5.1)");
/// `load_beyond`: what a load outside the grid gets.
const LOAD_BEYOND: Choice<LoadBeyond> = Choice::new(
    "load_beyond",
    &["clamp", "proportional"],
    &[LoadBeyond::Clamp, LoadBeyond::Proportional],
    "clamp",
    "outside the grid's loads: the nearest load's table (clamp, §6.4), or it scaled by m_u/m_edge (proportional: a grid of forces)",
);
/// `carrier`: whether the cells ride a Nyquist-rate carrier.
const CARRIER_MODE: Choice<CarrierMode> = Choice::new(
    "carrier",
    &["auto", "nyquist", "none"],
    &[CarrierMode::Auto, CarrierMode::Nyquist, CarrierMode::None],
    "auto",
    "cells riding a Nyquist-rate carrier are interpolated as envelopes (auto: as their condition.carrier says)",
);

/// `expect`: what the cells must be.
const EXPECT: Choice<Expect> = Choice::new(
    "expect",
    &["any", "force"],
    &[Expect::Any, Expect::Force],
    "any",
    "what the cells hold: any (unchecked) | force (a chain rendering forces: each cell in N and with no offset the 10 Hz high-pass removes, else refused naming the fix)",
);

/// One texture's grid and the geometry of its tables.
struct Texture {
    /// The cells; a carrier's cells hold their envelopes (demodulated at load).
    grid: Grid,
    geo: Geometry,
    shown: String,
    /// Whether the cells ride a Nyquist-rate carrier.
    carrier: bool,
    /// What aligning the cells in position did (`align`), cell by cell.
    shifts: Vec<Shift>,
}

/// The state of `interp`.
struct Interp {
    textures: Vec<Texture>,
    /// The texture of the current frame; the one the next frame takes; the
    /// one at t = 0.
    current: usize,
    pending: usize,
    initial: usize,
    kernel: SincKernel,
    scheme: Scheme,
    /// Scale the table by m_u/m_edge outside the grid's loads (a grid of forces).
    proportional: bool,
    frame: usize,
    in_clock: Clock,
    out_clock: Clock,
    /// Table samples sent since t = 0.
    sent: u64,
    /// Input samples received since t = 0, and consumed (latched) so far.
    received: u64,
    consumed: u64,
    latest: (f64, f64),
    mix: Option<Mix>,
    generation: u64,
    scratch: [Vec<f64>; 2],
}

/// The grid sources an `interp` node's parameters name — one per texture of
/// `textures`, or the one `folder`, or the list `paths` — each with how
/// errors and the summary name it. Shared with whatever shows the node's
/// grids (the studio), so both read the parameters alike.
pub fn grid_sources(p: &Params, ctx: &BuildContext) -> Result<Vec<(GridSource, String)>, NodeError> {
    let folder = FOLDER.get(p);
    let paths = PATHS.get(p);
    let textures = TEXTURES.get(p);
    let given = [!folder.is_empty(), !paths.is_empty(), !textures.is_empty()];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(NodeError::param(
            FOLDER.name(),
            "give one of `folder` (a folder of grid recordings), `paths` (a list of recordings) or `textures` \
             (a list of folders, one per texture)",
        ));
    }
    let range = |list: Floats| -> Result<Option<(f64, f64)>, NodeError> {
        match list.get(p) {
            [] => Ok(None),
            [lo, hi] => Ok(Some((*lo, *hi))),
            other => {
                Err(NodeError::param(list.name(), format!("give two numbers [lo, hi], not {} values", other.len())))
            }
        }
    };
    let base = GridSource {
        folder: None,
        paths: Vec::new(),
        material: MATERIAL.get(p).to_string(),
        channel: CHANNEL.get(p).to_string(),
        load_range: range(LOAD_RANGE)?,
        velocity_range: range(VELOCITY_RANGE)?,
        apply_gain: APPLY_GAIN.get(p),
        expect: EXPECT.get(p),
    };
    Ok(if !textures.is_empty() {
        textures.iter().map(|t| (GridSource { folder: Some(ctx.path(t)), ..base.clone() }, t.to_string())).collect()
    } else if !folder.is_empty() {
        vec![(GridSource { folder: Some(ctx.path(folder)), ..base.clone() }, folder.to_string())]
    } else {
        let paths = paths.iter().map(|s| ctx.path(s)).collect::<Vec<PathBuf>>();
        vec![(GridSource { paths, ..base.clone() }, format!("{} recordings", PATHS.get(p).len()))]
    })
}

fn build(p: &Params, ctx: &BuildContext) -> Result<Box<dyn Node>, NodeError> {
    let sources = grid_sources(p, ctx)?;
    let initial = TEXTURE.count(p);
    if initial >= sources.len() {
        return Err(NodeError::param(
            TEXTURE.name(),
            format!(
                "{initial} is not an index into the {} texture(s) given (0 … {})",
                sources.len(),
                sources.len() - 1
            ),
        ));
    }
    let update = UPDATE_RATE.get(p);
    let stream = ctx.output_rate(TABLE);
    let frame_f = stream / update;
    let frame = frame_f.round() as usize;
    if (frame_f - frame as f64).abs() > 1e-9 * frame_f || frame < HEADER + 32 {
        return Err(NodeError::param(
            STREAM_RATE.name(),
            format!("stream_rate/update_rate = {stream}/{update} = {frame_f} must be a whole number of samples ≥ {} (the frame length)", HEADER + 32),
        ));
    }
    let kernel = SincKernel::for_interp(HALF_WIDTH.count(p));
    let period = PERIOD.get(p);
    let mut loaded: Vec<Texture> = Vec::with_capacity(sources.len());
    for (src, shown) in sources {
        let mut grid = Grid::load(&src).map_err(|e| match e {
            // The message starts with the folder already.
            GridError::Folder { .. } => NodeError::Data(e.to_string()),
            _ => NodeError::Data(format!("grid {shown}: {e}")),
        })?;
        let carrier = match CARRIER_MODE.get(p) {
            CarrierMode::Nyquist => true,
            CarrierMode::None => false,
            CarrierMode::Auto => grid.carrier,
        };
        if carrier {
            // u[n] = (−1)ⁿ·a[n]: interpolate the envelopes, which live far
            // below the re-sampling's cutoff; playback puts the carrier back.
            for cell in &mut grid.cells {
                cell.iter_mut().skip(1).step_by(2).for_each(|x| *x = -*x);
            }
        }
        let nv = grid.velocities.len();
        let speeds: Vec<f64> = (0..grid.cells.len()).map(|k| grid.velocities[k % nv]).collect();
        let shifts = align::align(&mut grid.cells, &speeds, grid.rate, ALIGN.get(p));
        if let Some(first) = loaded.first() {
            if grid.rate != first.grid.rate {
                return Err(NodeError::Data(format!(
                    "grid {shown}: recorded at {} Hz, but texture 0 ({}) at {} Hz; every texture needs the same rate",
                    grid.rate, first.shown, first.grid.rate
                )));
            }
        }
        let overlap = (OVERLAP.get(p) * 1e-3 * grid.rate).round() as usize;
        let geometry = |want: f64| {
            Geometry::new(&grid, &kernel, frame - HEADER, overlap, want)
                .map_err(|e| NodeError::Data(format!("grid {shown}: {e}")))
        };
        let mut geo = geometry(LOOP.get(p))?;
        if period > 0.0 {
            let whole = (geo.loop_cm / period).floor();
            if whole < 1.0 {
                return Err(NodeError::param(
                    PERIOD.name(),
                    format!("a period of {period} cm is longer than the loop of {:.3} cm ({shown})", geo.loop_cm),
                ));
            }
            geo = geometry(whole * period)?;
        }
        loaded.push(Texture { grid, geo, shown, carrier, shifts });
    }
    let scheme = SCHEME.get(p);
    Ok(Box::new(Interp {
        in_clock: Clock::new(ctx.input_rate(LOAD), ctx.base_rate, "load")?,
        out_clock: Clock::new(stream, ctx.base_rate, "table")?,
        textures: loaded,
        current: initial,
        pending: initial,
        initial,
        kernel,
        scheme,
        proportional: LOAD_BEYOND.get(p) == LoadBeyond::Proportional,
        frame,
        sent: 0,
        received: 0,
        consumed: 0,
        latest: (0.0, 0.0),
        mix: None,
        generation: 0,
        scratch: [Vec::new(), Vec::new()],
    }))
}

impl Interp {
    /// Latches the inputs at or before table sample `s` from this call's
    /// inputs (`load`, `vel`, starting at global input index `first`).
    fn latch(&mut self, s: u64, first: u64, n: usize) {
        while self.consumed < first + n as u64 && self.in_clock.at_or_before(self.consumed, &self.out_clock, s) {
            let k = (self.consumed - first) as usize;
            self.latest = (self.scratch[0][k], self.scratch[1][k]);
            self.consumed += 1;
        }
    }

    /// Sample `pos` of the current frame.
    #[inline]
    fn value(&self, pos: usize) -> f64 {
        let Some(mix) = &self.mix else { return 0.0 };
        let grid = &self.textures[self.current].grid;
        if pos >= HEADER {
            let k = pos - HEADER;
            return if k < mix.len + mix.overlap { mix.sample(grid, &self.kernel, k) } else { 0.0 };
        }
        match pos {
            at::MAGIC => MAGIC,
            at::FRAME => self.frame as f64,
            at::LEN => mix.len as f64,
            at::OVERLAP => mix.overlap as f64,
            at::LOOP_CM => mix.loop_cm,
            at::RATE => grid.rate,
            at::LOAD => mix.load,
            at::VELOCITY => mix.velocity,
            at::GENERATION => self.generation as f64,
            _ => {
                let scheme = match mix.scheme {
                    Scheme::Basic => 0,
                    Scheme::Improved => IMPROVED,
                };
                (scheme + if self.textures[self.current].carrier { CARRIER } else { 0 }) as f64
            }
        }
    }
}

impl Node for Interp {
    fn prepare(&mut self, ctx: &PrepareContext) -> Result<(), NodeError> {
        self.scratch = [vec![0.0; ctx.max_block], vec![0.0; ctx.max_block]];
        Ok(())
    }

    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n_in = io.input_len(LOAD).min(io.input_len(VELOCITY));
        self.scratch[0][..n_in].copy_from_slice(&io.input(LOAD)[..n_in]);
        self.scratch[1][..n_in].copy_from_slice(&io.input(VELOCITY)[..n_in]);
        let first = self.received;
        let out = io.output(TABLE);
        for (q, y) in out.iter_mut().enumerate() {
            let s = self.sent + q as u64;
            let pos = (s % self.frame as u64) as usize;
            if pos == 0 {
                self.latch(s, first, n_in);
                let (m, v) = self.latest;
                self.current = self.pending;
                let t = &self.textures[self.current];
                let mix = Mix::new(&t.grid, &t.geo, &self.kernel, self.scheme, m, v);
                self.mix = Some(if self.proportional { mix.proportional_beyond(m) } else { mix });
                self.generation = s / self.frame as u64;
            }
            *y = self.value(pos);
        }
        self.sent += out.len() as u64;
        // Inputs after the last frame start of this call precede every later table sample.
        self.latch(u64::MAX / 4, first, n_in);
        self.received += n_in as u64;
        Ok(())
    }

    fn reset(&mut self) {
        self.sent = 0;
        self.received = 0;
        self.consumed = 0;
        self.latest = (0.0, 0.0);
        self.mix = None;
        self.generation = 0;
        self.current = self.initial;
        self.pending = self.initial;
    }

    fn finish(&mut self) -> Result<Summary, NodeError> {
        let mut s = Summary::default();
        for (k, t) in self.textures.iter().enumerate() {
            let g = &t.grid;
            let which = if self.textures.len() > 1 { format!("texture {k}, ") } else { String::new() };
            s = s.line(format!(
                "{which}grid {}: {} load(s) {:?} g × {} velocit(ies) {:?} cm/s loaded at {} Hz; loop {:.3} cm",
                t.shown,
                g.loads.len(),
                g.loads,
                g.velocities.len(),
                g.velocities,
                g.rate,
                t.geo.loop_cm,
            ));
            if t.shifts.iter().any(|x| x.trimmed > 0 || x.correlation.is_nan()) {
                let cells: Vec<String> = t
                    .shifts
                    .iter()
                    .map(|x| format!("{:+.3} cm (r {:.2}, {} trimmed)", x.delta_cm, x.correlation, x.trimmed))
                    .collect();
                s = s.line(format!("{which}aligned in position against the first cell: {}", cells.join(", ")));
            }
        }
        Ok(s.line(format!("{} frames sent", self.sent / self.frame as u64)))
    }

    fn set(&mut self, c: Change) -> Result<(), Refused> {
        match TEXTURE.changed(&c) {
            // Taken at the next frame start; playback crossfades into it.
            Some(texture) if texture < self.textures.len() => {
                self.pending = texture;
                Ok(())
            }
            _ => Err(c.refused()),
        }
    }
}
