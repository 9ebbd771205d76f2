//! The marching-cubes case table, built in code rather than typed in.
//!
//! # Cube numbering
//!
//! Corner `c` of a cell (`0..8`) sits at offset `(c & 1, (c >> 1) & 1, c >> 2)` from the cell's
//! low corner; bit `c` of a cell's 8-bit *configuration* is set when corner `c` is inside
//! (`f >= iso`). Edge `e` (`0..12`) runs along axis `a = e / 4`; with `(b, c)` the two other axes
//! in cyclic order (`b = (a + 1) % 3`, `c = (a + 2) % 3`) and `k = e % 4`, its low end has
//! offset 0 along `a`, `k & 1` along `b` and `k >> 1` along `c`.
//!
//! # Triangulation
//!
//! For every configuration the isosurface polygons are traced on the cube's six faces: on each
//! face the crossing edges are joined in pairs so that every inside corner is cut off on its own
//! (an *ambiguous* face, with two diagonal inside corners, never connects them: the fixed
//! ambiguity rule of the classic table). Since the rule depends only on the face's four corner
//! sides, two cells sharing a face cut it the same way and the mesh has no cracks. The face
//! segments are directed so that the inside lies on their left seen from outside the cube; they
//! chain into closed loops, and each loop is fanned into triangles whose right-hand normal
//! points toward the inside, i.e. along the gradient of `f`.
//!
//! # Tetrahedron selection (paper section 4)
//!
//! For a vertex on edge `e = (p, q)` of a cell, the paper picks one of the two corner
//! tetrahedra (at `p` or at `q`) from the cell's triangles: the one containing a whole triangle
//! incident to the vertex (rule 1), else the one containing more triangle edges (rule 2). The
//! paper folds this into an extended lookup table; [`CaseEntry::select`] is that extension.
//! Ties are left to run time ([`Selection::Nearer`]: the corner nearer to the vertex).
//!
//! # Rotation classes (paper section 5.3, Fig. 11)
//!
//! [`mc_rotation_class`] partitions the 256 configurations into their orbits under the 24
//! rotations of the cube (no complement symmetry): 23 classes, numbered by (number of inside
//! corners, smallest configuration of the orbit). The numbering is ours, not the paper's figure.

use std::sync::OnceLock;

/// Offset of corner `c` from the cell's low corner.
#[inline]
pub const fn corner_offset(c: usize) -> [usize; 3] {
    [c & 1, (c >> 1) & 1, c >> 2]
}

/// Corner index of an offset in `{0, 1}^3`.
#[inline]
pub const fn corner_index(o: [usize; 3]) -> usize {
    o[0] | (o[1] << 1) | (o[2] << 2)
}

/// Axis of edge `e`.
#[inline]
pub const fn edge_axis(e: usize) -> usize {
    e / 4
}

/// Offset of the low end of edge `e` from the cell's low corner.
#[inline]
pub const fn edge_low_offset(e: usize) -> [usize; 3] {
    let a = e / 4;
    let k = e % 4;
    let mut o = [0; 3];
    o[(a + 1) % 3] = k & 1;
    o[(a + 2) % 3] = k >> 1;
    o
}

/// The local edge of a cell along `axis` whose low end has offsets `db` (axis `(a+1)%3`) and
/// `dc` (axis `(a+2)%3`).
#[inline]
pub const fn edge_index(axis: usize, db: usize, dc: usize) -> usize {
    axis * 4 + db + 2 * dc
}

/// The two corners of edge `e` (low, high).
#[inline]
pub const fn edge_corners(e: usize) -> (usize, usize) {
    EDGE_CORNERS[e]
}

/// [`edge_corners`] of the 12 edges, computed at compile time (the lookup stays in
/// registers, where building the offsets by index would go through the stack).
const EDGE_CORNERS: [(usize, usize); 12] = {
    let mut t = [(0, 0); 12];
    let mut e = 0;
    while e < 12 {
        let lo = edge_low_offset(e);
        let mut hi = lo;
        hi[e / 4] = 1;
        t[e] = (corner_index(lo), corner_index(hi));
        e += 1;
    }
    t
};

