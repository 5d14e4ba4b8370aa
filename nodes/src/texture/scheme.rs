//! The interpolation schemes over the grid: the basic one of §5.3.3 and the
//! improved two-part one of Eq. 6.4, with the clamping of §6.4.
//!
//! For a user condition (m_u, v_u) between grid nodes m_i ≤ m_u ≤ m_{i+1}
//! and v_j ≤ v_u ≤ v_{j+1}:
//!
//! * **improved** (Eq. 6.4): 1.1/1.2 U_{u,j} = 𝒲𝒜(U_{i,j}, U_{i+1,j}, m_i,
//!   m_{i+1}, m_u) and likewise for j+1; 2.1/2.2 U^r_{u,j} = 𝓡𝓢(U_{u,j},
//!   v_j, v_u), i.e. U_{u,j} read at v_u / v_j input samples per output
//!   sample (its main component moves from the frequency of v_j to that of
//!   v_u, §6.3); 2.3 U_{u,u} = 𝒲𝒜(U^r_{u,j}, U^r_{u,j+1}, v_j, v_{j+1}, v_u).
//! * **basic** (§5.3.3): the same weights, no re-sampling: a sample-by-sample
//!   weighted average of the four neighbours (which keeps the main components
//!   of both velocities, the flaw chapter 6 fixes).
//!
//! Clamping (§6.4): m_u and v_u outside the grid are set to the nearest
//! extreme, which drops the first step (mass) or the second (velocity). A
//! grid with one load or one velocity is the same case: that step vanishes.
//! v_u ≤ 0 (a resting finger) is clamped to v_min like any slow velocity:
//! no division by zero anywhere; silence at rest is `playback`'s job.
//!
//! Because 𝒲𝒜 and 𝓡𝓢 are linear, step 1 is applied on the fly to the input
//! samples the re-sampling kernel reads, and any output sample k can be
//! computed alone ([`Mix::sample`]): that is what lets `interp` spread a
//! table over many ticks.
//!
//! **Spatial alignment.** Sample k of the table is the texture at position
//! x₀ + k·v_u/f_s; cell (i, j) holds that position at input sample
//! (x₀ + k·v_u/f_s)·f_s/v_j (every recording is taken to start at the same
//! place on the texture, as tribometer passes do). x₀ is a margin that keeps
//! the kernel inside the recordings.

use super::grid::Grid;
use super::kernel::SincKernel;
use super::kernel_mix;
use super::wa::weights;

/// Which scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// §5.3.3: bilinear weighted average, no re-sampling.
    Basic,
    /// Eq. 6.4: weighted average over mass, re-sampling and weighted average over velocity.
    Improved,
}

/// The bracket [a, b] of `x` on an ascending axis after clamping, with the
/// Eq. 6.1 weights: (lower index, upper index, w_lower, w_upper, clamped x).
pub fn bracket(axis: &[f64], x: f64) -> (usize, usize, f64, f64, f64) {
    let last = axis.len() - 1;
    let x = if x.is_nan() { axis[0] } else { x.clamp(axis[0], axis[last]) };
    let hi = axis.iter().position(|a| *a >= x).unwrap_or(last);
    let lo = if axis[hi] == x || hi == 0 { hi } else { hi - 1 };
    let (w1, w2) = weights(axis[lo], axis[hi], x);
    (lo, hi, w1, w2, x)
}

/// Fixed geometry of the tables made from one grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Spatial margin x₀ before the loop, cm.
    pub x0: f64,
    /// Spatial length of the loop, cm.
    pub loop_cm: f64,
    /// Seam overlap in table samples (read past the loop's end and
    /// crossfaded into its start by `playback`).
    pub overlap: usize,
    /// Largest table (loop + overlap) in samples.
    pub capacity: usize,
}

/// Why no table fits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    /// The recordings are too short for the kernel margins and the seam.
    #[error("the grid recordings are too short: after margins of {margin_cm:.3} cm at each end for the re-sampling kernel, {avail_cm:.3} cm of texture are left, less than the {need} samples a loop needs at {v_max} cm/s; use longer recordings or a smaller half_width")]
    TooShort {
        /// Margin, cm.
        margin_cm: f64,
        /// Left, cm.
        avail_cm: f64,
        /// Samples needed.
        need: usize,
        /// Fastest velocity.
        v_max: f64,
    },
    /// The loop asked for is longer than the recordings or the frame allow.
    #[error("a loop of {want_cm} cm is longer than the {longest_cm:.3} cm the grid recordings and the frame length allow; shorten `loop` or raise stream_rate")]
    LoopTooLong {
        /// Asked, cm.
        want_cm: f64,
        /// Possible, cm.
        longest_cm: f64,
    },
    /// The loop asked for is shorter than a table needs.
    #[error("a loop of {want_cm} cm is fewer than {need} samples at {v_max} cm/s")]
    LoopTooShort {
        /// Asked, cm.
        want_cm: f64,
        /// Samples needed.
        need: usize,
        /// Fastest velocity.
        v_max: f64,
    },
}

