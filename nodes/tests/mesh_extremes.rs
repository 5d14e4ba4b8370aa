//! Hidden surfaces and extreme meshes (issue 16, point 5), beyond what
//! `mesh_robustness.rs` covers: overhangs are felt on their highest
//! surface; f32 formats far from the origin and in mm or m fit to the
//! surface in cm; duplicate and zero-area triangles change nothing; open
//! boundaries and holes feel like cliffs when raised and like nothing on
//! the screen plane; an empty or all-degenerate file is refused. Every
//! output finite.

use crate::mesh_formats_util;

use evflow_engine::harness::Single;
use evflow_engine::Summary;
use evflow_nodes::mesh::edges_node;
use mesh_formats_util::gradient;
use std::fmt::Write;
use std::path::Path;

/// `mesh.edges` fed by `tri` from [`gradient`]: its outputs and summary.
fn edges(dir: &Path, params: &str, x: &[f64], y: &[f64], tri: &[f64]) -> (Vec<Vec<f64>>, Summary) {
    let s = Single::new(&edges_node::SPEC, params)
        .input("x", x.to_vec(), 1000.0)
        .input("y", y.to_vec(), 1000.0)
        .input("tri", tri.to_vec(), 1000.0)
        .outputs(["intensity", "sharpness", "angle"])
        .ticks(x.len() as u64)
        .base_dir(dir);
    (s.run().unwrap(), s.summary().unwrap())
}

fn finite(out: &[Vec<f64>], what: &str) {
    for (k, o) in out.iter().enumerate() {
        assert!(o.iter().all(|v| v.is_finite()), "{what}: output {k} not finite");
    }
}

/// A stroke along x at y (m), 5 cm/s at 1 kHz.
fn stroke(x0: f64, x1: f64, y: f64) -> (Vec<f64>, Vec<f64>) {
    let n = ((x1 - x0).abs() / 5e-5) as usize;
    ((0..n).map(|i| x0 + (x1 - x0) * i as f64 / n as f64).collect(), vec![y; n])
}

/// An OBJ of triangles (z-up; every file here is read with `up = "+z"`).
#[derive(Default)]
struct Obj {
    v: Vec<[f64; 3]>,
    f: Vec<[usize; 3]>,
}

impl Obj {
    fn vertex(&mut self, p: [f64; 3]) -> usize {
        self.v.push(p);
        self.v.len() - 1
    }
    fn tri(&mut self, a: [f64; 3], b: [f64; 3], c: [f64; 3]) {
        let t = [self.vertex(a), self.vertex(b), self.vertex(c)];
        self.f.push(t);
    }
    fn quad(&mut self, a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) {
        self.tri(a, b, c);
        self.tri(a, c, d);
    }
    /// A hexahedron from its bottom face (4 corners, counter-clockwise) and top face above them.
    fn hexa(&mut self, bottom: [[f64; 3]; 4], top: [[f64; 3]; 4]) {
        self.quad(bottom[3], bottom[2], bottom[1], bottom[0]);
        self.quad(top[0], top[1], top[2], top[3]);
        for k in 0..4 {
            let j = (k + 1) % 4;
            self.quad(bottom[k], bottom[j], top[j], top[k]);
        }
    }
    /// An axis-aligned box.
    fn cuboid(&mut self, lo: [f64; 3], hi: [f64; 3]) {
        let r = |z: f64| [[lo[0], lo[1], z], [hi[0], lo[1], z], [hi[0], hi[1], z], [lo[0], hi[1], z]];
        self.hexa(r(lo[2]), r(hi[2]));
    }
    fn text(&self) -> String {
        let mut s = String::new();
        for p in &self.v {
            writeln!(s, "v {} {} {}", p[0], p[1], p[2]).unwrap();
        }
        for t in &self.f {
            writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
        }
        s
    }
    /// The highest point of any triangle above (x, y), by brute force, or None.
    fn highest(&self, x: f64, y: f64) -> Option<f64> {
        let mut best: Option<f64> = None;
        for t in &self.f {
            let [a, b, c] = t.map(|i| self.v[i]);
            let d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            if d == 0.0 {
                continue; // vertical or degenerate
            }
            let u = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / d;
            let v = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / d;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 {
                let z = a[2] + u * (b[2] - a[2]) + v * (c[2] - a[2]);
                best = Some(best.map_or(z, |m: f64| m.max(z)));
            }
        }
        best
    }
}

