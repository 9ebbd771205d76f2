//! Isomap (Tenenbaum, de Silva and Langford, "A Global Geometric Framework for Nonlinear
//! Dimensionality Reduction", Science 290, 2000), exact and landmark (de Silva and Tenenbaum,
//! "Global Versus Local Methods in Nonlinear Dimensionality Reduction", NIPS 15, 2003), with
//! out-of-sample projection: the "kNN on 9-D Isomap" baseline of paper 05 (section 4,
//! Table 6).
//!
//! Data have one sample per row (`n x d`). The exact method follows scikit-learn's
//! `sklearn.manifold.Isomap` (`path_method = "D"`, `neighbors_algorithm = "brute"`, Euclidean
//! metric) step by step:
//!
//! 1. **Neighbourhood graph** (Tenenbaum et al., step 1): the `k = n_neighbors` nearest
//!    training points of every point (itself excluded by index; ties broken by index), edge
//!    `i - j` when `j` is among the neighbours of `i` *or* `i` among those of `j`, weighted by
//!    the Euclidean distance (sklearn's `kneighbors_graph` + undirected `shortest_path`).
//! 2. **Geodesics** (step 2): Dijkstra from every node over the graph (compressed sparse
//!    rows, binary heap with decrease-key, sources in parallel), `D = [d_G(i, j)]`. A disconnected graph is an error (sklearn >= 1.1 patches
//!    the graph with extra edges and warns; we ask for a larger `n_neighbors` instead).
//! 3. **Embedding** (step 3, classical MDS written as kernel PCA): `K = -D.^2 / 2`, double
//!    centred `Kc = H K H` (sklearn's `KernelCenterer`), its `n_components` largest
//!    eigenpairs `(lambda_c, v_c)`, training embedding `y_ic = v_c[i] sqrt(lambda_c)`.
//!    The eigenpairs come from a block Lanczos iteration with thick restart (residuals below
//!    `1e-12 |lambda_1|`; sklearn uses ARPACK's Lanczos for the same job), with
//!    [`wscg_math::dense::eigh_largest`] for small kernels or when it does not converge.
//!    As in sklearn's `KernelPCA`, eigenvalues below `1e-12 lambda_1` (or negative) are set to
//!    0 (their component is 0 everywhere) and each eigenvector's sign is fixed so that its
//!    largest-magnitude entry is positive (`svd_flip`).
//! 4. **Out of sample** ([`Isomap::transform`], sklearn's `Isomap.transform`): a new point
//!    `x` with nearest training points `N(x)` (`n_neighbors` of them, no exclusion) has
//!    geodesics `d_G(x, j) = min_{i in N(x)} (|x - x_i| + D(i, j))`; its kernel row
//!    `k = -d_G.^2 / 2` is centred with the training kernel's column means `c` and overall
//!    mean `c_bar` (`k - mean(k) - c + c_bar`) and projected on `v_c / sqrt(lambda_c)`
//!    (sklearn's `KernelPCA.transform`). A training point passed to `transform` is its own
//!    nearest neighbour at distance 0, so it gets back its training embedding.
//!
//! Exact Isomap stores the `n x n` geodesic matrix and is refused above
//! [`MAX_EXACT_POINTS`] points; **Landmark Isomap** (`n_landmarks = Some(m)`) computes
//! geodesics from `m` landmarks only, embeds the landmarks by classical MDS of their `m x m`
//! geodesics and places every point by distance-based triangulation (de Silva and
//! Tenenbaum): `y_a = L^# (delta_mu - delta_a) / 2` with `delta_a` the squared geodesics from
//! `a` to the landmarks, `delta_mu` their mean over landmarks and `L^#` the rows
//! `v_c' / sqrt(lambda_c)`. That is the out-of-sample formula of step 4 applied to the
//! landmark kernel (the row-mean term vanishes because `v_c` is orthogonal to `1`), so
//! training points and new points go through the same code. Landmarks are chosen
//! deterministically by **geodesic MaxMin** (farthest-point sampling, the alternative to a
//! random choice that de Silva and Tenenbaum discuss): the first is point 0, each next one
//! the point farthest in geodesic distance from those already chosen (ties to the lowest
//! index). The choice uses pruned Dijkstra searches that only visit the points a new landmark
//! brings closer (a fraction of a second for 2000 of 18500 points); the full Dijkstra runs
//! from the landmarks then go in parallel.

use faer::{Mat, MatRef};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use wscg_math::{dense, Error, Result};

use super::neighbours::{k_nearest, Neighbours};
use crate::subspace::kernel::center_kernel;
use crate::subspace::{check_data, check_query, Projector};

/// Largest training set accepted by exact Isomap (its `n x n` geodesic matrix is 200 MB at
/// this size); above it set [`IsomapParams::n_landmarks`].
pub const MAX_EXACT_POINTS: usize = 5000;

/// Largest `n x n_landmarks` geodesic table (entries, 8 bytes each: 4 GiB) Landmark Isomap
/// allocates.
pub const MAX_GEODESIC_ENTRIES: usize = 1 << 29;

