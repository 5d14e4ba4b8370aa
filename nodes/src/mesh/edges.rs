//! Edge emphasis (dissertation §4.1.2): the dihedral angle θ between the
//! triangle hit in the previous tick and the one hit now, convex edges
//! only, sharpness S = −(θ − 180°)/(180° − θ_min) (Eq. 4.8) relative to the
//! mesh's sharpest convex edge θ_min, and the EDGE-TICK intensity
//! I_e = 0.7·S + 0.3 (Eq. 4.9).
//!
//! **Sign convention.** Normals are [`Mesh::normals`]: consistent over
//! each connected piece whatever the file's winding, the faces a ray from
//! above hits first facing it (up), a closed solid's pointing out. θ is the
//! angle inside the solid: for two faces a → b with hit points p_a, p_b,
//! the bend is convex when each point lies behind the other face's plane,
//! (n_a − n_b)·(p_b − p_a) < 0, and then θ = 180° − ∠(n_a, n_b); otherwise
//! θ ≥ 180° (concave or flat) and the edge is not emphasized. A ridge of
//! two faces tilted ±45° (the top edge of a cube standing on an edge) has
//! θ = 90°, and so has every edge of an axis-aligned cube.
//!
//! **Walls.** A vertical face is never hit by a vertical ray, so stepping
//! over a wall (the top of a cube to the floor) joins two parallel faces:
//! the normals alone see no edge. The profile in the vertical plane of the
//! motion does: with the slope angles of face a, of the chord p_a → p_b and
//! of face b along the motion, α_a, α_c, α_b, crossing an ordinary edge
//! keeps α_c between α_a and α_b, while a wall makes the chord steeper than
//! both — a drop (α_c < min) turns convexly by α_a − α_c at its top, a step
//! up (α_c > max) by α_c − α_b — and θ is then the smaller of the normals'
//! angle and 180° minus that turn (about 90° over a wall). The profile is
//! not used otherwise: a vertical section across a sloping edge (a hip) is
//! not its normal section and can look sharper than the edge is.
//!
//! **θ_min** is computed once over every edge of the welded mesh: pairs of
//! faces (every pair around a non-manifold edge — the finger can cross
//! from any of them to any other; walls included, by the general rule when
//! the pair is consistently oriented, else as a wall going down from the
//! edge, θ = 180° − ∠(n_a, w), w the horizontal outward direction), and
//! boundary edges of open meshes: wholly above the floor a boundary is a
//! cliff (the same wall rule) — when it stands higher than the face beside
//! it is wide × tan(180° − `max_angle`); a lower step bends no more than a
//! facet and is not an edge (the 0.2 % tails of the Gaussian bumps where a
//! generated scene ends, 30 µm above the screen, are no cliff, so the
//! Gaussian scenes have no convex edge and `mesh.edges` on them is a
//! constant, `docs/pruning.md`); touching or below the floor it meets the
//! floor plane from below or level and is not convex. A mesh without a
//! convex edge has θ_min = 180° and never ticks (S = 0).
//!
//! Convex bends flatter than `max_angle` (default 160°) are the facets of a
//! smooth surface, not edges: they are neither emphasized nor counted in
//! θ_min (Fig. 4.4 marks θ < 135° as relatively sharp).

use super::raycast::vertical_hit;
use super::trimesh::{dot, sorted_edges, sub, Mesh};

/// Faces with n_z at or below this are vertical walls.
const VERTICAL: f64 = 1e-12;

/// What the mesh's edges are made of.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EdgeCensus {
    /// Distinct edges.
    pub edges: usize,
    /// Edges with one face (open mesh).
    pub boundary: usize,
    /// Edges with three or more faces.
    pub non_manifold: usize,
    /// Convex edges (or face pairs) sharper than `max_angle`.
    pub convex: usize,
    /// Of [`Self::convex`], the open mesh's boundary edges read as cliffs
    /// (standing above the floor, see the module's doc).
    pub cliffs: usize,
    /// The sharpest convex angle θ_min, degrees (180 when none).
    pub theta_min: f64,
}

/// Angle between unit vectors, degrees.
fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    dot(a, b).clamp(-1.0, 1.0).acos().to_degrees()
}

