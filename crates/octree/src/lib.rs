//! # wscg-octree
//!
//! Paper 10 of WSCG vol. 23: "A Unified Triangle/Voxel Structure for GPUs and its
//! Applications". One sparse voxel octree serves two purposes: every non-empty node carries a
//! pre-filtered voxel (colour and normal) for level of detail, and the leaves hold references
//! to the triangles inside them for exact ray tracing. Construction stops early at nodes with
//! at most two triangles, which saves memory and time where triangles are large. Rays stop at
//! the voxel level matching their pixel footprint, blending with the parent level, and
//! intersect triangles up close.
//!
//! The paper's GPU pipeline is re-expressed as a data-parallel CPU pipeline:
//!
//! - [`voxelize`]: exact triangle / box voxelization into Morton-coded fragments
//!   ([`overlap`] holds the separating-axis test).
//! - [`build()`]: level-by-level construction with early stop, the compact 8-byte [`Node`]
//!   layout with single / pair / list leaves, bottom-up attributes ([`BuildParams`];
//!   `early_stop = false` builds the paper's full-octree baseline).
//! - [`traverse`]: front-to-back traversal with a short stack in three modes: triangles only
//!   (baseline), voxels only, and the paper's hybrid with LoD blending.
//! - [`render()`]: primary rays, Phong shading and shadow rays (Table 3's renderer).
//! - [`baseline`]: brute-force and BVH triangle ray casting.
//! - [`scenes`]: synthetic scenes with the character of the paper's test scenes.
//! - [`HybridOctree::save`] / [`HybridOctree::load`]: a checksummed file that reloads
//!   bit-identically.
//!
//! Out of scope: the OpenGL voxelization and OpenCL renderer themselves, the 40 M instanced
//! trees, the display-wall focus-and-context ellipsoid and out-of-core construction.
//!
//! ```
//! use wscg_octree::{build, scenes, BuildParams, Ray, TraceMode};
//! let mesh = scenes::blob(3).unwrap();
//! let (oct, stats) = build(&mesh, &BuildParams::default().max_depth(6)).unwrap();
//! assert!(stats.early_leaves > 0);
//! let hit = oct.intersect(&Ray::new([0.0, 0.0, -2.0], [0.0, 0.0, 1.0]), &TraceMode::Triangles, None);
//! assert!(hit.is_some());
//! ```
#![warn(missing_docs)]

pub mod baseline;
pub mod build;
pub mod cube;
pub mod io;
pub mod node;
pub mod octree;
pub mod overlap;
pub mod render;
pub mod scenes;
pub mod traverse;
pub mod voxelize;

pub use baseline::{brute_force, TriangleBvh};
pub use build::{build, BuildParams, BuildStats};
pub use cube::{morton, Cube};
pub use node::{LeafTris, Node, NodeArray, Voxel};
pub use octree::{HybridOctree, MemoryReport, Tri};
pub use render::{
    lod_map, render, Camera, Focus, PixelRect, PointLight, RayGen, RenderStats, Shading,
};
pub use traverse::{Footprint, Hit, HitKind, Ray, TraceMode};
pub use voxelize::{voxelize, Fragment, Fragments};