wscg_math::params! {
    /// Parameters of [`Isomap::fit`].
    #[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
    pub struct IsomapParams {
        /// Neighbours per point in the graph and for out-of-sample points, `1 <= k < n`.
        /// Default 8 (the paper does not say).
        pub n_neighbors: usize,
        /// Embedding dimension, `1 <= l <= n` (`<= n_landmarks` in landmark mode). Default 9
        /// (the paper's "9-D Isomap").
        pub n_components: usize,
        /// `None`: exact Isomap (at most [`MAX_EXACT_POINTS`] points). `Some(m)`: Landmark
        /// Isomap with `m` geodesic-MaxMin landmarks, `n_components <= m <= n`. Default `None`.
        pub n_landmarks: Option<usize>,
    }
}

impl Default for IsomapParams {
    fn default() -> Self {
        Self {
            n_neighbors: 8,
            n_components: 9,
            n_landmarks: None,
        }
    }
}

impl IsomapParams {
    /// Errors: `n_neighbors` or `n_components` zero, `n_landmarks` below 2 or below
    /// `n_components`. The bounds that depend on the number of samples `n` are checked by
    /// [`Isomap::fit`].
    pub fn validate(&self) -> Result<()> {
        if self.n_neighbors == 0 {
            return Err(Error::invalid("n_neighbors", "must be >= 1"));
        }
        if self.n_components == 0 {
            return Err(Error::invalid("n_components", "must be >= 1, got 0"));
        }
        if let Some(m) = self.n_landmarks {
            if m < 2 {
                return Err(Error::invalid(
                    "n_landmarks",
                    format!("must be at least 2, got {m}"),
                ));
            }
            if self.n_components > m {
                return Err(Error::invalid(
                    "n_components",
                    format!(
                        "must be between 1 and n_landmarks = {m}, got {}",
                        self.n_components
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A fitted Isomap (exact or landmark).
///
/// "Landmarks" below are all training points, in index order, for the exact method.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Isomap {
    /// Neighbours per point (graph and out-of-sample).
    n_neighbors: usize,
    /// Training rows (`n x d`), for the neighbours of new points.
    #[serde(with = "crate::subspace::serde_mat")]
    train: Mat<f64>,
    /// Landmark indices into the training rows (`None`: exact, every point).
    landmarks: Option<Vec<usize>>,
    /// Geodesic distances, row-major `m x n`: row `c` holds `d_G(landmark_c, x_j)` for every
    /// training point `j` (exact: the symmetric `n x n` matrix).
    geodesic: Vec<f64>,
    /// Column means of the uncentred landmark kernel `-D_m.^2 / 2` (length `m`).
    k_col_means: Vec<f64>,
    /// Overall mean of that kernel.
    k_mean: f64,
    /// Kept eigenvalues of the centred kernel, non-increasing, clipped (0 = dropped).
    eigenvalues: Vec<f64>,
    /// Matching unit eigenvectors (`m x l`).
    #[serde(with = "crate::subspace::serde_mat")]
    eigenvectors: Mat<f64>,
    /// Training embedding (`n x l`).
    #[serde(with = "crate::subspace::serde_mat")]
    embedding: Mat<f64>,
}

impl Isomap {
    /// Fits Isomap to the rows of `x` (`n x d`, finite, `n >= 2`).
    ///
    /// Errors: empty or non-finite `x`; `n_neighbors` not in `1..n`; `n_components` not in
    /// `1..=n` (`1..=n_landmarks`); `n_landmarks` not in `2..=n`; more than
    /// [`MAX_EXACT_POINTS`] points without landmarks; a disconnected neighbourhood graph (use
    /// a larger `n_neighbors`); a geodesic kernel without positive eigenvalue (all samples
    /// coincide).
    pub fn fit(x: MatRef<'_, f64>, params: &IsomapParams) -> Result<Self> {
        params.validate()?;
        if x.nrows() == 0 {
            return Err(Error::Empty("x"));
        }
        check_data("x", x, 2)?;
        let n = x.nrows();
        let k = params.n_neighbors;
        if k >= n {
            return Err(Error::invalid(
                "n_neighbors",
                format!("must be smaller than the number of samples n = {n}, got {k}"),
            ));
        }
        let m = match params.n_landmarks {
            None if n > MAX_EXACT_POINTS => {
                return Err(Error::LimitExceeded(format!(
                    "exact Isomap is limited to {MAX_EXACT_POINTS} points (it stores the n x n \
                     geodesic matrix), got n = {n}; set n_landmarks (e.g. 2000) for Landmark \
                     Isomap"
                )))
            }
            None => n,
            Some(m) if m > n => {
                return Err(Error::invalid(
                    "n_landmarks",
                    format!("must be between 2 and the number of samples n = {n}, got {m}"),
                ))
            }
            Some(m) => {
                if n.checked_mul(m).is_none_or(|e| e > MAX_GEODESIC_ENTRIES) {
                    return Err(Error::LimitExceeded(format!(
                        "the {n} x {m} landmark geodesic table exceeds {MAX_GEODESIC_ENTRIES} \
                         entries; use fewer landmarks"
                    )));
                }
                m
            }
        };
        let l = params.n_components;
        if l > m {
            let what = if params.n_landmarks.is_some() {
                "n_landmarks"
            } else {
                "the number of samples n"
            };
            return Err(Error::invalid(
                "n_components",
                format!("must be between 1 and {what} = {m}, got {l}"),
            ));
        }

        let nb = k_nearest(x, x, k, true);
        let graph = Graph::from_neighbours(&nb, n);
        let (count, largest) = graph.components();
        if count > 1 {
            return Err(Error::invalid(
                "n_neighbors",
                format!(
                    "the symmetric {k}-nearest-neighbour graph has {count} connected components \
                     (the largest holds {largest} of {n} points), so some geodesic distances \
                     are infinite; use a larger n_neighbors"
                ),
            ));
        }

        let (landmarks, geodesic) = match params.n_landmarks {
            None => (None, graph.geodesics_from(&(0..n).collect::<Vec<_>>())),
            Some(m) => {
                let idx = graph.maxmin_landmarks(m);
                let geo = graph.geodesics_from(&idx);
                (Some(idx), geo)
            }
        };
        // Landmark-to-landmark geodesics (exact: all pairs), symmetrised.
        let lm = |a: usize| landmarks.as_ref().map_or(a, |v| v[a]);
        let mds = Mds::fit(m, |a, b| geodesic[a * n + lm(b)], l)?;

        let mut model = Self {
            n_neighbors: k,
            train: x.to_owned(),
            landmarks,
            geodesic,
            k_col_means: mds.col_means,
            k_mean: mds.mean,
            eigenvalues: mds.values,
            eigenvectors: mds.vectors,
            embedding: Mat::zeros(0, 0),
        };
        model.embedding = if model.landmarks.is_none() {
            // sklearn's KernelPCA.fit_transform: v_c sqrt(lambda_c).
            let (v, s) = (&model.eigenvectors, &model.eigenvalues);
            Mat::from_fn(n, l, |i, c| v[(i, c)] * s[c].sqrt())
        } else {
            // Distance-based triangulation of every point from its landmark geodesics.
            let mut out = vec![0.0; n * l];
            out.par_chunks_mut(l).enumerate().for_each_init(
                || vec![0.0; m],
                |dg, (i, o)| {
                    for (c, g) in dg.iter_mut().enumerate() {
                        *g = model.geodesic[c * n + i];
                    }
                    model.project(dg, o);
                },
            );
            Mat::from_fn(n, l, |i, c| out[i * l + c])
        };
        Ok(model)
    }

    /// [`Isomap::fit`] and the training embedding (`n x n_components`).
    pub fn fit_transform(x: MatRef<'_, f64>, params: &IsomapParams) -> Result<Mat<f64>> {
        Ok(Self::fit(x, params)?.embedding)
    }

    /// Embeds the rows of `x` (`q x d`, `d` the training dimension) out of sample (module
    /// docs, step 4; the landmark triangulation in landmark mode): `q x n_components`.
    ///
    /// Errors: `x` of the wrong width or non-finite; a model whose fields disagree (a
    /// corrupt deserialised file).
    pub fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        self.check_consistent()?;
        check_query(x, self.train.ncols())?;
        let (q, l, k) = (x.nrows(), self.eigenvalues.len(), self.n_neighbors);
        if q == 0 {
            return Ok(Mat::zeros(0, l));
        }
        let (n, m) = (self.train.nrows(), self.k_col_means.len());
        let nb = k_nearest(x, self.train.as_ref(), k, false);
        let mut out = vec![0.0; q * l];
        out.par_chunks_mut(l).enumerate().for_each_init(
            || vec![0.0; m],
            |dg, (i, o)| {
                let (idx, dist) = (&nb.idx[i * k..(i + 1) * k], &nb.dist[i * k..(i + 1) * k]);
                for (g, row) in dg.iter_mut().zip(self.geodesic.chunks_exact(n)) {
                    *g = idx
                        .iter()
                        .zip(dist)
                        .fold(f64::INFINITY, |acc, (&j, &dj)| acc.min(dj + row[j]));
                }
                self.project(dg, o);
            },
        );
        Ok(Mat::from_fn(q, l, |i, c| out[i * l + c]))
    }

    /// Training embedding (`n x n_components`).
    pub fn embedding(&self) -> MatRef<'_, f64> {
        self.embedding.as_ref()
    }

    /// Eigenvalues of the centred geodesic kernel, non-increasing; 0 marks a dropped
    /// (non-positive or negligible) component.
    pub fn eigenvalues(&self) -> &[f64] {
        &self.eigenvalues
    }

    /// Geodesic distances (`n x m`): entry `(i, c)` is `d_G(x_i, landmark_c)`; the exact
    /// method's full `n x n` matrix (sklearn's `dist_matrix_`) when there are no landmarks.
    /// Empty (`0 x 0`) for a model whose fields disagree in size.
    pub fn geodesic_distances(&self) -> MatRef<'_, f64> {
        let (n, m) = (self.train.nrows(), self.k_col_means.len());
        if n.checked_mul(m) != Some(self.geodesic.len()) {
            return MatRef::from_row_major_slice(&[], 0, 0);
        }
        MatRef::from_row_major_slice(&self.geodesic, m, n).transpose()
    }

    /// Landmark indices into the training rows, in MaxMin order (`None` for exact Isomap).
    pub fn landmarks(&self) -> Option<&[usize]> {
        self.landmarks.as_deref()
    }

    /// Neighbours per point.
    pub fn n_neighbors(&self) -> usize {
        self.n_neighbors
    }

    /// Embedding dimension.
    pub fn n_components(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Input dimension `d`.
    pub fn input_dim(&self) -> usize {
        self.train.ncols()
    }

    /// The model as JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// A model from [`Self::to_json`] output.
    pub fn from_json(s: &str) -> Result<Self> {
        serde_json::from_str(s)
            .map_err(|e| Error::invalid("model", format!("not an Isomap model: {e}")))
    }

    /// Number of training samples `n`.
    pub fn n_samples(&self) -> usize {
        self.train.nrows()
    }

    /// Kernel row `-dg.^2 / 2` of geodesics to the landmarks (overwritten), centred against
    /// the training kernel and projected on `v_c / sqrt(lambda_c)` into `out`.
    fn project(&self, dg: &mut [f64], out: &mut [f64]) {
        let m = dg.len();
        for v in dg.iter_mut() {
            *v = -0.5 * *v * *v;
        }
        let row_mean = dg.iter().sum::<f64>() / m as f64;
        for (v, c) in dg.iter_mut().zip(&self.k_col_means) {
            *v = *v - c - row_mean + self.k_mean;
        }
        for (c, o) in out.iter_mut().enumerate() {
            let lambda = self.eigenvalues[c];
            *o = if lambda > 0.0 {
                let v = self.eigenvectors.col_as_slice(c);
                dg.iter().zip(v).map(|(a, b)| a * b).sum::<f64>() / lambda.sqrt()
            } else {
                0.0
            };
        }
    }

    /// Errors unless the fields agree in size (guards deserialised models).
    fn check_consistent(&self) -> Result<()> {
        let (n, d) = (self.train.nrows(), self.train.ncols());
        let m = self.k_col_means.len();
        let l = self.eigenvalues.len();
        let landmarks_ok = match &self.landmarks {
            None => m == n,
            Some(v) => v.len() == m && v.iter().all(|&i| i < n),
        };
        let ok = n >= 2
            && d >= 1
            && (1..n).contains(&self.n_neighbors)
            && m >= 1
            && l >= 1
            && landmarks_ok
            && n.checked_mul(m) == Some(self.geodesic.len())
            && self.eigenvectors.nrows() == m
            && self.eigenvectors.ncols() == l
            && self.embedding.nrows() == n
            && self.embedding.ncols() == l;
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(
                "model",
                "inconsistent Isomap model (field sizes disagree); refit it",
            ))
        }
    }
}

impl Projector for Isomap {
    fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        Isomap::transform(self, x)
    }
    fn n_components(&self) -> usize {
        Isomap::n_components(self)
    }
    fn input_dim(&self) -> usize {
        Isomap::input_dim(self)
    }
}

/// Classical MDS of an `m x m` geodesic matrix: the centred kernel's statistics and top
/// eigenpairs.
struct Mds {
    col_means: Vec<f64>,
    mean: f64,
    values: Vec<f64>,
    vectors: Mat<f64>,
}

impl Mds {
    /// `dist(a, b)`: geodesic from landmark `b` to landmark `a` (symmetrised here).
    fn fit(m: usize, dist: impl Fn(usize, usize) -> f64, l: usize) -> Result<Self> {
        let mut k = Mat::from_fn(m, m, |a, b| {
            let (u, v) = (dist(a, b), dist(b, a));
            -0.25 * (u * u + v * v)
        });
        let (col_means, mean) = center_kernel(&mut k);
        if dense::check_matrix("kernel", k.as_ref()).is_err() {
            return Err(Error::invalid(
                "x",
                "squared geodesic distances overflow f64; rescale the data",
            ));
        }
        let e = top_eigenpairs(k.as_ref(), l)?;
        let top = e.values.first().copied().unwrap_or(0.0);
        if top.is_nan() || top <= 0.0 {
            return Err(Error::invalid(
                "x",
                "the centred geodesic kernel has no positive eigenvalue (all samples coincide)",
            ));
        }
        // sklearn's _check_psd_eigenvalues: negative and tiny eigenvalues become 0.
        let values = e
            .values
            .iter()
            .map(|&v| if v < 1e-12 * top { 0.0 } else { v })
            .collect();
        let mut vectors = e.vectors;
        // sklearn's svd_flip: the largest-magnitude entry of each eigenvector is positive.
        for c in 0..vectors.ncols() {
            let col = vectors.col_as_slice(c);
            let mut arg = 0;
            for (i, v) in col.iter().enumerate() {
                if v.abs() > col[arg].abs() {
                    arg = i;
                }
            }
            if col[arg] < 0.0 {
                for i in 0..m {
                    vectors[(i, c)] = -vectors[(i, c)];
                }
            }
        }
        Ok(Self {
            col_means,
            mean,
            values,
            vectors,
        })
    }
}

/// The `k` largest eigenpairs (non-increasing) of the symmetric `a`: block Lanczos with
/// thick restart ([`wscg_math::eigh_krylov::eigh_largest_restarted`]), or
/// [`dense::eigh_largest`] for small kernels or when that does not converge.
fn top_eigenpairs(a: MatRef<'_, f64>, k: usize) -> Result<dense::SymEigen> {
    match wscg_math::eigh_krylov::eigh_largest_restarted(a, k) {
        Some(e) => Ok(e),
        None => dense::eigh_largest(a, k),
    }
}

/// Undirected weighted graph in compressed sparse row form.
struct Graph {
    offsets: Vec<usize>,
    targets: Vec<usize>,
    weights: Vec<f64>,
}

/// Marks a node that is not in the [`NodeHeap`].
const NOT_IN_HEAP: usize = usize::MAX;

/// Scratch of [`Graph::dijkstra`]: a binary min-heap of nodes keyed by their tentative
/// distance (ties by node index), with every node's heap position for decrease-key, so
/// the heap never holds more than `n` entries.
#[derive(Default)]
struct NodeHeap {
    heap: Vec<usize>,
    pos: Vec<usize>,
}

impl NodeHeap {
    /// Empties the heap for a graph of `n` nodes (a finished search leaves every `pos` at
    /// `NOT_IN_HEAP`, so only a size change costs `O(n)`).
    fn reset(&mut self, n: usize) {
        self.heap.clear();
        if self.pos.len() != n {
            self.pos.clear();
            self.pos.resize(n, NOT_IN_HEAP);
        }
    }

