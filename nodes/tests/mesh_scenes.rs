//! Switching scenes live: `mesh.gradient` and `mesh.edges` load every mesh
//! of `scenes` when they are built, and the live parameter `scene` picks
//! the one felt. After a switch both nodes give exactly what they give on
//! the new mesh alone; the intensity crossfades over `switch_fade` instead
//! of jumping.

use evflow_engine::harness::{FEED, TAP};
use evflow_engine::params::toml_float;
use evflow_engine::{check, graph::parse_graph, Plan, PlanOptions};

/// Outputs per tick: surface intensity, fsq, slope, z, tri; edges intensity, angle.
type Outs = Vec<[f64; 7]>;

/// The finger scans along x at y = 0 across the scene's centre object,
/// 5 cm/s at 1 kHz; `mesh` is the mesh parameters of both nodes;
/// `changes` are `(tick, scene)` applied to both nodes before that tick.
fn run(mesh: &str, fade: f64, changes: &[(u64, f64)], block: usize) -> Result<Outs, String> {
    let n = 800;
    let x: Vec<String> = (0..n).map(|i| toml_float(-0.02 + 5e-5 * i as f64)).collect();
    let y = vec!["0.0".to_string(); n];
    let doc = format!(
        "[graph]\nformat = 1\nname = \"scenes\"\nrate = 1000\nconnections = [\"x.out -> s.x\", \"y.out -> s.y\", \
         \"x.out -> e.x\", \"y.out -> e.y\", \"s.tri -> e.tri\", \"s.intensity -> t0.in\", \"s.fsq -> t1.in\", \
         \"s.slope -> t2.in\", \"s.z -> t3.in\", \"e.intensity -> t4.in\", \"e.angle -> t5.in\"]\n\
         [nodes.x]\ntype = \"harness.feed\"\nvalues = [{}]\n[nodes.y]\ntype = \"harness.feed\"\nvalues = [{}]\n\
         [nodes.s]\ntype = \"mesh.gradient\"\nshape = \"frustum\"\nslope = \"normal\"\nrange = \"fixed\"\nswitch_fade = {}\n{mesh}\n\
         [nodes.e]\ntype = \"mesh.edges\"\nshape = \"frustum\"\n{mesh}\n\
         [nodes.t0]\ntype = \"harness.tap\"\n[nodes.t1]\ntype = \"harness.tap\"\n[nodes.t2]\ntype = \"harness.tap\"\n\
         [nodes.t3]\ntype = \"harness.tap\"\n[nodes.t4]\ntype = \"harness.tap\"\n[nodes.t5]\ntype = \"harness.tap\"\n",
        x.join(","),
        y.join(","),
        toml_float(fade)
    );
    let mut reg = evflow_nodes::registry();
    reg.add(&FEED).add(&TAP);
    let g = parse_graph(std::path::Path::new("scenes.toml"), &doc).map_err(|e| e.to_string())?;
    let checked = check(&g, &reg, &[]).map_err(|e| e.to_string())?;
    let mut plan = Plan::build(&checked, &PlanOptions { max_block: block, timing: false, ..PlanOptions::default() })
        .map_err(|e| e.to_string())?;
    let idx = |name: &str| (0..plan.len()).find(|&k| plan.node_name(k) == name).unwrap();
    let (s, e) = (idx("s"), idx("e"));
    let mut out = Vec::new();
    let mut done = 0u64;
    while done < n as u64 {
        for &(_, scene) in changes.iter().filter(|c| c.0 == done) {
            plan.set(s, "scene", scene).map_err(|e| e.to_string())?;
            plan.set(e, "scene", scene).map_err(|e| e.to_string())?;
        }
        let next = changes.iter().map(|c| c.0).filter(|&t| t > done).min().unwrap_or(u64::MAX);
        let k = (block as u64).min(n as u64 - done).min(next - done) as usize;
        plan.step(k).map_err(|e| e.to_string())?;
        let col = |node: &str, port: usize| plan.output(node, port).unwrap().to_vec();
        let cols = [col("s", 0), col("s", 1), col("s", 2), col("s", 3), col("s", 4), col("e", 0), col("e", 2)];
        out.extend((0..k).map(|i| std::array::from_fn(|c| cols[c][i])));
        done += k as u64;
    }
    Ok(out)
}

const BOTH: &str = "scenes = [\"bump\", \"hole\"]";

#[test]
fn after_a_switch_both_nodes_give_what_the_new_mesh_gives_alone() {
    let t = 250usize;
    let switched = run(BOTH, 10.0, &[(t as u64, 1.0)], 1).unwrap();
    let bump = run("config = \"bump\"", 10.0, &[], 1).unwrap();
    let hole = run("config = \"hole\"", 10.0, &[], 1).unwrap();
    assert_eq!(switched[..t], bump[..t], "the first scene until the switch");
    // From the end of the fade on, exactly the new mesh: the estimate
    // continued from the finger's last point and direction.
    let from = t + 10;
    assert_eq!(switched[from..], hole[from..], "the second scene after it");
    assert!(hole[from..].iter().zip(&bump[from..]).any(|(h, b)| h[0] != b[0]), "the meshes differ there");
    assert!(hole.iter().any(|h| h[5] > 0.0), "the scan crosses an edge of the hole");
    for o in &switched {
        assert!(o.iter().all(|v| v.is_finite()) && (0.3..=1.0).contains(&o[0]), "{o:?}");
    }
    // Block processing applies the switch at the same tick.
    assert_eq!(run(BOTH, 10.0, &[(t as u64, 1.0)], 64).unwrap(), switched);
}

#[test]
fn the_crossfade_removes_the_intensity_jump_of_a_switch() {
    let t = 250u64;
    let step = |fade: f64| {
        let o = run(BOTH, fade, &[(t, 1.0)], 1).unwrap();
        o[t as usize - 1..t as usize + 20].windows(2).map(|w| (w[1][0] - w[0][0]).abs()).fold(0.0, f64::max)
    };
    let (cut, faded) = (step(0.0), step(10.0));
    // Climbing the bump (I = 1.0) becomes descending into the hole (I = 0.3).
    assert!((cut - 0.7).abs() < 1e-9, "without a fade the intensity jumps: {cut}");
    assert!(faded <= cut / 10.0 + 1e-9, "with a 10 ms fade the largest step is {faded} (jump {cut})");
}

#[test]
fn scene_indices_and_sources_are_checked() {
    let e = run(&format!("{BOTH}\nscene = 2"), 10.0, &[], 1).unwrap_err();
    assert!(e.contains("2 is not an index into the 2 scenes"), "{e}");
    let e = run("scene = 1", 10.0, &[], 1).unwrap_err();
    assert!(e.contains("without a `scenes` list the only scene is 0"), "{e}");
    let e = run("scenes = [\"bump\", \"hil\"]", 10.0, &[], 1).unwrap_err();
    assert!(e.contains("entry 1 `hil`") && e.contains("hole"), "names the entry and suggests: {e}");
    let e = run("scenes = [\"bump\", \"missing.obj\"]", 10.0, &[], 1).unwrap_err();
    assert!(e.contains("entry 1 `missing.obj`"), "{e}");
    let e = run(BOTH, 10.0, &[(10, 5.0)], 1).unwrap_err();
    assert!(e.contains("scene"), "a live index beyond the list is refused: {e}");
}
