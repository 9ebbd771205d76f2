//! Acceptance checks of paper 10: exact voxelization, structure invariants,
//! ray-cast equivalence with brute force, the memory trend of Table 2, LoD behaviour, voxel
//! attributes, and bad input.

use std::collections::{HashMap, HashSet};

use rand::Rng;
use rayon::prelude::*;
use wscg_math::{metrics, rng, Image, TriMesh};
use wscg_octree::cube::{child_octant, morton};
use wscg_octree::overlap::{tri_box_overlap, CELL_HALF};
use wscg_octree::traverse::intersect_tri;
use wscg_octree::{
    brute_force, build, render, scenes, BuildParams, Camera, Cube, Footprint, HitKind,
    HybridOctree, LeafTris, PointLight, Ray, Shading, TraceMode, TriangleBvh,
};

fn params(depth: u8, early_stop: bool) -> BuildParams {
    BuildParams::default()
        .max_depth(depth)
        .early_stop(early_stop)
}

/// 1,000 triangles in the grid units of a 64^3 grid: general, slivers, axis-aligned on cell
/// planes, with lattice-point vertices, and large.
fn random_triangles(seed: u64) -> Vec<[[f64; 3]; 3]> {
    let mut r = rng::seeded(seed);
    let pt = |r: &mut rng::Rng| -> [f64; 3] { std::array::from_fn(|_| r.random_range(0.0..64.0)) };
    (0..1000)
        .map(|i| match i % 5 {
            0 => {
                let a = pt(&mut r);
                [
                    a,
                    std::array::from_fn(|k| (a[k] + r.random_range(-6.0..6.0)).clamp(0.0, 64.0)),
                    std::array::from_fn(|k| (a[k] + r.random_range(-6.0..6.0)).clamp(0.0, 64.0)),
                ]
            }
            1 => {
                // Sliver: the third vertex within 1e-3 cells of the first edge.
                let a = pt(&mut r);
                let b: [f64; 3] =
                    std::array::from_fn(|k| (a[k] + r.random_range(-10.0..10.0)).clamp(0.0, 64.0));
                let s = r.random_range(0.1..0.9);
                let c = std::array::from_fn(|k| {
                    (a[k] + s * (b[k] - a[k]) + r.random_range(-1e-3..1e-3)).clamp(0.0, 64.0)
                });
                [a, b, c]
            }
            2 => {
                // Axis-aligned in a cell plane, vertices on the lattice.
                let z = f64::from(r.random_range(0..=64u32));
                let mut q = || {
                    [
                        f64::from(r.random_range(0..=64u32)),
                        f64::from(r.random_range(0..=64u32)),
                    ]
                };
                let (a, b, c) = (q(), q(), q());
                let ax = i % 3;
                let lift = |p: [f64; 2]| {
                    let mut v = [0.0; 3];
                    v[ax] = z;
                    v[(ax + 1) % 3] = p[0];
                    v[(ax + 2) % 3] = p[1];
                    v
                };
                [lift(a), lift(b), lift(c)]
            }
            3 => {
                let mut q =
                    || std::array::from_fn(|_| f64::from(r.random_range(0..=64u32)) * 0.5 + 16.0);
                [q(), q(), q()]
            }
            _ => [pt(&mut r), pt(&mut r), pt(&mut r)],
        })
        .collect()
}

