//! Procedural test scenes of the many-light renderer (paper 08).
//!
//! The paper's scenes (Sibenik, Sponza, Conference from the McGuire archive) are not
//! redistributable here, so the tests, demos and benchmarks use stand-ins built in code:
//!
//! - [`cornell_box`]: the classic Cornell box, the paper's Fig. 3 scene.
//! - [`colonnade`]: the Sponza stand-in, a closed hall lit only through a roof opening.
//! - [`conference_room`]: the Conference stand-in, chairs half under a table.
//! - [`plane_with_light`]: a tiny emitter over a plane, for the closed-form single-VPL check.
//!
//! Every scene is deterministic, and every quad of it is split into `subdiv x subdiv` cells
//! of two triangles each, so the triangle count is `subdiv^2` times the count at
//! `subdiv = 1` (the emitter of [`plane_with_light`] excepted) and can be raised to the
//! paper's sizes for benchmarks: `conference_room(30, ..)` has 327,600 triangles (paper:
//! 331,179), `colonnade(17, ..)` 69,360 (Sponza: 66,450), `cornell_box(46, ..)` 76,176
//! (Sibenik: 75,284).
//!
//! Each function returns the scene and a camera preset that frames it at the requested image
//! size. The scenes are built with [`MeshBuilder`], which orients every quad by the side it
//! should face, so that the front side (counter-clockwise, the side emitters radiate from) of
//! each wall faces the inside of its room and of each solid faces out. Units are those of the
//! originals: millimetre-like units for the Cornell box, metres elsewhere. Emission is
//! radiance in linear RGB.

use nalgebra::Vector3;
use wscg_math::{Error, Result};

use super::camera::Camera;
use super::scene::{Rgb, Scene};

/// The largest accepted `subdiv`: `conference_room(64, ..)` already has about 1.5 million
/// triangles.
pub const MAX_SUBDIV: u32 = 64;

/// Height of the emitter of [`plane_with_light`] above the plane.
pub const PLANE_LIGHT_HEIGHT: f64 = 1.0;
/// Side of the square emitter of [`plane_with_light`].
pub const PLANE_LIGHT_SIDE: f64 = 0.01;
/// Emitted radiance of [`plane_with_light`]'s emitter (every channel): its power is
/// `Phi = pi * L_e * side^2 = pi`.
pub const PLANE_LIGHT_RADIANCE: f64 = 1.0 / (PLANE_LIGHT_SIDE * PLANE_LIGHT_SIDE);
/// Albedo of [`plane_with_light`]'s plane (every channel).
pub const PLANE_ALBEDO: f64 = 0.5;

/// Reflectance and emitted radiance of a surface (linear RGB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Lambertian albedo, each channel in `[0, 1]`.
    pub albedo: Rgb,
    /// Emitted radiance (`>= 0`), radiated from the front side only.
    pub emission: Rgb,
}

impl Material {
    /// A non-emitting Lambertian surface of albedo `albedo`.
    pub const fn diffuse(albedo: Rgb) -> Self {
        Self {
            albedo,
            emission: [0.0; 3],
        }
    }

    /// A grey non-emitting surface of albedo `a` in every channel.
    pub const fn grey(a: f64) -> Self {
        Self::diffuse([a, a, a])
    }

    /// An emitter of radiance `emission` that also reflects with albedo `albedo`.
    pub const fn emitter(albedo: Rgb, emission: Rgb) -> Self {
        Self { albedo, emission }
    }
}

/// Materials of the six sides of an axis-aligned room or box, `None` leaving a side out
/// (named by the coordinate plane the side lies in).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sides {
    /// The side at the smallest x.
    pub x_min: Option<Material>,
    /// The side at the largest x.
    pub x_max: Option<Material>,
    /// The side at the smallest y (the floor of a room).
    pub y_min: Option<Material>,
    /// The side at the largest y (the ceiling of a room).
    pub y_max: Option<Material>,
    /// The side at the smallest z.
    pub z_min: Option<Material>,
    /// The side at the largest z.
    pub z_max: Option<Material>,
}

impl Sides {
    /// All six sides of material `m`.
    pub const fn all(m: Material) -> Self {
        Self {
            x_min: Some(m),
            x_max: Some(m),
            y_min: Some(m),
            y_max: Some(m),
            z_min: Some(m),
            z_max: Some(m),
        }
    }
}

/// An indexed triangle mesh with per-face materials under construction, every quad split
/// into `subdiv x subdiv` cells of two triangles.
#[derive(Clone, Debug)]
pub struct MeshBuilder {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles (indices into `vertices`, counter-clockwise seen from the front).
    pub faces: Vec<[u32; 3]>,
    /// Albedo per face.
    pub albedo: Vec<Rgb>,
    /// Emitted radiance per face.
    pub emission: Vec<Rgb>,
    subdiv: u32,
}

