//! Vertical ray casting (dissertation §4.1): from the touch point (x, y)
//! a ray goes straight down from above the mesh's top and the highest hit
//! is taken.
//!
//! A compressed wide BVH (obvhs `CwBvh`, built once when the node is
//! constructed) culls the triangles; the hit test itself is exact-ish f64
//! and watertight: the ray is vertical, so it hits a triangle iff (x, y)
//! lies in the triangle's projection. Each edge function is evaluated with
//! the edge's endpoints in a canonical (lexicographic) order, so the two
//! triangles sharing an edge compute exactly opposite values and a point on
//! the edge — or on a vertex — is inside both (inclusive test) and never in
//! neither. The test accepts either winding. Triangles with zero projected
//! area (vertical walls, degenerate triangles) cannot be hit by a vertical
//! ray and are left out of the BVH.
//!
//! Coordinates are taken relative to the mesh's centre, and the f32 boxes
//! of the BVH are padded, so meshes far from the origin (10⁶ units) lose
//! nothing: the BVH only culls, the decision is made in f64.

use super::trimesh::{Bounds, Mesh};
use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::{Boundable, BvhBuildParams};

/// The highest point of the mesh under a touch point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Height of the hit, mesh units.
    pub z: f64,
    /// Index of the triangle hit (in [`Mesh::triangles`]).
    pub tri: u32,
}

/// One triangle's projection as the BVH sees it.
struct Footprint(Aabb);

impl Boundable for Footprint {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// A mesh prepared for vertical rays.
pub struct RayCaster {
    /// Vertices relative to `origin`.
    rel: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    /// Triangles that a vertical ray can hit (nonzero projected area).
    hittable: Vec<u32>,
    bvh: Option<CwBvh>,
    origin: [f64; 3],
    /// Height above every vertex (relative), where rays start.
    top: f64,
    /// Bounds of the mesh (absolute).
    pub bounds: Bounds,
}

/// Twice the signed area of (a, b, p), computed with (a, b) in canonical
/// order so that both triangles sharing an edge get exactly opposite values.
#[inline(always)]
fn edge(a: &[f64; 3], b: &[f64; 3], px: f64, py: f64) -> f64 {
    if (a[0], a[1]) <= (b[0], b[1]) {
        (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])
    } else {
        -((a[0] - b[0]) * (py - b[1]) - (a[1] - b[1]) * (px - b[0]))
    }
}