/// Check 1: the voxelizer's (cell, triangle) set equals a brute-force SAT over all 64^3 cells,
/// and contains the cell of every sampled point of every triangle.
#[test]
fn voxelization_is_exact_on_random_triangles() {
    let tris = random_triangles(11);
    let positions: Vec<[f64; 3]> = tris.iter().flatten().copied().collect();
    let faces: Vec<[u32; 3]> = (0..tris.len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    let cube = Cube::new([0.0; 3], 64.0).unwrap();
    let frags = wscg_octree::voxelize(&positions, &faces, None, &cube, 6).unwrap();
    let ours: HashSet<(u64, u32)> = frags.list.iter().map(|f| (f.morton, f.prim)).collect();
    assert_eq!(
        ours.len(),
        frags.list.len(),
        "a (cell, triangle) pair appears twice"
    );
    let degenerate: Vec<bool> = tris
        .iter()
        .map(|t| wscg_octree::voxelize::is_degenerate(t[0], t[1], t[2]))
        .collect();
    assert_eq!(frags.degenerate, degenerate.iter().filter(|d| **d).count());
    let reference: HashSet<(u64, u32)> = tris
        .par_iter()
        .enumerate()
        .filter(|(i, _)| !degenerate[*i])
        .flat_map_iter(|(i, t)| {
            let mut v = Vec::new();
            for z in 0..64u32 {
                for y in 0..64u32 {
                    for x in 0..64u32 {
                        let c = [x, y, z].map(|c| f64::from(c) + 0.5);
                        if tri_box_overlap(c, CELL_HALF, t[0], t[1], t[2]) {
                            v.push((morton([x, y, z]), i as u32));
                        }
                    }
                }
            }
            v
        })
        .collect();
    assert_eq!(ours, reference);
    // Independent of the SAT: every point on a triangle lies in a fragment cell of it.
    let mut r = rng::seeded(5);
    for (i, t) in tris.iter().enumerate().filter(|(i, _)| !degenerate[*i]) {
        for _ in 0..200 {
            let (mut a, mut b) = (r.random_range(0.0..1.0f64), r.random_range(0.0..1.0f64));
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let p: [f64; 3] = std::array::from_fn(|k| {
                t[0][k] + a * (t[1][k] - t[0][k]) + b * (t[2][k] - t[0][k])
            });
            let c = p.map(|v| (v.floor() as i64).clamp(0, 63) as u32);
            assert!(
                ours.contains(&(morton(c), i as u32)),
                "triangle {i} point {p:?} not in cell {c:?}"
            );
        }
    }
}

/// Distinct triangles referenced by the leaves below `node`.
fn subtree_tris(oct: &HybridOctree, node: u32, out: &mut HashSet<u32>) {
    let n = oct.nodes[node as usize];
    if n.is_empty() {
        return;
    }
    if n.is_leaf() {
        oct.decode_leaf(node).for_each(|t| {
            out.insert(t);
        });
    } else {
        for c in 0..8 {
            subtree_tris(oct, n.index() + c, out);
        }
    }
}

/// The leaf of `oct` containing finest cell `m`.
fn leaf_of(oct: &HybridOctree, m: u64) -> Option<u32> {
    let mut n = 0u32;
    for l in 0..=oct.max_depth {
        let node = oct.nodes[n as usize];
        if node.is_empty() {
            return None;
        }
        if node.is_leaf() {
            return Some(n);
        }
        n = node.index() + child_octant(m, l, oct.max_depth) as u32;
    }
    None
}

fn check_invariants(mesh: &TriMesh, depth: u8) {
    let (oct, stats) = build(mesh, &params(depth, true)).unwrap();
    oct.check().unwrap();
    let levels = oct.node_levels();
    let mut early = 0;
    for (i, n) in oct.nodes.iter().enumerate() {
        if n.is_empty() {
            continue;
        }
        let mut t = HashSet::new();
        subtree_tris(&oct, i as u32, &mut t);
        if n.is_leaf() {
            if levels[i] < depth {
                early += 1;
                assert!(
                    (1..=2).contains(&t.len()),
                    "early leaf {i} holds {} triangles",
                    t.len()
                );
            }
            // The decoded list round-trips: sorted, distinct, in range.
            let mut v = Vec::new();
            oct.decode_leaf(i as u32).for_each(|x| v.push(x));
            assert!(v.windows(2).all(|w| w[0] < w[1]) && v.iter().all(|&x| x < oct.n_tris));
            if let LeafTris::List(l) = oct.decode_leaf(i as u32) {
                assert!(l.len() > 2);
            }
        } else {
            assert!(t.len() > 2, "inner node {i} holds {} triangles", t.len());
        }
    }
    assert_eq!(early, stats.early_leaves);
    // Every (cell, triangle) fragment lies in a leaf referencing the triangle.
    let cube = oct.cube;
    let frags = wscg_octree::voxelize(&mesh.positions, &mesh.faces, None, &cube, depth).unwrap();
    let bad = frags
        .list
        .par_iter()
        .filter(|f| {
            let Some(leaf) = leaf_of(&oct, f.morton) else {
                return true;
            };
            let mut found = false;
            oct.decode_leaf(leaf).for_each(|t| found |= t == f.prim);
            !found
        })
        .count();
    assert_eq!(bad, 0);
}

/// Check 2: structure invariants on the test scenes.
#[test]
fn structure_invariants_hold_on_the_scenes() {
    check_invariants(&scenes::atrium(4).unwrap(), 7);
    check_invariants(&scenes::blob(4).unwrap(), 7);
    check_invariants(&scenes::forest(2, 3, 4, 1).unwrap(), 8);
    check_invariants(&scenes::city(4, 2).unwrap(), 7);
}

/// Check 2: the exact case: early stop makes the root a leaf; the full build has
/// `1 + 8 (4^L - 1) / 3` nodes and `(4^(L+1) - 1) / 3` voxels.
#[test]
fn exact_square_counts_for_every_depth() {
    let (mesh, cube) = scenes::exact_square().unwrap();
    for l in 1..=9u8 {
        let p = params(l, true).domain(Some(cube));
        let (early, _) = build(&mesh, &p).unwrap();
        assert_eq!(early.nodes.len(), 1);
        assert!(early.nodes[0].is_leaf());
        assert_eq!(early.decode_leaf(0), LeafTris::Pair(0, 1));
        let (full, _) = build(&mesh, &p.early_stop(false)).unwrap();
        let f4 = 4u64.pow(u32::from(l));
        assert_eq!(full.nodes.len() as u64, 1 + 8 * (f4 - 1) / 3, "L = {l}");
        assert_eq!(full.voxels.len() as u64, (4 * f4 - 1) / 3, "L = {l}");
    }
    // Depth 0 is valid: a single node.
    let (z, _) = build(&mesh, &params(0, false).domain(Some(cube))).unwrap();
    assert_eq!(z.nodes.len(), 1);
}

/// Random rays aimed into the mesh's bounding box from around it.
fn random_rays(cube: &Cube, n: usize, seed: u64) -> Vec<Ray> {
    let s = cube.size as f32;
    let c = cube.min.map(|v| v as f32);
    (0..n)
        .into_par_iter()
        .map(|i| {
            let mut r = rng::stream(seed, i as u64);
            let o: [f32; 3] = std::array::from_fn(|k| c[k] + s * r.random_range(-0.5..1.5f32));
            let t: [f32; 3] = std::array::from_fn(|k| c[k] + s * r.random_range(0.1..0.9f32));
            Ray::new(o, std::array::from_fn(|k| t[k] - o[k]))
        })
        .collect()
}

/// Compares the octree's triangle mode with `reference` on `rays`; returns the fraction of
/// untied hits with the same triangle.
fn compare_with(
    oct: &HybridOctree,
    rays: &[Ray],
    reference: impl Fn(&Ray) -> Option<(u32, f32, f32, f32)> + Sync,
) -> f64 {
    let tol = 1e-5 * oct.cube.size as f32;
    let res: Vec<(bool, bool)> = rays
        .par_iter()
        .map(|ray| {
            let ours = oct.intersect(ray, &TraceMode::Triangles, None);
            let theirs = reference(ray);
            match (ours, theirs) {
                (None, None) => (true, true),
                (Some(h), Some((prim, t, _, _))) => {
                    let dn = ray.dir.iter().map(|v| v * v).sum::<f32>().sqrt();
                    assert!(
                        (h.t - t).abs() * dn <= tol,
                        "|dt| = {} > {tol}",
                        (h.t - t).abs() * dn
                    );
                    let HitKind::Triangle { prim: p, .. } = h.kind else {
                        panic!("voxel hit in triangle mode")
                    };
                    // A tie: another triangle is hit within the tolerance of the nearest.
                    let tie = p != prim
                        && intersect_tri(&oct.tris()[p as usize], ray.origin, ray.dir)
                            .is_some_and(|(tp, _, _)| (tp - t).abs() * dn <= tol);
                    (p == prim || tie, !tie)
                }
                (a, b) => panic!("hit/miss differ: octree {a:?}, reference {b:?} for {ray:?}"),
            }
        })
        .collect();
    let counted = res.iter().filter(|r| r.1).count();
    res.iter().filter(|r| r.1 && r.0).count() as f64 / counted as f64
}

/// Check 3: triangle-mode ray casting equals brute force on small meshes (2^18 rays).
#[test]
fn ray_cast_equals_brute_force() {
    for mesh in [scenes::blob(3).unwrap(), scenes::atrium(3).unwrap()] {
        let (oct, _) = build(&mesh, &params(9, true)).unwrap();
        let rays = random_rays(&oct.cube, 1 << 18, 3);
        let same = compare_with(&oct, &rays, |r| brute_force(oct.tris(), r));
        assert!(same >= 0.9999, "same triangle on {same}");
        // The BVH baseline agrees with brute force too (it is the reference below).
        let bvh = TriangleBvh::build(&mesh).unwrap();
        let same = compare_with(&oct, &rays[..1 << 14], |r| bvh.intersect(r));
        assert!(same >= 0.9999);
    }
}

/// Check 3 with finite ray windows (as shadow rays have): the traversal keeps the closest hit
/// found in any leaf and stops once it passes it, so the window bounds must hold exactly as
/// in brute force.
#[test]
fn ray_windows_equal_brute_force() {
    let mesh = scenes::atrium(3).unwrap();
    let (oct, _) = build(&mesh, &params(9, true)).unwrap();
    let mut rays = random_rays(&oct.cube, 1 << 16, 5);
    for (i, r) in rays.iter_mut().enumerate() {
        let mut g = rng::stream(6, i as u64);
        r.t_min = g.random_range(0.0..0.8f32);
        r.t_max = r.t_min + g.random_range(0.02..0.6f32);
    }
    let same = compare_with(&oct, &rays, |r| brute_force(oct.tris(), r));
    assert!(same >= 0.9999, "same triangle on {same}");
    let hits = rays
        .par_iter()
        .filter(|r| brute_force(oct.tris(), r).is_some())
        .count();
    // Both outcomes occur often enough for the comparison to mean something.
    assert!(
        hits > rays.len() / 10 && hits < rays.len() * 9 / 10,
        "{hits}"
    );
    // The any-hit walk of shadow rays agrees with the closest-hit one, in every mode.
    let fp = Footprint {
        width0: 0.0,
        spread: 2e-3,
    };
    for mode in [TraceMode::Triangles, TraceMode::HYBRID, TraceMode::VOXELS] {
        let differ = rays
            .par_iter()
            .filter(|r| {
                oct.occluded(r, &mode, Some(fp)) != oct.intersect(r, &mode, Some(fp)).is_some()
            })
            .count();
        assert_eq!(differ, 0, "{mode:?}");
    }
}

/// Check 3 on the 1.3 M-triangle blob, against the BVH (brute force over 1.3 M triangles x
/// 2^18 rays is out of reach; the BVH is checked against brute force above).
#[test]
fn ray_cast_equals_reference_on_the_large_blob() {
    let mesh = scenes::blob(8).unwrap();
    assert_eq!(mesh.faces.len(), 1_310_720);
    let (oct, _) = build(&mesh, &params(9, true)).unwrap();
    let bvh = TriangleBvh::build(&mesh).unwrap();
    let rays = random_rays(&oct.cube, 1 << 18, 4);
    let same = compare_with(&oct, &rays, |r| bvh.intersect(r));
    assert!(same >= 0.9999, "same triangle on {same}");
}

/// Check 4: the memory trend of Table 2 at L = 9.
#[test]
fn memory_trend_follows_triangle_size() {
    let saving = |mesh: &TriMesh| {
        let (full, _) = build(mesh, &params(9, false)).unwrap();
        let (early, _) = build(mesh, &params(9, true)).unwrap();
        let (a, b) = (full.memory_report(), early.memory_report());
        assert!(
            a.nodes >= b.nodes && a.voxels >= b.voxels && a.total >= b.total,
            "full {a:?} early {b:?}"
        );
        assert_eq!(a.triangles, b.triangles);
        // An early pair leaf costs two words even where the full build splits its two
        // triangles into single leaves (no words): the index array can grow by at most that.
        let pairs = early
            .nodes
            .iter()
            .filter(|n| {
                n.is_leaf()
                    && !n.is_empty()
                    && n.index() >= early.n_tris
                    && n.index() < early.n_tris + early.n_pair_words
            })
            .count();
        assert!(b.tri_index <= a.tri_index + 8 * pairs);
        b.saving_against(&a)
    };
    let atrium = saving(&scenes::atrium(10).unwrap());
    let blob = saving(&scenes::blob(8).unwrap());
    let forest = saving(&scenes::forest(13, 6, 64, 3).unwrap());
    assert!(atrium >= 0.35, "atrium saving {atrium}");
    assert!(blob <= 0.03, "blob saving {blob}");
    assert!(forest > blob && forest < atrium, "forest saving {forest}");
}

/// The atrium, blob and forest at L = 9: name, full octree, early-stop octree (built one
/// scene at a time as the iterator advances).
fn full_and_early_builds() -> impl Iterator<Item = (&'static str, HybridOctree, HybridOctree)> {
    [
        ("atrium", scenes::atrium(10).unwrap()),
        ("blob", scenes::blob(8).unwrap()),
        ("forest", scenes::forest(13, 6, 64, 3).unwrap()),
    ]
    .into_iter()
    .map(|(name, mesh)| {
        let (full, _) = build(&mesh, &params(9, false)).unwrap();
        let (early, _) = build(&mesh, &params(9, true)).unwrap();
        (name, full, early)
    })
}

/// What check 4's strict reading compares, exactly: the two builds agree above every early
/// leaf and in the lists at level `L`, and a single never takes index words, so the full
/// build's index array differs from the early one's only under early pair leaves. Each such
/// pair's 2 words become 2 words per finest cell that holds both triangles:
/// `full - early = sum over early pairs of 2 (k - 1)` words, `k` those shared cells. A pair
/// whose triangles share no finest cell (`k = 0`) makes the full array smaller.
#[test]
fn tri_index_difference_is_two_words_per_shared_cell_minus_one() {
    for (name, full, early) in full_and_early_builds() {
        let pairs_at = |oct: &HybridOctree, deep: bool| {
            let mut out = Vec::new();
            oct.visit(|n, l, c| {
                let leaf = oct.nodes[n as usize].is_leaf();
                if leaf && (l == oct.max_depth) == deep {
                    if let LeafTris::Pair(a, b) = oct.decode_leaf(n) {
                        out.push((l, c, (a.min(b), a.max(b))));
                    }
                }
            });
            out
        };
        // Pair leaves of the full build at level L, by cell.
        let deep: HashMap<[u32; 3], (u32, u32)> = pairs_at(&full, true)
            .into_iter()
            .map(|(_, c, p)| (c, p))
            .collect();
        let mut shared_of = HashMap::new();
        for (c, p) in &deep {
            shared_of.entry(*p).or_insert_with(Vec::new).push(*c);
        }
        let (mut predicted, mut unshared) = (0i64, 0);
        for (l, c, p) in pairs_at(&early, false) {
            let shift = 9 - u32::from(l);
            let k = shared_of.get(&p).map_or(0, |cells| {
                cells
                    .iter()
                    .filter(|d| (0..3).all(|i| d[i] >> shift == c[i]))
                    .count()
            }) as i64;
            predicted += 2 * (k - 1);
            unshared += usize::from(k == 0);
        }
        let diff = full.tri_index.len() as i64 - early.tri_index.len() as i64;
        println!(
            "{name}: full - early = {diff} words, early pairs with no shared cell: {unshared}"
        );
        assert_eq!(diff, predicted, "{name}");
        assert_eq!(diff < 0, predicted < 0);
    }
}

/// Check 4's strict reading: the full build's triangle-index array is never smaller than the
/// early-stop one. It fails on the blob by 8 bytes of 25.5 MB (one early pair leaf whose two
/// triangles never share a finest cell): the identity of
/// `tri_index_difference_is_two_words_per_shared_cell_minus_one` makes the full array smaller
/// whenever such pairs outweigh the shared cells, so this reading is not a property of the
/// method.
#[test]
#[ignore = "fails by 8 bytes of 25.5 MB on the blob: one early pair leaf whose triangles the full build stores as singles"]
fn full_tri_index_is_never_smaller() {
    let mut short = Vec::new();
    for (name, full, early) in full_and_early_builds() {
        let (a, b) = (
            full.memory_report().tri_index,
            early.memory_report().tri_index,
        );
        if a < b {
            short.push(format!("{name}: full {a} B < early {b} B"));
        }
    }
    assert!(short.is_empty(), "{short:?}");
}

fn orbit_camera(oct: &HybridOctree, dist: f32, res: usize) -> Camera {
    let c = oct.cube;
    let centre = [0, 1, 2].map(|k| (c.min[k] + 0.5 * c.size) as f32);
    Camera {
        eye: [
            centre[0] + 0.8 * dist,
            centre[1] - 0.5 * dist,
            centre[2] + 0.35 * dist,
        ],
        target: centre,
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 45.0,
        width: res,
        height: res,
    }
}

/// Check 5: far views stop at voxels, near views hit triangles, blend factors stay in [0, 1],
/// and the near hybrid image matches the triangle image (PSNR >= 40 dB).
#[test]
fn lod_selects_voxels_far_and_triangles_near() {
    let mesh = scenes::blob(6).unwrap();
    let (oct, _) = build(&mesh, &params(9, true)).unwrap();
    let light = PointLight {
        position: [2.0, -3.0, 4.0],
        intensity: 1.0,
    };
    let s = oct.cube.size as f32;
    // Far: the scene spans about 64 of 256 pixels (fov 45 deg: visible height 0.83 d).
    let far = orbit_camera(&oct, 4.8 * s, 256);
    let (_, st) = render(&oct, &far, &light, &TraceMode::HYBRID, &Shading::default()).unwrap();
    assert!(
        st.voxel_fraction() >= 0.9,
        "far voxel fraction {}",
        st.voxel_fraction()
    );
    assert!((0.0..=1.0).contains(&st.blend_min) && st.blend_max <= 1.0);
    // Near: the pixel footprint (0.7 S * 0.83 / 512 = S / 880) is below the finest voxel (S / 512).
    let near = orbit_camera(&oct, 0.7 * s, 512);
    let (hy, st) = render(&oct, &near, &light, &TraceMode::HYBRID, &Shading::default()).unwrap();
    assert!(
        1.0 - st.voxel_fraction() >= 0.9,
        "near triangle fraction {}",
        1.0 - st.voxel_fraction()
    );
    assert!((0.0..=1.0).contains(&st.blend_min) && st.blend_max <= 1.0);
    // A voxel hit stops where v_w <= f at its entry (the parent, entered earlier, had
    // v_w > f there), and its blend is the paper's i = (2 v_w - f) / v_w.
    let fp = far.footprint();
    let gen = far.ray_gen(&far.frame().unwrap());
    let mut checked = 0;
    for y in (0..256).step_by(4) {
        for x in (0..256).step_by(4) {
            let Some(h) = oct.intersect(&gen.ray(x, y), &TraceMode::HYBRID, Some(fp)) else {
                continue;
            };
            let HitKind::Voxel { level, blend, .. } = h.kind else {
                continue;
            };
            let f = fp.spread * h.t;
            let vw = oct.cube.cell_size(level) as f32;
            assert!(vw <= f * (1.0 + 1e-5), "level {level}: v_w {vw}, f {f}");
            assert!((blend - ((2.0 * vw - f) / vw).clamp(0.0, 1.0)).abs() < 1e-4);
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked} voxel hits checked");
    let (tr, _) = render(
        &oct,
        &near,
        &light,
        &TraceMode::Triangles,
        &Shading::default(),
    )
    .unwrap();
    let clamp = |im: &Image<f32>| im.map(|v| v.clamp(0.0, 1.0)).into_data();
    let psnr = metrics::psnr(&clamp(&tr), &clamp(&hy), 1.0).unwrap();
    assert!(psnr >= 40.0, "near hybrid vs triangles PSNR {psnr}");
}

/// Whether the ray from `o` along `d` meets the box `[lo, hi]` (f64 slab test).
fn meets_box(o: [f32; 3], d: [f32; 3], lo: [f64; 3], hi: [f64; 3]) -> bool {
    let (mut t0, mut t1) = (0f64, f64::INFINITY);
    for k in 0..3 {
        let inv = 1.0 / f64::from(d[k]);
        let (a, b) = (
            (lo[k] - f64::from(o[k])) * inv,
            (hi[k] - f64::from(o[k])) * inv,
        );
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 <= t1
}

/// Whether a corner of `cube` lies on or behind the eye plane of `cam`.
fn cam_is_near(cam: &Camera, cube: &Cube) -> bool {
    let f: [f32; 3] = std::array::from_fn(|k| cam.target[k] - cam.eye[k]);
    (0..8).any(|corner| {
        let z: f64 = (0..3)
            .map(|k| {
                let p = cube.min[k] + if corner >> k & 1 == 1 { cube.size } else { 0.0 };
                (p - f64::from(cam.eye[k])) * f64::from(f[k])
            })
            .sum();
        z <= 0.0
    })
}

/// The renderer traces only the pixels of `Camera::cube_pixels`: every primary ray that meets
/// the cube lies inside that rectangle, far views cover a small part of the image, a camera
/// inside the cube gets the whole image and one looking away none of it.
#[test]
fn cube_pixels_hold_every_ray_that_enters_the_cube() {
    let mesh = scenes::blob(4).unwrap();
    let (oct, _) = build(&mesh, &params(6, true)).unwrap();
    let c = oct.cube;
    let s = c.size as f32;
    let hi = c.min.map(|v| v + c.size);
    let mut cams: Vec<(Camera, &str)> = [0.2f32, 0.9, 2.0, 6.0]
        .iter()
        .map(|&d| {
            let mut cam = orbit_camera(&oct, d * s, 64);
            cam.height = 48;
            (cam, "orbit")
        })
        .collect();
    let mut away = orbit_camera(&oct, 3.0 * s, 64);
    away.target = std::array::from_fn(|k| 2.0 * away.eye[k] - away.target[k]);
    cams.push((away, "away"));
    for (cam, what) in &cams {
        let frame = cam.frame().unwrap();
        let rect = cam.cube_pixels(&frame, &c);
        let gen = cam.ray_gen(&frame);
        let mut entering = 0;
        // Bounding rectangle of the entering pixels (inclusive).
        let (mut ex, mut ey) = ([usize::MAX, 0], [usize::MAX, 0]);
        for y in 0..cam.height {
            for x in 0..cam.width {
                let r = gen.ray(x, y);
                if meets_box(r.origin, r.dir, c.min, hi) {
                    entering += 1;
                    (ex, ey) = ([ex[0].min(x), ex[1].max(x)], [ey[0].min(y), ey[1].max(y)]);
                    assert!(
                        rect.x.contains(&x) && rect.y.contains(&y),
                        "{what} {:?}: pixel ({x}, {y}) enters the cube outside {rect:?}",
                        cam.eye
                    );
                }
            }
        }
        let area = rect.x.len() * rect.y.len();
        let n = cam.width * cam.height;
        match *what {
            "away" => assert_eq!((area, entering), (0, 0)),
            // A corner on or behind the eye plane (the camera inside or next to the cube):
            // the projection is unbounded, the whole image.
            _ if cam_is_near(cam, &c) => assert_eq!(area, n),
            // Otherwise tight: within 2 pixels of the entering pixels' rectangle (the
            // projected corners' rectangle, widened by one pixel).
            _ => {
                assert!(entering > 0);
                assert!(
                    rect.x.start + 2 >= ex[0] && rect.x.end <= ex[1] + 3,
                    "{rect:?} {ex:?}"
                );
                assert!(
                    rect.y.start + 2 >= ey[0] && rect.y.end <= ey[1] + 3,
                    "{rect:?} {ey:?}"
                );
            }
        }
    }
    // The 6-side view: the cube spans a small part of the image.
    let (far, _) = &cams[3];
    let rect = far.cube_pixels(&far.frame().unwrap(), &c);
    assert!(rect.x.len() * rect.y.len() * 8 < 64 * 48, "{rect:?}");
}

/// The hybrid walk skips rays that miss the mesh's bounding box widened by the largest voxel
/// its footprint allows. Its premise: an occupied cell of side `v_w` lies within `v_w` of the
/// box. And voxels do reach past the box: in a far view some rays that miss it hit voxels,
/// which a walk culling at the unwidened box would lose.
#[test]
fn hybrid_voxels_reach_past_the_mesh_bounds() {
    let mesh = scenes::blob(6).unwrap();
    let (oct, _) = build(&mesh, &params(9, true)).unwrap();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &mesh.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let c = oct.cube;
    for level in 0..=9u8 {
        let vw = c.cell_size(level);
        for cell in oct.occupancy(level) {
            for k in 0..3 {
                let a = c.min[k] + f64::from(cell[k]) * vw;
                assert!(
                    a >= lo[k] - vw * (1.0 + 1e-9) && a + vw <= hi[k] + vw * (1.0 + 1e-9),
                    "level {level} cell {cell:?} axis {k}"
                );
            }
        }
    }
    // A flat square: its bounding box has no thickness, and the cells along its far edge
    // stand above the plane, where rays that miss the square's box still pass.
    let (square, _) = scenes::exact_square().unwrap();
    let (oct, _) = build(&square, &params(9, false)).unwrap();
    let (lo, hi) = ([0.0, 0.0, 1.0 / 3.0], [1.0, 1.0, 1.0 / 3.0]);
    let far = orbit_camera(&oct, 6.0 * oct.cube.size as f32, 256);
    let fp = far.footprint();
    let gen = far.ray_gen(&far.frame().unwrap());
    let mut outside = 0;
    for y in 0..256 {
        for x in 0..256 {
            let r = gen.ray(x, y);
            let Some(h) = oct.intersect(&r, &TraceMode::HYBRID, Some(fp)) else {
                continue;
            };
            if !meets_box(r.origin, r.dir, lo, hi) {
                assert!(matches!(h.kind, HitKind::Voxel { .. }));
                outside += 1;
            }
        }
    }
    assert!(
        outside > 0,
        "no voxel hit on a ray that misses the mesh bounds"
    );
}

/// Check 6: a constant-colour plane gives that colour (+-1/255) and the plane's normal (within
/// 1e-3) at every level; a two-sided slab (opposite normals in one cell) gives no NaN.
#[test]
fn voxel_attributes_of_a_plane_and_a_slab() {
    let col = [0.2f32, 0.6, 0.9];
    let tilt = [0.3f64, -0.2, 1.0];
    let pl = TriMesh::grid(16, 16, 1.0, 1.0).unwrap();
    let positions: Vec<[f64; 3]> = pl
        .positions
        .iter()
        .map(|p| {
            [
                p[0],
                p[1],
                0.4 + tilt[0] * p[0] * 0.3 + tilt[1] * p[1] * 0.3,
            ]
        })
        .collect();
    let mesh = TriMesh::new(positions, pl.faces.clone())
        .unwrap()
        .with_colors(vec![col; pl.positions.len()])
        .unwrap();
    let n = mesh.face_normals()[0];
    let (oct, _) = build(&mesh, &params(7, false)).unwrap();
    for v in &oct.voxels {
        let c = v.color();
        for k in 0..3 {
            assert!((c[k] - col[k]).abs() <= 1.0 / 255.0 + 1e-6, "{c:?}");
        }
        let vn = v.normal();
        let dot: f64 = (0..3).map(|k| f64::from(vn[k]) * n[k]).sum();
        assert!(
            dot.clamp(-1.0, 1.0).acos() <= 1e-3,
            "normal off by {}",
            dot.acos()
        );
    }
    // Slab: two parallel faces 1e-4 apart with opposite orientation.
    let z = 0.5;
    let slab = TriMesh::new(
        vec![
            [0.0, 0.0, z],
            [1.0, 0.0, z],
            [1.0, 1.0, z],
            [0.0, 1.0, z],
            [0.0, 0.0, z + 1e-4],
            [1.0, 0.0, z + 1e-4],
            [1.0, 1.0, z + 1e-4],
            [0.0, 1.0, z + 1e-4],
        ],
        vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]],
    )
    .unwrap();
    let (oct, _) = build(&slab, &params(6, false)).unwrap();
    assert!(oct
        .voxels
        .iter()
        .all(|v| v.normal().iter().all(|x| x.is_finite())));
}

/// A saved tree reloads bit-identically; damaged files are errors.
#[test]
fn file_round_trip_and_corruption() {
    let mesh = scenes::blob(3).unwrap();
    let (oct, _) = build(&mesh, &params(6, true)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("t.bin");
    oct.save(&p).unwrap();
    let back = HybridOctree::load(&p).unwrap();
    assert_eq!(back, oct);
    assert_eq!(back.to_bytes(), std::fs::read(&p).unwrap());
    let bytes = std::fs::read(&p).unwrap();
    let origin = std::path::Path::new("t.bin");
    for cut in [0, 7, 20, bytes.len() / 2, bytes.len() - 1] {
        assert!(HybridOctree::from_bytes(&bytes[..cut], origin).is_err());
    }
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 3] ^= 0x10;
    let e = HybridOctree::from_bytes(&flipped, origin).unwrap_err();
    assert!(e.to_string().contains("checksum"), "{e}");
    assert!(HybridOctree::load(dir.path().join("missing.bin"))
        .unwrap_err()
        .is_io());
}

/// Bad input is an error naming the problem, never a panic.
#[test]
fn bad_input_is_rejected() {
    let ok = scenes::blob(1).unwrap();
    assert!(build(&TriMesh::default(), &BuildParams::default()).is_err());
    let mut bad = ok.clone();
    bad.faces[3][1] = 10_000;
    assert!(build(&bad, &BuildParams::default())
        .unwrap_err()
        .to_string()
        .contains("faces"));
    let mut bad = ok.clone();
    bad.positions[2][0] = f64::NAN;
    assert!(build(&bad, &BuildParams::default())
        .unwrap_err()
        .to_string()
        .contains("non-finite"));
    let mut bad = ok.clone();
    bad.colors = Some(vec![[0.5; 3]; 3]);
    assert!(build(&bad, &BuildParams::default()).is_err());
    assert!(build(&ok, &params(22, true))
        .unwrap_err()
        .to_string()
        .contains("max_depth"));
    // Index overflow: 10-bit node words cannot hold the full tree of this mesh.
    let e = build(&ok, &params(8, false).index_bits(10)).unwrap_err();
    assert!(matches!(e, wscg_math::Error::LimitExceeded(_)), "{e}");
    let small = Cube::new([0.0; 3], 0.1).unwrap();
    assert!(build(&ok, &BuildParams::default().domain(Some(small))).is_err());
    // All-degenerate mesh.
    let flat = TriMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        vec![[0, 1, 2]],
    )
    .unwrap();
    assert!(build(&flat, &BuildParams::default()).is_err());
    // Zero-length and NaN ray directions miss.
    let (oct, _) = build(&ok, &params(5, true)).unwrap();
    assert!(oct
        .intersect(&Ray::new([0.0; 3], [0.0; 3]), &TraceMode::Triangles, None)
        .is_none());
    assert!(oct
        .intersect(
            &Ray::new([0.0; 3], [f32::NAN, 0.0, 1.0]),
            &TraceMode::HYBRID,
            None
        )
        .is_none());
    // A camera looking along its up vector.
    let cam = Camera {
        eye: [0.0, 0.0, 2.0],
        target: [0.0; 3],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 40.0,
        width: 8,
        height: 8,
    };
    let light = PointLight {
        position: [1.0; 3],
        intensity: 1.0,
    };
    assert!(render(
        &oct,
        &cam,
        &light,
        &TraceMode::Triangles,
        &Shading::default()
    )
    .is_err());
}