impl MeshBuilder {
    /// An empty mesh whose quads will be split into `subdiv x subdiv` cells.
    ///
    /// Errors: `subdiv` outside `1..=`[`MAX_SUBDIV`].
    pub fn new(subdiv: u32) -> Result<Self> {
        if !(1..=MAX_SUBDIV).contains(&subdiv) {
            return Err(Error::invalid(
                "subdiv",
                format!("must lie in 1..={MAX_SUBDIV}, got {subdiv}"),
            ));
        }
        Ok(Self {
            vertices: Vec::new(),
            faces: Vec::new(),
            albedo: Vec::new(),
            emission: Vec::new(),
            subdiv,
        })
    }

    /// The number of cells along each edge of a quad.
    pub fn subdiv(&self) -> u32 {
        self.subdiv
    }

    /// Adds the planar quad with corners `corners` (in order around its boundary, either
    /// direction), its front side facing `facing`: the corners are reversed when
    /// `(b - a) x (c - a)` points away from `facing` (kept as given when perpendicular).
    pub fn quad(&mut self, corners: [[f64; 3]; 4], facing: [f64; 3], mat: Material) -> &mut Self {
        self.grid(corners, facing, mat, self.subdiv)
    }

    /// Adds an axis-aligned box from `min` to `max` with outward-facing sides of material
    /// `mat` (six quads).
    pub fn boxx(&mut self, min: [f64; 3], max: [f64; 3], mat: Material) -> &mut Self {
        self.cuboid(min, max, Sides::all(mat), false)
    }

    /// Adds the sides of the axis-aligned room from `min` to `max` facing inwards (the
    /// `None` sides left out).
    pub fn room(&mut self, min: [f64; 3], max: [f64; 3], sides: Sides) -> &mut Self {
        self.cuboid(min, max, sides, true)
    }

    /// Adds the vertical prism over the convex quadrilateral `footprint` (`[x, z]` corners in
    /// order around it, either direction) from height `y0` to `y1`, sides facing out (six
    /// quads): a box rotated about the vertical axis.
    pub fn prism(
        &mut self,
        footprint: [[f64; 2]; 4],
        y0: f64,
        y1: f64,
        mat: Material,
    ) -> &mut Self {
        let m = Some(mat);
        self.solid(footprint, y0, y1, [m; 6], false)
    }

    /// The scene of the faces added so far (see [`Scene::from_triangles`] for the errors).
    pub fn build(&self) -> Result<Scene> {
        Scene::from_triangles(&self.vertices, &self.faces, &self.albedo, &self.emission)
    }

    fn cuboid(&mut self, min: [f64; 3], max: [f64; 3], s: Sides, inward: bool) -> &mut Self {
        let fp = [
            [min[0], min[2]],
            [max[0], min[2]],
            [max[0], max[2]],
            [min[0], max[2]],
        ];
        // Order of `solid`: bottom, top, then the sides from footprint edge 0 -> 1 on.
        let mats = [s.y_min, s.y_max, s.z_min, s.x_max, s.z_max, s.x_min];
        self.solid(fp, min[1], max[1], mats, inward)
    }

    /// The prism over `fp` from `y0` to `y1`; `mats` for the bottom, the top and the sides
    /// over footprint edges 0-1, 1-2, 2-3, 3-0; each face oriented away from (or, `inward`,
    /// towards) the centre.
    fn solid(
        &mut self,
        fp: [[f64; 2]; 4],
        y0: f64,
        y1: f64,
        mats: [Option<Material>; 6],
        inward: bool,
    ) -> &mut Self {
        let b = fp.map(|p| [p[0], y0, p[1]]);
        let t = fp.map(|p| [p[0], y1, p[1]]);
        let centre = fp
            .iter()
            .fold(Vector3::new(0.0, 0.5 * (y0 + y1), 0.0), |c, p| {
                c + Vector3::new(0.25 * p[0], 0.0, 0.25 * p[1])
            });
        let mut quads = vec![b, t];
        for i in 0..4 {
            let j = (i + 1) % 4;
            quads.push([b[i], b[j], t[j], t[i]]);
        }
        for (q, mat) in quads.into_iter().zip(mats) {
            let Some(mat) = mat else { continue };
            let mid = q.iter().fold(Vector3::zeros(), |c, p| c + v3(*p)) * 0.25;
            let out = if inward { centre - mid } else { mid - centre };
            self.grid(q, out.into(), mat, self.subdiv);
        }
        self
    }

