//! The flake microstructure of the binder layer: the stack model of paper 07, section 2.2
//! (Couka, Willot and Jeulin, "A mixed Boolean and deposit model for the modeling of metal
//! flakes in paint layers", Image Anal. Stereol. 32(2), 2012).
//!
//! The paper characterises the paint by two numbers measured on SEM images, the flake radius
//! and the flake density, and gives only the outline of the model; the rest is filled in here
//! and documented on each parameter:
//!
//! - flakes are flat discs (thin cylinders) of radius `r` and thickness `h`; radii are
//!   lognormal with mean `radius_um` and coefficient of variation `radius_cv`;
//! - their centres form a homogeneous 2-D Poisson point process ("clusters simulated by a 2-D
//!   Poisson point process") of intensity `density / (pi E[r^2])` per µm²: `density` is the
//!   mean *coverage number*, the expected number of flakes above a point of the plate (the
//!   paper's density is unitless, studied over 3.5-9.5 with 6.5 at the centre);
//! - each normal is tilted from the plate normal by an angle drawn from [`TiltDist`], with a
//!   uniform azimuth;
//! - heights follow [`StackModel::Deposit`] (sequential deposition, Jeulin) or
//!   [`StackModel::Boolean`] (independent heights, interpenetration allowed).
//!
//! A tile is periodic: a flake that crosses the tile's edge continues on the opposite side,
//! so tiles can be laid side by side; each cell of the plate shows the part of its tile that
//! lies inside the cell (see [`super::plate`]).

use nalgebra::Vector3;
use rand::Rng;
use rand_distr::{Distribution, LogNormal, Normal, Poisson};
use wscg_math::vec3::add;
use wscg_math::{Error, Result};

pub use super::disc::Flake;
use super::grid::FlakeGrid;

/// How flakes are placed in height.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StackModel {
    /// Sequential deposition (Jeulin): flakes are placed one after the other in random
    /// order, each with its drawn tilt at the lowest height of its column where it touches no
    /// flake placed before (it settles on the flakes below and may slide under the raised
    /// edge of a tilted one). No two flakes interpenetrate. A flake that finds no place
    /// inside the layer is clamped to the layer's top and counted.
    Deposit,
    /// Matheron's Boolean model: heights uniform over the layer, flakes may interpenetrate.
    Boolean,
}

/// Distribution of the angle between a flake's normal and the plate's normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TiltDist {
    /// `|N(0, sigma)|`; measured orientations in the literature spread 5-15 degrees (Sung et
    /// al. 2001); 8 degrees by default (the paper gives no value).
    HalfNormal {
        /// Standard deviation (degrees).
        sigma_deg: f64,
    },
    /// Normals uniform over the spherical cap of half-angle `max_deg`.
    UniformCap {
        /// Half-angle of the cap (degrees).
        max_deg: f64,
    },
    /// Every flake parallel to the plate.
    Flat,
}

impl TiltDist {
    /// Cumulative distribution of the tilt angle (radians).
    pub fn cdf(&self, theta: f64) -> f64 {
        if theta < 0.0 {
            return 0.0;
        }
        match *self {
            TiltDist::HalfNormal { sigma_deg } => {
                let s = sigma_deg.to_radians();
                statrs::function::erf::erf(theta / (s * std::f64::consts::SQRT_2))
            }
            TiltDist::UniformCap { max_deg } => {
                let m = max_deg.to_radians();
                ((1.0 - theta.cos()) / (1.0 - m.cos())).min(1.0)
            }
            TiltDist::Flat => 1.0,
        }
    }

    fn validate(&self) -> Result<()> {
        match *self {
            TiltDist::HalfNormal { sigma_deg }
                if !(sigma_deg.is_finite() && sigma_deg > 0.0 && sigma_deg <= 60.0) =>
            {
                Err(Error::invalid(
                    "tilt",
                    format!("sigma_deg must lie in (0, 60], got {sigma_deg}"),
                ))
            }
            TiltDist::UniformCap { max_deg }
                if !(max_deg.is_finite() && max_deg > 0.0 && max_deg < 90.0) =>
            {
                Err(Error::invalid(
                    "tilt",
                    format!("max_deg must lie in (0, 90), got {max_deg}"),
                ))
            }
            _ => Ok(()),
        }
    }

