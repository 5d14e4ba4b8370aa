//! What the finger moves over, for the page's finger view: the height map
//! of each scene the first node declaring [`Scene::Mesh`] (`mesh.gradient`)
//! can switch between (sampled by the node family's own ray caster, on a
//! grid over the scene's footprint), or the (load, velocity) axes of each
//! texture grid the first node declaring [`Scene::TextureGrid`] (`interp`)
//! can switch between. Computed once, off the real-time thread, before the
//! session starts.

use evflow_engine::spec::Scene;
use evflow_engine::{BuildContext, Checked};
use serde_json::{json, Value};
use std::path::Path;

/// The scenes the finger view draws, in the order it looks for them.
const SCENES: [Scene; 2] = [Scene::Mesh, Scene::TextureGrid];

/// Height-map samples along the longer side of a scene's footprint.
#[cfg(feature = "mesh")]
const MAP_SAMPLES: usize = 96;

/// The first node, in the plan's order, whose type draws `scene`.
#[allow(dead_code)]
fn first(checked: &Checked, scene: Scene) -> Option<usize> {
    checked.order.iter().copied().find(|&k| checked.nodes[k].spec.scene == Some(scene))
}

#[allow(dead_code)]
fn context(checked: &Checked, k: usize, base_dir: &Path) -> BuildContext {
    let n = &checked.nodes[k];
    BuildContext {
        node: n.origin.clone(),
        base_rate: checked.graph.rate,
        rate: n.ratio.hz(checked.graph.rate),
        input_rates: n.inputs().map(|p| n.ports[p].ratio.hz(checked.graph.rate)).collect(),
        output_rates: n.outputs().map(|p| n.ports[p].ratio.hz(checked.graph.rate)).collect(),
        base_dir: base_dir.to_path_buf(),
        out_dir: std::env::temp_dir(),
        seed: checked.graph.seed,
        check_only: false,
    }
}

/// The height maps (mm, on a grid in touch coordinates, m) of the scenes
/// of the first node that draws a [`Scene::Mesh`].
#[cfg(feature = "mesh")]
fn mesh_maps(checked: &Checked, base_dir: &Path) -> Option<Value> {
    use evflow_nodes::mesh::{place, raycast::RayCaster, source};
    let k = first(checked, Scene::Mesh)?;
    let n = &checked.nodes[k];
    let placed = match source::load_scenes(&n.params, &context(checked, k, base_dir)) {
        Ok(p) => p,
        Err(e) => return Some(json!({ "kind": "none", "why": format!("{}: {e}", n.name) })),
    };
    let mut maps = Vec::new();
    for p in &placed {
        let Some((lo, hi)) = place::footprint(&p.mesh) else { continue };
        let rc = RayCaster::new(&p.mesh);
        let (x0, y0) = (p.offset[0] + lo[0] * p.unit, p.offset[1] + lo[1] * p.unit);
        let (x1, y1) = (p.offset[0] + hi[0] * p.unit, p.offset[1] + hi[1] * p.unit);
        let long = (x1 - x0).max(y1 - y0).max(1e-12);
        let nx = (((x1 - x0) / long * MAP_SAMPLES as f64).round() as usize).max(2);
        let ny = (((y1 - y0) / long * MAP_SAMPLES as f64).round() as usize).max(2);
        let mut z = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            let y = y0 + (y1 - y0) * (j as f64 + 0.5) / ny as f64;
            for i in 0..nx {
                let x = x0 + (x1 - x0) * (i as f64 + 0.5) / nx as f64;
                let (mx, my) = p.to_mesh(x, y);
                let h = rc.cast(mx, my).map(|h| (h.z - p.z0) * p.unit * 1e3);
                z.push(h.filter(|h| h.is_finite()).map(|h| (h * 1e3).round() / 1e3));
            }
        }
        maps.push(json!({ "name": p.name, "x0": x0, "x1": x1, "y0": y0, "y1": y1, "nx": nx, "ny": ny, "z_mm": z }));
    }
    Some(
        json!({ "kind": "mesh", "node": n.name, "scene": n.params.get("scene").and_then(|v| v.as_f64()), "maps": maps }),
    )
}

#[cfg(not(feature = "mesh"))]
fn mesh_maps(_: &Checked, _: &Path) -> Option<Value> {
    None
}