    /// The quad as an `n x n` grid of cells (bilinear in the corners), two triangles each.
    fn grid(&mut self, c: [[f64; 3]; 4], facing: [f64; 3], mat: Material, n: u32) -> &mut Self {
        let [a, b, cc, d] = c.map(v3);
        let (a, b, cc, d) = if (b - a).cross(&(cc - a)).dot(&v3(facing)) < 0.0 {
            (a, d, cc, b)
        } else {
            (a, b, cc, d)
        };
        let base = self.vertices.len() as u32;
        let nf = n as f64;
        for j in 0..=n {
            let v = j as f64 / nf;
            for i in 0..=n {
                let u = i as f64 / nf;
                let p = a * ((1.0 - u) * (1.0 - v))
                    + b * (u * (1.0 - v))
                    + cc * (u * v)
                    + d * ((1.0 - u) * v);
                self.vertices.push(p.into());
            }
        }
        let id = |i: u32, j: u32| base + j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                let (p00, p10, p11, p01) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                self.faces.push([p00, p10, p11]);
                self.faces.push([p00, p11, p01]);
                for _ in 0..2 {
                    self.albedo.push(mat.albedo);
                    self.emission.push(mat.emission);
                }
            }
        }
        self
    }
}

fn v3(p: [f64; 3]) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

/// The corners of the horizontal rectangle centred at `c` with half-sides `half` (along `x`
/// and `z`).
fn horizontal(c: [f64; 3], half: [f64; 2]) -> [[f64; 3]; 4] {
    let ([x, y, z], [hx, hz]) = (c, half);
    [
        [x - hx, y, z - hz],
        [x + hx, y, z - hz],
        [x + hx, y, z + hz],
        [x - hx, y, z + hz],
    ]
}

/// A camera with `+y` up, checked to give a valid frame.
fn preset(
    eye: [f64; 3],
    target: [f64; 3],
    fov_deg: f64,
    width: usize,
    height: usize,
) -> Result<Camera> {
    let cam = Camera {
        eye,
        target,
        up: [0.0, 1.0, 0.0],
        fov_deg,
        width,
        height,
    };
    cam.frame()?;
    Ok(cam)
}

/// White of the Cornell box.
const CORNELL_WHITE: Material = Material::grey(0.725);

/// The Cornell box (Goral et al. 1984; the paper's Fig. 3 scene) with its classic camera.
///
/// The room spans `x` in `[0, 555]`, `y` in `[0, 548.8]` (floor to ceiling), `z` in
/// `[0, 559.2]` (the back wall at the largest `z`): the measured Cornell data squared up.
/// Its front (`z = 0`) is open, as in the original and in Mitsuba 3's `cornell_box()`,
/// because the camera looks in from outside (the scene's rays hit both sides of a triangle,
/// so a front wall would hide the room); every ray from inside that hits nothing leaves
/// through that opening. Walls: red `(0.63, 0.065, 0.05)` at `x = 555` (on the left of the
/// image), green `(0.14, 0.45, 0.091)` at `x = 0` (right), white `0.725` floor, ceiling
/// and back wall, all facing the inside. The two blocks are the classic rotated ones
/// (white, sides facing out, bottoms included): the short block of height 165 on the
/// footprint `(130, 65), (82, 225), (240, 272), (290, 114)` (`x, z`) and the tall one of
/// height 330 on `(423, 247), (265, 296), (314, 456), (472, 406)`. The light is a
/// `130 x 105` quad (`x` by `z`) centred under the ceiling at `y = 548.7`, facing down, of
/// radiance `L_e = (17, 12, 4)` and white albedo.
///
/// Triangles: `36 subdiv^2`, of which `2 subdiv^2` emit. Camera: eye `(278, 273, -800)`,
/// target `(278, 273, 0)`, up `+y`, vertical field of view 39.3 degrees, `width x height`
/// pixels.
///
/// Errors: `subdiv` outside `1..=`[`MAX_SUBDIV`], an empty image size.
pub fn cornell_box(subdiv: u32, width: usize, height: usize) -> Result<(Scene, Camera)> {
    let (w, h, d) = (555.0, 548.8, 559.2);
    let mut m = MeshBuilder::new(subdiv)?;
    m.room(
        [0.0; 3],
        [w, h, d],
        Sides {
            x_min: Some(Material::diffuse([0.14, 0.45, 0.091])),
            x_max: Some(Material::diffuse([0.63, 0.065, 0.05])),
            y_min: Some(CORNELL_WHITE),
            y_max: Some(CORNELL_WHITE),
            z_min: None,
            z_max: Some(CORNELL_WHITE),
        },
    );
    m.quad(
        horizontal([0.5 * w, 548.7, 0.5 * d], [65.0, 52.5]),
        [0.0, -1.0, 0.0],
        Material::emitter(CORNELL_WHITE.albedo, [17.0, 12.0, 4.0]),
    );
    m.prism(
        [[130.0, 65.0], [82.0, 225.0], [240.0, 272.0], [290.0, 114.0]],
        0.0,
        165.0,
        CORNELL_WHITE,
    );
    m.prism(
        [
            [423.0, 247.0],
            [265.0, 296.0],
            [314.0, 456.0],
            [472.0, 406.0],
        ],
        0.0,
        330.0,
        CORNELL_WHITE,
    );
    let cam = preset(
        [278.0, 273.0, -800.0],
        [278.0, 273.0, 0.0],
        39.3,
        width,
        height,
    )?;
    Ok((m.build()?, cam))
}

