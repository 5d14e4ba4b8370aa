//! The triangle mesh every mesh node works on: f64 vertices welded so that
//! neighbouring triangles share edges, triangles as vertex-index triples,
//! per-triangle unit normals, bounds and a content hash.
//!
//! **Orientation.** The file's winding is not trusted: each connected
//! piece (triangles joined across edges with exactly two faces) is
//! re-oriented consistently from one seed — among the faces at the piece's
//! highest vertex the least steep one, turned to face up (toward the ray).
//! A neighbour that runs the shared edge in the same direction as its
//! oriented neighbour is flipped. Triangles are stored in the oriented
//! winding (right-hand rule gives the normal), so a closed solid ends up
//! with outward normals and a terrain with upward ones, whatever the
//! file's winding was — even mixed.

use super::error::MeshError;
use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// A triangle mesh in mesh units (the scenes of §4.2 are in cm).
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// Unit normal of each triangle in the oriented winding (see the module
    /// doc); the faces a ray from above hits first face up. Never zero:
    /// zero-area triangles are dropped.
    pub normals: Vec<[f64; 3]>,
}

/// Axis-aligned bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Smallest coordinates.
    pub min: [f64; 3],
    /// Largest coordinates.
    pub max: [f64; 3],
}

impl Bounds {
    /// The centre.
    pub fn center(&self) -> [f64; 3] {
        [0, 1, 2].map(|i| 0.5 * (self.min[i] + self.max[i]))
    }
    /// The largest side length.
    pub fn extent(&self) -> f64 {
        (0..3).map(|i| self.max[i] - self.min[i]).fold(0.0, f64::max)
    }
}

/// The unit normal of a triangle (right-hand rule over its vertex order),
/// or zero when its area is zero.
pub fn raw_normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let u = sub(b, a);
    let v = sub(c, a);
    let n = cross(u, v);
    let len = dot(n, n).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|x| x / len)
    } else {
        [0.0; 3]
    }
}

/// a − b.
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// a · b.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// a × b.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

impl Mesh {
    /// A mesh from vertices and triangles: vertices at the same position
    /// (within `weld` mesh units; 0 = bit-identical coordinates) are merged;
    /// triangles of zero area (corners merged into fewer than three, or
    /// collinear) and repeats of a triangle already kept (the same three
    /// corners, in either winding: a two-sided sheet) are dropped — they
    /// hold no surface a ray could feel, and would make the edges they
    /// share look non-manifold; vertices no triangle uses are dropped;
    /// the triangles are oriented consistently (module doc) and normals are
    /// computed from the geometry (never taken from a file).
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>, weld: f64) -> Self {
        let (vertices, remap) = weld_vertices(&vertices, weld);
        let mut tris = Vec::with_capacity(triangles.len());
        let mut normals: Vec<[f64; 3]> = Vec::with_capacity(triangles.len());
        let mut seen: KeySet<[u32; 3]> = KeySet::with_capacity_and_hasher(triangles.len(), Default::default());
        for t in triangles {
            let t = t.map(|i| remap[i as usize]);
            let n = raw_normal(vertices[t[0] as usize], vertices[t[1] as usize], vertices[t[2] as usize]);
            let mut key = t;
            key.sort_unstable();
            // Zero area (corners merged or collinear) or the same corners again (either winding).
            if n != [0.0; 3] && seen.insert(key) {
                tris.push(t);
                normals.push(n);
            }
        }
        let vertices = drop_unused(vertices, &mut tris);
        for (t, flip) in orientation(&vertices, &tris, &normals).into_iter().enumerate() {
            if flip {
                tris[t].swap(1, 2);
                normals[t] = normals[t].map(|x| -x);
            }
        }
        Mesh { vertices, triangles: tris, normals }
    }

    /// A mesh read from a file or scene named `what`: [`Mesh::new`], refused
    /// when it has nothing a ray can hit — no face at all
    /// ([`MeshError::Empty`]) or only faces of zero area, collapsed by the
    /// weld or with collinear corners ([`MeshError::Degenerate`]).
    pub fn from_faces(
        what: &str,
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        weld: f64,
    ) -> Result<Self, MeshError> {
        let read = triangles.len();
        if read == 0 {
            return Err(MeshError::Empty { what: what.to_string() });
        }
        let mesh = Mesh::new(vertices, triangles, weld);
        if mesh.normals.iter().all(|n| *n == [0.0; 3]) {
            return Err(MeshError::Degenerate { what: what.to_string(), triangles: read });
        }
        Ok(mesh)
    }

    /// The three corners of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [[f64; 3]; 3] {
        self.triangles[t].map(|i| self.vertices[i as usize])
    }

    /// Bounds of all vertices used by a triangle (all vertices if none).
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds { min: [f64::INFINITY; 3], max: [f64::NEG_INFINITY; 3] };
        for v in &self.vertices {
            for (i, x) in v.iter().enumerate() {
                b.min[i] = b.min[i].min(*x);
                b.max[i] = b.max[i].max(*x);
            }
        }
        if self.vertices.is_empty() {
            b = Bounds { min: [0.0; 3], max: [0.0; 3] };
        }
        b
    }

    /// A 64-bit FNV-1a hash of the welded vertices and triangles (bit
    /// patterns), which keys the calibration cache.
    pub fn content_hash(&self) -> u64 {
        let mut h = Fnv::new();
        h.u64(self.vertices.len() as u64);
        for v in &self.vertices {
            for x in v {
                h.u64(x.to_bits());
            }
        }
        h.u64(self.triangles.len() as u64);
        for t in &self.triangles {
            for i in t {
                h.u64(*i as u64);
            }
        }
        h.finish()
    }
}