/// Hit counts by kind on a voxel-only render of the full tree: every hit is a voxel.
#[test]
fn voxel_mode_returns_voxels_at_the_requested_level() {
    let mesh = scenes::blob(4).unwrap();
    let (oct, _) = build(&mesh, &params(7, false)).unwrap();
    let rays = random_rays(&oct.cube, 4096, 9);
    let mut levels: HashMap<u8, usize> = HashMap::new();
    for r in &rays {
        if let Some(h) = oct.intersect(r, &TraceMode::Voxels { level: Some(4) }, None) {
            let HitKind::Voxel { level, .. } = h.kind else {
                panic!("triangle hit in voxel mode")
            };
            *levels.entry(level).or_default() += 1;
        }
    }
    assert_eq!(levels.keys().copied().collect::<Vec<_>>(), vec![4]);
    // Voxel hits of the finest level lie no later than the exact triangle hit.
    for r in &rays {
        if let (Some(v), Some(t)) = (
            oct.intersect(r, &TraceMode::VOXELS, None),
            oct.intersect(r, &TraceMode::Triangles, None),
        ) {
            assert!(v.t <= t.t + 1e-5);
        }
    }
}

/// `cast` finds what `intersect` finds (ray parameter, triangle and barycentrics, or voxel,
/// level and blend weight) in every mode, with and without a footprint: it only leaves out the
/// normal and the colour.
#[test]
fn cast_equals_intersect_without_shading() {
    let mesh = scenes::blob(4).unwrap();
    let (oct, _) = build(&mesh, &params(8, true)).unwrap();
    let rays = random_rays(&oct.cube, 1 << 14, 21);
    let fp = Footprint {
        width0: 0.0,
        spread: 0.004,
    };
    let modes = [
        TraceMode::Triangles,
        TraceMode::HYBRID,
        TraceMode::VOXELS,
        TraceMode::Voxels { level: Some(5) },
    ];
    for mode in &modes {
        for footprint in [None, Some(fp)] {
            let (mut tris, mut voxels, mut blended) = (0, 0, 0);
            for r in &rays {
                let full = oct.intersect(r, mode, footprint);
                let cast = oct.cast(r, mode, footprint);
                assert_eq!(full.map(|h| (h.t, h.kind)), cast, "{mode:?} {footprint:?}");
                match cast {
                    Some((_, HitKind::Triangle { .. })) => tris += 1,
                    Some((_, HitKind::Voxel { blend, .. })) => {
                        voxels += 1;
                        blended += usize::from(blend > 0.0 && blend < 1.0);
                    }
                    None => {}
                }
            }
            // Every answer kind is exercised: the hybrid mode with a footprint stops at
            // voxels (some with a blend between two levels) and at triangles.
            if matches!(mode, TraceMode::Hybrid { .. }) && footprint.is_some() {
                assert!(
                    tris > 100 && voxels > 100 && blended > 10,
                    "hybrid: {tris} triangle hits, {voxels} voxel hits, {blended} blended"
                );
            }
        }
    }
}

