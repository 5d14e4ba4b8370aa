//! Robustness of the mesh chain (issue 5, point 8): every awkward input
//! gives finite, bounded outputs or a clear error, never a panic.

use evflow_engine::harness::Single;
use evflow_nodes::mesh::{edges_node, gradient_node};
use std::fmt::Write;
use std::path::Path;

/// OBJ text of a height field on an n × n grid of unit cells (cm), z up:
/// every file here is read with `up = "+z"` (OBJ's default is +y).
fn grid_obj(n: usize, off: f64, f: impl Fn(f64, f64) -> f64) -> String {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64, j as f64);
            writeln!(s, "v {} {} {}", off + x, off + y, f(x, y)).unwrap();
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i + 1;
    for j in 0..n {
        for i in 0..n {
            // Quads: tobj triangulates them.
            writeln!(s, "f {} {} {} {}", id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)).unwrap();
        }
    }
    s
}

struct Run {
    out: Vec<Vec<f64>>,
}

fn gradient(dir: &Path, params: &str, x: Vec<f64>, y: Vec<f64>) -> Result<Run, String> {
    let n = x.len() as u64;
    Single::new(&gradient_node::SPEC, params)
        .input("x", x, 1000.0)
        .input("y", y, 1000.0)
        .outputs(["intensity", "fsq", "slope", "z", "tri"])
        .ticks(n)
        .block(100)
        .base_dir(dir)
        .run()
        .map(|out| Run { out })
}

fn sane(r: &Run) {
    for (k, o) in r.out.iter().enumerate() {
        assert!(o.iter().all(|v| v.is_finite()), "output {k} not finite");
    }
    assert!(r.out[0].iter().all(|&i| (0.3..=1.0).contains(&i)));
}

/// A scan along x at y, 1 kHz, 5 cm/s, from x0 to x1 (m).
fn scan(x0: f64, x1: f64, y: f64) -> (Vec<f64>, Vec<f64>) {
    let n = ((x1 - x0).abs() / 5e-5) as usize;
    let xs: Vec<f64> = (0..n).map(|i| x0 + (x1 - x0) * i as f64 / n as f64).collect();
    (xs.clone(), vec![y; xs.len()])
}

#[test]
fn a_stationary_finger_holds_its_last_intensity() {
    let dir = tempfile::tempdir().unwrap();
    let (mut x, mut y) = scan(-0.02, -0.005, 0.0);
    let last = *x.last().unwrap();
    x.extend(std::iter::repeat_n(last, 2000));
    y.extend(std::iter::repeat_n(0.0, 2000));
    let r = gradient(dir.path(), "config = \"bump\"\nresolution = 16", x, y).unwrap();
    sane(&r);
    let moving = r.out[0][r.out[0].len() - 2001];
    assert!(r.out[0][r.out[0].len() - 2000..].iter().all(|&v| v == moving));
    assert!(moving > 0.65, "climbing the bump resists: {moving}");
}

#[test]
fn vertical_walls_outside_and_degenerate_triangles() {
    let dir = tempfile::tempdir().unwrap();
    // A 2 cm box on a 10 × 10 cm plate: vertical walls (zero projected area),
    // plus a zero-area triangle and a sliver.
    let mut s = String::from("v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nf 1 2 3 4\n");
    s += "v 4 4 2\nv 6 4 2\nv 6 6 2\nv 4 6 2\nv 4 4 0\nv 6 4 0\nv 6 6 0\nv 4 6 0\n";
    s += "f 5 6 7 8\nf 9 10 6 5\nf 10 11 7 6\nf 11 12 8 7\nf 12 9 5 8\n";
    s += "v 1 1 1\nv 2 2 1\nv 3 3 1\nf 13 14 15\nv 1 9 0.5\nv 9 9 0.5\nv 5 9.0000000001 0.5\nf 16 17 18\n";
    std::fs::write(dir.path().join("box.obj"), s).unwrap();
    let (x, y) = scan(-0.01, 0.11, 0.05);
    let r = gradient(dir.path(), "file = \"box.obj\"\nup = \"+z\"", x.clone(), y).unwrap();
    sane(&r);
    // The finger climbs the wall (resist, I = 1), rides the top, drops (assist, I = 0.3).
    let on_top = x.iter().position(|&v| v > 0.045).unwrap();
    assert!((r.out[3][on_top] - 0.02).abs() < 1e-12);
    assert_eq!(r.out[0].iter().cloned().fold(0.0, f64::max), 1.0);
    assert_eq!(r.out[0].iter().cloned().fold(1.0, f64::min), 0.3);
    // Outside the plate: no triangle, the floor's height.
    assert_eq!(r.out[4][0], -1.0);
    assert_eq!(r.out[3][0], 0.0);
    // Far outside, and NaN touch points.
    // (Non-finite touch points are held; the unit tests of `gradient` cover them.)
    let r = gradient(dir.path(), "file = \"box.obj\"\nup = \"+z\"", vec![1e3, 1e300, -1e3], vec![1e3, 0.0, -1e300])
        .unwrap();
    sane(&r);
}