/// Whether edge `e` has corner `c` as an endpoint.
#[inline]
pub const fn edge_touches(e: usize, c: usize) -> bool {
    let (lo, hi) = edge_corners(e);
    lo == c || hi == c
}

/// Which corner tetrahedron gives a vertex its spline gradient inside one cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Selection {
    /// The tetrahedron at the edge's low corner `p`.
    Low,
    /// The tetrahedron at the edge's high corner `q`.
    High,
    /// The paper's rules tie: use the corner nearer to the vertex (`t <= 0.5` means `p`).
    Nearer,
}

/// The table entry of one configuration.
#[derive(Clone, Debug)]
pub struct CaseEntry {
    /// Triangles as triples of local edges, wound so that the right-hand normal points toward
    /// the inside (increasing `f`).
    pub triangles: Vec<[u8; 3]>,
    /// Bit `e` set when edge `e` crosses the isosurface.
    pub edge_mask: u16,
    /// Bit `c` set when corner `c` is an endpoint of a crossing edge (its sample is needed).
    pub endpoints: u8,
    /// Per crossing edge, the tetrahedron the paper's rules choose (unused for other edges).
    pub select: [Selection; 12],
}

/// The 256 table entries, built on first use.
pub fn case_table() -> &'static [CaseEntry] {
    static TABLE: OnceLock<Vec<CaseEntry>> = OnceLock::new();
    TABLE.get_or_init(|| (0..256).map(|c| build_case(c as u8)).collect())
}

/// Corners of face `(axis m, side s)` in counter-clockwise order seen from outside the cube.
fn face_cycle(m: usize, s: usize) -> [usize; 4] {
    let (u, v) = ((m + 1) % 3, (m + 2) % 3);
    let at = |du: usize, dv: usize| {
        let mut o = [0; 3];
        o[m] = s;
        o[u] = du;
        o[v] = dv;
        corner_index(o)
    };
    let ccw = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
    if s == 1 {
        ccw
    } else {
        [ccw[0], ccw[3], ccw[2], ccw[1]]
    }
}

/// The local edge joining two adjacent corners.
fn edge_between(c0: usize, c1: usize) -> usize {
    (0..12)
        .find(|&e| {
            let (lo, hi) = edge_corners(e);
            (lo == c0 && hi == c1) || (lo == c1 && hi == c0)
        })
        .expect("corners of a face cycle are adjacent")
}

/// Traces the isosurface polygons of configuration `config` (see the module documentation).
fn polygons(config: u8) -> Vec<Vec<u8>> {
    let inside = |c: usize| config >> c & 1 == 1;
    let mut next = [u8::MAX; 12];
    for m in 0..3 {
        for s in 0..2 {
            let cyc = face_cycle(m, s);
            for i in 0..4 {
                // An inside-to-outside step of the boundary walk starts a segment ...
                if !inside(cyc[i]) || inside(cyc[(i + 1) % 4]) {
                    continue;
                }
                // ... which ends where the walk entered this run of inside corners.
                let mut start = i;
                while inside(cyc[(start + 3) % 4]) {
                    start = (start + 3) % 4;
                }
                let from = edge_between(cyc[i], cyc[(i + 1) % 4]);
                let to = edge_between(cyc[(start + 3) % 4], cyc[start]);
                debug_assert_eq!(next[from], u8::MAX, "edge starts two segments");
                next[from] = to as u8;
            }
        }
    }
    let mut seen = [false; 12];
    let mut loops = Vec::new();
    for e in 0..12 {
        if next[e] == u8::MAX || seen[e] {
            continue;
        }
        let mut poly = Vec::new();
        let mut cur = e;
        while !seen[cur] {
            seen[cur] = true;
            poly.push(cur as u8);
            cur = next[cur] as usize;
            assert!(
                cur < 12,
                "face segments of configuration {config} do not close"
            );
        }
        assert_eq!(
            cur, e,
            "face segments of configuration {config} do not close"
        );
        loops.push(poly);
    }
    loops
}

