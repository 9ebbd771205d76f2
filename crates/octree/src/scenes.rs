//! Synthetic test scenes with the triangle-size-to-voxel-size character of the paper's scenes
//! (§5): the paper's Sponza, Urban Sprawl, Happy Buddha and plant models are not available
//! offline, so the trends of Tables 2-3 are reproduced on generated geometry.
//!
//! - [`atrium`] (Sponza-like): a hall, two rows of pillars and arches; large triangles.
//! - [`city`] (Urban Sprawl-like): a grid of buildings with facades tessellated into windows.
//! - [`blob`] (Happy Buddha-like): a displaced icosphere whose triangles are voxel-sized.
//! - [`forest`]: procedural trees (branch prisms and leaf quads) on a ground plane.
//! - [`exact_square`]: two triangles with closed-form node counts.

use rand::Rng;
use wscg_math::{rng, Error, Result, TriMesh};

use crate::cube::Cube;

/// Accumulates coloured triangles (vertices are not shared between parts, so colours are
/// per part).
#[derive(Default)]
pub struct SceneBuilder {
    positions: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    colors: Vec<[f32; 3]>,
}

fn lerp3(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
}

impl SceneBuilder {
    /// Adds a vertex.
    pub fn vertex(&mut self, p: [f64; 3], c: [f32; 3]) -> u32 {
        self.positions.push(p);
        self.colors.push(c);
        (self.positions.len() - 1) as u32
    }

    /// Adds a quad `a b c d` (counter-clockwise) as an `nu x nv` grid of cells, two triangles
    /// each.
    pub fn quad(&mut self, q: [[f64; 3]; 4], nu: usize, nv: usize, c: [f32; 3]) {
        let base = self.positions.len() as u32;
        for j in 0..=nv {
            let t = j as f64 / nv as f64;
            let (l, r) = (lerp3(q[0], q[3], t), lerp3(q[1], q[2], t));
            for i in 0..=nu {
                self.vertex(lerp3(l, r, i as f64 / nu as f64), c);
            }
        }
        let w = nu as u32 + 1;
        for j in 0..nv as u32 {
            for i in 0..nu as u32 {
                let a = base + j * w + i;
                self.faces.push([a, a + 1, a + w + 1]);
                self.faces.push([a, a + w + 1, a + w]);
            }
        }
    }

    /// Adds an axis-aligned box `[lo, hi]` with its 6 faces (each `n x n` cells).
    pub fn cuboid(&mut self, lo: [f64; 3], hi: [f64; 3], n: usize, c: [f32; 3]) {
        let p = |x: usize, y: usize, z: usize| [[lo, hi][x][0], [lo, hi][y][1], [lo, hi][z][2]];
        let faces = [
            [p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0)],
            [p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1)],
            [p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1)],
            [p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0)],
            [p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0)],
            [p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1)],
        ];
        for q in faces {
            self.quad(q, n, n, c);
        }
    }

    /// Adds an open prism (a tube) of `sides` sides and radius `r` around segment `a -> b`.
    pub fn prism(&mut self, a: [f64; 3], b: [f64; 3], r: f64, sides: usize, c: [f32; 3]) {
        let axis = std::array::from_fn::<f64, 3, _>(|k| b[k] - a[k]);
        let len = axis.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
        let w = axis.map(|v| v / len);
        let helper = if w[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let u = wscg_math::vec3::normalized_or_zero(wscg_math::vec3::cross(w, helper));
        let v = wscg_math::vec3::cross(w, u);
        let base = self.positions.len() as u32;
        for end in [a, b] {
            for s in 0..sides {
                let ang = std::f64::consts::TAU * s as f64 / sides as f64;
                let (cs, sn) = (ang.cos(), ang.sin());
                self.vertex(
                    std::array::from_fn(|k| end[k] + r * (cs * u[k] + sn * v[k])),
                    c,
                );
            }
        }
        let n = sides as u32;
        for s in 0..n {
            let (i, j) = (base + s, base + (s + 1) % n);
            self.faces.push([i, j, j + n]);
            self.faces.push([i, j + n, i + n]);
        }
    }

    /// Number of triangles so far.
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    /// Whether nothing was added.
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// The mesh with per-vertex colours.
    pub fn finish(self) -> Result<TriMesh> {
        TriMesh::new(self.positions, self.faces)?.with_colors(self.colors)
    }
}