    fn sample(&self, rng: &mut impl Rng) -> f64 {
        match *self {
            TiltDist::HalfNormal { sigma_deg } => {
                let n = Normal::new(0.0, sigma_deg.to_radians()).expect("validated sigma");
                // Tilts beyond 90 degrees are drawn again (negligible for the validated range).
                loop {
                    let t: f64 = n.sample(rng);
                    let t = t.abs();
                    if t < std::f64::consts::FRAC_PI_2 {
                        return t;
                    }
                }
            }
            TiltDist::UniformCap { max_deg } => {
                let c = 1.0 - rng.random::<f64>() * (1.0 - max_deg.to_radians().cos());
                c.clamp(-1.0, 1.0).acos()
            }
            TiltDist::Flat => 0.0,
        }
    }
}

wscg_math::params! {
    /// Microstructure parameters (paper 07, section 2.2 and Table 1).
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct FlakeParams {
        /// Mean flake radius (µm): 30 in the paper (physical value), studied 15-45.
        pub radius_um: f64,
        /// Coefficient of variation of the (lognormal) radius: 0.15 (not given in the paper).
        pub radius_cv: f64,
        /// Flake thickness (µm): 0.5 (not given; aluminium pigments are 0.1-1 µm thick).
        pub thickness_um: f64,
        /// Mean coverage number (flakes above a point): 6.5 at the centre of the paper's range
        /// 3.5-9.5 (the paper's unit is not defined; this is ours).
        pub density: f64,
        /// Tilt distribution: half-normal with sigma 8 degrees. A drawn tilt at which the flake
        /// would not fit the layer is lowered to the largest that fits ([`max_tilt`]; with radius
        /// 30 µm in the 20.24 µm layer that is 19.2 degrees).
        pub tilt: TiltDist,
        /// Thickness of the flake layer (µm): 20.24 in the paper.
        pub layer_um: f64,
        /// Side of a square tile (µm): 450 in the paper.
        pub tile_um: f64,
        /// Height model: Boolean. The sequential deposit cannot hold the study's densities
        /// without interpenetration (at the design's centre, radius 30 µm, density 6.5, tilts of
        /// sigma 8 degrees, two thirds of the flakes find no place in the 20.24 µm layer), so the
        /// default is the Boolean model, whose flakes may cross.
        pub model: StackModel,
        /// Distinct tiles the plate draws from: 16.
        pub tiles_in_pool: usize,
        /// Largest fraction of flakes that [`StackModel::Deposit`] may clamp to the layer's top
        /// before generation fails (0.05).
        pub max_clamped_fraction: f64,
    }
}

impl Default for FlakeParams {
    fn default() -> Self {
        Self {
            radius_um: 30.0,
            radius_cv: 0.15,
            thickness_um: 0.5,
            density: 6.5,
            tilt: TiltDist::HalfNormal { sigma_deg: 8.0 },
            layer_um: 20.24,
            tile_um: 450.0,
            model: StackModel::Boolean,
            tiles_in_pool: 16,
            max_clamped_fraction: 0.05,
        }
    }
}

