//! `wscg octree`: paper 10 (the unified triangle/voxel octree) on the user's own meshes.
//!
//! - `build`: voxelize an OBJ/PLY mesh (vertex colours are kept) and build the octree; writes
//!   the tree with its mesh to a checksummed file and prints the memory report.
//! - `render`: ray-cast a saved tree from a camera in triangles, voxels or hybrid mode, with
//!   Phong shading and shadows; optionally a false-colour map of the LoD levels.
//! - `info`: the memory report (the paper's Table 2 columns) of a saved tree.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use wscg_math::{Error, Result, TriMesh};
use wscg_octree::{
    build, lod_map, render, scenes, BuildParams, Camera, Focus, HybridOctree, PointLight, Shading,
    TraceMode,
};

#[derive(Subcommand, Debug)]
pub enum OctreeCommand {
    /// Build the octree of an OBJ/PLY mesh and save it.
    Build(BuildArgs),
    /// Render a saved octree to a PNG.
    Render(RenderArgs),
    /// Print the memory report of a saved octree.
    Info {
        /// Octree file written by `wscg octree build`.
        tree: PathBuf,
    },
}

#[derive(Args, Debug)]
pub struct BuildArgs {
    /// Input mesh (.obj or .ply; per-vertex colours are used when present); only read.
    mesh: PathBuf,
    /// Deepest level L (512^3 cells: 9); at most 21.
    #[arg(long, default_value_t = 9)]
    depth: u8,
    /// Build the full octree (no early stop at nodes with at most two triangles).
    #[arg(long)]
    full: bool,
    /// Output octree file.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Octree file written by `wscg octree build`.
    tree: PathBuf,
    /// Camera as eye x,y,z,target x,y,z (9 values with up x,y,z; default up +z). Default: an
    /// oblique view from 1.5 cube sides away.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    camera: Vec<f32>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 45.0)]
    fov: f32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x1024")]
    size: String,
    /// Trace mode: triangles, voxels or hybrid.
    #[arg(long, default_value = "hybrid")]
    mode: String,
    /// Stop voxels mode at this level instead of the leaves.
    #[arg(long)]
    level: Option<u8>,
    /// Point light position x,y,z (default: above and beside the cube).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    light: Vec<f32>,
    /// No shadow rays.
    #[arg(long)]
    no_shadows: bool,
    /// View-dependent detail (hybrid mode): triangles inside the ellipse cx,cy,a,b (pixels),
    /// voxels coarsening outside it, the LoD scale doubling every FALLOFF pixels:
    /// cx,cy,a,b,falloff.
    #[arg(long, value_delimiter = ',')]
    focus: Vec<f32>,
    /// Ambient-occlusion rays per hit (0: none).
    #[arg(long, default_value_t = 0)]
    ao: u32,
    /// Length of the ambient-occlusion rays as a fraction of the cube side.
    #[arg(long, default_value_t = 0.05)]
    ao_radius: f32,
    /// Write a false-colour map of what each pixel stopped at instead of the shaded image.
    #[arg(long)]
    lod_map: bool,
    /// Output PNG.
    #[arg(long)]
    out: PathBuf,
}

fn mode_arg(name: &str, level: Option<u8>) -> Result<TraceMode> {
    match name {
        "triangles" => Ok(TraceMode::Triangles),
        "voxels" => Ok(TraceMode::Voxels { level }),
        "hybrid" => Ok(TraceMode::HYBRID),
        other => Err(Error::invalid(
            "mode",
            format!("{other:?} is not valid; valid: triangles, voxels, hybrid"),
        )),
    }
}

