//! Vertex normal estimators for marching-cubes meshes on (sparse) grids.
//!
//! - [`spline`]: the paper's tetrahedral-spline estimator (sections 3-4, eqs. 2-8).
//! - [`central`]: central-difference gradients interpolated along the edge (eq. 1), the
//!   classic MC normal; undefined wherever a needed neighbour is missing.
//! - [`lsn`]: Locally Supported Normals of Nielson, Huang and Sylvester (Vis 2002), the
//!   baseline, reconstructed from the paper's description (section 2.2).
//!
//! Every estimator returns unit normals pointing toward increasing `f` (the triangles of
//! [`crate::extract`] are wound the same way); an undefined estimate is `[0, 0, 0]` and is
//! counted in [`NormalStats::undefined`].

pub mod central;
pub mod lsn;
pub mod spline;

use rayon::prelude::*;
use wscg_math::{Error, Result};

use crate::edge::{vertex_on_edge, EdgeId};
use crate::grid::{check_iso, Sample, ScalarGrid};

pub use lsn::{AmbiguousRule, LsnParams};
pub use spline::{SplineParams, TetSelection};

/// Which vertex normals to compute.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum NormalMethod {
    /// Central differences of the grid, interpolated along the edge (eq. 1).
    CentralDifference,
    /// The paper's tetrahedral-spline estimator.
    Spline(SplineParams),
    /// Locally Supported Normals (Nielson et al. 2002), reconstructed.
    Lsn(LsnParams),
    /// No normals.
    #[default]
    None,
}

impl NormalMethod {
    /// The paper's estimator with its defaults.
    pub fn spline() -> Self {
        NormalMethod::Spline(SplineParams::default())
    }

    /// The LSN baseline with its defaults.
    pub fn lsn() -> Self {
        NormalMethod::Lsn(LsnParams::default())
    }

    /// Parses `"spline"`, `"lsn"`, `"central"` (or `"cd"`) and `"none"`.
    pub fn parse(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().as_str() {
            "spline" => Ok(Self::spline()),
            "lsn" => Ok(Self::lsn()),
            "central" | "cd" | "central-difference" => Ok(NormalMethod::CentralDifference),
            "none" => Ok(NormalMethod::None),
            other => Err(Error::invalid(
                "normals",
                format!("{other:?} is not a normal estimator; valid: spline, lsn, central, none"),
            )),
        }
    }

    /// Checks the parameters of the estimator ([`SplineParams::validate`],
    /// [`LsnParams::validate`]).
    pub fn validate(&self) -> Result<()> {
        match self {
            NormalMethod::Spline(p) => p.validate(),
            NormalMethod::Lsn(p) => p.validate(),
            NormalMethod::CentralDifference | NormalMethod::None => Ok(()),
        }
    }

    /// Short name (`spline`, `lsn`, `central`, `none`).
    pub fn name(&self) -> &'static str {
        match self {
            NormalMethod::CentralDifference => "central",
            NormalMethod::Spline(_) => "spline",
            NormalMethod::Lsn(_) => "lsn",
            NormalMethod::None => "none",
        }
    }
}

/// Diagnostics of an extraction and its normals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NormalStats {
    /// Vertices whose normal is undefined (zero vector): a missing central-difference
    /// neighbour, or a zero LSN perp sum at degenerate triangles (the paper's Table 5).
    pub undefined: usize,
    /// Spline normals that came from the fallback (no adjacent cell had a usable tetrahedron).
    pub fallback: usize,
    /// Cells with some surface that could not be triangulated (see [`crate::cell`]).
    pub skipped_cells: usize,
}

/// How one vertex's estimate came about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Outcome {
    Defined,
    Fallback,
    Undefined,
}

/// The vertex on an edge: its low and high samples, their values, and `t`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct EdgeVertex<T: Sample> {
    pub p: [usize; 3],
    pub q: [usize; 3],
    pub axis: usize,
    pub fp: T,
    pub fq: T,
    pub t: T,
    pub position: [T; 3],
}

impl<T: Sample> EdgeVertex<T> {
    pub(crate) fn new(g: &ScalarGrid<T>, iso: T, e: &EdgeId) -> Option<Self> {
        let axis = e.axis as usize;
        if axis > 2 || (0..3).any(|i| e.point[i] as usize >= g.dims[i]) {
            return None;
        }
        let p = e.low();
        let (position, t) = vertex_on_edge(g, iso, p, axis)?;
        let q = e.high();
        Some(Self {
            p,
            q,
            axis,
            fp: g.value(p)?,
            fq: g.value(q)?,
            t,
            position,
        })
    }
}

/// Normalises `v` and rounds it to the sample type; `None` when it is zero or not finite.
#[inline]
pub(crate) fn unit<T: Sample>(v: [f64; 3]) -> Option<[T; 3]> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (n > 0.0 && n.is_finite()).then(|| v.map(|c| T::from_f64(c / n)))
}

/// Normals of the vertices on `edges` (as in [`crate::IsoMesh::vertex_edge`]) for isovalue
/// `iso`, with diagnostics (`skipped_cells` is left at 0), in the grid's sample type.
///
/// # Errors
/// An invalid grid, a non-finite isovalue, or an edge that does not cross `iso` on this grid
/// (a mesh from another grid or isovalue).
pub fn estimate_normals<T: Sample>(
    grid: &ScalarGrid<T>,
    iso: T,
    edges: &[EdgeId],
    method: NormalMethod,
) -> Result<(Vec<[T; 3]>, NormalStats)> {
    method.validate()?;
    grid.validate()?;
    check_iso(iso)?;
    if matches!(method, NormalMethod::None) {
        return Ok((Vec::new(), NormalStats::default()));
    }
    // Normals are written in place; the per-vertex outcome comes back as one byte (`None`:
    // the edge does not cross).
    let mut normals = vec![[T::default(); 3]; edges.len()];
    let outcomes: Vec<Option<Outcome>> = normals
        .par_iter_mut()
        .zip(edges.par_iter())
        .map(|(out, e)| {
            let v = EdgeVertex::new(grid, iso, e)?;
            let (n, outcome) = match method {
                NormalMethod::CentralDifference => central::normal(grid, &v),
                NormalMethod::Spline(o) => spline::normal(grid, iso, &v, &o),
                NormalMethod::Lsn(o) => lsn::normal(grid, iso, &v, &o),
                NormalMethod::None => unreachable!("handled above"),
            };
            *out = n;
            Some(outcome)
        })
        .collect();
    let mut stats = NormalStats::default();
    for (i, o) in outcomes.iter().enumerate() {
        match o {
            Some(Outcome::Defined) => {}
            Some(Outcome::Fallback) => stats.fallback += 1,
            Some(Outcome::Undefined) => stats.undefined += 1,
            None => {
                return Err(Error::invalid(
                    "edges",
                    format!(
                        "vertex {i}: edge {:?} does not cross the isovalue {} on this grid",
                        edges[i],
                        iso.to_f64()
                    ),
                ))
            }
        }
    }
    Ok((normals, stats))
}