    fn less(dist: &[f64], a: usize, b: usize) -> bool {
        dist[a] < dist[b] || (dist[a] == dist[b] && a < b)
    }

    fn sift_up(&mut self, dist: &[f64], mut i: usize) {
        let v = self.heap[i];
        while i > 0 {
            let p = (i - 1) / 2;
            let u = self.heap[p];
            if !Self::less(dist, v, u) {
                break;
            }
            self.heap[i] = u;
            self.pos[u] = i;
            i = p;
        }
        self.heap[i] = v;
        self.pos[v] = i;
    }

    fn sift_down(&mut self, dist: &[f64], mut i: usize) {
        let len = self.heap.len();
        let v = self.heap[i];
        loop {
            let l = 2 * i + 1;
            if l >= len {
                break;
            }
            let r = l + 1;
            let c = if r < len && Self::less(dist, self.heap[r], self.heap[l]) {
                r
            } else {
                l
            };
            let u = self.heap[c];
            if !Self::less(dist, u, v) {
                break;
            }
            self.heap[i] = u;
            self.pos[u] = i;
            i = c;
        }
        self.heap[i] = v;
        self.pos[v] = i;
    }

    /// Inserts `v`, or moves it up after `dist[v]` decreased.
    fn push_or_decrease(&mut self, dist: &[f64], v: usize) {
        let i = if self.pos[v] == NOT_IN_HEAP {
            self.heap.push(v);
            self.heap.len() - 1
        } else {
            self.pos[v]
        };
        self.sift_up(dist, i);
    }