impl Geometry {
    /// The loop for `grid`: `want_cm` long (0: as long as every cell allows
    /// after the kernel margins), and at most `capacity` samples (loop +
    /// `overlap`) at the slowest velocity.
    pub fn new(
        grid: &Grid,
        kernel: &SincKernel,
        capacity: usize,
        overlap: usize,
        want_cm: f64,
    ) -> Result<Self, GeometryError> {
        let fs = grid.rate;
        let v = &grid.velocities;
        let (v_min, v_max) = (v[0], v[v.len() - 1]);
        let t_max = v.windows(2).map(|w| w[1] / w[0]).fold(1.0, f64::max);
        let reach = kernel.reach(kernel.cutoff_for(t_max)) + 2.0;
        let margin_cm = reach * v_max / fs;
        let mut extent = f64::INFINITY;
        for (k, cell) in grid.cells.iter().enumerate() {
            let vj = v[k % v.len()];
            extent = extent.min(cell.len() as f64 * vj / fs);
        }
        let avail = extent - 2.0 * margin_cm - overlap as f64 * v_max / fs;
        let by_capacity = capacity.saturating_sub(overlap) as f64 * v_min / fs;
        let longest = avail.min(by_capacity);
        let need = (2 * overlap).max(16);
        let fits = longest * fs / v_max;
        if fits.is_nan() || fits < need as f64 {
            return Err(GeometryError::TooShort { margin_cm, avail_cm: avail.max(0.0), need, v_max });
        }
        let loop_cm = if want_cm > 0.0 {
            if want_cm > longest * (1.0 + 1e-12) {
                return Err(GeometryError::LoopTooLong { want_cm, longest_cm: longest });
            }
            if want_cm * fs / v_max < need as f64 {
                return Err(GeometryError::LoopTooShort { want_cm, need, v_max });
            }
            want_cm
        } else {
            longest
        };
        Ok(Self { x0: margin_cm, loop_cm, overlap, capacity })
    }
}

/// One table's recipe: the neighbours, weights and read positions for a
/// user condition. Computing it allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mix {
    /// Scheme.
    pub scheme: Scheme,
    /// m_u after clamping, g.
    pub load: f64,
    /// v_u after clamping, cm/s.
    pub velocity: f64,
    /// Load neighbours i, i+1 (equal when clamped or single).
    pub i: [usize; 2],
    /// Their weights (step 1).
    pub wl: [f64; 2],
    /// Velocity neighbours j, j+1.
    pub j: [usize; 2],
    /// Their weights (step 2.3).
    pub wv: [f64; 2],
    /// Input samples per table sample in cell column j, j+1 (v_u / v_j; 1 for basic).
    pub step: [f64; 2],
    /// Kernel cutoff per column.
    pub cut: [f64; 2],
    /// Input position of table sample 0 per column.
    pub start: [f64; 2],
    /// Loop length T in table samples.
    pub len: usize,
    /// Seam overlap X.
    pub overlap: usize,
    /// Spatial length of this loop, T·v_u/f_s, cm.
    pub loop_cm: f64,
    /// Factor on every table sample (1 unless [`Mix::proportional_beyond`]).
    pub scale: f64,
}

impl Mix {
    /// The recipe for user load `m` (g) and speed `v` (cm/s; its magnitude is used).
    pub fn new(grid: &Grid, geo: &Geometry, kernel: &SincKernel, scheme: Scheme, m: f64, v: f64) -> Self {
        let fs = grid.rate;
        let v = if v.is_finite() { v.abs() } else { 0.0 };
        let (i0, i1, a0, a1, m) = bracket(&grid.loads, m);
        let (j0, j1, b0, b1, v) = bracket(&grid.velocities, v);
        let vj = [grid.velocities[j0], grid.velocities[j1]];
        let len_avail = geo.capacity - geo.overlap;
        let mut mix = Mix {
            scheme,
            load: m,
            velocity: v,
            i: [i0, i1],
            wl: [a0, a1],
            j: [j0, j1],
            wv: [b0, b1],
            step: [1.0; 2],
            cut: [1.0; 2],
            start: [0.0; 2],
            len: 0,
            overlap: geo.overlap,
            loop_cm: 0.0,
            scale: 1.0,
        };
        match scheme {
            Scheme::Improved => {
                #[allow(clippy::needless_range_loop)] // b indexes five parallel arrays
                for b in 0..2 {
                    mix.step[b] = v / vj[b];
                    mix.cut[b] = kernel.cutoff_for(mix.step[b]);
                    mix.start[b] = geo.x0 * fs / vj[b];
                }
                mix.len = ((geo.loop_cm * fs / v).floor() as usize).clamp(2, len_avail);
            }
            Scheme::Basic => {
                let mut avail = len_avail;
                for b in 0..2 {
                    mix.start[b] = (geo.x0 * fs / vj[b]).round();
                    let n = grid.cell(i0, [j0, j1][b]).len().min(grid.cell(i1, [j0, j1][b]).len());
                    avail = avail.min(n.saturating_sub(mix.start[b] as usize + geo.overlap));
                }
                mix.len = ((geo.loop_cm * fs / v).floor() as usize).min(avail).max(2);
            }
        }
        mix.loop_cm = mix.len as f64 * v / fs;
        mix
    }