impl FlakeParams {
    /// Errors: a radius <= 0 or above half the tile, a negative density, a thickness not
    /// below the layer, a negative or non-finite coefficient of variation, an empty pool, a
    /// bad tilt law.
    pub fn validate(&self) -> Result<()> {
        wscg_math::error::ensure_positive("tile_um", self.tile_um)?;
        wscg_math::error::ensure_positive("layer_um", self.layer_um)?;
        wscg_math::error::ensure_positive("thickness_um", self.thickness_um)?;
        if !(self.radius_um.is_finite()
            && self.radius_um > 0.0
            && self.radius_um <= 0.5 * self.tile_um)
        {
            return Err(Error::invalid(
                "radius_um",
                format!(
                    "must lie in (0, tile_um / 2 = {}], got {}",
                    0.5 * self.tile_um,
                    self.radius_um
                ),
            ));
        }
        if !(self.density.is_finite() && self.density >= 0.0) {
            return Err(Error::invalid(
                "density",
                format!("must be finite and >= 0, got {}", self.density),
            ));
        }
        if self.thickness_um >= self.layer_um {
            return Err(Error::invalid(
                "thickness_um",
                format!(
                    "must be below the layer thickness {}, got {}",
                    self.layer_um, self.thickness_um
                ),
            ));
        }
        if !(self.radius_cv.is_finite() && (0.0..=2.0).contains(&self.radius_cv)) {
            return Err(Error::invalid(
                "radius_cv",
                format!("must lie in [0, 2], got {}", self.radius_cv),
            ));
        }
        if self.tiles_in_pool == 0 {
            return Err(Error::invalid(
                "tiles_in_pool",
                "at least one tile is needed",
            ));
        }
        if !(0.0..=1.0).contains(&self.max_clamped_fraction) {
            return Err(Error::invalid(
                "max_clamped_fraction",
                format!("must lie in [0, 1], got {}", self.max_clamped_fraction),
            ));
        }
        self.tilt.validate()
    }

    /// `E[r^2]` of the lognormal radius: `r^2 (1 + cv^2)`.
    pub fn mean_r2(&self) -> f64 {
        self.radius_um * self.radius_um * (1.0 + self.radius_cv * self.radius_cv)
    }

    /// Intensity of the Poisson process of centres (flakes per µm²): `density / (pi E[r^2])`.
    pub fn intensity(&self) -> f64 {
        self.density / (std::f64::consts::PI * self.mean_r2())
    }

    /// Expected number of flakes per tile.
    pub fn expected_count(&self) -> f64 {
        self.intensity() * self.tile_um * self.tile_um
    }
}

/// One tile of the microstructure.
#[derive(Clone, Debug)]
pub struct FlakeTile {
    /// Side (µm).
    pub size_um: f64,
    /// Flake thickness (µm).
    pub thickness_um: f64,
    /// The flakes, in deposition order.
    pub flakes: Vec<Flake>,
    /// Number of flakes that [`StackModel::Deposit`] found no place for inside the layer and
    /// clamped to its top.
    pub clamped: usize,
    /// Indices of those flakes.
    pub clamped_flakes: Vec<u32>,
    /// The discs the tile shows: every flake plus its periodic copies that reach into the
    /// tile, with the index of the flake each belongs to.
    pieces: Vec<(Flake, u32)>,
    grid: FlakeGrid,
    /// The discs of `pieces`, contiguous for the grid.
    discs: Vec<Flake>,
}

impl FlakeTile {
    /// The nearest disc hit along `o + t d` (tile frame) with `0 < t <= t_max` whose hit
    /// point lies inside the tile's square `[0, size)^2`: `(t, normal, flake index)`.
    pub fn hit(&self, o: [f64; 3], d: [f64; 3], t_max: f64) -> Option<(f64, [f64; 3], u32)> {
        self.grid.nearest(&self.discs, o, d, t_max).map(|(t, i)| {
            let (f, id) = &self.pieces[i as usize];
            (t, f.n, *id)
        })
    }

    /// Every disc the tile shows (periodic copies included) with its flake index.
    pub fn pieces(&self) -> &[(Flake, u32)] {
        &self.pieces
    }
}