/// The Sponza stand-in: a closed hall with two rows of pillars, lit only by a "sun" emitter
/// seen through an opening strip of the roof, so that most of the hall is lit indirectly
/// and visibility changes strongly from place to place.
///
/// The hall spans `x` in `[0, 30]` (its length), `y` in `[0, 10]`, `z` in `[0, 12]`:
/// floor grey `0.6`, long walls `(0.55, 0.5, 0.45)`, end walls `(0.5, 0.5, 0.55)`, all
/// facing in. Two rows of 8 square `1 x 1` pillars `(0.7, 0.6, 0.5)` of height 8, centred at
/// `x = 3.75 (i + 0.5)` and `z = 3.5` and `8.5`, carry lintels `(0.6, 0.5, 0.4)` (`1 x 1`
/// cross-section, `y` in `[8, 9]`) along the whole length; the central aisle lies between
/// `z = 4` and `z = 8`. The roof `(0.5, 0.5, 0.5)` at `y = 10` faces down and leaves open
/// the strip `z` in `[5, 7]` over the full length, above the aisle. Over the strip, a light
/// well of height 1 (walls grey `0.5`, facing in) is closed by the sun proxy: a `30 x 2`
/// emitter at `y = 11` facing down, radiance `(20, 19, 17)`, albedo 0. The whole is closed:
/// every ray from inside hits something.
///
/// Triangles: `240 subdiv^2`, of which `2 subdiv^2` emit. Camera: eye `(1, 2.5, 6)` at one
/// end of the aisle, looking along it at `(29, 4.5, 6)`, up `+y`, vertical field of view
/// 65 degrees.
///
/// Errors: `subdiv` outside `1..=`[`MAX_SUBDIV`], an empty image size.
pub fn colonnade(subdiv: u32, width: usize, height: usize) -> Result<(Scene, Camera)> {
    let (len, hgt, dep) = (30.0, 10.0, 12.0);
    let (z0, z1, well) = (5.0, 7.0, 1.0);
    let long_wall = Some(Material::diffuse([0.55, 0.5, 0.45]));
    let end_wall = Some(Material::diffuse([0.5, 0.5, 0.55]));
    let roof = Material::grey(0.5);
    let pillar = Material::diffuse([0.7, 0.6, 0.5]);
    let lintel = Material::diffuse([0.6, 0.5, 0.4]);
    let mut m = MeshBuilder::new(subdiv)?;
    m.room(
        [0.0; 3],
        [len, hgt, dep],
        Sides {
            x_min: end_wall,
            x_max: end_wall,
            y_min: Some(Material::grey(0.6)),
            y_max: None,
            z_min: long_wall,
            z_max: long_wall,
        },
    );
    for (za, zb) in [(0.0, z0), (z1, dep)] {
        m.quad(
            [
                [0.0, hgt, za],
                [len, hgt, za],
                [len, hgt, zb],
                [0.0, hgt, zb],
            ],
            [0.0, -1.0, 0.0],
            roof,
        );
    }
    m.room(
        [0.0, hgt, z0],
        [len, hgt + well, z1],
        Sides {
            y_min: None,
            y_max: Some(Material::emitter([0.0; 3], [20.0, 19.0, 17.0])),
            ..Sides::all(Material::grey(0.5))
        },
    );
    for zc in [3.5, 8.5] {
        for i in 0..8 {
            let xc = len / 8.0 * (i as f64 + 0.5);
            m.boxx([xc - 0.5, 0.0, zc - 0.5], [xc + 0.5, 8.0, zc + 0.5], pillar);
        }
        m.boxx([0.0, 8.0, zc - 0.5], [len, 9.0, zc + 0.5], lintel);
    }
    let cam = preset([1.0, 2.5, 6.0], [29.0, 4.5, 6.0], 65.0, width, height)?;
    Ok((m.build()?, cam))
}