/// θ of a convex wall or cliff at edge (v0, v1) of a face with normal `n`
/// and opposite vertex `o`: 180° − ∠(n, w), w horizontal, away from the face.
fn wall_angle(n: [f64; 3], v0: [f64; 3], v1: [f64; 3], o: [f64; 3]) -> Option<f64> {
    let e = sub(v1, v0);
    let len = e[0].hypot(e[1]);
    if len == 0.0 {
        return None; // a vertical edge: no wall along it
    }
    let mut w = [e[1] / len, -e[0] / len, 0.0];
    if dot(w, sub(o, v0)) > 0.0 {
        w = w.map(|x| -x);
    }
    Some(180.0 - angle(n, w))
}

/// Horizontal distance from `o` to the line through `v0`, `v1` (the width
/// of a face across its edge, seen from above).
fn across(v0: [f64; 3], v1: [f64; 3], o: [f64; 3]) -> f64 {
    let (ex, ey) = (v1[0] - v0[0], v1[1] - v0[1]);
    let len = ex.hypot(ey);
    if len == 0.0 {
        return 0.0;
    }
    ((o[0] - v0[0]) * ey - (o[1] - v0[1]) * ex).abs() / len
}

/// A normal turned to face up (the slope along a direction does not depend
/// on the normal's sign; the angle formulas below do).
fn up(n: [f64; 3]) -> [f64; 3] {
    if n[2] < 0.0 {
        n.map(|x| -x)
    } else {
        n
    }
}

/// The convex angle of faces a and b sharing edge (v0, v1), if convex.
/// When the two run the edge in opposite directions (consistently
/// oriented, [`Mesh`]'s normals then point out of the solid) the general
/// rule holds for any faces, walls included: convex when each opposite
/// vertex lies behind the other face's plane, θ = 180° − ∠(n_a, n_b).
/// Otherwise (around a non-manifold edge, or on a non-orientable piece)
/// the faces are taken as seen from above: normals turned up, and a
/// vertical face is a wall, convex when it goes down from the edge.
fn pair_angle(m: &Mesh, a: u32, b: u32, v0: u32, v1: u32) -> Option<f64> {
    let runs = |t: u32| {
        let tri = m.triangles[t as usize];
        (0..3).any(|k| tri[k] == v0 && tri[(k + 1) % 3] == v1)
    };
    let opp = |t: u32| m.triangles[t as usize].into_iter().find(|&k| k != v0 && k != v1);
    let (oa, ob) = (opp(a)?, opp(b)?);
    let (na, nb) = (m.normals[a as usize], m.normals[b as usize]);
    let (p0, p1) = (m.vertices[v0 as usize], m.vertices[v1 as usize]);
    let (va, vb) = (m.vertices[oa as usize], m.vertices[ob as usize]);
    let scale = dot(sub(p1, p0), sub(p1, p0)).sqrt().max(1e-300);
    let convex = |na: [f64; 3], nb: [f64; 3]| dot(na, sub(vb, p0)) + dot(nb, sub(va, p0)) < -1e-12 * scale;
    if runs(a) != runs(b) {
        return convex(na, nb).then(|| 180.0 - angle(na, nb));
    }
    let (na, nb) = (up(na), up(nb));
    match (na[2] <= VERTICAL, nb[2] <= VERTICAL) {
        (true, true) => None,
        (false, true) | (true, false) => {
            let (n, o, wall_o) = if nb[2] <= VERTICAL { (na, va, vb) } else { (nb, vb, va) };
            (wall_o[2] < p0[2].min(p1[2])).then(|| wall_angle(n, p0, p1, o)).flatten()
        }
        (false, false) => convex(na, nb).then(|| 180.0 - angle(na, nb)),
    }
}

/// The census and θ_min of a mesh whose floor (screen plane) is at `floor`.
pub fn census(m: &Mesh, floor: f64, max_angle: f64) -> EdgeCensus {
    // Each edge with its triangles in the order they are listed (every
    // count and the minimum angle are the same in any order of the edges).
    let mut tally = Tally::new(m, floor, max_angle);
    let mut faces = Vec::new();
    for run in sorted_edges(&m.triangles).chunk_by(|a, b| a.same_edge(*b)) {
        faces.clear();
        faces.extend(run.iter().map(|e| e.triangle()));
        let (v0, v1) = run[0].vertices();
        tally.edge(v0, v1, &faces);
    }
    tally.c
}