/// Which triangles to flip so each connected piece is consistently
/// oriented with its seed facing up (see the module doc).
fn orientation(v: &[[f64; 3]], tris: &[[u32; 3]], normals: &[[f64; 3]]) -> Vec<bool> {
    let across = edge_neighbours(tris);
    let neighbours = |t: usize, out: &mut Vec<(usize, bool)>| {
        out.clear();
        out.extend(across[t].iter().flatten().map(|&(n, inconsistent)| (n as usize, inconsistent)));
    };
    let mut flip = vec![false; tris.len()];
    let mut component = vec![usize::MAX; tris.len()];
    let mut done = vec![false; tris.len()];
    let mut buf = Vec::new();
    let mut stack = Vec::new();
    for start in 0..tris.len() {
        if component[start] != usize::MAX {
            continue;
        }
        // Collect the piece.
        let mut piece = vec![start];
        component[start] = start;
        stack.push(start);
        while let Some(t) = stack.pop() {
            neighbours(t, &mut buf);
            for &(n, _) in &buf {
                if component[n] == usize::MAX {
                    component[n] = start;
                    piece.push(n);
                    stack.push(n);
                }
            }
        }
        // Seed: the least steep face at the piece's highest vertex, facing up.
        let top = piece.iter().flat_map(|&t| tris[t]).max_by(|&a, &b| v[a as usize][2].total_cmp(&v[b as usize][2]));
        let seed = piece
            .iter()
            .copied()
            .filter(|&t| top.is_some_and(|tv| tris[t].contains(&tv)))
            .max_by(|&a, &b| normals[a][2].abs().total_cmp(&normals[b][2].abs()))
            .unwrap_or(start);
        flip[seed] = normals[seed][2] < 0.0;
        done[seed] = true;
        stack.push(seed);
        while let Some(t) = stack.pop() {
            neighbours(t, &mut buf);
            for &(n, inconsistent) in &buf {
                if !done[n] {
                    done[n] = true;
                    flip[n] = flip[t] ^ inconsistent;
                    stack.push(n);
                }
            }
        }
    }
    flip
}

/// One triangle's edge, packed so that sorting the numbers sorts the edges
/// by their vertex pair (low, high), then by triangle, then by corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) struct EdgeEntry(u128);

impl EdgeEntry {
    /// Edge `k` (corner k to corner k + 1) of triangle `t`, from vertex `a` to `b`.
    fn new(a: u32, b: u32, t: usize, k: usize) -> Self {
        let pair = ((a.min(b) as u128) << 32) | a.max(b) as u128;
        Self((pair << 64) | ((t as u128) << 3) | ((k as u128) << 1) | u128::from(a < b))
    }
    /// The vertex pair, lower index first.
    pub(crate) fn vertices(self) -> (u32, u32) {
        ((self.0 >> 96) as u32, (self.0 >> 64) as u32)
    }
    /// The triangle.
    pub(crate) fn triangle(self) -> u32 {
        (self.0 >> 3) as u32
    }
    /// Which of the triangle's edges (0, 1, 2).
    fn corner(self) -> usize {
        (self.0 >> 1 & 3) as usize
    }
    /// True when the triangle runs along it from the lower vertex index to the higher.
    fn low_to_high(self) -> bool {
        self.0 & 1 == 1
    }
    /// True when `other` joins the same two vertices.
    pub(crate) fn same_edge(self, other: EdgeEntry) -> bool {
        self.0 >> 64 == other.0 >> 64
    }
}