#[test]
fn open_and_non_manifold_meshes() {
    let dir = tempfile::tempdir().unwrap();
    // An open sheet with a hole cut out, and a fin sharing an edge with two faces.
    let mut s = grid_obj(6, 0.0, |x, y| 0.2 * (x + y));
    s += "v 3 3 5\nf 24 25 50\n"; // fin on the edge (2,3)-(3,3): three faces there
    std::fs::write(dir.path().join("open.obj"), s).unwrap();
    for slope in ["secant", "normal"] {
        let (x, y) = scan(-0.01, 0.07, 0.031);
        let p = format!("file = \"open.obj\"\nup = \"+z\"\nslope = \"{slope}\"");
        let r = gradient(dir.path(), &p, x.clone(), y.clone()).unwrap();
        sane(&r);
        let edges = Single::new(&edges_node::SPEC, "file = \"open.obj\"\nup = \"+z\"")
            .input("x", x, 1000.0)
            .input("y", y, 1000.0)
            .input("tri", r.out[4].clone(), 1000.0)
            .outputs(["intensity", "sharpness", "angle"])
            .ticks(r.out[4].len() as u64)
            .base_dir(dir.path());
        let s = edges.summary().unwrap();
        assert!(s.lines.iter().any(|l| l.contains("1 non-manifold")), "{:?}", s.lines);
        let out = edges.run().unwrap();
        assert!(out.iter().flatten().all(|v| v.is_finite()));
        assert!(out[0].iter().all(|&v| v == 0.0 || (0.3..=1.0).contains(&v)));
    }
}

#[test]
fn a_flat_mesh_has_f_min_equal_f_max_and_renders_full_intensity() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("flat.obj"), grid_obj(4, 0.0, |_, _| 1.0)).unwrap();
    let (x, y) = scan(0.0, 0.04, 0.02);
    let s = Single::new(&gradient_node::SPEC, "file = \"flat.obj\"\nup = \"+z\"")
        .input("x", x.clone(), 1000.0)
        .input("y", y.clone(), 1000.0)
        .output("intensity")
        .ticks(x.len() as u64)
        .block(100)
        .base_dir(dir.path());
    let sum = s.summary().unwrap();
    assert_eq!((sum.get("f_min"), sum.get("f_max")), (Some(0.0), Some(0.0)));
    assert!(s.run().unwrap()[0].iter().all(|&v| v == 1.0));
}

fn edges_summary(dir: &Path, file: &str, y: f64) -> evflow_engine::Summary {
    let (x, yv) = scan(-0.01, 0.13, y);
    let p = format!("file = \"{file}\"\nup = \"+z\"");
    let tri = gradient(dir, &p, x.clone(), yv.clone()).unwrap().out[4].clone();
    Single::new(&edges_node::SPEC, &p)
        .input("x", x, 1000.0)
        .input("y", yv, 1000.0)
        .input("tri", tri.clone(), 1000.0)
        .output("intensity")
        .ticks(tri.len() as u64)
        .base_dir(dir)
        .summary()
        .unwrap()
}

#[test]
fn a_mesh_without_convex_edges_never_ticks() {
    let dir = tempfile::tempdir().unwrap();
    // A gentle dome on the screen plane: its facets bend by a few degrees
    // (flatter than max_angle), its foot is concave, its border lies on the floor.
    let dome = |x: f64, y: f64| (0.3 * (1.0 - ((x - 6.0).powi(2) + (y - 6.0).powi(2)) / 16.0)).max(0.0);
    std::fs::write(dir.path().join("dome.obj"), grid_obj(12, 0.0, dome)).unwrap();
    let s = edges_summary(dir.path(), "dome.obj", 0.06);
    assert_eq!((s.get("theta_min"), s.get("convex_edges"), s.get("crossings")), (Some(180.0), Some(0.0), Some(0.0)));
    // The same dome raised 1 cm above the screen: its border is a cliff, the only convex edge.
    std::fs::write(
        dir.path().join("raised.obj"),
        grid_obj(12, 0.0, |x, y| dome(x, y) + 1.0) + "v -5 -5 0\nv -4 -5 0\nv -5 -4 0\nf 170 171 172\n",
    )
    .unwrap();
    let s = edges_summary(dir.path(), "raised.obj", 0.06);
    assert!((s.get("theta_min").unwrap() - 90.0).abs() < 1e-9, "{s:?}");
    assert_eq!(s.get("crossings"), Some(2.0)); // on and off the raised plate
}

