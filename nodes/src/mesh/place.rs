//! Orientation and fit of a loaded mesh: which of its axes points out of
//! the screen (`up`), and how its footprint maps onto the screen (`fit`).
//!
//! **Up.** The mesh nodes take z as height. A file whose up axis is
//! another one is turned by the proper rotation (a permutation of axes
//! with signs, determinant +1: exact in floating point, never a mirror
//! image) that takes that axis to +z; y-up files (the OBJ convention) keep
//! x pointing right and their front (+z) faces the bottom edge of the
//! screen (−y).
//!
//! **Fit.** The footprint is the x–y bounding box of the triangles' corners
//! after the rotation. Fitting it chooses the metres per mesh unit (one
//! uniform scale, heights included, so the aspect ratio and the slopes are
//! kept) and the touch position of the mesh origin, so that the footprint's
//! larger side spans the asked length and its centre lands on the asked
//! point. The vertices themselves are not moved: touch points are mapped
//! into mesh units ([`super::source::Placed::to_mesh`]), where the ray
//! caster already keeps its precision far from the origin.

use super::trimesh::Mesh;

/// The mesh axis that points up, out of the screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Up {
    /// +x up.
    PlusX,
    /// −x up.
    MinusX,
    /// +y up (the OBJ convention).
    PlusY,
    /// −y up.
    MinusY,
    /// +z up (the generated scenes; no rotation).
    PlusZ,
    /// −z up.
    MinusZ,
}

/// Every axis with its word, as written in a graph file.
pub const UP_WORDS: [(&str, Up); 6] = [
    ("+x", Up::PlusX),
    ("-x", Up::MinusX),
    ("+y", Up::PlusY),
    ("-y", Up::MinusY),
    ("+z", Up::PlusZ),
    ("-z", Up::MinusZ),
];

impl Up {
    /// The axis a word names (`+x` … `-z`), if any.
    pub fn parse(word: &str) -> Option<Up> {
        UP_WORDS.iter().find(|(w, _)| *w == word).map(|(_, u)| *u)
    }

    /// The word of this axis (`+x` … `-z`).
    pub fn word(self) -> &'static str {
        UP_WORDS.iter().find(|(_, u)| *u == self).map_or("+z", |(w, _)| w)
    }

    /// A point in file coordinates turned so that this axis is +z (a proper
    /// rotation, see the module doc).
    #[inline]
    pub fn to_z_up(self, [x, y, z]: [f64; 3]) -> [f64; 3] {
        match self {
            Up::PlusZ => [x, y, z],
            Up::MinusZ => [x, -y, -z],
            Up::PlusY => [x, -z, y],
            Up::MinusY => [x, z, -y],
            Up::PlusX => [-z, y, x],
            Up::MinusX => [z, y, -x],
        }
    }
}

/// The mesh turned so that `up` is +z: the vertices rotated, then welded
/// (bit-identical positions only: the rotation is exact, so nothing new
/// merges) and oriented again with the new up. `PlusZ` returns it as is.
pub fn reorient(mesh: Mesh, up: Up) -> Mesh {
    if up == Up::PlusZ {
        return mesh;
    }
    let vertices = mesh.vertices.iter().map(|&v| up.to_z_up(v)).collect();
    Mesh::new(vertices, mesh.triangles, 0.0)
}

/// The x–y bounding box of the triangles' corners, as (min, max); `None`
/// for a mesh without triangles.
pub fn footprint(mesh: &Mesh) -> Option<([f64; 2], [f64; 2])> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for t in &mesh.triangles {
        for &i in t {
            let v = mesh.vertices[i as usize];
            for k in 0..2 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
    }
    (lo[0] <= hi[0] && lo[1] <= hi[1]).then_some((lo, hi))
}

/// Where a fitted mesh lands: metres per mesh unit and the touch position
/// (m) of the mesh origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fitted {
    /// Metres per mesh unit.
    pub unit: f64,
    /// Touch coordinates of the mesh origin, m.
    pub offset: [f64; 2],
}

/// Why a mesh cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The footprint has no extent (no triangles, or all of them stand on
    /// one vertical line seen from above).
    #[error("the mesh's footprint has no extent (x {0} … {1}, y {2} … {3} mesh units): nothing to fit")]
    NoFootprint(f64, f64, f64, f64),
    /// The scale that fits is not a finite positive number.
    #[error("fitting a footprint of {side} mesh units to {size} m needs a scale of {unit} m per unit, out of range")]
    Scale {
        /// The footprint's larger side, mesh units.
        side: f64,
        /// The asked length, m.
        size: f64,
        /// The scale found, m per mesh unit.
        unit: f64,
    },
}