    /// Removes and returns the node of smallest distance.
    fn pop(&mut self, dist: &[f64]) -> Option<usize> {
        let top = *self.heap.first()?;
        let last = self.heap.pop()?;
        self.pos[top] = NOT_IN_HEAP;
        if !self.heap.is_empty() {
            self.heap[0] = last;
            self.sift_down(dist, 0);
        }
        Some(top)
    }
}

impl Graph {
    /// The symmetric kNN graph: edge `i - j` if either is among the other's neighbours,
    /// weighted by their distance.
    fn from_neighbours(nb: &Neighbours, n: usize) -> Self {
        let k = nb.k;
        let mut adj: Vec<Vec<(usize, f64)>> = vec![Vec::with_capacity(2 * k); n];
        for i in 0..n {
            for t in 0..k {
                let (j, w) = (nb.idx[i * k + t], nb.dist[i * k + t]);
                adj[i].push((j, w));
                adj[j].push((i, w));
            }
        }
        let mut offsets = Vec::with_capacity(n + 1);
        let mut targets = Vec::new();
        let mut weights = Vec::new();
        offsets.push(0);
        for list in adj.iter_mut() {
            list.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
            list.dedup_by_key(|e| e.0);
            for &(j, w) in list.iter() {
                targets.push(j);
                weights.push(w);
            }
            offsets.push(targets.len());
        }
        Self {
            offsets,
            targets,
            weights,
        }
    }