#[test]
fn coordinates_of_a_million_render_like_the_origin() {
    let dir = tempfile::tempdir().unwrap();
    let f = |x: f64, y: f64| 0.5 * (0.8 * x).sin() + 0.1 * y;
    std::fs::write(dir.path().join("near.obj"), grid_obj(8, 0.0, f)).unwrap();
    std::fs::write(dir.path().join("far.obj"), grid_obj(8, 1e6, f)).unwrap();
    let (x, y) = scan(0.0, 0.08, 0.037);
    // Every tick's secant (min_step = 0), so both runs difference the same pairs of points.
    let near = gradient(
        dir.path(),
        "file = \"near.obj\"\nup = \"+z\"\nrange = \"fixed\"\nmin_step = 0.0",
        x.clone(),
        y.clone(),
    )
    .unwrap();
    // 10⁶ cm = 10⁴ m: the mesh sits there, and so does the finger.
    let xf: Vec<f64> = x.iter().map(|v| v + 1e4).collect();
    let yf: Vec<f64> = y.iter().map(|v| v + 1e4).collect();
    let far =
        gradient(dir.path(), "file = \"far.obj\"\nup = \"+z\"\nrange = \"fixed\"\nmin_step = 0.0", xf, yf).unwrap();
    sane(&far);
    // Points on shared edges may pick the neighbouring triangle after rounding; the surface is the same.
    assert!(far.out[4].iter().all(|&t| t >= 0.0));
    for (a, b) in near.out[3].iter().zip(&far.out[3]) {
        assert!((a - b).abs() < 1e-11, "height {a} vs {b}");
    }
    for (a, b) in near.out[2].iter().zip(&far.out[2]) {
        assert!((a - b).abs() < 1e-5, "slope {a} vs {b}");
    }
}

#[test]
fn touch_points_exactly_on_vertices_and_edges_never_miss() {
    let dir = tempfile::tempdir().unwrap();
    // Alternating windings: every other quad written clockwise.
    let mut s = grid_obj(10, 0.0, |x, y| 0.1 * x * y);
    let faces: Vec<String> = s.lines().filter(|l| l.starts_with('f')).map(String::from).collect();
    s = s.lines().filter(|l| !l.starts_with('f')).map(|l| format!("{l}\n")).collect();
    for (k, f) in faces.iter().enumerate() {
        if k % 2 == 0 {
            let mut w: Vec<&str> = f.split_whitespace().collect();
            w[1..].reverse();
            s += &(w.join(" ") + "\n");
        } else {
            s += &format!("{f}\n");
        }
    }
    std::fs::write(dir.path().join("grid.obj"), s).unwrap();
    // Touch coordinates quantized to 1/4 cell: vertices, edges, diagonals, interiors.
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for j in 0..=40 {
        for i in 0..=40 {
            x.push(i as f64 * 0.0025);
            y.push(j as f64 * 0.0025);
        }
    }
    let r = gradient(dir.path(), "file = \"grid.obj\"\nup = \"+z\"\nrange = \"fixed\"", x, y).unwrap();
    sane(&r);
    assert_eq!(r.out[4].iter().filter(|&&t| t < 0.0).count(), 0, "misses");
}

#[test]
fn a_malformed_obj_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n# ok\nf 1 2 7\n").unwrap();
    let e = gradient(dir.path(), "file = \"bad.obj\"", vec![0.0], vec![0.0]).err().unwrap();
    assert!(e.contains("bad.obj:5:") && e.contains("out of range"), "{e}");
    let e = gradient(dir.path(), "file = \"missing.obj\"", vec![0.0], vec![0.0]).err().unwrap();
    assert!(e.contains("missing.obj") && e.contains("cannot read"), "{e}");
}

#[test]
fn a_pruned_mesh_node_is_never_constructed() {
    // The mesh node's file does not exist: constructing it would fail. It
    // feeds no sink, so the plan leaves it out and builds.
    let text = r#"
[graph]
format = 1
name = "pruned"
rate = 1000.0
connections = ["src.out -> s.in", "src.out -> g.x", "src.out -> g.y"]
[nodes.src]
type = "sine"
[nodes.g]
type = "mesh.gradient"
file = "does-not-exist.obj"
[nodes.s]
type = "stats"
"#;
    let reg = evflow_nodes::registry();
    let g = evflow_engine::graph::parse_graph(Path::new("pruned.toml"), text).unwrap();
    let checked = evflow_engine::check(&g, &reg, &[]).unwrap();
    let plan = evflow_engine::Plan::build(&checked, &Default::default()).unwrap();
    assert!(plan.index("g").is_none());
    // Connected to a sink, it is built — and fails with the file's name.
    let text = text.replace("\"src.out -> s.in\"", "\"g.intensity -> s.in\"");
    let g = evflow_engine::graph::parse_graph(Path::new("pruned.toml"), &text).unwrap();
    let checked = evflow_engine::check(&g, &reg, &[]).unwrap();
    let e = evflow_engine::Plan::build(&checked, &Default::default()).err().unwrap();
    assert!(e.to_string().contains("does-not-exist.obj"), "{e}");
}