fn size_arg(s: &str) -> Result<(usize, usize)> {
    let bad = || Error::invalid("size", format!("expected WIDTHxHEIGHT, got {s:?}"));
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    Ok((
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

fn camera_arg(
    v: &[f32],
    oct: &HybridOctree,
    fov: f32,
    (width, height): (usize, usize),
) -> Result<Camera> {
    let (eye, target, up) = match v {
        [] => {
            let c = scenes::orbit_path(&oct.cube, 1, 1.5, 1.5, width)[0];
            (c.eye, c.target, c.up)
        }
        [a, b, c, d, e, f] => ([*a, *b, *c], [*d, *e, *f], [0.0, 0.0, 1.0]),
        [a, b, c, d, e, f, g, h, i] => ([*a, *b, *c], [*d, *e, *f], [*g, *h, *i]),
        _ => {
            return Err(Error::invalid(
                "camera",
                format!(
                    "give 6 values (eye, target) or 9 (eye, target, up), got {}",
                    v.len()
                ),
            ))
        }
    };
    Ok(Camera {
        eye,
        target,
        up,
        fov_y_deg: fov,
        width,
        height,
    })
}

fn report(oct: &HybridOctree) {
    let m = oct.memory_report();
    let mb = |b: usize| b as f64 / (1024.0 * 1024.0);
    println!(
        "depth {}, {}; {} triangles, {} nodes, {} voxels\nmemory (MB): nodes {:.2}, triangles {:.2}, triangle index {:.2}, voxels {:.2}, total {:.2}",
        oct.max_depth,
        if oct.early_stop { "early stop" } else { "full octree" },
        oct.mesh.faces.len(),
        oct.nodes.len(),
        oct.voxels.len(),
        mb(m.nodes),
        mb(m.triangles),
        mb(m.tri_index),
        mb(m.voxels),
        mb(m.total)
    );
}

pub fn run(cmd: OctreeCommand) -> Result<()> {
    match cmd {
        OctreeCommand::Build(a) => {
            crate::commands::overwrite::check_file("out", &a.out, [&a.mesh])?;
            let mesh = TriMesh::read(&a.mesh)?;
            let p = BuildParams::default()
                .max_depth(a.depth)
                .early_stop(!a.full);
            let (oct, st) = build(&mesh, &p)?;
            println!(
                "{} fragments ({} zero-area triangles skipped); voxelize {:.2} s, hierarchy {:.2} s, attributes {:.2} s",
                st.fragments, st.degenerate_triangles, st.voxelize_s, st.hierarchy_s, st.attributes_s
            );
            report(&oct);
            oct.save(&a.out)?;
            println!("wrote {}", a.out.display());
            Ok(())
        }
        OctreeCommand::Render(a) => {
            crate::commands::overwrite::check_file("out", &a.out, [&a.tree])?;
            let oct = HybridOctree::load(&a.tree)?;
            let mode = mode_arg(&a.mode, a.level)?;
            let cam = camera_arg(&a.camera, &oct, a.fov, size_arg(&a.size)?)?;
            let focus = match a.focus.as_slice() {
                [] => None,
                [cx, cy, ra, rb, f] => Some(Focus {
                    centre: [*cx, *cy],
                    radii: [*ra, *rb],
                    falloff: *f,
                }),
                _ => {
                    return Err(Error::invalid(
                        "focus",
                        "give five values cx,cy,a,b,falloff (pixels)",
                    ))
                }
            };
            if a.lod_map {
                lod_map(&oct, &cam, &mode, focus.as_ref())?.save(&a.out)?;
            } else {
                let light = match a.light.as_slice() {
                    [] => scenes::default_light(&oct.cube),
                    [x, y, z] => PointLight {
                        position: [*x, *y, *z],
                        intensity: 1.0,
                    },
                    _ => return Err(Error::invalid("light", "give three values x,y,z")),
                };
                let shading = Shading {
                    shadows: !a.no_shadows,
                    ..Default::default()
                };
                let (img, st) = render(&oct, &cam, &light, &mode, &shading)?;
                println!(
                    "{} triangle hits, {} voxel hits, {} misses in {:.3} s",
                    st.triangle_hits, st.voxel_hits, st.misses, st.seconds
                );
                img.map(|v| v.clamp(0.0, 1.0)).save(&a.out)?;
            }
            println!("wrote {}", a.out.display());
            Ok(())
        }
        OctreeCommand::Info { tree } => {
            report(&HybridOctree::load(&tree)?);
            Ok(())
        }
    }
}