fn build_case(config: u8) -> CaseEntry {
    let mut triangles = Vec::new();
    for poly in polygons(config) {
        for i in 1..poly.len() - 1 {
            triangles.push([poly[0], poly[i], poly[i + 1]]);
        }
    }
    let mut edge_mask = 0u16;
    let mut endpoints = 0u8;
    for e in 0..12 {
        let (lo, hi) = edge_corners(e);
        if (config >> lo & 1) != (config >> hi & 1) {
            edge_mask |= 1 << e;
            endpoints |= (1 << lo) | (1 << hi);
        }
    }
    let mut select = [Selection::Nearer; 12];
    for (e, sel) in select.iter_mut().enumerate() {
        if edge_mask >> e & 1 == 1 {
            *sel = select_tetrahedron(&triangles, e);
        }
    }
    CaseEntry {
        triangles,
        edge_mask,
        endpoints,
        select,
    }
}

/// The paper's tetrahedron choice for the vertex on edge `e` (section 4): rule 1, a triangle
/// incident to the vertex lies entirely in one corner tetrahedron (all three of its vertices on
/// edges at that corner); rule 2, the tetrahedron holding more edges of the incident triangles.
fn select_tetrahedron(triangles: &[[u8; 3]], e: usize) -> Selection {
    let (p, q) = edge_corners(e);
    let incident: Vec<&[u8; 3]> = triangles
        .iter()
        .filter(|t| t.contains(&(e as u8)))
        .collect();
    let whole = |c: usize| {
        incident
            .iter()
            .any(|t| t.iter().all(|&v| edge_touches(v as usize, c)))
    };
    match (whole(p), whole(q)) {
        (true, false) => return Selection::Low,
        (false, true) => return Selection::High,
        _ => {}
    }
    let count = |c: usize| {
        incident
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .filter(|&(a, b)| edge_touches(a as usize, c) && edge_touches(b as usize, c))
            .count()
    };
    match count(p).cmp(&count(q)) {
        std::cmp::Ordering::Greater => Selection::Low,
        std::cmp::Ordering::Less => Selection::High,
        std::cmp::Ordering::Equal => Selection::Nearer,
    }
}

/// The 24 rotations of the cube as permutations of its corners.
pub fn cube_rotations() -> Vec<[usize; 8]> {
    let mut out = Vec::with_capacity(24);
    let perms = [
        [0, 1, 2],
        [1, 2, 0],
        [2, 0, 1],
        [0, 2, 1],
        [2, 1, 0],
        [1, 0, 2],
    ];
    for (pi, perm) in perms.iter().enumerate() {
        let parity = if pi < 3 { 1 } else { -1 };
        for signs in 0..8 {
            let sg = [
                if signs & 1 == 0 { 1 } else { -1 },
                if signs & 2 == 0 { 1 } else { -1 },
                if signs & 4 == 0 { 1 } else { -1 },
            ];
            if parity * sg[0] * sg[1] * sg[2] != 1 {
                continue;
            }
            let mut map = [0usize; 8];
            for (c, slot) in map.iter_mut().enumerate() {
                let o = corner_offset(c);
                let mut r = [0usize; 3];
                for i in 0..3 {
                    // Row i of the signed permutation matrix picks axis perm[i] with sign sg[i];
                    // centred coordinates are o - 1/2, so a flip maps o to 1 - o.
                    let v = o[perm[i]];
                    r[i] = if sg[i] == 1 { v } else { 1 - v };
                }
                *slot = corner_index(r);
            }
            out.push(map);
        }
    }
    out
}

/// Applies a corner permutation to a configuration.
pub fn permute_config(config: u8, map: &[usize; 8]) -> u8 {
    (0..8).fold(0u8, |acc, c| {
        if config >> c & 1 == 1 {
            acc | (1 << map[c])
        } else {
            acc
        }
    })
}

