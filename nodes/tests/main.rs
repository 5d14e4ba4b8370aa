//! The node families' integration tests in one binary: each file is a module
//! (one link instead of fifteen). The allocation tests (narx_alloc,
//! rate_alloc) stay binaries of their own: each installs a counting
//! global allocator.

mod mesh_formats_util;
mod texture_util;

mod every_node;
mod families;
mod mesh_extremes;
mod mesh_formats;
mod mesh_robustness;
mod mesh_scan;
mod mesh_scenes;
mod narx_grid;
mod narx_lab;
mod narx_node;
mod texture_carrier;
mod texture_extremes;
mod texture_nodes;
mod texture_sines;
mod texture_switch;