/// Refuses, before building it, a scene of `units` repeated parts (buildings, pillars) of at
/// most `vertices` vertices each whose mesh cannot fit in memory or index its vertices with
/// `u32`.
fn check_units(what: &'static str, units: usize, vertices: usize) -> Result<()> {
    // A vertex holds a position and a colour (36 bytes) and comes with about 1.5 triangles
    // (18 bytes); 64 bytes bound both.
    let total = wscg_math::alloc::elements(what, &[units, vertices])?;
    wscg_math::alloc::ensure::<[u8; 64]>(what, total)?;
    if total >= u32::MAX as usize {
        return Err(Error::invalid(
            what,
            format!("{units} parts of up to {vertices} vertices exceed the 2^32 vertex indices of a mesh"),
        ));
    }
    Ok(())
}

/// A case with an exactly known voxelization: the square `[0,1]^2` at `z = 1/3` as two
/// triangles, and the unit cube as its domain (1/3 is never on a dyadic cell boundary).
pub fn exact_square() -> Result<(TriMesh, Cube)> {
    let z = 1.0 / 3.0;
    let m = TriMesh::new(
        vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
        vec![[0, 1, 2], [0, 2, 3]],
    )?;
    Ok((m, Cube::new([0.0; 3], 1.0)?))
}

/// Sponza-like hall: floor, ceiling and walls of a 4 x 2 x 1.6 box, two rows of `pillars`
/// octagonal pillars with arches between them. Most triangles span many voxels at 512^3.
///
/// Errors: [`Error::OutOfMemory`] or [`Error::InvalidArgument`] naming `pillars` when the
/// mesh cannot fit in memory or in 32-bit vertex indices.
pub fn atrium(pillars: usize) -> Result<TriMesh> {
    // Per pillar and row: a prism of 16 vertices and an arch of 8 prisms of 12.
    check_units("pillars", pillars, 2 * (16 + 8 * 12))?;
    let mut s = SceneBuilder::default();
    let (lx, ly, lz) = (4.0, 2.0, 1.6);
    let stone = [0.75, 0.68, 0.55];
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [lx, 0.0, 0.0],
            [lx, ly, 0.0],
            [0.0, ly, 0.0],
        ],
        4,
        2,
        [0.55, 0.35, 0.25],
    );
    s.quad(
        [[0.0, 0.0, lz], [0.0, ly, lz], [lx, ly, lz], [lx, 0.0, lz]],
        4,
        2,
        stone,
    );
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, lz],
            [lx, 0.0, lz],
            [lx, 0.0, 0.0],
        ],
        4,
        2,
        [0.8, 0.2, 0.2],
    );
    s.quad(
        [[0.0, ly, 0.0], [lx, ly, 0.0], [lx, ly, lz], [0.0, ly, lz]],
        4,
        2,
        [0.2, 0.3, 0.8],
    );
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [0.0, ly, 0.0],
            [0.0, ly, lz],
            [0.0, 0.0, lz],
        ],
        2,
        2,
        stone,
    );
    s.quad(
        [[lx, 0.0, 0.0], [lx, 0.0, lz], [lx, ly, lz], [lx, ly, 0.0]],
        2,
        2,
        stone,
    );
    let (h, r) = (1.0, 0.06);
    for row in [0.6, ly - 0.6] {
        let xs: Vec<f64> = (0..pillars)
            .map(|i| 0.4 + (lx - 0.8) * i as f64 / (pillars.max(2) - 1) as f64)
            .collect();
        for &x in &xs {
            s.prism([x, row, 0.0], [x, row, h], r, 8, stone);
        }
        for w in xs.windows(2) {
            // A half-ring arch of 8 segments between neighbouring pillars.
            let (cx, rad) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
            for k in 0..8 {
                let a0 = std::f64::consts::PI * k as f64 / 8.0;
                let a1 = std::f64::consts::PI * (k + 1) as f64 / 8.0;
                let p = |a: f64| [cx - rad * a.cos(), row, h + rad * a.sin()];
                s.prism(p(a0), p(a1), 0.5 * r, 6, stone);
            }
        }
    }
    s.finish()
}