/// A census being taken, one edge at a time.
struct Tally<'a> {
    m: &'a Mesh,
    floor: f64,
    max_angle: f64,
    ext: f64,
    c: EdgeCensus,
}

impl<'a> Tally<'a> {
    fn new(m: &'a Mesh, floor: f64, max_angle: f64) -> Self {
        let ext = m.bounds().extent().max(1e-300);
        Self { m, floor, max_angle, ext, c: EdgeCensus { theta_min: 180.0, ..Default::default() } }
    }

    /// A convex angle `th`, counted when sharper than `max_angle`; true if it was.
    fn take(&mut self, th: f64) -> bool {
        let sharp = th < self.max_angle;
        if sharp {
            self.c.convex += 1;
            self.c.theta_min = self.c.theta_min.min(th);
        }
        sharp
    }

    /// The edge from vertex `v0` to `v1` and the triangles on it, in order.
    fn edge(&mut self, v0: u32, v1: u32, faces: &[u32]) {
        let m = self.m;
        self.c.edges += 1;
        if let [t] = *faces {
            self.c.boundary += 1;
            let n = up(m.normals[t as usize]);
            let (p0, p1) = (m.vertices[v0 as usize], m.vertices[v1 as usize]);
            let drop = p0[2].min(p1[2]) - self.floor;
            let o = m.triangles[t as usize].into_iter().find(|&k| k != v0 && k != v1);
            if n[2] > VERTICAL && drop > 1e-9 * self.ext {
                let o = o.map(|o| m.vertices[o as usize]);
                // A step lower than the face beside it is wide × tan(180° − max_angle)
                // bends no more than a facet would: not a cliff.
                let turn = (180.0 - self.max_angle).clamp(0.0, 89.0).to_radians().tan();
                let tall = o.is_some_and(|o| drop > turn * across(p0, p1, o));
                if let Some(th) = o.filter(|_| tall).and_then(|o| wall_angle(n, p0, p1, o)) {
                    if self.take(th) {
                        self.c.cliffs += 1;
                    }
                }
            }
            return;
        }
        if faces.len() > 2 {
            self.c.non_manifold += 1;
        }
        for (i, &a) in faces.iter().enumerate() {
            for &b in &faces[i + 1..] {
                if let Some(th) = pair_angle(m, a, b, v0, v1) {
                    self.take(th);
                }
            }
        }
    }
}

/// Eq. 4.8, clamped to [0, 1]; 0 when the mesh has no convex edge.
pub fn sharpness(theta: f64, theta_min: f64) -> f64 {
    if theta_min >= 180.0 || theta >= 180.0 {
        return 0.0;
    }
    (-(theta - 180.0) / (180.0 - theta_min)).clamp(0.0, 1.0)
}

/// Eq. 4.9.
pub fn edge_intensity(s: f64) -> f64 {
    0.7 * s + 0.3
}

/// One tick's edge result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeEvent {
    /// θ of the bend crossed this tick, degrees (180 when none).
    pub theta: f64,
    /// Eq. 4.8 (0 when none).
    pub sharpness: f64,
    /// Eq. 4.9 when an edge is emphasized this tick, else 0.
    pub intensity: f64,
}

/// No edge this tick.
pub const NO_EDGE: EdgeEvent = EdgeEvent { theta: 180.0, sharpness: 0.0, intensity: 0.0 };

/// Tracks the triangle under the finger from tick to tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeTracker {
    theta_min: f64,
    max_angle: f64,
    max_step: f64,
    floor: f64,
    prev: Option<([f64; 3], Option<u32>)>,
}

/// Slope angle (degrees) of a face with normal `n` along horizontal unit `d`.
fn slope_angle(n: [f64; 3], d: [f64; 2]) -> f64 {
    let n = up(n);
    (-(n[0] * d[0] + n[1] * d[1])).atan2(n[2]).to_degrees()
}

/// The height of triangle (a, b, c)'s plane above (x, y) when the point
/// lies inside it or outside by at most 1e-9 of its size (barycentric), else `None`.
fn near_hit(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], x: f64, y: f64) -> Option<f64> {
    let d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let u = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / d;
    let v = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / d;
    let tol = 1e-9;
    if u >= -tol && v >= -tol && u + v <= 1.0 + tol {
        let z = a[2] + u * (b[2] - a[2]) + v * (c[2] - a[2]);
        Some(z.clamp(a[2].min(b[2]).min(c[2]), a[2].max(b[2]).max(c[2])))
    } else {
        None
    }
}