/// Generates one periodic tile of the microstructure.
///
/// Errors: invalid parameters ([`FlakeParams::validate`]); more than `max_clamped_fraction`
/// of the flakes finding no place inside the layer.
pub fn generate_tile(p: &FlakeParams, seed: u64) -> Result<FlakeTile> {
    p.validate()?;
    let mut rng = wscg_math::rng::seeded(seed);
    let l = p.tile_um;
    let lambda = p.expected_count();
    let count = if lambda > 0.0 {
        let d = Poisson::new(lambda)
            .map_err(|e| Error::invalid("density", format!("Poisson intensity {lambda}: {e}")))?;
        d.sample(&mut rng) as usize
    } else {
        0
    };
    if count > 5_000_000 {
        return Err(Error::LimitExceeded(format!(
            "{count} flakes per tile (density {} with radius {} µm); at most 5e6",
            p.density, p.radius_um
        )));
    }
    let sigma2 = (1.0 + p.radius_cv * p.radius_cv).ln();
    let radius = LogNormal::new(p.radius_um.ln() - 0.5 * sigma2, sigma2.sqrt())
        .map_err(|e| Error::invalid("radius_cv", e.to_string()))?;
    let mut flakes: Vec<Flake> = (0..count)
        .map(|_| {
            let x = rng.random::<f64>() * l;
            let y = rng.random::<f64>() * l;
            let r = if p.radius_cv > 0.0 {
                radius.sample(&mut rng).min(0.5 * l)
            } else {
                p.radius_um
            };
            // The layer confines the tilt: a flake never reaches out of it.
            let th = p
                .tilt
                .sample(&mut rng)
                .min(max_tilt(r, p.thickness_um, p.layer_um));
            let ph = 2.0 * std::f64::consts::PI * rng.random::<f64>();
            let n = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            Flake {
                c: [x, y, 0.0],
                n,
                r,
            }
        })
        .collect();
    let h = p.thickness_um;
    let t = p.layer_um;
    let mut clamped_flakes = Vec::new();
    let mut settle = match p.model {
        StackModel::Deposit => Some(Settler::new(l, &flakes, h)),
        StackModel::Boolean => None,
    };
    for (i, f) in flakes.iter_mut().enumerate() {
        let e = f.half_height(h);
        let z = match settle.as_mut() {
            None => Some(e + rng.random::<f64>() * (t - 2.0 * e).max(0.0)),
            Some(s) => s.lowest(f, e, t - e),
        };
        f.c[2] = match z {
            Some(z) => z,
            None => {
                clamped_flakes.push(i as u32);
                t - e
            }
        };
        if let Some(s) = settle.as_mut() {
            s.insert(f);
        }
    }
    let clamped = clamped_flakes.len();
    if count > 0 && clamped as f64 > p.max_clamped_fraction * count as f64 {
        return Err(Error::invalid(
            "density",
            format!(
                "the flakes overflow the {t} µm layer: {clamped} of {count} flakes ({:.1} %) find no place inside it (limit {:.1} %); lower the density, the radius or the tilts, or raise layer_um or max_clamped_fraction",
                100.0 * clamped as f64 / count as f64,
                100.0 * p.max_clamped_fraction
            ),
        ));
    }
    let mut pieces = Vec::with_capacity(flakes.len() + flakes.len() / 4);
    for (i, f) in flakes.iter().enumerate() {
        let b = f.aabb();
        for sx in [-1.0, 0.0, 1.0] {
            for sy in [-1.0, 0.0, 1.0] {
                let off = [sx * l, sy * l, 0.0];
                let (lo, hi) = (add(b.min, off), add(b.max, off));
                if hi[0] >= 0.0 && lo[0] < l && hi[1] >= 0.0 && lo[1] < l {
                    let c = add(f.c, off);
                    pieces.push((Flake { c, ..*f }, i as u32));
                }
            }
        }
    }
    let discs: Vec<Flake> = pieces.iter().map(|(f, _)| *f).collect();
    let grid = FlakeGrid::build(&discs, l);
    Ok(FlakeTile {
        size_um: l,
        thickness_um: h,
        flakes,
        clamped,
        clamped_flakes,
        pieces,
        grid,
        discs,
    })
}

