//! Generated scene meshes and their ray casters, built once while in use.
//!
//! Building a generated §4.2 scene ([`scenes::scene`], whose `Mesh::new`
//! finds every edge's neighbours) and its BVH ([`RayCaster::new`]) is most
//! of what loading a mesh node costs: seconds at a million triangles. The
//! same scene is often built several times over: by the two mesh nodes of
//! one graph (`mesh.gradient` and `mesh.edges` in `graphs/mesh-live.toml`
//! load the same scenes), and by runs that follow one another in a study
//! (`report precision`'s live-mesh curve strokes its 512-cell reference in
//! eight graphs). Here each is built once and handed out as an [`Arc`].
//!
//! Sharing changes no result: a generated scene is a function of its shape,
//! config word and resolution alone, built by the same code either way, and
//! neither a [`Mesh`] nor a [`RayCaster`] changes after it is built (nodes
//! read both through shared references).
//!
//! # How long a mesh lives
//!
//! The process keeps weak references only, so by default a mesh lives as
//! long as some node holds it — the nodes of one graph, or of graphs run at
//! the same time, share; nothing outlives them. A [`Keep`] guard holds on
//! to every mesh and caster built while it lives, so that runs one after
//! the other share too; the last guard dropped lets them go. A study that
//! runs the same scenes in a row takes one for its duration.
//!
//! Mesh files are not shared (a file can change between two loads); their
//! ray casters are, between the nodes that hold the same mesh.
//!
//! The store is behind a mutex: nodes are built before a run starts, never
//! on the real-time thread.

use super::raycast::RayCaster;
use super::scenes::{self, Shape};
use super::{Mesh, MeshError};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, Weak};

/// A generated scene: shape, config word, resolution.
type Key = (Shape, String, usize);

/// What the process knows of the meshes and casters in use.
#[derive(Default)]
struct Store {
    meshes: HashMap<Key, Weak<Mesh>>,
    /// Each caster beside the mesh it was built for. The weak reference to
    /// the mesh keeps its allocation, so its address is not reused while
    /// the entry exists: comparing addresses identifies the mesh.
    casters: Vec<(Weak<Mesh>, Weak<RayCaster>)>,
    /// Held for the [`Keep`] guards alive.
    kept_meshes: Vec<Arc<Mesh>>,
    kept_casters: Vec<Arc<RayCaster>>,
    keepers: usize,
}

static STORE: Mutex<Option<Store>> = Mutex::new(None);

/// The store, locked (a panic elsewhere while it was held leaves nothing
/// half-written: every change below is one insertion or removal).
fn store() -> MutexGuard<'static, Option<Store>> {
    STORE.lock().unwrap_or_else(PoisonError::into_inner)
}

fn with_store<T>(f: impl FnOnce(&mut Store) -> T) -> T {
    f(store().get_or_insert_with(Store::default))
}

/// The generated scene (as [`scenes::scene`] builds it), shared with every
/// node that holds the same one.
pub fn scene(shape: Shape, config: &str, resolution: usize) -> Result<Arc<Mesh>, MeshError> {
    let key = (shape, config.to_string(), resolution);
    if let Some(m) = with_store(|s| s.meshes.get(&key).and_then(Weak::upgrade)) {
        return Ok(m);
    }
    // Built without the lock: other threads go on loading meanwhile.
    let built = Arc::new(scenes::scene(shape, config, resolution)?);
    Ok(with_store(|s| {
        s.meshes.retain(|_, w| w.strong_count() > 0);
        // Another thread may have built the same scene meanwhile: the first one stays.
        if let Some(m) = s.meshes.get(&key).and_then(Weak::upgrade) {
            return m;
        }
        s.meshes.insert(key, Arc::downgrade(&built));
        if s.keepers > 0 {
            s.kept_meshes.push(built.clone());
        }
        built
    }))
}

/// The ray caster (BVH) of `mesh`, shared with every node that holds the
/// same mesh.
pub fn ray_caster(mesh: &Arc<Mesh>) -> Arc<RayCaster> {
    let find = |s: &Store| {
        s.casters.iter().find(|(m, _)| std::ptr::eq(m.as_ptr(), Arc::as_ptr(mesh))).and_then(|(_, c)| c.upgrade())
    };
    if let Some(c) = with_store(|s| find(s)) {
        return c;
    }
    let built = Arc::new(RayCaster::new(mesh));
    with_store(|s| {
        s.casters.retain(|(m, c)| m.strong_count() > 0 && c.strong_count() > 0);
        if let Some(c) = find(s) {
            return c;
        }
        s.casters.push((Arc::downgrade(mesh), Arc::downgrade(&built)));
        if s.keepers > 0 {
            s.kept_casters.push(built.clone());
        }
        built
    })
}