    fn n(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of connected components and the size of the largest.
    fn components(&self) -> (usize, usize) {
        let n = self.n();
        let mut seen = vec![false; n];
        let mut stack = Vec::new();
        let (mut count, mut largest) = (0, 0);
        for s in 0..n {
            if seen[s] {
                continue;
            }
            count += 1;
            seen[s] = true;
            stack.push(s);
            let mut size = 0;
            while let Some(v) = stack.pop() {
                size += 1;
                for &u in &self.targets[self.offsets[v]..self.offsets[v + 1]] {
                    if !seen[u] {
                        seen[u] = true;
                        stack.push(u);
                    }
                }
            }
            largest = largest.max(size);
        }
        (count, largest)
    }

    /// Shortest-path distances from `source` into `dist` (length `n`; unreachable: inf).
    fn dijkstra(&self, source: usize, dist: &mut [f64], heap: &mut NodeHeap) {
        dist.fill(f64::INFINITY);
        self.lower_from(source, dist, heap);
    }

    /// Lowers `dist[v]` to `min(dist[v], d_G(source, v))` for every node: Dijkstra seeded
    /// with the current `dist` as upper bounds, so it only visits the nodes it improves.
    /// That is exact: a path from `source` to `v` through a node `u` it cannot improve is no
    /// shorter than `dist[u] + d_G(u, v) >= dist[v]` when `dist` holds distances to a set of
    /// earlier sources (MaxMin) or infinity (plain Dijkstra).
    fn lower_from(&self, source: usize, dist: &mut [f64], heap: &mut NodeHeap) {
        heap.reset(dist.len());
        dist[source] = 0.0;
        heap.push_or_decrease(dist, source);
        while let Some(v) = heap.pop(dist) {
            let d = dist[v];
            let (lo, hi) = (self.offsets[v], self.offsets[v + 1]);
            for (&u, &w) in self.targets[lo..hi].iter().zip(&self.weights[lo..hi]) {
                // Weights are >= 0, so a settled node is never improved (nor re-queued).
                let nd = d + w;
                if nd < dist[u] {
                    dist[u] = nd;
                    heap.push_or_decrease(dist, u);
                }
            }
        }
    }

    /// Geodesics from each of `sources` to every node, row-major `sources.len() x n`
    /// (Dijkstra per source, sources in parallel).
    fn geodesics_from(&self, sources: &[usize]) -> Vec<f64> {
        let n = self.n();
        let mut geo = vec![0.0; sources.len() * n];
        geo.par_chunks_mut(n)
            .zip(sources.par_iter())
            .for_each_init(NodeHeap::default, |heap, (row, &s)| {
                self.dijkstra(s, row, heap)
            });
        geo
    }

    /// `m` landmarks by geodesic MaxMin: node 0 first, then repeatedly the node farthest
    /// from the chosen ones (ties to the lowest index). Each step only runs the pruned
    /// search of [`Graph::lower_from`], so the choice costs far less than the `m` full
    /// Dijkstra runs that follow it (in parallel, in [`Graph::geodesics_from`]).
    fn maxmin_landmarks(&self, m: usize) -> Vec<usize> {
        let n = self.n();
        let mut nearest = vec![f64::INFINITY; n];
        let mut chosen = vec![false; n];
        let mut heap = NodeHeap::default();
        let mut landmarks = Vec::with_capacity(m);
        let mut next = 0;
        for _ in 0..m {
            landmarks.push(next);
            chosen[next] = true;
            self.lower_from(next, &mut nearest, &mut heap);
            let mut best: Option<usize> = None;
            for (i, (&near, &taken)) in nearest.iter().zip(&chosen).enumerate() {
                if !taken && best.is_none_or(|b| near > nearest[b]) {
                    best = Some(i);
                }
            }
            if let Some(b) = best {
                next = b;
            }
        }
        landmarks
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;
    use wscg_math::rng::uniform_vec;

    /// Noise-free Swiss roll (sklearn's `make_swiss_roll` formula) and its parameter `t`.
    fn swiss_roll(n: usize, seed: u64) -> (Mat<f64>, Vec<f64>) {
        let u = uniform_vec(seed, n, 0.0, 1.0).unwrap();
        let v = uniform_vec(seed + 1, n, 0.0, 1.0).unwrap();
        let t: Vec<f64> = u.iter().map(|&u| 1.5 * PI * (1.0 + 2.0 * u)).collect();
        let x = Mat::from_fn(n, 3, |i, j| match j {
            0 => t[i] * t[i].cos(),
            1 => 21.0 * v[i],
            _ => t[i] * t[i].sin(),
        });
        (x, t)
    }

    /// Arc length of the spiral `(t cos t, t sin t)` from 0 to `t`.
    fn arc_length(t: &[f64]) -> Vec<f64> {
        t.iter()
            .map(|&t| 0.5 * (t * (1.0 + t * t).sqrt() + t.asinh()))
            .collect()
    }

    fn corr(a: &[f64], b: &[f64]) -> f64 {
        let n = a.len() as f64;
        let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
        let (mut c, mut va, mut vb) = (0.0, 0.0, 0.0);
        for (x, y) in a.iter().zip(b) {
            c += (x - ma) * (y - mb);
            va += (x - ma) * (x - ma);
            vb += (y - mb) * (y - mb);
        }
        c / (va * vb).sqrt()
    }

    fn col(m: MatRef<'_, f64>, c: usize) -> Vec<f64> {
        (0..m.nrows()).map(|i| m[(i, c)]).collect()
    }

    /// Max over components of the smaller of |a - b| and |a + b| (equality up to sign).
    fn max_diff_up_to_sign(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
        assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()));
        (0..a.ncols())
            .map(|c| {
                let (mut plus, mut minus) = (0.0f64, 0.0f64);
                for i in 0..a.nrows() {
                    minus = minus.max((a[(i, c)] - b[(i, c)]).abs());
                    plus = plus.max((a[(i, c)] + b[(i, c)]).abs());
                }
                plus.min(minus)
            })
            .fold(0.0, f64::max)
    }