/// Urban-Sprawl-like city: an `n x n` grid of buildings of random height on a ground plane,
/// facades tessellated into one cell per window (4 per side and floor).
///
/// Errors: [`Error::OutOfMemory`] or [`Error::InvalidArgument`] naming `n` when the mesh
/// cannot fit in memory or in 32-bit vertex indices.
pub fn city(n: usize, seed: u64) -> Result<TriMesh> {
    // Four facades of 5 x 12 vertices and a roof of 4 per building.
    check_units(
        "n",
        wscg_math::alloc::elements("n", &[n, n])?,
        4 * 5 * 12 + 4,
    )?;
    let mut s = SceneBuilder::default();
    let mut r = rng::seeded(seed);
    let pitch = 1.0;
    let size = n as f64 * pitch;
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [size, 0.0, 0.0],
            [size, size, 0.0],
            [0.0, size, 0.0],
        ],
        4,
        4,
        [0.3, 0.3, 0.3],
    );
    for i in 0..n {
        for j in 0..n {
            let floors = r.random_range(2..12usize);
            let h = 0.25 * floors as f64;
            let (x0, y0) = (i as f64 * pitch + 0.15, j as f64 * pitch + 0.15);
            let (x1, y1) = (x0 + 0.7, y0 + 0.7);
            let c = [
                r.random_range(0.4..0.9f32),
                r.random_range(0.4..0.9f32),
                r.random_range(0.4..0.9f32),
            ];
            s.quad(
                [[x0, y0, 0.0], [x1, y0, 0.0], [x1, y0, h], [x0, y0, h]],
                4,
                floors,
                c,
            );
            s.quad(
                [[x1, y0, 0.0], [x1, y1, 0.0], [x1, y1, h], [x1, y0, h]],
                4,
                floors,
                c,
            );
            s.quad(
                [[x1, y1, 0.0], [x0, y1, 0.0], [x0, y1, h], [x1, y1, h]],
                4,
                floors,
                c,
            );
            s.quad(
                [[x0, y1, 0.0], [x0, y0, 0.0], [x0, y0, h], [x0, y1, h]],
                4,
                floors,
                c,
            );
            s.quad(
                [[x0, y0, h], [x1, y0, h], [x1, y1, h], [x0, y1, h]],
                1,
                1,
                [0.2, 0.2, 0.25],
            );
        }
    }
    s.finish()
}

/// Happy-Buddha-like blob: an icosphere of `subdivisions` (8 gives 1,310,720 triangles) and
/// radius 0.4, displaced radially by smooth noise; colour follows the displacement.
pub fn blob(subdivisions: u32) -> Result<TriMesh> {
    let sphere = TriMesh::icosphere(subdivisions, 1.0)?;
    let disp = |p: [f64; 3]| {
        0.12 * (3.0 * p[0] + 1.0).sin() * (4.0 * p[1]).cos()
            + 0.08 * (5.0 * p[2] + 2.0 * p[0]).sin()
            + 0.04 * (9.0 * p[1] + 7.0 * p[2]).sin()
    };
    let mut colors = Vec::with_capacity(sphere.positions.len());
    let positions = sphere
        .positions
        .iter()
        .map(|&p| {
            let d = disp(p);
            let t = (0.5 + 2.5 * d) as f32;
            colors.push([
                0.9 * t.clamp(0.0, 1.0) + 0.1,
                0.6,
                0.9 - 0.7 * t.clamp(0.0, 1.0),
            ]);
            p.map(|v| 0.4 * (1.0 + d) * v)
        })
        .collect();
    TriMesh::new(positions, sphere.faces)?.with_colors(colors)
}