    /// The same recipe for a grid of *forces* at a user load `m` (g) outside
    /// the grid's loads: the table of the nearest load scaled by m / m_edge,
    /// friction being proportional to the normal load (Coulomb; the lab's
    /// samples too, §5.3.1: "with heavier mass, only the level of power
    /// density increased"). Inside the grid, or for a non-finite m, nothing
    /// changes; a load ≤ 0 gives silence.
    pub fn proportional_beyond(mut self, m: f64) -> Self {
        if m.is_finite() && m != self.load && self.load > 0.0 {
            self.scale = m.max(0.0) / self.load;
        }
        self
    }

    /// Table sample k (0 ≤ k < len + overlap) of U_{u,u}.
    #[inline]
    pub fn sample(&self, grid: &Grid, kernel: &SincKernel, k: usize) -> f64 {
        let mut y = 0.0;
        for b in 0..2 {
            if self.wv[b] == 0.0 {
                continue;
            }
            let j = self.j[b];
            let (u0, u1) = (grid.cell(self.i[0], j), grid.cell(self.i[1], j));
            let (a0, a1) = (self.wl[0], self.wl[1]);
            let n = u0.len().min(u1.len());
            let v = match self.scheme {
                Scheme::Basic => {
                    let p = self.start[b] as usize + k;
                    if p < n {
                        a0 * u0[p] + a1 * u1[p]
                    } else {
                        0.0
                    }
                }
                Scheme::Improved => {
                    let p = self.start[b] + k as f64 * self.step[b];
                    kernel_mix::eval_mix(kernel, p, self.cut[b], u0, u1, a0, a1)
                }
            };
            y += self.wv[b] * v;
        }
        self.scale * y
    }

    /// The whole table (loop and overlap), for offline use and tests.
    pub fn table(&self, grid: &Grid, kernel: &SincKernel) -> Vec<f64> {
        (0..self.len + self.overlap).map(|k| self.sample(grid, kernel, k)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beyond_the_grid_a_force_grid_scales_with_the_load() {
        let sine = |a: f64| -> Vec<f64> { (0..3000).map(|k| a * (k as f64 * 0.1).sin()).collect() };
        let grid = Grid::from_signals(vec![60.0, 110.0], vec![5.0], 1000.0, vec![vec![sine(1.0)], vec![sine(2.0)]]);
        let kernel = SincKernel::for_interp(16);
        let geo = Geometry::new(&grid, &kernel, 4000, 10, 0.0).unwrap();
        let mix = |m: f64| Mix::new(&grid, &geo, &kernel, Scheme::Improved, m, 5.0);
        let at = |m: f64| mix(m).proportional_beyond(m).table(&grid, &kernel);
        let (t30, t60, t85, t220) = (at(30.0), at(60.0), at(85.0), at(220.0));
        let (b60, b85, b110) =
            (mix(60.0).table(&grid, &kernel), mix(85.0).table(&grid, &kernel), mix(110.0).table(&grid, &kernel));
        for k in 0..t60.len() {
            assert_eq!(t60[k], b60[k]);
            assert_eq!(t85[k], b85[k], "inside the grid nothing changes");
            assert!((t30[k] - 0.5 * b60[k]).abs() < 1e-12);
            assert!((t220[k] - 2.0 * b110[k]).abs() < 1e-12);
        }
        assert_eq!(mix(-5.0).proportional_beyond(-5.0).scale, 0.0);
        assert_eq!(mix(f64::NAN).proportional_beyond(f64::NAN).scale, 1.0);
    }

    #[test]
    fn brackets_clamp_and_handle_single_nodes() {
        let v = [3.0, 4.0, 5.0];
        assert_eq!(bracket(&v, 3.5), (0, 1, 0.5, 0.5, 3.5));
        assert_eq!(bracket(&v, 4.0), (1, 1, 1.0, 0.0, 4.0));
        assert_eq!(bracket(&v, 0.0), (0, 0, 1.0, 0.0, 3.0));
        assert_eq!(bracket(&v, 99.0), (2, 2, 1.0, 0.0, 5.0));
        assert_eq!(bracket(&v, f64::NAN), (0, 0, 1.0, 0.0, 3.0));
        assert_eq!(bracket(&[85.0], 60.0), (0, 0, 1.0, 0.0, 85.0));
    }
}