    fn params(k: usize, l: usize, landmarks: Option<usize>) -> IsomapParams {
        IsomapParams {
            n_neighbors: k,
            n_components: l,
            n_landmarks: landmarks,
        }
    }

    #[test]
    fn swiss_roll_is_unrolled() {
        let (x, t) = swiss_roll(800, 11);
        let iso = Isomap::fit(x.as_ref(), &params(6, 2, None)).unwrap();
        assert_eq!(iso.embedding().ncols(), 2);
        let r = corr(&col(iso.embedding(), 0), &t).abs();
        eprintln!("exact: |corr(y1, t)| = {r:.5}");
        assert!(r > 0.99, "{r}");
        // y1 is the arc length along the spiral (t itself correlates with it at only 0.992).
        let ra = corr(&col(iso.embedding(), 0), &arc_length(&t)).abs();
        eprintln!("exact: |corr(y1, arc length)| = {ra:.5}");
        assert!(ra > 0.999, "{ra}");
        // The second component spans the roll's height.
        let h = col(x.as_ref(), 1);
        let r2 = corr(&col(iso.embedding(), 1), &h).abs();
        eprintln!("exact: |corr(y2, height)| = {r2:.5}");
        assert!(r2 > 0.9, "{r2}");
        assert!(iso.eigenvalues()[0] >= iso.eigenvalues()[1]);
    }

