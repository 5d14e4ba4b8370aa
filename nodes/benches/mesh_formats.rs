//! Loading the Stanford bunny (69 451 triangles, `tests/data/bunny.glb`)
//! from each mesh format: read, parse, weld, orient — `formats::load_file`,
//! what a mesh node does before building its BVH (issue 16, point 2).
//!
//! `cargo bench -p evflow-nodes --bench mesh_formats`

#[path = "../tests/mesh_formats_util/mod.rs"]
mod mesh_formats_util;

use criterion::{criterion_group, criterion_main, Criterion};
use evflow_nodes::mesh::formats::load_file;
use mesh_formats_util::{Axis, WRITERS};
use std::hint::black_box;
use std::path::Path;

fn load(c: &mut Criterion) {
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bunny.glb");
    let mesh = load_file(&bunny, 0.0).expect("the shipped bunny");
    let dir = tempfile::tempdir().unwrap();
    let mut g = c.benchmark_group("load bunny");
    g.sample_size(10);
    for (suffix, write) in WRITERS {
        let path = dir.path().join(format!("bunny.{suffix}"));
        let bytes = write(&mesh, Axis::YUp);
        std::fs::write(&path, &bytes).unwrap();
        let name = format!("{suffix} ({:.1} MB)", bytes.len() as f64 / 1e6);
        g.bench_function(name, |b| b.iter(|| black_box(load_file(&path, 0.0).unwrap().triangles.len())));
    }
    g.finish();
}

criterion_group!(benches, load);
criterion_main!(benches);