/// Every triangle's edges, sorted by their vertex pair, ties in the order
/// (triangle, corner) they were listed in: the edges shared by the same
/// triangles are neighbours, in the order a map from each vertex pair to
/// the list of its triangles, filled triangle by triangle, would hold
/// them — without one allocation per edge.
pub(crate) fn sorted_edges(tris: &[[u32; 3]]) -> Vec<EdgeEntry> {
    let mut list = Vec::with_capacity(tris.len() * 3);
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            list.push(EdgeEntry::new(tri[k], tri[(k + 1) % 3], t, k));
        }
    }
    list.sort_unstable();
    list
}

/// For each triangle and each of its edges k (corner k to corner k + 1),
/// the triangle across that edge and whether the two run the same way
/// along it (inconsistent winding), where exactly two triangles share the
/// edge; `None` on a boundary edge or one shared by three or more. The two
/// of an edge are taken in [`sorted_edges`]' order — as the map from each
/// edge to the list of its triangles that this replaces (the test keeps it
/// as the reference) took them.
fn edge_neighbours(tris: &[[u32; 3]]) -> Vec<[Option<(u32, bool)>; 3]> {
    let mut across = vec![[None; 3]; tris.len()];
    for run in sorted_edges(tris).chunk_by(|a, b| a.same_edge(*b)) {
        if let [p, q] = *run {
            let inconsistent = p.low_to_high() == q.low_to_high();
            across[p.triangle() as usize][p.corner()] = Some((q.triangle(), inconsistent));
            across[q.triangle() as usize][q.corner()] = Some((p.triangle(), inconsistent));
        }
    }
    across
}

/// FNV-1a, 64 bits.
#[derive(Debug, Clone, Copy)]
pub struct Fnv(u64);

impl Fnv {
    /// The offset basis.
    pub fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    /// Hashes the 8 bytes of `x` (little-endian).
    pub fn u64(&mut self, x: u64) {
        for b in x.to_le_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    /// The hash.
    pub fn finish(&self) -> u64 {
        self.0
    }
}

impl Default for Fnv {
    fn default() -> Self {
        Self::new()
    }
}

/// Keeps the vertices some triangle uses (in their order), renumbering
/// the triangles: bounds, floor and hash then describe the surface only.
fn drop_unused(vertices: Vec<[f64; 3]>, tris: &mut [[u32; 3]]) -> Vec<[f64; 3]> {
    let mut new_index = vec![u32::MAX; vertices.len()];
    for t in tris.iter() {
        for &i in t {
            new_index[i as usize] = 0;
        }
    }
    let mut kept = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.into_iter().enumerate() {
        if new_index[i] == 0 {
            new_index[i] = kept.len() as u32;
            kept.push(v);
        }
    }
    for t in tris.iter_mut() {
        *t = t.map(|i| new_index[i as usize]);
    }
    kept
}

/// A hasher for the integer keys of [`Mesh::new`]'s look-ups (grid cells,
/// exact coordinates, sorted corner triples): one multiply per word and a
/// final mix (MurmurHash3's `fmix64`) so that the low and the top bits a
/// hash table reads both depend on every word. It replaces std's SipHash,
/// whose per-key cost was most of building a million-triangle mesh; only
/// look-ups use it (no map is iterated), so what is built does not change.
#[derive(Debug, Default, Clone, Copy)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
    #[inline]
    fn write_u32(&mut self, x: u32) {
        self.write_u64(u64::from(x));
    }
    #[inline]
    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }
    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        let mut z = self.0;
        z ^= z >> 33;
        z = z.wrapping_mul(0xff51_afd7_ed55_8ccd);
        z ^= z >> 33;
        z = z.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        z ^ (z >> 33)
    }
}