/// While a `Keep` lives, every mesh and ray caster built here is kept, so
/// that graphs run one after the other build each once (module
/// documentation). Dropping the last one lets them go.
#[must_use = "the meshes are kept only while the guard lives"]
pub struct Keep {
    _private: (),
}

impl Keep {
    /// Starts keeping.
    pub fn new() -> Self {
        with_store(|s| s.keepers += 1);
        Keep { _private: () }
    }
}

impl Default for Keep {
    fn default() -> Self {
        Self::new()
    }
}

impl Drop for Keep {
    fn drop(&mut self) {
        // Freed after the lock is released.
        let _released = with_store(|s| {
            s.keepers -= 1;
            if s.keepers == 0 {
                (std::mem::take(&mut s.kept_meshes), std::mem::take(&mut s.kept_casters))
            } else {
                (Vec::new(), Vec::new())
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The store is one per process and tests run in parallel: each test
    // uses a scene of its own.

    #[test]
    fn a_scene_in_use_is_built_once_and_equals_a_fresh_one() {
        let a = scene(Shape::Gaussian, "1B3H", 5).unwrap();
        let b = scene(Shape::Gaussian, "1B3H", 5).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        let fresh = scenes::scene(Shape::Gaussian, "1B3H", 5).unwrap();
        assert_eq!(a.vertices, fresh.vertices);
        assert_eq!(a.triangles, fresh.triangles);
        // Another resolution, config or shape is another mesh.
        assert!(!Arc::ptr_eq(&a, &scene(Shape::Gaussian, "1B3H", 6).unwrap()));
        assert!(!Arc::ptr_eq(&a, &scene(Shape::Gaussian, "2B2H", 5).unwrap()));
        assert!(!Arc::ptr_eq(&a, &scene(Shape::Frustum, "1B3H", 5).unwrap()));
        // Errors are the scene's own, and nothing is stored for them.
        assert!(scene(Shape::Gaussian, "9B9H", 5).is_err());
        assert!(scene(Shape::Gaussian, "1B3H", 1).is_err());
    }

    #[test]
    fn a_scene_no_node_holds_is_let_go() {
        let a = scene(Shape::Gaussian, "3B1H", 7).unwrap();
        let weak = Arc::downgrade(&a);
        drop(a);
        assert!(weak.upgrade().is_none(), "the store held the mesh");
        // Built again on demand.
        assert_eq!(scene(Shape::Gaussian, "3B1H", 7).unwrap().triangles.len(), {
            scenes::scene(Shape::Gaussian, "3B1H", 7).unwrap().triangles.len()
        });
    }

    #[test]
    fn a_caster_is_shared_by_the_holders_of_one_mesh_only() {
        let m = scene(Shape::Gaussian, "4B0H", 4).unwrap();
        let (a, b) = (ray_caster(&m), ray_caster(&m));
        assert!(Arc::ptr_eq(&a, &b));
        // The same triangles in another allocation get their own caster.
        let other = Arc::new(scenes::scene(Shape::Gaussian, "4B0H", 4).unwrap());
        let c = ray_caster(&other);
        assert!(!Arc::ptr_eq(&a, &c));
        // And it casts as one built directly.
        let direct = RayCaster::new(&m);
        for (x, y) in [(0.0, 0.0), (0.01, -0.02), (0.5, 0.5), (-0.03, 0.004)] {
            let (got, want) = (a.cast(x, y), direct.cast(x, y));
            assert_eq!(got.map(|h| (h.tri, h.z.to_bits())), want.map(|h| (h.tri, h.z.to_bits())));
        }
        let weak = Arc::downgrade(&a);
        drop((a, b));
        assert!(weak.upgrade().is_none(), "the store held the caster");
    }

    #[test]
    fn a_keep_guard_holds_what_is_built_while_it_lives() {
        let keep = Keep::new();
        let m = scene(Shape::Gaussian, "0B4H", 9).unwrap();
        let c = ray_caster(&m);
        let (wm, wc) = (Arc::downgrade(&m), Arc::downgrade(&c));
        drop((m, c));
        let again = scene(Shape::Gaussian, "0B4H", 9).unwrap();
        assert!(std::ptr::eq(wm.as_ptr(), Arc::as_ptr(&again)), "kept: the same mesh comes back");
        assert!(Arc::ptr_eq(&wc.upgrade().unwrap(), &ray_caster(&again)));
        drop(again);
        drop(keep);
        // This is the only test that takes a guard: with it gone, so are they.
        assert_eq!((wm.strong_count(), wc.strong_count()), (0, 0), "the last guard dropped, they are let go");
    }
}