/// A teapot in boxes (cm): a body on a floor plate, a handle — a vertical
/// loop whose top bar overhangs its bottom bar and the floor — and a spout
/// rising outward over the floor, its tip overhanging.
fn teapot() -> Obj {
    let mut m = Obj::default();
    m.quad([0.0, 0.0, 0.0], [22.0, 0.0, 0.0], [22.0, 12.0, 0.0], [0.0, 12.0, 0.0]);
    m.cuboid([6.0, 3.0, 0.0], [12.0, 9.0, 5.0]); // body
    m.cuboid([12.0, 5.0, 4.0], [17.0, 7.0, 5.0]); // handle: top bar
    m.cuboid([16.0, 5.0, 1.0], [17.0, 7.0, 5.0]); //         outer bar
    m.cuboid([12.0, 5.0, 1.0], [17.0, 7.0, 2.0]); //         bottom bar
                                                  // Spout: from the body's side (x = 6, z 1…2.5) up and out to x = 1 (z 5…6).
    let (y0, y1) = (5.5, 6.5);
    let bottom = [[6.0, y0, 1.0], [1.0, y0, 5.0], [1.0, y1, 5.0], [6.0, y1, 1.0]];
    let top = [[6.0, y0, 2.5], [1.0, y0, 6.0], [1.0, y1, 6.0], [6.0, y1, 2.5]];
    m.hexa(bottom, top);
    m
}

#[test]
fn overhangs_are_felt_on_their_highest_surface() {
    let dir = tempfile::tempdir().unwrap();
    let pot = teapot();
    std::fs::write(dir.path().join("teapot.obj"), pot.text()).unwrap();
    let p = "file = \"teapot.obj\"\nup = \"+z\"";
    // Touch points scattered over the floor plate (a fixed sequence), and named places.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut x, mut y): (Vec<f64>, Vec<f64>) = (0..4000).map(|_| (0.22 * next(), 0.12 * next())).unzip();
    x.extend([0.14, 0.165, 0.035]);
    y.extend([0.06, 0.06, 0.06]);
    let out = gradient(dir.path(), p, &x, &y).unwrap();
    finite(&out, "teapot");
    for k in 0..x.len() {
        let want = pot.highest(x[k] * 100.0, y[k] * 100.0).expect("the floor plate is under every point");
        assert!((out[3][k] - want / 100.0).abs() < 1e-12, "({}, {}): z {} vs highest {}", x[k], y[k], out[3][k], want);
        assert!(out[4][k] >= 0.0);
    }
    let n = x.len();
    // Over the handle: its top (5 cm), not its bottom bar (2 cm) or the floor; its outer bar's top too.
    assert_eq!([out[3][n - 3], out[3][n - 2]], [0.05, 0.05]);
    // Over the spout, 3.5 cm from its tip: its upper face, 4.25 cm + (6 − 4.25)·… — the top face's height.
    let spout_top = 2.5 + (6.0 - 2.5) * (6.0 - 3.5) / 5.0;
    assert!((out[3][n - 1] - spout_top / 100.0).abs() < 1e-12, "{}", out[3][n - 1]);
    // Strokes across the handle and the spout: the edges node stays finite and bounded.
    for y0 in [0.06, 0.055, 0.0652] {
        let (x, y) = stroke(-0.01, 0.23, y0);
        let g = gradient(dir.path(), p, &x, &y).unwrap();
        finite(&g, "stroke");
        assert!(g[0].iter().all(|i| (0.3..=1.0).contains(i)));
        let (e, _) = edges(dir.path(), p, &x, &y, &g[4]);
        finite(&e, "edges");
        assert!(e[0].iter().all(|&v| v == 0.0 || (0.3..=1.0).contains(&v)));
    }
}