impl EdgeTracker {
    /// A tracker for a mesh with the given θ_min.
    pub fn new(theta_min: f64, max_angle: f64, max_step: f64, floor: f64) -> Self {
        EdgeTracker { theta_min, max_angle, max_step, floor, prev: None }
    }

    /// Back to t = 0.
    pub fn reset(&mut self) {
        self.prev = None;
    }

    /// The surface point and triangle under (x, y), given the triangle the
    /// ray cast reported (`None`, or an index that does not hold the point,
    /// means the floor).
    pub fn locate(&self, m: &Mesh, x: f64, y: f64, tri: Option<u32>) -> ([f64; 3], Option<u32>) {
        if let Some(t) = tri.filter(|&t| (t as usize) < m.triangles.len()) {
            let [a, b, c] = m.corners(t as usize);
            if let Some(z) = vertical_hit(&a, &b, &c, x, y) {
                return ([x, y, z], Some(t));
            }
            // On an edge the ray caster (relative coordinates) and this test (absolute)
            // can round to different sides: a point within a hair of the triangle is on it,
            // or the finger would seem to drop to the floor and back — a spurious cliff.
            if let Some(z) = near_hit(&a, &b, &c, x, y) {
                return ([x, y, z], Some(t));
            }
        }
        ([x, y, self.floor], None)
    }

    /// One tick: the finger at `p` on triangle `tri` (`None`: the floor).
    pub fn step(&mut self, m: &Mesh, p: [f64; 3], tri: Option<u32>) -> EdgeEvent {
        if !p.iter().all(|v| v.is_finite()) {
            return NO_EDGE;
        }
        let prev = self.prev.replace((p, tri));
        let Some((q, qt)) = prev else { return NO_EDGE };
        if qt == tri {
            return NO_EDGE;
        }
        let up = [0.0, 0.0, 1.0];
        let normal = |t: Option<u32>| t.map_or(up, |t| m.normals[t as usize]);
        let (na, nb) = (normal(qt), normal(tri));
        let d3 = sub(p, q);
        let dr = d3[0].hypot(d3[1]);
        if dr > self.max_step {
            return NO_EDGE; // a jump, not a crossing
        }
        let mut theta = 180.0;
        if dot(sub(na, nb), d3) < 0.0 {
            theta = 180.0 - angle(na, nb);
        }
        if dr > 0.0 {
            let d = [d3[0] / dr, d3[1] / dr];
            let (aa, ab) = (slope_angle(na, d), slope_angle(nb, d));
            let ac = d3[2].atan2(dr).to_degrees();
            let cliff = if ac < aa.min(ab) {
                aa - ac
            } else if ac > aa.max(ab) {
                ac - ab
            } else {
                0.0
            };
            theta = f64::min(theta, 180.0 - cliff);
        }
        let theta = theta.max(0.0);
        if theta >= self.max_angle {
            return EdgeEvent { theta, ..NO_EDGE };
        }
        let s = sharpness(theta, self.theta_min);
        if s <= 0.0 {
            return EdgeEvent { theta, ..NO_EDGE };
        }
        EdgeEvent { theta, sharpness: s, intensity: edge_intensity(s) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::raycast::RayCaster;
    use crate::mesh::scenes::{grid, scene, Shape};

    /// The census as it was taken before the sorted edge list: a SipHash
    /// map from each vertex pair to its triangles, visited in the map's
    /// (random) order.
    fn census_by_map(m: &Mesh, floor: f64, max_angle: f64) -> EdgeCensus {
        let mut map: std::collections::HashMap<(u32, u32), Vec<u32>> = Default::default();
        for (t, tri) in m.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                map.entry((a.min(b), a.max(b))).or_default().push(t as u32);
            }
        }
        let mut tally = Tally::new(m, floor, max_angle);
        for (&(v0, v1), faces) in &map {
            tally.edge(v0, v1, faces);
        }
        tally.c
    }