/// The display-wall application: triangles inside the focus ellipse, the LoD scale doubling
/// every `falloff` pixels outside it.
#[test]
fn focus_ellipse_selects_triangles_inside_and_coarsens_outside() {
    let f = wscg_octree::Focus {
        centre: [100.0, 50.0],
        radii: [40.0, 20.0],
        falloff: 10.0,
    };
    assert_eq!(f.mode_at(&TraceMode::HYBRID, 100, 50), TraceMode::Triangles);
    assert_eq!(f.mode_at(&TraceMode::HYBRID, 139, 50), TraceMode::Triangles);
    // About 20.5 px right of the ellipse's edge along the major axis: scale 2^(20.5 / 10).
    let TraceMode::Hybrid { lod_scale, .. } = f.mode_at(&TraceMode::HYBRID, 160, 49) else {
        panic!()
    };
    assert!((lod_scale - 2f32.powf(2.05)).abs() < 0.01, "{lod_scale}");
    assert_eq!(
        f.mode_at(&TraceMode::Triangles, 160, 49),
        TraceMode::Triangles
    );
    // Rendering with a focus: the ellipse's pixels are triangle hits, the rest mostly voxels.
    let mesh = scenes::blob(6).unwrap();
    let (oct, _) = build(&mesh, &params(9, true)).unwrap();
    let cam = orbit_camera(&oct, 1.2 * oct.cube.size as f32, 128);
    let focus = wscg_octree::Focus {
        centre: [64.0, 64.0],
        radii: [12.0, 12.0],
        falloff: 4.0,
    };
    let map = wscg_octree::lod_map(&oct, &cam, &TraceMode::HYBRID, Some(&focus)).unwrap();
    let grey = |y: usize, x: usize| (0..3).all(|c| (map.at(y, x, c) - 0.85).abs() < 1e-6);
    assert!(grey(64, 64) && grey(60, 70));
    let outside = (0..128)
        .flat_map(|y| (0..128).map(move |x| (y, x)))
        .filter(|&(y, x)| {
            let d = ((x as f32 - 64.0).powi(2) + (y as f32 - 64.0).powi(2)).sqrt();
            d > 40.0 && map.pixel(y, x).iter().any(|v| *v > 0.0)
        });
    let (mut hits, mut voxels) = (0, 0);
    for (y, x) in outside {
        hits += 1;
        voxels += usize::from(!grey(y, x));
    }
    assert!(
        hits > 100 && voxels as f64 >= 0.9 * hits as f64,
        "{voxels} of {hits}"
    );
    let light = PointLight {
        position: [2.0, -3.0, 4.0],
        intensity: 1.0,
    };
    let bad = Shading {
        focus: Some(wscg_octree::Focus {
            radii: [0.0, 1.0],
            ..focus
        }),
        ..Default::default()
    };
    assert!(render(&oct, &cam, &light, &TraceMode::HYBRID, &bad).is_err());
}