struct Classes {
    class_of: [u8; 256],
    canonical: Vec<u8>,
}

fn classes() -> &'static Classes {
    static CLASSES: OnceLock<Classes> = OnceLock::new();
    CLASSES.get_or_init(|| {
        let rots = cube_rotations();
        let canon = |c: u8| rots.iter().map(|r| permute_config(c, r)).min().unwrap_or(c);
        let mut reps: Vec<u8> = (0..=255u8).map(canon).collect();
        reps.sort_by_key(|&r| (r.count_ones(), r));
        reps.dedup();
        let mut class_of = [0u8; 256];
        for (c, slot) in class_of.iter_mut().enumerate() {
            let r = canon(c as u8);
            *slot = reps.iter().position(|&x| x == r).unwrap_or(0) as u8;
        }
        Classes {
            class_of,
            canonical: reps,
        }
    })
}

/// Rotation class (`0..number_of_rotation_classes()`) of a configuration: its orbit under the
/// 24 cube rotations, numbered by (inside-corner count, smallest configuration of the orbit).
pub fn mc_rotation_class(config: u8) -> u8 {
    classes().class_of[config as usize]
}

/// Number of rotation classes (23).
pub fn number_of_rotation_classes() -> usize {
    classes().canonical.len()
}

/// The smallest configuration of each rotation class, indexed by class.
pub fn rotation_class_representatives() -> &'static [u8] {
    &classes().canonical
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_are_unit_segments() {
        for e in 0..12 {
            let (lo, hi) = edge_corners(e);
            let (a, b) = (corner_offset(lo), corner_offset(hi));
            let diff: usize = (0..3).map(|i| a[i].abs_diff(b[i])).sum();
            assert_eq!(diff, 1);
            assert_eq!(b[edge_axis(e)], 1);
            let o = edge_low_offset(e);
            assert_eq!(
                edge_index(
                    edge_axis(e),
                    o[(edge_axis(e) + 1) % 3],
                    o[(edge_axis(e) + 2) % 3]
                ),
                e
            );
        }
    }

    #[test]
    fn every_crossing_edge_is_used_and_triangles_use_only_crossing_edges() {
        for (config, entry) in case_table().iter().enumerate() {
            let mut used = 0u16;
            for t in &entry.triangles {
                for &v in t {
                    used |= 1 << v;
                }
            }
            assert_eq!(used, entry.edge_mask, "configuration {config}");
            // A closed polygon set: every triangle-fan edge on the boundary of the loops
            // appears once; the number of triangles is crossings - 2 * loops.
            assert!(entry.triangles.len() <= 12);
        }
        assert!(case_table()[0].triangles.is_empty());
        assert!(case_table()[255].triangles.is_empty());
        assert_eq!(case_table()[1].triangles.len(), 1);
    }

    #[test]
    fn rotations_are_distinct_and_preserve_adjacency() {
        let rots = cube_rotations();
        assert_eq!(rots.len(), 24);
        let mut sorted = rots.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), 24);
        for r in &rots {
            for e in 0..12 {
                let (a, b) = edge_corners(e);
                let (ra, rb) = (corner_offset(r[a]), corner_offset(r[b]));
                let diff: usize = (0..3).map(|i| ra[i].abs_diff(rb[i])).sum();
                assert_eq!(diff, 1);
            }
        }
    }

    #[test]
    fn twenty_three_rotation_classes() {
        assert_eq!(number_of_rotation_classes(), 23);
        // Complements of one-corner configurations are a different class (no complement
        // symmetry), and a class never mixes corner counts.
        assert_ne!(mc_rotation_class(1), mc_rotation_class(254));
        for c in 0..=255u8 {
            let r = rotation_class_representatives()[mc_rotation_class(c) as usize];
            assert_eq!(r.count_ones(), c.count_ones());
        }
    }
}