/// The Conference stand-in: a meeting room whose chairs stand half under a table, the
/// paper's case of surfaces occluded from most lights (Fig. 6, 9).
///
/// The room spans `x` in `[0, 10]`, `y` in `[0, 3]`, `z` in `[0, 7]`: floor
/// `(0.4, 0.35, 0.3)`, ceiling `0.8`, walls `(0.7, 0.68, 0.62)` except the one at `x = 10`
/// `(0.55, 0.6, 0.7)`, all facing in. The table `(0.55, 0.35, 0.2)` has a `4 x 1.5` top
/// (`x` in `[3, 7]`, `z` in `[2.75, 4.25]`) from `y = 0.7` to `0.75` on four `0.08 x 0.08`
/// legs `(0.2, 0.2, 0.2)` set in by 0.1. Eight chairs `(0.15, 0.25, 0.5)`, four along each
/// long side at `x = 3.5, 4.5, 5.5, 6.5`, each a `0.45 x 0.45` seat (`y` in
/// `[0.42, 0.47]`) centred on the table's edge (so half under the table), a back `0.05`
/// thick up to `y = 0.95` on its outer edge, and a `0.06 x 0.06` post under the seat (so
/// that seats do not float). Two `1.2 x 0.6` ceiling
/// panels centred at `(3.5, 3.5)` and `(6.5, 3.5)` (`x, z`) at `y = 2.99` face down,
/// radiance `(15, 14, 12)`, albedo `0.8`. Every side of a solid faces out; the room is
/// closed.
///
/// Triangles: `364 subdiv^2`, of which `4 subdiv^2` emit. Camera: eye `(0.4, 1.7, 0.4)` in
/// a corner, looking at the table's centre `(5, 0.75, 3.5)`, up `+y`, vertical field of
/// view 60 degrees.
///
/// Errors: `subdiv` outside `1..=`[`MAX_SUBDIV`], an empty image size.
pub fn conference_room(subdiv: u32, width: usize, height: usize) -> Result<(Scene, Camera)> {
    let wall = Some(Material::diffuse([0.7, 0.68, 0.62]));
    let wood = Material::diffuse([0.55, 0.35, 0.2]);
    let leg = Material::grey(0.2);
    let chair = Material::diffuse([0.15, 0.25, 0.5]);
    let mut m = MeshBuilder::new(subdiv)?;
    m.room(
        [0.0; 3],
        [10.0, 3.0, 7.0],
        Sides {
            x_min: wall,
            x_max: Some(Material::diffuse([0.55, 0.6, 0.7])),
            y_min: Some(Material::diffuse([0.4, 0.35, 0.3])),
            y_max: Some(Material::grey(0.8)),
            z_min: wall,
            z_max: wall,
        },
    );
    let (tx0, tx1, tz0, tz1, ty0, ty1) = (3.0, 7.0, 2.75, 4.25, 0.7, 0.75);
    m.boxx([tx0, ty0, tz0], [tx1, ty1, tz1], wood);
    let (inset, lw) = (0.1, 0.08);
    for x in [tx0 + inset, tx1 - inset - lw] {
        for z in [tz0 + inset, tz1 - inset - lw] {
            m.boxx([x, 0.0, z], [x + lw, ty0, z + lw], leg);
        }
    }
    let (half, seat0, seat1, back_top, back, post) = (0.225, 0.42, 0.47, 0.95, 0.05, 0.03);
    // Each side: the table edge, and the back's z range on the seat's outer edge.
    let sides = [
        (tz0, [tz0 - half - back, tz0 - half]),
        (tz1, [tz1 + half, tz1 + half + back]),
    ];
    for (edge, [ba, bb]) in sides {
        for xc in [3.5, 4.5, 5.5, 6.5] {
            let (za, zb) = (edge - half, edge + half);
            m.boxx([xc - half, seat0, za], [xc + half, seat1, zb], chair);
            m.boxx([xc - half, seat0, ba], [xc + half, back_top, bb], chair);
            m.boxx(
                [xc - post, 0.0, edge - post],
                [xc + post, seat0, edge + post],
                chair,
            );
        }
    }
    let panel = Material::emitter([0.8; 3], [15.0, 14.0, 12.0]);
    for xc in [3.5, 6.5] {
        m.quad(
            horizontal([xc, 2.99, 3.5], [0.6, 0.3]),
            [0.0, -1.0, 0.0],
            panel,
        );
    }
    let cam = preset([0.4, 1.7, 0.4], [5.0, 0.75, 3.5], 60.0, width, height)?;
    Ok((m.build()?, cam))
}