/// The hash maps and sets of mesh building, keyed through [`KeyHasher`].
type KeyMap<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;
/// See [`KeyMap`].
type KeySet<K> = HashSet<K, BuildHasherDefault<KeyHasher>>;

/// Merges vertices closer than `tol` (exactly equal when `tol` = 0): the
/// merged list and, for each input vertex, its index in it. With a
/// tolerance the vertices are hashed on a grid of cell `tol` and compared
/// with the 27 neighbouring cells, so no pair closer than `tol` is missed.
fn weld_vertices(v: &[[f64; 3]], tol: f64) -> (Vec<[f64; 3]>, Vec<u32>) {
    let mut out = Vec::with_capacity(v.len());
    let mut remap = Vec::with_capacity(v.len());
    if tol <= 0.0 {
        let mut seen: KeyMap<[u64; 3], u32> = KeyMap::with_capacity_and_hasher(v.len(), Default::default());
        for p in v {
            // +0.0 and −0.0 are the same point.
            let key = p.map(|x| (x + 0.0).to_bits());
            let id = *seen.entry(key).or_insert_with(|| {
                out.push(*p);
                (out.len() - 1) as u32
            });
            remap.push(id);
        }
        return (out, remap);
    }
    let mut grid: KeyMap<[i64; 3], Vec<u32>> = KeyMap::with_capacity_and_hasher(v.len(), Default::default());
    let cell = |p: &[f64; 3]| p.map(|x| (x / tol).floor() as i64);
    for p in v {
        let c = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &j in list {
                            let q = out[j as usize];
                            let d = sub(*p, q);
                            if dot(d, d) <= tol * tol {
                                found = Some(j);
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        let id = match found {
            Some(j) => j,
            None => {
                out.push(*p);
                let j = (out.len() - 1) as u32;
                grid.entry(c).or_default().push(j);
                j
            }
        };
        remap.push(id);
    }
    (out, remap)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The edge map `orientation` used before `edge_neighbours`: each edge
    /// to the list of its triangles, in the order they were listed.
    fn neighbours_by_map(tris: &[[u32; 3]], t: usize) -> Vec<(usize, bool)> {
        let mut edges: HashMap<(u32, u32), Vec<(u32, bool)>> = HashMap::new();
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges.entry((a.min(b), a.max(b))).or_default().push((t as u32, a < b));
            }
        }
        let mut out = Vec::new();
        let tri = tris[t];
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if let Some(f) = edges.get(&(a.min(b), a.max(b))) {
                if f.len() == 2 {
                    let (me, other) = if f[0].0 as usize == t { (f[0], f[1]) } else { (f[1], f[0]) };
                    out.push((other.0 as usize, me.1 == other.1));
                }
            }
        }
        out
    }

    #[test]
    fn edge_neighbours_are_those_of_the_edge_map() {
        // A grid of quads split in two, every third triangle wound the
        // other way, plus a fin (a third triangle on an edge), a
        // degenerate triangle with a repeated vertex and a lone triangle.
        let n = 9u32;
        let at = |i: u32, j: u32| i * (n + 1) + j;
        let mut tris = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        for (k, t) in tris.iter_mut().enumerate() {
            if k % 3 == 0 {
                t.swap(1, 2);
            }
        }
        let extra = (n + 1) * (n + 1);
        tris.push([at(0, 0), at(1, 0), extra]);
        tris.push([at(2, 2), at(2, 3), at(2, 2)]);
        tris.push([extra + 1, extra + 2, extra + 3]);
        let across = edge_neighbours(&tris);
        let mut shared = 0;
        for (t, edges) in across.iter().enumerate() {
            let ours: Vec<(usize, bool)> = edges.iter().flatten().map(|&(o, i)| (o as usize, i)).collect();
            assert_eq!(ours, neighbours_by_map(&tris, t), "triangle {t}");
            shared += ours.len();
        }
        // The grid's inner edges (2n(n − 1) between cells, n² diagonals)
        // are each seen from two triangles; the fin's edge, now on three,
        // from none (−2); the degenerate triangle's edge, which it runs
        // along twice, from both of its sides (+2).
        assert_eq!(shared as u32, 2 * (2 * n * (n - 1) + n * n) - 2 + 2);
    }

    #[test]
    fn seams_are_welded_and_collapsed_triangles_dropped() {
        // Two triangles of a square, the diagonal's vertices duplicated (a UV seam).
        let v =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [-0.0, 0.0, 0.0]];
        let m = Mesh::new(v.clone(), vec![[0, 1, 2], [3, 4, 5]], 0.0);
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.triangles[0][0], m.triangles[1][2]);
        assert_eq!(m.triangles[0][2], m.triangles[1][0]);
        // A tolerance merges near points; a triangle collapsing to a segment goes.
        let v2 = vec![[0.0, 0.0, 0.0], [1e-9, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let collapsed = Mesh::new(v2.clone(), vec![[0, 1, 2]], 1e-6);
        // Repeats (either winding, any rotation) and collinear triangles go too.
        let sq = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.5, 0.0, 0.0]];
        let m = Mesh::new(sq, vec![[0, 1, 2], [2, 1, 0], [1, 2, 0], [0, 3, 1], [0, 1, 2]], 0.0);
        assert_eq!((m.triangles.len(), m.vertices.len()), (1, 3));
        assert_eq!((collapsed.triangles.len(), collapsed.vertices.len()), (0, 0));
        assert_eq!(Mesh::new(v2.clone(), vec![[0, 1, 2]], 0.0).triangles.len(), 1);
        // Vertices no triangle uses are dropped: they would move the bounds and the floor.
        let mut v3 = v2;
        v3.insert(0, [5.0, 5.0, -100.0]);
        let m = Mesh::new(v3, vec![[1, 2, 3]], 0.0);
        assert_eq!((m.vertices.len(), m.triangles[0]), (3, [0, 1, 2]));
        assert_eq!(m.bounds().min[2], 0.0);
    }

    #[test]
    fn a_file_without_faces_or_with_only_zero_area_faces_is_refused() {
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let e = Mesh::from_faces("f.stl", v.clone(), vec![], 0.0).unwrap_err();
        assert_eq!(e.to_string(), "f.stl: the mesh has no triangles");
        // Collinear corners, and corners welded into one point.
        let e = Mesh::from_faces("f.stl", v.clone(), vec![[0, 1, 2], [0, 1, 3], [0, 1, 2]], 0.0).unwrap_err();
        assert_eq!(e, MeshError::Degenerate { what: "f.stl".into(), triangles: 3 });
        assert!(e.to_string().contains("all 3 triangles have zero area"), "{e}");
        let mut v = v;
        v[2] = [0.0, 1.0, 0.0];
        assert_eq!(Mesh::from_faces("f.stl", v, vec![[0, 1, 2], [0, 1, 3]], 0.0).unwrap().triangles.len(), 1);
    }

    #[test]
    fn mixed_windings_are_made_consistent_with_the_top_facing_up() {
        // A ridge of four triangles, two of them written clockwise.
        let v =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0], [2.0, 1.0, 0.0]];
        let m = Mesh::new(v, vec![[0, 1, 4], [0, 4, 3], [1, 5, 4], [1, 2, 5]], 0.0);
        assert!(m.normals.iter().all(|n| n[2] > 0.0), "{:?}", m.normals);
        for (t, n) in m.triangles.iter().zip(&m.normals) {
            assert_eq!(raw_normal(m.vertices[t[0] as usize], m.vertices[t[1] as usize], m.vertices[t[2] as usize]), *n);
        }
    }

    #[test]
    fn normals_face_the_ray_whatever_the_winding() {
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [0.0, 1.0, 0.0]];
        let a = Mesh::new(v.clone(), vec![[0, 1, 2]], 0.0);
        let b = Mesh::new(v, vec![[0, 2, 1]], 0.0);
        assert_eq!(a.normals, b.normals);
        assert!(a.normals[0][2] > 0.0);
        let n = a.normals[0];
        assert!((dot(n, n) - 1.0).abs() < 1e-15);
        assert!((n[0] + 0.5 / 1.25f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn hash_changes_with_content() {
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let a = Mesh::new(v.clone(), vec![[0, 1, 2]], 0.0);
        let mut v2 = v;
        v2[1][2] = 1e-12;
        let b = Mesh::new(v2, vec![[0, 1, 2]], 0.0);
        assert_ne!(a.content_hash(), b.content_hash());
        assert_eq!(a.content_hash(), a.clone().content_hash());
    }
}