/// The (load, velocity) axes of every texture of the first node that
/// draws a [`Scene::TextureGrid`].
#[cfg(feature = "texture")]
fn texture_grids(checked: &Checked, base_dir: &Path) -> Option<Value> {
    use evflow_nodes::texture::grid::Grid;
    use evflow_nodes::texture::interp::grid_sources;
    let k = first(checked, Scene::TextureGrid)?;
    let n = &checked.nodes[k];
    let p = &n.params;
    let ctx = context(checked, k, base_dir);
    let sources = match grid_sources(p, &ctx) {
        Ok(s) => s,
        Err(e) => return Some(json!({ "kind": "none", "why": format!("{}: {e}", n.name) })),
    };
    let mut grids = Vec::new();
    for (src, name) in sources {
        match Grid::load(&src) {
            Ok(g) => grids.push(json!({ "name": name, "loads_g": g.loads, "velocities_cm_s": g.velocities })),
            Err(e) => return Some(json!({ "kind": "none", "why": format!("{}: {name}: {e}", n.name) })),
        }
    }
    Some(
        json!({ "kind": "grid", "node": n.name, "texture": p.get("texture").and_then(|v| v.as_f64()), "grids": grids }),
    )
}

#[cfg(not(feature = "texture"))]
fn texture_grids(_: &Checked, _: &Path) -> Option<Value> {
    None
}

/// The finger view's background for `checked` (relative paths from
/// `base_dir`, the graph file's folder): a mesh scene's height maps, else a
/// texture's (load, velocity) grid, else `{"kind": "none"}` naming the
/// node types that would have drawn one.
pub fn scene_json(checked: &Checked, base_dir: &Path) -> Value {
    mesh_maps(checked, base_dir).or_else(|| texture_grids(checked, base_dir)).unwrap_or_else(|| {
        let drawers: Vec<&str> = SCENES
            .iter()
            .flat_map(|&s| evflow_nodes::all_specs().into_iter().filter(move |n| n.scene == Some(s)))
            .map(|n| n.name)
            .collect();
        json!({ "kind": "none", "why": format!("no {} node", drawers.join(" or ")) })
    })
}

#[cfg(all(test, feature = "mesh", feature = "texture"))]
mod tests {
    use super::*;

    fn load(name: &str) -> (Checked, std::path::PathBuf) {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("graphs");
        let c = evflow_engine::load_file(&root.join(name), &evflow_nodes::registry(), &[]).unwrap();
        (c, root)
    }

    #[test]
    fn a_graph_without_a_scene_says_which_node_types_draw_one() {
        let (c, dir) = load("excitation.toml");
        let s = scene_json(&c, &dir);
        assert_eq!(s, json!({ "kind": "none", "why": "no mesh.gradient or interp node" }));
    }

    #[test]
    fn mesh_live_has_five_height_maps_with_bumps_and_holes() {
        let (c, dir) = load("mesh-live.toml");
        let s = scene_json(&c, &dir);
        assert_eq!(s["kind"], "mesh");
        let maps = s["maps"].as_array().unwrap();
        assert_eq!(maps.len(), 5);
        // 4B0H: four bumps (heights > 0), 0B4H: four holes (< 0).
        let range = |m: &Value| {
            let z: Vec<f64> = m["z_mm"].as_array().unwrap().iter().filter_map(Value::as_f64).collect();
            (z.iter().cloned().fold(f64::INFINITY, f64::min), z.iter().cloned().fold(f64::NEG_INFINITY, f64::max))
        };
        let (lo0, hi0) = range(&maps[0]);
        let (lo4, hi4) = range(&maps[4]);
        assert!(lo0 < -0.1 && hi0 < 0.1, "0B4H: holes only ({lo0}, {hi0}) mm");
        assert!(hi4 > 0.1 && lo4 > -0.1, "4B0H: bumps only ({lo4}, {hi4}) mm");
    }

    #[test]
    fn texture_live_has_the_grid_axes_of_each_texture() {
        let (c, dir) = load("texture-live.toml");
        let s = scene_json(&c, &dir);
        assert_eq!(s["kind"], "grid");
        assert_eq!(s["grids"].as_array().unwrap().len(), 6);
        assert_eq!(s["grids"][0]["loads_g"], json!([60.0, 110.0]));
        assert_eq!(s["grids"][0]["velocities_cm_s"], json!([3.0, 7.0]));
    }
}