/// The placement that centres `footprint` on `centre` (touch coordinates,
/// m) and scales it uniformly so that its larger side is `size` m.
pub fn fit(footprint: ([f64; 2], [f64; 2]), size: f64, centre: [f64; 2]) -> Result<Fitted, FitError> {
    let (lo, hi) = footprint;
    let side = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    if !(side > 0.0 && side.is_finite()) {
        return Err(FitError::NoFootprint(lo[0], hi[0], lo[1], hi[1]));
    }
    let unit = size / side;
    if !(unit > 0.0 && unit.is_finite()) {
        return Err(FitError::Scale { side, size, unit });
    }
    // The footprint's centre in mesh units, halved first so that huge
    // coordinates do not overflow.
    let mid = [0.5 * lo[0] + 0.5 * hi[0], 0.5 * lo[1] + 0.5 * hi[1]];
    Ok(Fitted { unit, offset: [centre[0] - mid[0] * unit, centre[1] - mid[1] * unit] })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn det(m: [[f64; 3]; 3]) -> f64 {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }

    #[test]
    fn each_up_axis_is_turned_to_z_by_a_proper_rotation() {
        let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for (word, up) in UP_WORDS {
            assert_eq!(Up::parse(word), Some(up));
            assert_eq!(up.word(), word);
            let sign = if word.starts_with('-') { -1.0 } else { 1.0 };
            let k = ["x", "y", "z"].iter().position(|a| word.ends_with(a)).unwrap();
            let axis = axes[k].map(|c| c * sign);
            assert_eq!(up.to_z_up(axis), [0.0, 0.0, 1.0], "{word}");
            // Columns: images of the unit vectors.
            let c = axes.map(|a| up.to_z_up(a));
            let m = [0, 1, 2].map(|r| [c[0][r], c[1][r], c[2][r]]);
            assert_eq!(det(m), 1.0, "{word} must not mirror");
        }
        assert_eq!(Up::parse("y"), None);
        // y-up: x stays right, the model's front (+z) faces −y.
        assert_eq!(Up::PlusY.to_z_up([1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]);
        assert_eq!(Up::PlusY.to_z_up([0.0, 0.0, 1.0]), [0.0, -1.0, 0.0]);
    }

    #[test]
    fn reorienting_keeps_the_triangles_and_faces_them_up() {
        // A ramp rising along x, written y-up: height is the file's y.
        let v = vec![[0.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, 1.0, -1.0], [0.0, 0.0, -1.0]];
        let m = reorient(Mesh::new(v, vec![[0, 1, 2], [0, 2, 3]], 0.0), Up::PlusY);
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(footprint(&m), Some(([0.0, 0.0], [2.0, 1.0])));
        for n in &m.normals {
            assert!(n[2] > 0.0 && (n[0] + 0.5 / 1.25f64.sqrt()).abs() < 1e-15, "{n:?}");
        }
    }

    #[test]
    fn fit_centres_the_footprint_and_scales_its_larger_side() {
        // A 4 × 2 footprint centred at (12, −2), onto 0.1 m centred at (0.02, −0.01).
        let f = fit(([10.0, -3.0], [14.0, -1.0]), 0.1, [0.02, -0.01]).unwrap();
        assert_eq!(f.unit, 0.025);
        let to_screen = |x: f64, y: f64| [f.offset[0] + x * f.unit, f.offset[1] + y * f.unit];
        let c = to_screen(12.0, -2.0);
        assert!((c[0] - 0.02).abs() < 1e-15 && (c[1] + 0.01).abs() < 1e-15, "{c:?}");
        let (a, b) = (to_screen(10.0, -3.0), to_screen(14.0, -1.0));
        assert!((b[0] - a[0] - 0.1).abs() < 1e-15 && (b[1] - a[1] - 0.05).abs() < 1e-15);
        // Taller than wide: y sets the scale.
        assert_eq!(fit(([0.0, 0.0], [1.0, 5.0]), 0.1, [0.0, 0.0]).unwrap().unit, 0.02);
        // Nothing to fit, or no finite scale.
        assert!(matches!(fit(([1.0, 1.0], [1.0, 1.0]), 0.1, [0.0; 2]), Err(FitError::NoFootprint(..))));
        assert!(matches!(fit(([0.0, 0.0], [1e-320, 0.0]), 0.1, [0.0; 2]), Err(FitError::Scale { .. })));
        // Far coordinates neither overflow nor lose the centre.
        let f = fit(([1e308, 1e308], [1.5e308, 1.2e308]), 0.1, [0.0; 2]).unwrap();
        assert!(f.offset.iter().all(|o| o.is_finite()));
    }
}