/// Largest tilt (radians) at which a disc of radius `r` and thickness `h` fits a layer of
/// thickness `t`: `r sin(a) + h/2 cos(a) <= t/2`.
pub fn max_tilt(r: f64, h: f64, t: f64) -> f64 {
    let big_r = r.hypot(0.5 * h);
    let s = 0.5 * t / big_r;
    if s >= 1.0 {
        std::f64::consts::FRAC_PI_2
    } else {
        (s.asin() - (0.5 * h).atan2(r)).max(0.0)
    }
}

/// Sequential deposition with settling: each flake, with its drawn tilt, takes the lowest
/// height in its column at which it touches no flake placed before (it may slide under the
/// raised edge of a tilted flake, as flakes settle in a drying film). Two flakes are slabs of
/// thickness `h`; over the overlap of their footprints (discs of radius `r + h/2` around the
/// centres, which contain the tilted footprints) the vertical gap between their mid-planes
/// is linear, so the heights at which the new flake would cut an old one form an open
/// interval, computed exactly from the extremes of the gap over the lens of the two discs.
struct Settler {
    size: f64,
    h: f64,
    /// Buckets of side `bucket` (periodic) holding placed flakes.
    nb: usize,
    bucket: f64,
    cells: Vec<Vec<u32>>,
    placed: Vec<Flake>,
    intervals: Vec<(f64, f64)>,
}

impl Settler {
    fn new(size: f64, flakes: &[Flake], h: f64) -> Self {
        let r_max = flakes.iter().fold(0.0f64, |m, f| m.max(f.r)) + h;
        let nb = ((size / (2.0 * r_max)).floor() as usize).max(1);
        Self {
            size,
            h,
            nb,
            bucket: size / nb as f64,
            cells: vec![Vec::new(); nb * nb],
            placed: Vec::with_capacity(flakes.len()),
            intervals: Vec::new(),
        }
    }

    fn bucket_of(&self, x: f64) -> usize {
        ((x / self.bucket).floor().max(0.0) as usize).min(self.nb - 1)
    }

    fn insert(&mut self, f: &Flake) {
        let k = self.bucket_of(f.c[1]) * self.nb + self.bucket_of(f.c[0]);
        self.cells[k].push(self.placed.len() as u32);
        self.placed.push(*f);
    }

    /// The lowest centre height in `[lo, hi]` where `f` touches no placed flake.
    fn lowest(&mut self, f: &Flake, lo: f64, hi: f64) -> Option<f64> {
        let h = self.h;
        let grad = |g: &Flake| Vector3::new(-g.n[0] / g.n[2], -g.n[1] / g.n[2], 0.0);
        let gn = grad(f);
        let rn = f.r + 0.5 * h;
        self.intervals.clear();
        let span = if self.nb >= 3 { 1 } else { self.nb as isize };
        let (bx, by) = (
            self.bucket_of(f.c[0]) as isize,
            self.bucket_of(f.c[1]) as isize,
        );
        let nb = self.nb as isize;
        let mut seen_cells = Vec::with_capacity(9);
        for dy in -span..=span {
            for dx in -span..=span {
                let k = ((by + dy).rem_euclid(nb) * nb + (bx + dx).rem_euclid(nb)) as usize;
                if seen_cells.contains(&k) {
                    continue;
                }
                seen_cells.push(k);
                for &i in &self.cells[k] {
                    let o = &self.placed[i as usize];
                    // Nearest periodic image of the old flake.
                    let mut co = o.c;
                    co[0] -= ((co[0] - f.c[0]) / self.size).round() * self.size;
                    co[1] -= ((co[1] - f.c[1]) / self.size).round() * self.size;
                    let ro = o.r + 0.5 * h;
                    let Some((m, big_m)) =
                        lens_range((f.c[0], f.c[1], rn), (co[0], co[1], ro), gn - grad(o))
                    else {
                        continue;
                    };
                    // gap(p) = zc + w.p + K with K = -gn.cn + go.co - zo.
                    let go = grad(o);
                    let k_off =
                        -(gn.x * f.c[0] + gn.y * f.c[1]) + (go.x * co[0] + go.y * co[1]) - o.c[2];
                    let hh = 0.5 * h / f.n[2] + 0.5 * h / o.n[2];
                    self.intervals.push((-hh - big_m - k_off, hh - m - k_off));
                }
            }
        }
        self.intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut z = lo;
        for &(a, b) in &self.intervals {
            if a >= z {
                break;
            }
            if b > z {
                z = b;
            }
        }
        (z <= hi).then_some(z)
    }
}