/// A tiny square emitter over a large plane: a scene where the contribution of a single VPL
/// (the summand of eq. 1) has a closed form.
///
/// The plane is the `20 x 20` square `x, z` in `[-10, 10]` at `y = 0`, facing `+y`, albedo
/// [`PLANE_ALBEDO`] `= 0.5`, split into `subdiv x subdiv` cells. The emitter is one square
/// of side [`PLANE_LIGHT_SIDE`] `= 0.01` centred at `(0, h, 0)`, `h =`
/// [`PLANE_LIGHT_HEIGHT`] `= 1`, facing down, albedo 0, radiance [`PLANE_LIGHT_RADIANCE`]
/// `= 10^4` in every channel, so its power is `Phi = pi L_e side^2 = pi`; it is never
/// subdivided (always 2 triangles). Treated as a point light (one VPL of power `Phi` at its
/// centre, normal `-y`), it gives the plane point at distance `d` from it the radiance
///
/// `L = (rho / pi) (Phi / pi) cos(theta_x) cos(theta_y) / d^2 = 0.5 h^2 / (pi d^4)`
///
/// per channel (`cos(theta_x) = cos(theta_y) = h / d`); the area emitter itself deviates
/// from that point-light value by a relative `O((side / d)^2) ~ 10^-4`.
///
/// Triangles: `2 subdiv^2 + 2`, of which 2 emit. Camera: eye `(0, 3, -5)`, target the
/// origin, up `+y`, vertical field of view 50 degrees.
///
/// Errors: `subdiv` outside `1..=`[`MAX_SUBDIV`], an empty image size.
pub fn plane_with_light(subdiv: u32, width: usize, height: usize) -> Result<(Scene, Camera)> {
    let mut m = MeshBuilder::new(subdiv)?;
    let plane = horizontal([0.0; 3], [10.0, 10.0]);
    m.quad(plane, [0.0, 1.0, 0.0], Material::grey(PLANE_ALBEDO));
    let s = 0.5 * PLANE_LIGHT_SIDE;
    let light = horizontal([0.0, PLANE_LIGHT_HEIGHT, 0.0], [s, s]);
    let mat = Material::emitter([0.0; 3], [PLANE_LIGHT_RADIANCE; 3]);
    m.grid(light, [0.0, -1.0, 0.0], mat, 1);
    let cam = preset([0.0, 3.0, -5.0], [0.0; 3], 50.0, width, height)?;
    Ok((m.build()?, cam))
}

/// Names of the procedural scenes, for [`by_name`].
pub const SCENE_NAMES: [&str; 4] = ["cornell", "colonnade", "conference", "plane"];

