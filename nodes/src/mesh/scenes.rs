//! The user-study scenes of dissertation §4.2 (Fig. 4.5, 4.6), generated so
//! no file is needed: Gaussian bumps z = 8/(1.4π)·exp(−(x²+y²)/1.4) and
//! square frustums (base 3×3, top 1×1, height 2), holes as their
//! inversions, four objects per scene (each in a 6×6 cell of a 12×12
//! ground, all in cm) in the configurations 0B4H … 4B0H; plus single
//! objects and general height-field grids for tests and benchmarks.

use super::error::MeshError;
use super::trimesh::Mesh;

/// Object profile of a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Shape {
    /// z = 8/(1.4π)·exp(−(x²+y²)/1.4) (Fig. 4.5a).
    Gaussian,
    /// Square frustum, base 3×3, top 1×1, height 2 (Fig. 4.5b).
    Frustum,
}

impl Shape {
    /// The word a graph file writes for it (`gaussian`, `frustum`).
    pub const fn word(self) -> &'static str {
        match self {
            Shape::Gaussian => "gaussian",
            Shape::Frustum => "frustum",
        }
    }
}

/// Which objects are bumps (+1) and which holes (−1), with their centres.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// (centre x, centre y, sign) per object, cm.
    pub objects: Vec<(f64, f64, f64)>,
    /// Half side of the ground square, cm.
    pub half: f64,
}

/// Side of one object's cell (Fig. 4.5: width 6, length 6), cm.
pub const CELL: f64 = 6.0;

/// The configuration names accepted by [`layout`].
pub const CONFIGS: &[&str] = &["0B4H", "1B3H", "2B2H", "3B1H", "4B0H", "bump", "hole"];

/// Cell centres: top-left, top-right, bottom-left, bottom-right.
const TL: (f64, f64) = (-3.0, 3.0);
const TR: (f64, f64) = (3.0, 3.0);
const BL: (f64, f64) = (-3.0, -3.0);
const BR: (f64, f64) = (3.0, -3.0);

/// The layout of a configuration. The dissertation fixes the single bump of
/// 1B3H top-right for Gaussian scenes and bottom-right for frustums and
/// leaves the others to a random draw it does not list; here bumps fill
/// the cells in the order TR, BL, TL, BR (Gaussian) and BR, TL, TR, BL
/// (frustum). `bump` and `hole` are one object in a 6×6 cell at the origin.
pub fn layout(shape: Shape, config: &str) -> Result<Layout, MeshError> {
    let single = |s| Layout { objects: vec![(0.0, 0.0, s)], half: CELL / 2.0 };
    let bumps = match config {
        "bump" => return Ok(single(1.0)),
        "hole" => return Ok(single(-1.0)),
        "0B4H" => 0,
        "1B3H" => 1,
        "2B2H" => 2,
        "3B1H" => 3,
        "4B0H" => 4,
        other => {
            return Err(MeshError::Scene(format!("unknown configuration `{other}` (one of {})", CONFIGS.join(", "))))
        }
    };
    let order = match shape {
        Shape::Gaussian => [TR, BL, TL, BR],
        Shape::Frustum => [BR, TL, TR, BL],
    };
    let objects = order.iter().enumerate().map(|(i, c)| (c.0, c.1, if i < bumps { 1.0 } else { -1.0 })).collect();
    Ok(Layout { objects, half: CELL })
}

/// Peak height of the Gaussian bump, 8/(1.4π) ≈ 1.819 cm.
pub const GAUSS_PEAK: f64 = 8.0 / (1.4 * std::f64::consts::PI);

/// Height and gradient (z, ∂z/∂x, ∂z/∂y) of a Gaussian scene at (x, y): the
/// sum of its signed bumps (the tails of neighbours, ≤ 0.2 % of the peak at
/// a cell border, are kept so the surface is smooth).
pub fn gaussian_height(l: &Layout, x: f64, y: f64) -> (f64, f64, f64) {
    let (mut z, mut zx, mut zy) = (0.0, 0.0, 0.0);
    for &(cx, cy, s) in &l.objects {
        let (dx, dy) = (x - cx, y - cy);
        let g = s * GAUSS_PEAK * (-(dx * dx + dy * dy) / 1.4).exp();
        z += g;
        zx += -2.0 * dx / 1.4 * g;
        zy += -2.0 * dy / 1.4 * g;
    }
    (z, zx, zy)
}

/// Height and gradient of a frustum scene (piecewise planar; on a crease
/// the gradient of either side).
pub fn frustum_height(l: &Layout, x: f64, y: f64) -> (f64, f64, f64) {
    for &(cx, cy, s) in &l.objects {
        let (dx, dy) = (x - cx, y - cy);
        let m = dx.abs().max(dy.abs());
        if m < 1.5 {
            if m <= 0.5 {
                return (2.0 * s, 0.0, 0.0);
            }
            let z = 2.0 * s * (1.5 - m);
            let (gx, gy) =
                if dx.abs() >= dy.abs() { (-2.0 * s * dx.signum(), 0.0) } else { (0.0, -2.0 * s * dy.signum()) };
            return (z, gx, gy);
        }
    }
    (0.0, 0.0, 0.0)
}