/// A forest of `trees` procedural trees on a ground plane: branches are 6-sided prisms split
/// recursively `levels` times into 3 children, each terminal branch carries `leaves` leaf quads.
/// 13 trees with `levels = 6`, `leaves = 64` give about 1.4 M triangles.
pub fn forest(trees: usize, levels: usize, leaves: usize, seed: u64) -> Result<TriMesh> {
    let mut s = SceneBuilder::default();
    let mut r = rng::seeded(seed);
    let side = (trees as f64).sqrt().ceil().max(1.0);
    let extent = 2.0 * side;
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [extent, 0.0, 0.0],
            [extent, extent, 0.0],
            [0.0, extent, 0.0],
        ],
        8,
        8,
        [0.35, 0.5, 0.2],
    );
    for t in 0..trees {
        let base = [
            2.0 * (t as f64 % side) + 1.0 + r.random_range(-0.3..0.3),
            2.0 * (t as f64 / side).floor() + 1.0 + r.random_range(-0.3..0.3),
            0.0,
        ];
        branch(
            &mut s,
            &mut r,
            base,
            [0.0, 0.0, 1.0],
            0.6,
            0.05,
            levels,
            leaves,
        );
    }
    s.finish()
}

#[allow(clippy::too_many_arguments)]
fn branch(
    s: &mut SceneBuilder,
    r: &mut rng::Rng,
    a: [f64; 3],
    dir: [f64; 3],
    len: f64,
    rad: f64,
    level: usize,
    leaves: usize,
) {
    let b = std::array::from_fn(|k| a[k] + len * dir[k]);
    s.prism(a, b, rad, 6, [0.4, 0.27, 0.15]);
    if level == 0 {
        for _ in 0..leaves {
            let c: [f64; 3] = std::array::from_fn(|k| b[k] + r.random_range(-0.15..0.15));
            let u: [f64; 3] = std::array::from_fn(|_| r.random_range(-0.015..0.015));
            let v: [f64; 3] = std::array::from_fn(|_| r.random_range(-0.015..0.015));
            let g = [
                0.15 + r.random_range(0.0..0.2f32),
                0.5 + r.random_range(0.0..0.3f32),
                0.1,
            ];
            let q = [
                std::array::from_fn(|k| c[k] - u[k] - v[k]),
                std::array::from_fn(|k| c[k] + u[k] - v[k]),
                std::array::from_fn(|k| c[k] + u[k] + v[k]),
                std::array::from_fn(|k| c[k] - u[k] + v[k]),
            ];
            s.quad(q, 1, 1, g);
        }
        return;
    }
    for _ in 0..3 {
        let mut d: [f64; 3] = std::array::from_fn(|k| dir[k] + r.random_range(-0.7..0.7));
        d[2] = d[2].abs() + 0.2;
        let d = wscg_math::vec3::normalized_or_zero(d);
        branch(s, r, b, d, len * 0.7, rad * 0.65, level - 1, leaves);
    }
}

/// Cameras on an orbit around the centre of `cube`: frame `i` of `frames` turns by
/// `i / frames` of a full circle and moves linearly from `near` to `far` cube sides away, 0.3
/// times that distance above the centre. Square images of `res` pixels, 45 degree
/// field of view. The fly-throughs of the paper's Table 3 are paths like this one.
pub fn orbit_path(
    cube: &Cube,
    frames: usize,
    near: f32,
    far: f32,
    res: usize,
) -> Vec<crate::Camera> {
    let s = cube.size as f32;
    let c = cube.min.map(|v| v as f32);
    let target = [c[0] + 0.5 * s, c[1] + 0.5 * s, c[2] + 0.5 * s];
    (0..frames)
        .map(|i| {
            let f = i as f32 / frames.max(1) as f32;
            let a = f * std::f32::consts::TAU;
            let d = s * (near + (far - near) * f);
            crate::Camera {
                eye: [
                    target[0] + d * a.cos(),
                    target[1] + d * a.sin(),
                    target[2] + 0.3 * d,
                ],
                target,
                up: [0.0, 0.0, 1.0],
                fov_y_deg: 45.0,
                width: res,
                height: res,
            }
        })
        .collect()
}

/// A point light above and to the side of `cube`, used by the demos and benchmarks.
pub fn default_light(cube: &Cube) -> crate::PointLight {
    let s = cube.size as f32;
    let c = cube.min.map(|v| v as f32);
    crate::PointLight {
        position: [c[0] + 1.5 * s, c[1] - 0.5 * s, c[2] + 2.0 * s],
        intensity: 1.0,
    }
}