/// Ambient occlusion: nothing occludes the upper side of a lone plane (the image is unchanged);
/// an inside corner darkens.
#[test]
fn ambient_occlusion_is_one_on_a_plane_and_darkens_a_corner() {
    let plane = TriMesh::grid(8, 8, 1.0, 1.0).unwrap();
    let lift: Vec<[f64; 3]> = plane.positions.iter().map(|p| [p[0], p[1], 0.3]).collect();
    let plane = TriMesh::new(lift, plane.faces.clone()).unwrap();
    let (oct, _) = build(&plane, &params(7, true)).unwrap();
    let cam = Camera {
        eye: [0.5, 0.5, 2.0],
        target: [0.5, 0.5, 0.3],
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 30.0,
        width: 48,
        height: 48,
    };
    let light = PointLight {
        position: [0.2, 0.4, 3.0],
        intensity: 1.0,
    };
    let plain = Shading::default();
    let ao = Shading {
        ao_samples: 8,
        ao_radius: 0.2,
        ..Default::default()
    };
    let (a, _) = render(&oct, &cam, &light, &TraceMode::Triangles, &plain).unwrap();
    let (b, _) = render(&oct, &cam, &light, &TraceMode::Triangles, &ao).unwrap();
    assert_eq!(a.data(), b.data());
    // Floor and two walls meeting in a corner.
    let mut s = scenes::SceneBuilder::default();
    let c = [0.8; 3];
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        4,
        4,
        c,
    );
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 1.0],
            [0.0, 0.0, 1.0],
        ],
        4,
        4,
        c,
    );
    s.quad(
        [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
        ],
        4,
        4,
        c,
    );
    let corner = s.finish().unwrap();
    let (oct, _) = build(&corner, &params(7, true)).unwrap();
    let cam = Camera {
        eye: [1.5, 1.5, 1.2],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 20.0,
        width: 48,
        height: 48,
    };
    let only_ambient = |n| Shading {
        ka: 1.0,
        kd: 0.0,
        ks: 0.0,
        shadows: false,
        ao_samples: n,
        ao_radius: 0.3,
        ..Default::default()
    };
    let (a, _) = render(&oct, &cam, &light, &TraceMode::Triangles, &only_ambient(0)).unwrap();
    let (b, _) = render(&oct, &cam, &light, &TraceMode::Triangles, &only_ambient(32)).unwrap();
    // The pixel looking into the corner loses a large part of its ambient light.
    let centre = (24, 24);
    let ratio = b.at(centre.0, centre.1, 0) / a.at(centre.0, centre.1, 0);
    assert!(ratio < 0.6, "corner ambient kept {ratio}");
    assert!(b.data().iter().zip(a.data()).all(|(x, y)| x <= y));
}