/// A scene mesh. `resolution` is the number of grid cells along one 6 cm
/// object side of a Gaussian scene (≥ 2); frustum scenes are exact
/// polyhedra (18 triangles per object) and ignore it.
pub fn scene(shape: Shape, config: &str, resolution: usize) -> Result<Mesh, MeshError> {
    let l = layout(shape, config)?;
    match shape {
        Shape::Gaussian => {
            if resolution < 2 {
                return Err(MeshError::Scene(format!("resolution {resolution} is below 2")));
            }
            let n = resolution * (2.0 * l.half / CELL).round() as usize;
            Ok(grid(n, n, [-l.half, l.half], [-l.half, l.half], |x, y| gaussian_height(&l, x, y).0))
        }
        Shape::Frustum => Ok(frustums(&l)),
    }
}

/// A height field z = f(x, y) on an nx × ny grid of cells over the given
/// ranges, each cell split into two triangles along its rising diagonal.
pub fn grid(nx: usize, ny: usize, xr: [f64; 2], yr: [f64; 2], f: impl Fn(f64, f64) -> f64) -> Mesh {
    let mut v = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        let y = yr[0] + (yr[1] - yr[0]) * j as f64 / ny as f64;
        for i in 0..=nx {
            let x = xr[0] + (xr[1] - xr[0]) * i as f64 / nx as f64;
            v.push([x, y, f(x, y)]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut t = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::new(v, t, 0.0)
}

/// Frustum cells: per object a ground ring (outer 6×6 square to the 3×3
/// base), four sides (base to the 1×1 top at ±2) and the top.
fn frustums(l: &Layout) -> Mesh {
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut t = Vec::new();
    // Square corners in counter-clockwise order.
    let sq = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    for &(cx, cy, s) in &l.objects {
        let ring = |r: f64, z: f64| sq.map(|(a, b)| [cx + r * a, cy + r * b, z]);
        let rings = [ring(CELL / 2.0, 0.0), ring(1.5, 0.0), ring(0.5, 2.0 * s)];
        let base = v.len() as u32;
        for r in &rings {
            v.extend_from_slice(r);
        }
        let at = |r: u32, k: usize| base + 4 * r + (k % 4) as u32;
        for r in 0..2 {
            for k in 0..4 {
                let (a, b, c, d) = (at(r, k), at(r, k + 1), at(r + 1, k + 1), at(r + 1, k));
                t.push([a, b, c]);
                t.push([a, c, d]);
            }
        }
        t.push([at(2, 0), at(2, 1), at(2, 2)]);
        t.push([at(2, 0), at(2, 2), at(2, 3)]);
    }
    Mesh::new(v, t, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_bump_has_the_figure_4_5_height() {
        let l = layout(Shape::Gaussian, "bump").unwrap();
        assert!((gaussian_height(&l, 0.0, 0.0).0 - 1.8189136353359467).abs() < 1e-12);
        // Central difference of the analytic height matches its gradient.
        let (x, y, h) = (0.7, -0.4, 1e-6);
        let (_, gx, gy) = gaussian_height(&l, x, y);
        let nx = (gaussian_height(&l, x + h, y).0 - gaussian_height(&l, x - h, y).0) / (2.0 * h);
        let ny = (gaussian_height(&l, x, y + h).0 - gaussian_height(&l, x, y - h).0) / (2.0 * h);
        assert!((gx - nx).abs() < 1e-8 && (gy - ny).abs() < 1e-8);
        let m = scene(Shape::Gaussian, "hole", 8).unwrap();
        assert_eq!(m.triangles.len(), 2 * 8 * 8);
        let b = m.bounds();
        assert!((b.min[2] + GAUSS_PEAK).abs() < 1e-12 && b.max[2] < 0.01);
    }

    #[test]
    fn configurations_count_their_bumps() {
        for (k, c) in ["0B4H", "1B3H", "2B2H", "3B1H", "4B0H"].iter().enumerate() {
            for shape in [Shape::Gaussian, Shape::Frustum] {
                let l = layout(shape, c).unwrap();
                assert_eq!(l.objects.iter().filter(|o| o.2 > 0.0).count(), k);
                assert_eq!(l.objects.len(), 4);
            }
        }
        assert_eq!(layout(Shape::Gaussian, "1B3H").unwrap().objects[0], (3.0, 3.0, 1.0));
        assert_eq!(layout(Shape::Frustum, "1B3H").unwrap().objects[0], (3.0, -3.0, 1.0));
        assert!(layout(Shape::Frustum, "5B0H").is_err());
    }

    #[test]
    fn frustum_scene_is_a_closed_height_field_of_the_right_size() {
        let m = scene(Shape::Frustum, "2B2H", 0).unwrap();
        assert_eq!(m.triangles.len(), 4 * 18);
        let b = m.bounds();
        assert_eq!((b.min, b.max), ([-6.0, -6.0, -2.0], [6.0, 6.0, 2.0]));
        // Total projected area equals the ground square: a height field without gaps or overlaps.
        let area: f64 = (0..m.triangles.len())
            .map(|t| {
                let [a, b, c] = m.corners(t);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs()
            })
            .sum();
        assert!((area - 144.0).abs() < 1e-9);
        // Side slope: 2 up over 1 across.
        let l = layout(Shape::Frustum, "bump").unwrap();
        assert_eq!(frustum_height(&l, 1.0, 0.2), (1.0, -2.0, 0.0));
    }
}