    #[test]
    fn the_census_is_that_of_the_edge_map() {
        let mut meshes = vec![scene(Shape::Gaussian, "2B2H", 12).unwrap(), scene(Shape::Frustum, "1B3H", 9).unwrap()];
        // A cube with a fin (a third triangle on one edge) and an open flap.
        let c = cube(0.3, 0.2, true);
        let (mut v, mut t) = (c.vertices.clone(), c.triangles.clone());
        v.extend([[2.0, 2.0, 3.0], [0.9, -0.7, 0.1]]);
        let n = v.len() as u32;
        t.push([t[0][0], t[0][1], n - 2]);
        t.push([t[5][1], t[5][2], n - 1]);
        meshes.push(Mesh::new(v, t, 0.0));
        for m in &meshes {
            for (floor, max_angle) in [(m.bounds().min[2], 160.0), (m.bounds().min[2] - 0.5, 175.0)] {
                let c = census(m, floor, max_angle);
                assert_eq!(c, census_by_map(m, floor, max_angle));
                assert!(c.edges > 0 && c.convex > 0, "{c:?}");
            }
        }
        assert!(census(&meshes[2], 0.0, 175.0).non_manifold > 0);
    }

    /// A unit cube rotated by `rx` about x then `ry` about y, 12 triangles
    /// in the given winding (true = outward).
    fn cube(rx: f64, ry: f64, outward: bool) -> Mesh {
        let mut v = Vec::new();
        for k in 0..8 {
            let p = [(k & 1) as f64 - 0.5, ((k >> 1) & 1) as f64 - 0.5, ((k >> 2) & 1) as f64 - 0.5];
            let (c, s) = (rx.cos(), rx.sin());
            let p = [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]];
            let (c, s) = (ry.cos(), ry.sin());
            v.push([c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]]);
        }
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut t = Vec::new();
        for q in quads {
            let (a, b) = if outward {
                ([q[0], q[1], q[2]], [q[0], q[2], q[3]])
            } else {
                ([q[0], q[2], q[1]], [q[0], q[3], q[2]])
            };
            t.push(a);
            t.push(b);
        }
        Mesh::new(v, t, 0.0)
    }

    #[test]
    fn cube_edges_are_90_degrees_and_convex_whatever_the_winding() {
        let q = std::f64::consts::FRAC_PI_4;
        for outward in [true, false] {
            // Standing on an edge: the top ridge is a 90° convex edge between two faces at ±45°.
            let m = cube(q, 0.0, outward);
            let c = census(&m, m.bounds().min[2], 160.0);
            assert!((c.theta_min - 90.0).abs() < 1e-9, "{c:?}");
            assert_eq!((c.edges, c.boundary, c.non_manifold), (18, 0, 0));
            // Scan across the ridge (along y) at 1 kHz-like steps.
            let rc = RayCaster::new(&m);
            let mut tr = EdgeTracker::new(c.theta_min, 160.0, 1.0, m.bounds().min[2]);
            let mut events = Vec::new();
            for k in 0..200 {
                let y = -0.5 + k as f64 * 0.005;
                let h = rc.cast(0.1, y).unwrap();
                let e = tr.step(&m, [0.1, y, h.z], Some(h.tri));
                if e.intensity > 0.0 {
                    events.push((y, e));
                }
            }
            assert_eq!(events.len(), 1, "{events:?}");
            let (y, e) = events[0];
            assert!(y.abs() < 0.01);
            assert!((e.theta - 90.0).abs() < 1e-9, "{e:?}");
            assert!((e.sharpness - 1.0).abs() < 1e-9 && (e.intensity - 1.0).abs() < 1e-9);
        }
        // Axis-aligned: all twelve edges are convex 90° (the walls' outward
        // normals are known from the orientation); stepping off the top onto
        // the floor is caught by the profile.
        let m = cube(0.0, 0.0, true);
        let floor = m.bounds().min[2];
        let c = census(&m, floor, 160.0);
        assert!((c.theta_min - 90.0).abs() < 1e-9 && c.convex == 12, "{c:?}");
        let rc = RayCaster::new(&m);
        let mut tr = EdgeTracker::new(c.theta_min, 160.0, 1.0, floor);
        let mut hits = 0;
        for k in 0..100 {
            let x = k as f64 * 0.01;
            let h = rc.cast(x, 0.0);
            let (p, t) = tr.locate(&m, x, 0.0, h.map(|h| h.tri));
            let e = tr.step(&m, p, t);
            if e.intensity > 0.0 {
                hits += 1;
                assert!(e.theta < 91.0 && e.sharpness > 0.98, "{e:?}");
            }
        }
        assert_eq!(hits, 1);
    }

    #[test]
    fn concave_edges_are_ignored_and_a_valley_has_no_convex_edge() {
        // V-shaped valley z = |x| − 1 with its rim on the floor: one concave edge.
        let m = grid(2, 2, [-1.0, 1.0], [-1.0, 1.0], |x, _| x.abs() - 1.0);
        let c = census(&m, 0.0, 160.0);
        assert_eq!(c.theta_min, 180.0);
        assert_eq!(sharpness(120.0, c.theta_min), 0.0);
        let rc = RayCaster::new(&m);
        let mut tr = EdgeTracker::new(c.theta_min, 160.0, 1.0, 0.0);
        assert_eq!(c.boundary, 8);
        for k in 0..100 {
            let x = -0.5 + k as f64 * 0.01;
            let h = rc.cast(x, 0.3).unwrap();
            assert_eq!(tr.step(&m, [x, 0.3, h.z], Some(h.tri)).intensity, 0.0);
        }
        // Ridge z = −|x|: convex with θ = 180 − 90 = 90°.
        let m = grid(2, 2, [-1.0, 1.0], [-1.0, 1.0], |x, _| -x.abs());
        assert!((census(&m, -1.0, 160.0).theta_min - 90.0).abs() < 1e-9);
    }

    #[test]
    fn frustum_angles_match_their_geometry() {
        // Top–side: 180° − atan 2; side–side (hip): 180° − acos(1/5).
        let top_side = 180.0 - 2f64.atan().to_degrees();
        let hip = 180.0 - (0.2f64).acos().to_degrees();
        // Scenes stand on the screen plane z = 0 (their floor).
        let m = scene(Shape::Frustum, "bump", 0).unwrap();
        let c = census(&m, 0.0, 160.0);
        assert!((c.theta_min - hip).abs() < 1e-9, "{c:?} vs {hip}");
        assert_eq!(c.convex, 4 + 4);
        // A hole: the rim (ground–side) is the only convex edge; the open
        // border of the ground lies on the floor and is not an edge.
        let m = scene(Shape::Frustum, "hole", 0).unwrap();
        let c = census(&m, 0.0, 160.0);
        assert!((c.theta_min - top_side).abs() < 1e-9, "{c:?} vs {top_side}");
        assert_eq!((c.boundary, c.convex), (4, 4));
    }

    #[test]
    fn boundary_and_non_manifold_edges_are_handled() {
        // A square floating at z = 1 over a floor at 0: its border is a 90° cliff.
        let sq = grid(1, 1, [0.0, 1.0], [0.0, 1.0], |_, _| 1.0);
        let c = census(&sq, 0.0, 160.0);
        assert_eq!((c.boundary, c.convex, c.cliffs), (4, 4, 4));
        assert!((c.theta_min - 90.0).abs() < 1e-9);
        // The same square lying on the floor: no edge.
        assert_eq!(census(&sq, 1.0, 160.0).theta_min, 180.0);
        // A fin: three faces on the edge (0,0,0)-(1,0,0): two roof halves and
        // a third face going up. Pairs: roof halves 90°, ...
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, -1.0, -1.0], [0.5, 1.0, -1.0], [0.5, 0.0, 1.0]];
        let m = Mesh::new(v, vec![[0, 1, 2], [0, 1, 3], [0, 1, 4]], 0.0);
        let c = census(&m, -1.0, 160.0);
        assert_eq!(c.non_manifold, 1);
        // Roof halves: normals (0,−1,1)/√2 and (0,1,1)/√2 → 90°; the fin is
        // vertical and goes up (not convex); the roof's open borders reach
        // down to the floor (not cliffs).
        assert!((c.theta_min - 90.0).abs() < 1e-9, "{c:?}");
        assert_eq!((c.convex, c.boundary, c.cliffs), (1, 6, 0));
    }

    #[test]
    fn eq_4_8_and_4_9() {
        assert_eq!(sharpness(180.0, 90.0), 0.0);
        assert_eq!(sharpness(90.0, 90.0), 1.0);
        assert!((sharpness(135.0, 90.0) - 0.5).abs() < 1e-15);
        assert_eq!(sharpness(60.0, 90.0), 1.0);
        assert_eq!(edge_intensity(0.0), 0.3);
        assert_eq!(edge_intensity(1.0), 1.0);
        assert!((edge_intensity(0.5) - 0.65).abs() < 1e-15);
    }
}