/// The procedural scene `name` (one of [`SCENE_NAMES`]) with its camera.
///
/// Errors: an unknown name (the message lists the valid ones), the scene's own.
pub fn by_name(name: &str, subdiv: u32, width: usize, height: usize) -> Result<(Scene, Camera)> {
    match name {
        "cornell" => cornell_box(subdiv, width, height),
        "colonnade" => colonnade(subdiv, width, height),
        "conference" => conference_room(subdiv, width, height),
        "plane" => plane_with_light(subdiv, width, height),
        other => Err(Error::invalid(
            "scene",
            format!(
                "{other:?} is not a scene; valid scenes are {}",
                SCENE_NAMES.join(", ")
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    type Builder = fn(u32, usize, usize) -> Result<(Scene, Camera)>;

    const CLOSED: [(&str, Builder); 3] = [
        ("cornell_box", cornell_box),
        ("colonnade", colonnade),
        ("conference_room", conference_room),
    ];

    fn unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                rng.random::<f64>() * 2.0 - 1.0,
                rng.random::<f64>() * 2.0 - 1.0,
                rng.random::<f64>() * 2.0 - 1.0,
            );
            let n = v.norm();
            if n > 1e-3 && n <= 1.0 {
                return v / n;
            }
        }
    }

    fn emitter_area(s: &Scene) -> f64 {
        s.emitters()
            .iter()
            .map(|&i| s.triangles()[i as usize].area)
            .sum()
    }

    /// Points in free space (inside the room, outside every solid) of each closed scene.
    fn free_points(name: &str) -> Vec<Vector3<f64>> {
        let p: &[[f64; 3]] = match name {
            "cornell_box" => &[
                [278.0, 450.0, 280.0],
                [150.0, 300.0, 400.0],
                [450.0, 100.0, 100.0],
            ],
            "colonnade" => &[
                [15.0, 5.0, 6.0],
                [2.5, 2.0, 1.5],
                [28.0, 9.5, 10.5],
                [15.0, 10.5, 6.0],
            ],
            _ => &[
                [5.0, 2.0, 1.0],
                [1.0, 0.3, 6.0],
                [5.0, 0.3, 3.5],
                [9.0, 2.9, 6.0],
            ],
        };
        p.iter().map(|&q| v3(q)).collect()
    }

    #[test]
    fn triangle_and_emitter_counts() {
        let expect = [(36, 2), (240, 2), (364, 4)];
        for ((name, f), (tris, emit)) in CLOSED.iter().zip(expect) {
            let (s, _) = f(1, 64, 48).unwrap();
            assert_eq!((s.len(), s.emitters().len()), (tris, emit), "{name}");
            assert_eq!(s.skipped_degenerate, 0, "{name}");
            let (s3, _) = f(3, 64, 48).unwrap();
            assert_eq!(s3.len(), 9 * tris, "{name}");
            assert_eq!(s3.emitters().len(), 9 * emit, "{name}");
        }
        let (p1, _) = plane_with_light(1, 8, 8).unwrap();
        let (p4, _) = plane_with_light(4, 8, 8).unwrap();
        assert_eq!((p1.len(), p4.len()), (4, 34));
        assert_eq!((p1.emitters().len(), p4.emitters().len()), (2, 2));
    }

    #[test]
    fn cornell_light_area_radiance_and_facing() {
        for subdiv in [1, 2, 5] {
            let (s, _) = cornell_box(subdiv, 64, 48).unwrap();
            assert!((emitter_area(&s) - 130.0 * 105.0).abs() < 1e-6 * 130.0 * 105.0);
            for &i in s.emitters() {
                assert_eq!(s.emission(i), [17.0, 12.0, 4.0]);
                let t = &s.triangles()[i as usize];
                assert!((v3(t.normal) - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12);
                assert!((t.p0[1] - 548.7).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn cornell_walls_face_the_inside_with_their_colours() {
        let (s, _) = cornell_box(2, 64, 48).unwrap();
        let (mut floor, mut red, mut green) = (0.0, 0.0, 0.0);
        for (i, t) in s.triangles().iter().enumerate() {
            let c = v3(t.p0) + (v3(t.e1) + v3(t.e2)) / 3.0;
            let a = s.albedo(i as u32);
            if c.y.abs() < 1e-9 && t.normal[1] > 0.5 {
                floor += t.area;
                assert_eq!(a, [0.725; 3]);
            }
            if (c.x - 555.0).abs() < 1e-9 {
                assert!((v3(t.normal) - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-12);
                assert_eq!(a, [0.63, 0.065, 0.05]);
                red += t.area;
            }
            if c.x.abs() < 1e-9 {
                assert!((v3(t.normal) - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
                assert_eq!(a, [0.14, 0.45, 0.091]);
                green += t.area;
            }
            if (c.z - 559.2).abs() < 1e-9 {
                assert!(t.normal[2] < -0.999);
            }
            if (c.y - 548.8).abs() < 1e-9 {
                assert!(t.normal[1] < -0.999);
            }
        }
        assert!((floor - 555.0 * 559.2).abs() < 1e-6 * floor);
        assert!((red - 548.8 * 559.2).abs() < 1e-6 * red);
        assert!((green - red).abs() < 1e-6 * red);
    }

    /// 2000 random rays from free space in each closed scene hit something, and hit the
    /// front side (walls face in, solids out); only the Cornell box's open front lets rays
    /// out.
    #[test]
    fn closed_scenes_catch_every_ray_on_front_sides() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for (name, f) in CLOSED {
            let (s, _) = f(2, 64, 48).unwrap();
            let pts = free_points(name);
            let mut escaped = 0;
            for k in 0..2000 {
                let o = pts[k % pts.len()];
                let d = unit(&mut rng);
                match s.intersect(o.into(), d.into(), f64::INFINITY) {
                    Some(h) => assert!(
                        v3(h.normal).dot(&d) < 0.0,
                        "{name}: back side hit from {o:?}"
                    ),
                    None => {
                        assert_eq!(name, "cornell_box", "ray from {o:?} along {d:?} escaped");
                        // It leaves through the open front z = 0 inside the wall's outline.
                        assert!(d.z < 0.0);
                        let p = o + d * (-o.z / d.z);
                        assert!((0.0..=555.0).contains(&p.x) && (0.0..=548.8).contains(&p.y));
                        escaped += 1;
                    }
                }
            }
            if name == "cornell_box" {
                assert!(escaped > 0 && escaped < 1000, "{escaped}");
            }
        }
    }

    #[test]
    fn colonnade_light_enters_only_through_the_roof_opening() {
        let (s, _) = colonnade(1, 64, 48).unwrap();
        assert!((emitter_area(&s) - 60.0).abs() < 1e-9);
        let down = [0.0, -1.0, 0.0];
        // Straight down from the sun through the opening onto the aisle floor.
        for x in [0.5, 7.0, 15.0, 29.5] {
            let h = s.intersect([x, 10.9, 6.0], down, f64::INFINITY).unwrap();
            assert!(h.pos[1].abs() < 1e-9 && h.normal[1] > 0.999);
            // From above the side aisles, the roof blocks the way up.
            let up = [0.0, 1.0, 0.0];
            let h = s.intersect([x, 5.0, 1.5], up, f64::INFINITY).unwrap();
            assert!((h.pos[1] - 10.0).abs() < 1e-9 && h.normal[1] < -0.999);
        }
        // Each pillar is there: a ray along a row hits the first pillar's face.
        let h = s
            .intersect([0.01, 4.0, 3.5], [1.0, 0.0, 0.0], f64::INFINITY)
            .unwrap();
        assert!((h.pos[0] - (30.0 / 16.0 - 0.5)).abs() < 1e-9);
    }

    #[test]
    fn conference_chairs_are_half_under_the_table() {
        let (s, _) = conference_room(1, 64, 48).unwrap();
        assert!((emitter_area(&s) - 2.0 * 1.2 * 0.6).abs() < 1e-9);
        let up = [0.0, 1.0, 0.0];
        for xc in [3.5, 4.5, 5.5, 6.5] {
            for (inside, outside) in [(2.85, 2.6), (4.15, 4.4)] {
                // The inner half of the seat lies under the table top, the outer half not.
                let h = s
                    .intersect([xc + 0.1, 0.5, inside], up, f64::INFINITY)
                    .unwrap();
                assert!((h.pos[1] - 0.7).abs() < 1e-9, "{xc} {inside}: {h:?}");
                let h = s
                    .intersect([xc + 0.1, 0.5, outside], up, f64::INFINITY)
                    .unwrap();
                assert!(h.pos[1] > 2.9, "{xc} {outside}: {h:?}");
            }
        }
    }

    #[test]
    fn camera_presets_frame_their_scenes() {
        let all: [(&str, Builder); 4] = [
            CLOSED[0],
            CLOSED[1],
            CLOSED[2],
            ("plane_with_light", plane_with_light),
        ];
        for (name, f) in all {
            let (s, cam) = f(1, 32, 24).unwrap();
            assert_eq!((cam.width, cam.height), (32, 24));
            let fr = cam.frame().unwrap();
            let h = s.intersect(fr.eye(), fr.ray(16.0, 12.0), f64::INFINITY);
            assert!(h.is_some(), "{name}: the central ray misses");
            // Inside the closed rooms, the four corner rays hit the scene as well (the
            // Cornell frame has a thin margin around the box's open front, as the classic).
            if name == "colonnade" || name == "conference_room" {
                for (x, y) in [(0.5, 0.5), (31.5, 0.5), (0.5, 23.5), (31.5, 23.5)] {
                    assert!(
                        s.intersect(fr.eye(), fr.ray(x, y), f64::INFINITY).is_some(),
                        "{name}"
                    );
                }
            }
        }
        // The Cornell camera's central ray meets the tall block's front side, between its
        // front corners (265, 296) and (423, 247) (x, z).
        let (s, cam) = cornell_box(1, 32, 24).unwrap();
        let fr = cam.frame().unwrap();
        let h = s.intersect(fr.eye(), fr.forward(), f64::INFINITY).unwrap();
        assert!(
            h.pos[2] > 247.0 && h.pos[2] < 296.0 && h.pos[1] < 330.0,
            "{h:?}"
        );
    }

    #[test]
    fn plane_with_light_matches_its_documentation() {
        let (s, _) = plane_with_light(3, 8, 8).unwrap();
        let area = emitter_area(&s);
        assert!((area - 1e-4).abs() < 1e-15);
        let phi = std::f64::consts::PI * PLANE_LIGHT_RADIANCE * area;
        assert!((phi - std::f64::consts::PI).abs() < 1e-12);
        for &i in s.emitters() {
            let t = &s.triangles()[i as usize];
            assert!(t.normal[1] < -0.999 && (t.p0[1] - 1.0).abs() < 1e-12);
        }
        let plane: f64 = s
            .triangles()
            .iter()
            .enumerate()
            .filter(|(i, _)| s.emission(*i as u32) == [0.0; 3])
            .map(|(i, t)| {
                assert!(t.normal[1] > 0.999);
                assert_eq!(s.albedo(i as u32), [0.5; 3]);
                t.area
            })
            .sum();
        assert!((plane - 400.0).abs() < 1e-9);
    }

    #[test]
    fn bad_arguments_are_errors() {
        for (name, f) in CLOSED {
            assert!(f(0, 8, 8).is_err(), "{name}");
            assert!(f(MAX_SUBDIV + 1, 8, 8).is_err(), "{name}");
            assert!(f(1, 0, 8).is_err(), "{name}");
            assert!(f(1, 8, 0).is_err(), "{name}");
        }
        let e = plane_with_light(0, 8, 8).unwrap_err().to_string();
        assert!(e.contains("subdiv"), "{e}");
        assert!(MeshBuilder::new(1).unwrap().build().is_err());
    }

    #[test]
    fn builder_orients_quads_by_their_facing() {
        let mut m = MeshBuilder::new(2).unwrap();
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
        ];
        m.quad(c, [0.0, 1.0, 0.0], Material::grey(0.5));
        m.quad(c, [0.0, -1.0, 0.0], Material::grey(0.5));
        m.boxx([2.0, 2.0, 2.0], [3.0, 4.0, 5.0], Material::grey(0.5));
        let s = m.build().unwrap();
        assert_eq!(s.len(), 2 * 8 + 6 * 8);
        let t = s.triangles();
        assert!(t[..8].iter().all(|t| t.normal[1] > 0.999));
        assert!(t[8..16].iter().all(|t| t.normal[1] < -0.999));
        let centre = Vector3::new(2.5, 3.0, 3.5);
        for t in &t[16..] {
            let c = v3(t.p0) + (v3(t.e1) + v3(t.e2)) / 3.0;
            assert!(v3(t.normal).dot(&(c - centre)) > 0.0);
        }
        let vol: f64 = t[16..]
            .iter()
            .map(|t| v3(t.p0).dot(&v3(t.normal)) * t.area / 3.0)
            .sum();
        assert!((vol - 6.0).abs() < 1e-9);
    }
}