/// A height field h(x, y) on an n × m grid of unit cells, each point written as
/// `(x·scale + off, y·scale + off, h·scale + off)`.
fn grid(n: usize, m: usize, scale: f64, off: f64) -> Vec<[[f64; 3]; 3]> {
    let h = |x: f64, y: f64| 0.5 * (0.8 * x).sin() + 0.1 * y + 1.0;
    let p = |i: usize, j: usize| {
        let (x, y) = (i as f64, j as f64);
        [x * scale + off, y * scale + off, h(x, y) * scale + off]
    };
    let mut t = Vec::new();
    for j in 0..m {
        for i in 0..n {
            t.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            t.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    t
}

fn binary_stl(tris: &[[[f64; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend([0u8; 12]);
        for x in t.iter().flatten() {
            b.extend((*x as f32).to_le_bytes());
        }
        b.extend([0u8; 2]);
    }
    b
}

fn ascii_ply(tris: &[[[f64; 3]; 3]]) -> String {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        3 * tris.len(),
        tris.len()
    );
    for p in tris.iter().flatten() {
        writeln!(s, "{} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for k in 0..tris.len() {
        writeln!(s, "3 {} {} {}", 3 * k, 3 * k + 1, 3 * k + 2).unwrap();
    }
    s
}

#[test]
fn f32_and_f64_formats_far_away_in_mm_or_in_m_fit_to_the_surface_in_cm() {
    let dir = tempfile::tempdir().unwrap();
    let obj = |t: &[[[f64; 3]; 3]]| {
        let mut o = Obj::default();
        t.iter().for_each(|t| o.tri(t[0], t[1], t[2]));
        o.text()
    };
    std::fs::write(dir.path().join("cm.obj"), obj(&grid(8, 6, 1.0, 0.0))).unwrap();
    std::fs::write(dir.path().join("m.ply"), ascii_ply(&grid(8, 6, 0.01, 0.0))).unwrap();
    std::fs::write(dir.path().join("mm-far.ply"), ascii_ply(&grid(8, 6, 10.0, 1e6))).unwrap();
    // Binary STL stores f32: 10⁶ mm away its coordinates are multiples of 1/16 mm.
    std::fs::write(dir.path().join("mm-far.stl"), binary_stl(&grid(8, 6, 10.0, 1e6))).unwrap();
    let n = 2000;
    let x: Vec<f64> = (0..n).map(|i| -0.049 + 0.098 * i as f64 / n as f64).collect();
    let y: Vec<f64> = (0..n).map(|i| -0.036 + 0.072 * i as f64 / n as f64).collect();
    let fitted = |file: &str| {
        gradient(dir.path(), &format!("file = \"{file}\"\nup = \"+z\"\nfit = \"footprint\"\nfit_size = 0.1"), &x, &y)
            .unwrap()
    };
    let cm = fitted("cm.obj");
    for (file, dz, ds) in [("m.ply", 1e-12, 1e-6), ("mm-far.ply", 1e-12, 1e-6), ("mm-far.stl", 4e-5, 0.02)] {
        let out = fitted(file);
        finite(&out, file);
        assert!(out[4].iter().all(|&t| t >= 0.0), "{file}: every tick on the footprint");
        // 1/16 mm of an 80 mm footprint fitted to 0.1 m is 7.8e-5 m; corners are off by half that at most.
        for (k, (a, b)) in cm[3].iter().zip(&out[3]).enumerate() {
            assert!((a - b).abs() < dz, "{file}: height at {k}: {a} vs {b}");
        }
        for (k, (a, b)) in cm[2].iter().zip(&out[2]).enumerate() {
            assert!((a - b).abs() < ds, "{file}: slope at {k}: {a} vs {b}");
        }
    }
}

/// A roof (ridge at x = 6, sharp) on an n × n grid, as triangles of unit cells.
fn roof(n: usize) -> Vec<[[f64; 3]; 3]> {
    let h = |x: f64| 3.0 - 0.8 * (x - 6.0).abs();
    let p = |i: usize, j: usize| [i as f64, j as f64, h(i as f64)];
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            t.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    t
}

#[test]
fn duplicate_and_zero_area_triangles_change_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let clean = roof(12);
    let mut o = Obj::default();
    clean.iter().for_each(|t| o.tri(t[0], t[1], t[2]));
    std::fs::write(dir.path().join("clean.obj"), o.text()).unwrap();
    // Every triangle again, reversed (a two-sided sheet) and rotated; zero-area slivers
    // along shared edges (midpoint on the edge) and triangles with a repeated corner.
    let mut messy = Obj::default();
    for t in &clean {
        messy.tri(t[0], t[1], t[2]);
        let mid = [0, 1, 2].map(|i| 0.5 * (t[0][i] + t[2][i]));
        messy.tri(t[0], mid, t[2]);
        messy.tri(t[2], t[1], t[0]);
        messy.tri(t[1], t[2], t[0]);
        messy.tri(t[0], t[0], t[1]);
    }
    std::fs::write(dir.path().join("messy.obj"), messy.text()).unwrap();
    let (x, y) = stroke(-0.01, 0.13, 0.0613);
    for file in ["clean.obj", "messy.obj"] {
        let p = format!("file = \"{file}\"\nup = \"+z\"");
        let g = gradient(dir.path(), &p, &x, &y).unwrap();
        finite(&g, file);
        let (e, s) = edges(dir.path(), &p, &x, &y, &g[4]);
        finite(&e, file);
        assert!(s.lines.iter().any(|l| l.contains(" 0 non-manifold")), "{file}: {:?}", s.lines);
        // One crossing: the ridge (θ = 180° − 2·atan 0.8 ≈ 102.7°). The far border lies on the
        // screen plane (the floor): stepping off it is not an edge. The stroke passes grid lines
        // exactly (x = 1 cm, 2 cm, …), where the ray cast and the edge tracker once rounded to
        // different sides and felt a drop to the floor and back: no tick there.
        assert_eq!(s.get("crossings"), Some(1.0), "{file}: {s:?}");
        let ticks: Vec<usize> = (1..x.len()).filter(|&k| e[0][k - 1] == 0.0 && e[0][k] > 0.0).collect();
        assert_eq!(ticks.len(), 1, "{file}: ticks at {:?}", ticks.iter().map(|&k| x[k]).collect::<Vec<_>>());
        assert!((e[2][ticks[0]] - (180.0 - 2.0 * 0.8f64.atan().to_degrees())).abs() < 1e-9);
        if file == "messy.obj" {
            let base = gradient(dir.path(), "file = \"clean.obj\"\nup = \"+z\"", &x, &y).unwrap();
            assert_eq!(g, base, "gradient");
            let (eb, sb) = edges(dir.path(), "file = \"clean.obj\"\nup = \"+z\"", &x, &y, &base[4]);
            assert_eq!(e, eb, "edges");
            assert_eq!(s.get("theta_min"), sb.get("theta_min"));
        }
    }
}

/// A flat sheet of n × n unit cells at height z, with the cells in `hole` left out.
fn sheet(n: usize, z: f64, hole: impl Fn(usize, usize) -> bool) -> Obj {
    let mut o = Obj::default();
    for j in 0..n {
        for i in 0..n {
            if !hole(i, j) {
                let (x, y) = (i as f64, j as f64);
                o.quad([x, y, z], [x + 1.0, y, z], [x + 1.0, y + 1.0, z], [x, y + 1.0, z]);
            }
        }
    }
    o
}

#[test]
fn open_boundaries_are_cliffs_when_raised_and_nothing_on_the_screen_plane() {
    let dir = tempfile::tempdir().unwrap();
    let hole = |i: usize, j: usize| (5..7).contains(&i) && (5..7).contains(&j);
    // On the screen plane: the sheet's border and its hole's rim lie on the floor.
    std::fs::write(dir.path().join("low.obj"), sheet(12, 0.0, hole).text()).unwrap();
    // Raised 1 cm (a far triangle on the screen plane sets the floor): border and rim are cliffs.
    let mut raised = sheet(12, 1.0, hole);
    raised.tri([-5.0, -5.0, 0.0], [-4.0, -5.0, 0.0], [-5.0, -4.0, 0.0]);
    std::fs::write(dir.path().join("raised.obj"), raised.text()).unwrap();
    let (x, y) = stroke(-0.01, 0.13, 0.06);
    for (file, crossings, theta_min) in [("low.obj", 0.0, 180.0), ("raised.obj", 4.0, 90.0)] {
        let p = format!("file = \"{file}\"\nup = \"+z\"");
        let g = gradient(dir.path(), &p, &x, &y).unwrap();
        finite(&g, file);
        let (e, s) = edges(dir.path(), &p, &x, &y, &g[4]);
        finite(&e, file);
        // Onto the sheet, into the hole, out of it, off the sheet: four cliffs when raised.
        assert_eq!(s.get("crossings"), Some(crossings), "{file}: {s:?}");
        assert!((s.get("theta_min").unwrap() - theta_min).abs() < 1e-9, "{file}: {s:?}");
        let ticks = e[0].iter().zip(e[0].iter().skip(1)).filter(|(a, b)| **a == 0.0 && **b > 0.0).count();
        assert!(ticks as f64 <= crossings, "{file}: {ticks} ticks");
        // Over the hole the finger is on the floor.
        let k = x.iter().position(|&v| v > 0.06).unwrap();
        assert_eq!((g[4][k], g[3][k]), (-1.0, 0.0), "{file}");
    }
}

#[test]
fn the_bunny_an_open_scanned_mesh_with_holes_renders_finite_and_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bunny.glb");
    let p = format!("file = \"{}\"\nfit = \"footprint\"", bunny.display());
    for y0 in [-0.02, 0.0, 0.015] {
        let (x, y) = stroke(-0.06, 0.06, y0);
        let g = gradient(dir.path(), &p, &x, &y).unwrap();
        finite(&g, "bunny");
        assert!(g[0].iter().all(|i| (0.3..=1.0).contains(i)));
        assert!(g[4].iter().filter(|&&t| t >= 0.0).count() > x.len() / 3);
        let (e, s) = edges(dir.path(), &p, &x, &y, &g[4]);
        finite(&e, "bunny edges");
        assert!(e[0].iter().all(|&v| v == 0.0 || (0.3..=1.0).contains(&v)));
        assert!(s.lines.iter().any(|l| l.contains("boundary")), "{:?}", s.lines);
    }
}

#[test]
fn an_empty_or_all_degenerate_file_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let files: [(&str, &[u8], &str); 4] = [
        ("empty.obj", b"# nothing\nv 0 0 0\nv 1 0 0\n", "empty.obj: the mesh has no triangles"),
        (
            "line.stl",
            b"solid s\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 2 0 0\nendloop\nendfacet\nendsolid s\n",
            "line.stl: all 1 triangles have zero area",
        ),
        (
            "point.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 0\n3 0 0 0\n",
            "point.ply: all 2 triangles have zero area",
        ),
        ("nothing.stl", &binary_stl(&[]), "nothing.stl: the mesh has no triangles"),
    ];
    for (file, bytes, want) in files {
        std::fs::write(dir.path().join(file), bytes).unwrap();
        let e = gradient(dir.path(), &format!("file = \"{file}\"\nup = \"+z\""), &[0.0], &[0.0]).err().unwrap();
        assert!(e.contains(want), "{file}: {e}");
    }
}