    #[test]
    fn geodesics_and_embedding_match_brute_force() {
        let n = 30;
        let d = 4;
        let u = uniform_vec(5, n * d, -1.0, 1.0).unwrap();
        let x = Mat::from_fn(n, d, |i, j| u[i * d + j]);
        let (k, l) = (5, 3);
        let iso = Isomap::fit(x.as_ref(), &params(k, l, None)).unwrap();

        // kNN graph by sorting all distances, then Floyd-Warshall.
        let dist = |i: usize, j: usize| -> f64 {
            (0..d)
                .map(|t| (x[(i, t)] - x[(j, t)]).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let mut fw = vec![f64::INFINITY; n * n];
        for i in 0..n {
            fw[i * n + i] = 0.0;
            let mut others: Vec<usize> = (0..n).filter(|&j| j != i).collect();
            others.sort_by(|&a, &b| dist(i, a).total_cmp(&dist(i, b)));
            for &j in &others[..k] {
                fw[i * n + j] = dist(i, j);
                fw[j * n + i] = dist(i, j);
            }
        }
        for via in 0..n {
            for i in 0..n {
                for j in 0..n {
                    let c = fw[i * n + via] + fw[via * n + j];
                    if c < fw[i * n + j] {
                        fw[i * n + j] = c;
                    }
                }
            }
        }
        let fw = Mat::from_fn(n, n, |i, j| fw[i * n + j]);
        let g = iso.geodesic_distances();
        assert_eq!((g.nrows(), g.ncols()), (n, n));
        assert!(fw.is_all_finite());
        let err = (g - &fw).norm_max();
        eprintln!("max |Dijkstra - Floyd-Warshall| = {err:e}");
        assert!(err < 1e-12, "{err}");

        // Double-centred -D^2/2 and its full eigendecomposition.
        let kern = Mat::from_fn(n, n, |i, j| -0.5 * fw[(i, j)] * fw[(i, j)]);
        let h = Mat::from_fn(n, n, |i, j| f64::from(u8::from(i == j)) - 1.0 / n as f64);
        let kc = &h * &kern * &h;
        let kc = Mat::from_fn(n, n, |i, j| 0.5 * (kc[(i, j)] + kc[(j, i)]));
        let e = dense::eigh(kc.as_ref()).unwrap();
        let mut worst = 0.0f64;
        for c in 0..l {
            let lambda = e.values[n - 1 - c];
            let rel = (iso.eigenvalues()[c] - lambda).abs() / lambda;
            assert!(
                rel < 1e-10,
                "eigenvalue {c}: {} vs {lambda}",
                iso.eigenvalues()[c]
            );
            let (mut plus, mut minus) = (0.0f64, 0.0f64);
            for i in 0..n {
                let y = e.vectors[(i, n - 1 - c)] * lambda.sqrt();
                minus = minus.max((iso.embedding()[(i, c)] - y).abs());
                plus = plus.max((iso.embedding()[(i, c)] + y).abs());
            }
            worst = worst.max(plus.min(minus));
        }
        eprintln!("max embedding difference to the dense eigendecomposition = {worst:e}");
        assert!(worst < 1e-8, "{worst}");
        // Y'Y = diag(lambda).
        let yty = iso.embedding().transpose() * iso.embedding();
        for a in 0..l {
            for b in 0..l {
                let want = if a == b { iso.eigenvalues()[a] } else { 0.0 };
                assert!((yty[(a, b)] - want).abs() < 1e-8 * iso.eigenvalues()[0]);
            }
        }
    }

    #[test]
    fn transform_of_training_points_reproduces_embedding() {
        let (x, t) = swiss_roll(800, 21);
        let iso = Isomap::fit(x.as_ref(), &params(6, 3, None)).unwrap();
        let y = iso.transform(x.as_ref()).unwrap();
        let mut err = 0.0f64;
        let mut scale = 0.0f64;
        for i in 0..800 {
            for c in 0..3 {
                err = err.max((y[(i, c)] - iso.embedding()[(i, c)]).abs());
                scale = scale.max(iso.embedding()[(i, c)].abs());
            }
        }
        eprintln!("transform(train) vs embedding: max abs diff {err:e} (max |y| {scale:.2})");
        assert!(err < 1e-8 * scale.max(1.0), "{err}");
        // Held-out points of the same roll land where their t says.
        let (xn, tn) = swiss_roll(200, 99);
        let yn = iso.transform(xn.as_ref()).unwrap();
        let r = corr(&col(yn.as_ref(), 0), &tn).abs();
        let r_train = corr(&col(iso.embedding(), 0), &t).abs();
        eprintln!("held-out |corr(y1, t)| = {r:.5} (train {r_train:.5})");
        assert!(r > 0.98, "{r}");
        // Empty query.
        let y0 = iso.transform(Mat::<f64>::zeros(0, 3).as_ref()).unwrap();
        assert_eq!((y0.nrows(), y0.ncols()), (0, 3));
    }

    #[test]
    fn landmarks_match_exact_and_scale_down() {
        let (x, t) = swiss_roll(800, 11);
        let exact = Isomap::fit(x.as_ref(), &params(6, 2, None)).unwrap();
        let all = Isomap::fit(x.as_ref(), &params(6, 2, Some(800))).unwrap();
        let mut lm = all.landmarks().unwrap().to_vec();
        assert_eq!(lm[0], 0);
        lm.sort_unstable();
        assert_eq!(lm, (0..800).collect::<Vec<_>>());
        let diff = max_diff_up_to_sign(exact.embedding(), all.embedding());
        eprintln!("landmarks = all points vs exact: max abs diff {diff:e}");
        assert!(diff < 1e-8, "{diff}");
        let xq = swiss_roll(50, 7).0;
        let dq = max_diff_up_to_sign(
            exact.transform(xq.as_ref()).unwrap().as_ref(),
            all.transform(xq.as_ref()).unwrap().as_ref(),
        );
        eprintln!("landmarks = all points vs exact, transform: max abs diff {dq:e}");
        assert!(dq < 1e-8, "{dq}");

        let few = Isomap::fit(x.as_ref(), &params(6, 2, Some(200))).unwrap();
        assert_eq!(few.landmarks().unwrap().len(), 200);
        assert_eq!(few.geodesic_distances().ncols(), 200);
        let r = corr(&col(few.embedding(), 0), &t).abs();
        eprintln!("200 of 800 landmarks: |corr(y1, t)| = {r:.5}");
        assert!(r > 0.98, "{r}");
        // In landmark mode transform uses the same triangulation as the training embedding.
        let y = few.transform(x.as_ref()).unwrap();
        let e = max_diff_up_to_sign(y.as_ref(), few.embedding());
        assert!(e < 1e-8, "{e}");
    }

    #[test]
    fn model_round_trips_through_serde() {
        let (x, _) = swiss_roll(100, 3);
        let iso = Isomap::fit(x.as_ref(), &params(8, 2, Some(40))).unwrap();
        let s = serde_json::to_string(&iso).unwrap();
        let back: Isomap = serde_json::from_str(&s).unwrap();
        assert_eq!(back, iso);
        let y = back.transform(x.as_ref()).unwrap();
        assert_eq!(y.ncols(), 2);
        // A corrupted model is an error, not a panic.
        let mut bad = iso.clone();
        bad.geodesic.pop();
        assert!(bad.transform(x.as_ref()).is_err());
        assert_eq!(bad.geodesic_distances().nrows(), 0);
        let p = IsomapParams::default();
        assert_eq!((p.n_neighbors, p.n_components, p.n_landmarks), (8, 9, None));
    }

    #[test]
    fn bad_input_is_rejected() {
        let (x, _) = swiss_roll(40, 1);
        let p = params(5, 2, None);
        assert!(matches!(
            Isomap::fit(Mat::<f64>::zeros(0, 3).as_ref(), &p),
            Err(Error::Empty("x"))
        ));
        assert!(Isomap::fit(Mat::<f64>::zeros(40, 0).as_ref(), &p).is_err());
        let mut xn = x.clone();
        xn[(3, 1)] = f64::NAN;
        assert!(matches!(
            Isomap::fit(xn.as_ref(), &p),
            Err(Error::NonFinite { .. })
        ));
        for k in [0, 40, 41] {
            let e = Isomap::fit(x.as_ref(), &params(k, 2, None)).unwrap_err();
            assert!(e.to_string().contains("n_neighbors"), "{e}");
        }
        for l in [0, 41] {
            let e = Isomap::fit(x.as_ref(), &params(5, l, None)).unwrap_err();
            assert!(e.to_string().contains("n_components"), "{e}");
        }
        for m in [0, 1, 41] {
            let e = Isomap::fit(x.as_ref(), &params(5, 2, Some(m))).unwrap_err();
            assert!(e.to_string().contains("n_landmarks"), "{e}");
        }
        let e = Isomap::fit(x.as_ref(), &params(5, 3, Some(2))).unwrap_err();
        assert!(e.to_string().contains("n_components"), "{e}");
        // Two far clusters.
        let u = uniform_vec(9, 20 * 2, 0.0, 1.0).unwrap();
        let two = Mat::from_fn(20, 2, |i, j| {
            u[i * 2 + j] + if i < 10 { 0.0 } else { 100.0 }
        });
        for lm in [None, Some(8)] {
            let e = Isomap::fit(two.as_ref(), &params(3, 2, lm)).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains("2 connected components"), "{msg}");
            assert!(msg.contains("larger n_neighbors"), "{msg}");
        }
        // All samples identical.
        assert!(Isomap::fit(
            Mat::<f64>::from_fn(10, 2, |_, _| 1.0).as_ref(),
            &params(3, 1, None)
        )
        .is_err());
        // Too many points for the exact method.
        let big = Mat::<f64>::zeros(MAX_EXACT_POINTS + 1, 1);
        let e = Isomap::fit(big.as_ref(), &params(5, 2, None)).unwrap_err();
        assert!(e.to_string().contains("n_landmarks"), "{e}");
        // Transform with the wrong width or NaN.
        let iso = Isomap::fit(x.as_ref(), &p).unwrap();
        assert!(matches!(
            iso.transform(Mat::<f64>::zeros(2, 4).as_ref()),
            Err(Error::ShapeMismatch(_))
        ));
        let mut q = Mat::<f64>::zeros(2, 3);
        q[(1, 2)] = f64::INFINITY;
        assert!(iso.transform(q.as_ref()).is_err());
    }
}