/// Range `[min, max]` of `w . p` over the intersection of the discs `(x, y, radius)` `a` and
/// `b`, or `None` when they do not overlap.
fn lens_range(a: (f64, f64, f64), b: (f64, f64, f64), w: Vector3<f64>) -> Option<(f64, f64)> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let d = dx.hypot(dy);
    if d >= a.2 + b.2 {
        return None;
    }
    let inside =
        |p: (f64, f64), c: (f64, f64, f64)| (p.0 - c.0).hypot(p.1 - c.1) <= c.2 * (1.0 + 1e-12);
    let wn = w.x.hypot(w.y);
    let mut cands: Vec<(f64, f64)> = Vec::with_capacity(6);
    for (c, other) in [(a, b), (b, a)] {
        if wn > 0.0 {
            for s in [1.0, -1.0] {
                let p = (c.0 + s * c.2 * w.x / wn, c.1 + s * c.2 * w.y / wn);
                if inside(p, other) {
                    cands.push(p);
                }
            }
        } else {
            cands.push((c.0, c.1));
        }
    }
    // The two corners of the lens, when the circles cross.
    if d > (a.2 - b.2).abs() && d > 0.0 {
        let along = (d * d + a.2 * a.2 - b.2 * b.2) / (2.0 * d);
        let across = (a.2 * a.2 - along * along).max(0.0).sqrt();
        let (ux, uy) = (dx / d, dy / d);
        let (mx, my) = (a.0 + along * ux, a.1 + along * uy);
        cands.push((mx - across * uy, my + across * ux));
        cands.push((mx + across * uy, my - across * ux));
    }
    if cands.is_empty() {
        // One disc inside the other without an extreme point inside: use the smaller disc.
        let c = if a.2 <= b.2 { a } else { b };
        cands.push((c.0 + c.2, c.1));
        cands.push((c.0 - c.2, c.1));
    }
    let vals = cands.iter().map(|p| w.x * p.0 + w.y * p.1);
    let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    Some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tile grid's nearest hit equals a brute-force search over every disc of a tile, for steep and
    /// grazing rays going down and up.
    #[test]
    fn grid_nearest_equals_brute_force() {
        let t = generate_tile(&FlakeParams::default(), 1).unwrap();
        let discs: Vec<Flake> = t.pieces().iter().map(|(f, _)| *f).collect();
        let grid = FlakeGrid::build(&discs, 450.0);
        let dirs = [
            Vector3::new(0.05, 0.03, -1.0),
            Vector3::new(0.5, -0.3, 0.4),
            Vector3::new(-0.9, 0.2, -0.1),
            Vector3::new(0.0, 0.0, 1.0),
        ];
        for k in 0..4000 {
            let x = (k as f64 * 0.618034).fract() * 500.0 - 25.0;
            let y = (k as f64 * 0.7548776).fract() * 500.0 - 25.0;
            let d = dirs[k % 4].normalize();
            let o = [x, y, if d.z < 0.0 { 20.24 } else { 0.0 }];
            let d: [f64; 3] = d.into();
            let brute = discs
                .iter()
                .enumerate()
                .filter_map(|(i, f)| {
                    let (tt, p) = f.intersect(o, d)?;
                    let inside = p[0] >= 0.0 && p[0] < 450.0 && p[1] >= 0.0 && p[1] < 450.0;
                    (tt <= 60.0 && inside).then_some((tt, i as u32))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let fast = grid.nearest(&discs, o, d, 60.0);
            assert_eq!(brute.map(|b| b.1), fast.map(|f| f.1), "ray {k}");
        }
    }
}