/// The height of triangle (a, b, c) above (px, py) if the point lies in its
/// projection (edges and vertices included), else `None`.
#[inline(always)]
pub fn vertical_hit(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], px: f64, py: f64) -> Option<f64> {
    let e0 = edge(b, c, px, py);
    let e1 = edge(c, a, px, py);
    let e2 = edge(a, b, px, py);
    let inside = (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
    let sum = e0 + e1 + e2;
    if !inside || sum == 0.0 {
        return None;
    }
    let z = (e0 * a[2] + e1 * b[2] + e2 * c[2]) / sum;
    // Rounding can push the interpolation a hair outside the corners' range.
    let lo = a[2].min(b[2]).min(c[2]);
    let hi = a[2].max(b[2]).max(c[2]);
    Some(z.clamp(lo, hi))
}

impl RayCaster {
    /// Prepares a mesh: relative coordinates, hittable triangles, the BVH.
    pub fn new(mesh: &Mesh) -> Self {
        let bounds = mesh.bounds();
        let origin = bounds.center();
        let rel: Vec<[f64; 3]> =
            mesh.vertices.iter().map(|v| [v[0] - origin[0], v[1] - origin[1], v[2] - origin[2]]).collect();
        let extent = bounds.extent().max(f64::MIN_POSITIVE);
        let pad = 1e-5 * extent;
        let mut hittable = Vec::new();
        let mut boxes = Vec::new();
        for (i, t) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = t.map(|k| rel[k as usize]);
            let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            if area2 == 0.0 || !area2.is_finite() {
                continue;
            }
            let lo = [0, 1, 2].map(|k| (a[k].min(b[k]).min(c[k]) - pad) as f32);
            let hi = [0, 1, 2].map(|k| (a[k].max(b[k]).max(c[k]) + pad) as f32);
            hittable.push(i as u32);
            boxes.push(Footprint(Aabb::new(Vec3A::from(lo), Vec3A::from(hi))));
        }
        let bvh = if boxes.is_empty() {
            None
        } else {
            Some(build_cwbvh(&boxes, BvhBuildParams::medium_build(), &mut std::time::Duration::default()))
        };
        let top = bounds.max[2] - origin[2] + 0.01 * extent + 1.0;
        RayCaster { rel, tris: mesh.triangles.clone(), hittable, bvh, origin, top, bounds }
    }

    /// Number of triangles a vertical ray can hit.
    pub fn hittable(&self) -> usize {
        self.hittable.len()
    }

    /// Tests one triangle; keeps the highest hit (ties: lower index).
    #[inline(always)]
    fn consider(&self, t: u32, px: f64, py: f64, best: &mut Option<Hit>) -> Option<f64> {
        let [a, b, c] = self.tris[t as usize].map(|k| &self.rel[k as usize]);
        let z = vertical_hit(a, b, c, px, py)?;
        let better = match best {
            None => true,
            Some(h) => z > h.z || (z == h.z && t < h.tri),
        };
        if better {
            *best = Some(Hit { z, tri: t });
        }
        Some(z)
    }

    /// The highest hit under (x, y) (absolute mesh coordinates), or `None`
    /// off the mesh. Allocation-free.
    pub fn cast(&self, x: f64, y: f64) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let (px, py) = (x - self.origin[0], y - self.origin[1]);
        // Off the bounds (or not finite): no hit, and nothing unrepresentable reaches the f32 BVH.
        let inside = |v: f64, k: usize| v >= self.bounds.min[k] && v <= self.bounds.max[k];
        if !(inside(x, 0) && inside(y, 1)) {
            return None;
        }
        let ray =
            Ray::new(Vec3A::new(px as f32, py as f32, self.top as f32), Vec3A::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY);
        let mut best: Option<Hit> = None;
        let mut rh = RayHit::none();
        bvh.ray_traverse(ray, &mut rh, |_, id| {
            let t = self.hittable[bvh.primitive_indices[id] as usize];
            match self.consider(t, px, py, &mut best) {
                // Report a distance slightly beyond the true one so the
                // traversal never culls a box holding an equal or higher hit.
                Some(z) => ((self.top - z) * (1.0 + 1e-5) + 1e-5) as f32,
                None => f32::INFINITY,
            }
        });
        best.map(|h| Hit { z: h.z + self.origin[2], tri: h.tri })
    }

    /// The same answer by testing every triangle (the reference for tests
    /// and the benchmark's baseline).
    pub fn cast_brute(&self, x: f64, y: f64) -> Option<Hit> {
        let (px, py) = (x - self.origin[0], y - self.origin[1]);
        let mut best = None;
        for &t in &self.hittable {
            self.consider(t, px, py, &mut best);
        }
        best.map(|h| Hit { z: h.z + self.origin[2], tri: h.tri })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::scenes::grid;

    #[test]
    fn grid_vertices_and_edges_never_miss_and_match_brute_force() {
        // Unit cells; touch points on a quarter-cell lattice hit every vertex,
        // every edge (axis-aligned and diagonal) and interior points.
        let m = grid(8, 8, [0.0, 8.0], [0.0, 8.0], |x, y| (0.7 * x).sin() + 0.3 * y);
        for winding in [false, true] {
            let mut m = m.clone();
            if winding {
                for (k, t) in m.triangles.iter_mut().enumerate() {
                    if k % 3 == 0 {
                        t.swap(1, 2);
                    }
                }
            }
            let rc = RayCaster::new(&m);
            let mut misses = 0;
            for j in 0..=32 {
                for i in 0..=32 {
                    let (x, y) = (i as f64 * 0.25, j as f64 * 0.25);
                    let h = rc.cast(x, y);
                    assert_eq!(h, rc.cast_brute(x, y), "({x}, {y})");
                    match h {
                        None => misses += 1,
                        Some(h) => {
                            let want = (0.7f64 * x).sin() + 0.3 * y;
                            // On vertices the height is exact; elsewhere linear interpolation.
                            if i % 4 == 0 && j % 4 == 0 {
                                assert!((h.z - want).abs() < 1e-12, "({x},{y}) {} vs {want}", h.z);
                            }
                        }
                    }
                }
            }
            assert_eq!(misses, 0);
            assert!(rc.cast(-0.01, 4.0).is_none() && rc.cast(4.0, 8.000001).is_none());
        }
    }

    #[test]
    fn far_from_the_origin_nothing_is_lost() {
        let off = 1e6;
        let m = grid(16, 16, [off, off + 16.0], [off, off + 16.0], |x, y| 0.1 * (x - off) + 0.05 * (y - off));
        let rc = RayCaster::new(&m);
        for k in 0..=64 {
            let (x, y) = (off + k as f64 * 0.25, off + 16.0 - k as f64 * 0.25);
            let h = rc.cast(x, y).expect("hit");
            assert!((h.z - (0.1 * (x - off) + 0.05 * (y - off))).abs() < 1e-9);
            assert_eq!(Some(h), rc.cast_brute(x, y));
        }
    }

    #[test]
    fn highest_hit_wins_and_walls_and_degenerates_are_skipped() {
        let v = vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [0.0, 4.0, 0.0], // floor triangle
            [0.0, 0.0, 2.0],
            [4.0, 0.0, 2.0],
            [0.0, 4.0, 2.0], // roof triangle above it
            [1.0, 1.0, 0.0],
            [1.0, 1.0, 5.0],
            [2.0, 1.0, 0.0], // vertical wall
            [1.0, 1.0, 9.0],
            [2.0, 2.0, 9.0],
            [3.0, 3.0, 9.0], // zero-area (collinear) triangle
        ];
        let m = Mesh::new(v, vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]], 0.0);
        let rc = RayCaster::new(&m);
        assert_eq!(rc.hittable(), 2);
        let h = rc.cast(1.0, 1.0).unwrap();
        assert_eq!((h.z, h.tri), (2.0, 1));
        assert_eq!(rc.cast(1.5, 1.0).unwrap().z, 2.0);
        assert_eq!(rc.cast(2.0, 2.0).unwrap().z, 2.0);
        assert!(rc.cast(3.0, 3.0).is_none());
        assert!(rc.cast(f64::NAN, 0.0).is_none());
        assert!(rc.cast(1e300, -1e300).is_none() && rc.cast(f64::INFINITY, 1.0).is_none());
    }
}
