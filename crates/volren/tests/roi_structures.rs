//! Acceptance checks 1-6 of paper 03 (hybrid ROI visualisation) on the server's data
//! structures: octree addressing, the lossless 1-bit-per-node structure, edge-voxel and ROI
//! counts against independent counts, the wavelet round trip and resolutions.

use std::collections::HashSet;

use wscg_math::Volume;
use wscg_volren::gradient_octree::{cube_side, lookup, octree_address, EdgeRule};
use wscg_volren::normal_code::decode_voxel;
use wscg_volren::wavelet::{
    decode_lowres, encode_blocks, forward_block, inverse_block, pool, preprocess, HaarQuant,
};
use wscg_volren::{GoStructure, GradientOctree, MaterialTable, PiecewiseTransferFunction, Roi};

fn ramp(lo: f32, hi: f32) -> PiecewiseTransferFunction {
    PiecewiseTransferFunction::new(vec![(lo, [1.0, 1.0, 1.0, 0.0]), (hi, [1.0, 1.0, 1.0, 0.8])])
        .unwrap()
}

/// Overlapping balls of densities 60, 120, 200 and 250 in a non-cubic volume, with noise.
fn blobs(dims: [usize; 3]) -> Volume<u8> {
    let u = wscg_math::rng::uniform_vec(11, dims[0] * dims[1] * dims[2], -6.0, 6.0).unwrap();
    let balls = [
        ([0.4, 0.5, 0.5], 0.3, 60.0),
        ([0.6, 0.45, 0.5], 0.2, 120.0),
        ([0.3, 0.6, 0.4], 0.12, 200.0),
        ([0.7, 0.3, 0.6], 0.08, 250.0),
    ];
    Volume::from_fn(dims, [1.0; 3], |x, y, z| {
        let p = [
            x as f64 / dims[0] as f64,
            y as f64 / dims[1] as f64,
            z as f64 / dims[2] as f64,
        ];
        let mut d = 10.0;
        for (c, r, v) in balls {
            let q: f64 = (0..3).map(|a| (p[a] - c[a]).powi(2)).sum();
            if q < r * r {
                d = v;
            }
        }
        (d + u[x + dims[0] * (y + dims[1] * z)]).clamp(0.0, 255.0) as u8
    })
    .unwrap()
}

fn two_tfs() -> Vec<PiecewiseTransferFunction> {
    let soft = PiecewiseTransferFunction::new(vec![
        (40.0, [1.0, 0.6, 0.5, 0.0]),
        (70.0, [1.0, 0.6, 0.5, 0.1]),
        (140.0, [1.0, 0.6, 0.5, 0.1]),
        (150.0, [1.0, 0.6, 0.5, 0.0]),
    ])
    .unwrap();
    vec![soft, ramp(180.0, 255.0)]
}

/// Edge voxels by an independent brute-force test on the material volume.
fn edge_set(v: &Volume<u8>, mats: &MaterialTable) -> HashSet<[u32; 3]> {
    let d = v.dims();
    let m = |x: isize, y: isize, z: isize| -> u8 {
        if x < 0 || y < 0 || z < 0 || x >= d[0] as isize || y >= d[1] as isize || z >= d[2] as isize
        {
            0
        } else {
            mats.material(v.at(x as usize, y as usize, z as usize))
        }
    };
    let mut s = HashSet::new();
    for z in 0..d[2] as isize {
        for y in 0..d[1] as isize {
            for x in 0..d[0] as isize {
                let c = m(x, y, z);
                let nb = [
                    m(x - 1, y, z),
                    m(x + 1, y, z),
                    m(x, y - 1, z),
                    m(x, y + 1, z),
                    m(x, y, z - 1),
                    m(x, y, z + 1),
                ];
                if c != 0 && nb.iter().any(|&n| n != c) {
                    s.insert([x as u32, y as u32, z as u32]);
                }
            }
        }
    }
    s
}

#[test]
fn addressing_matches_the_paper_example() {
    // Check 1: the paper's example for R = 512.
    let (cell, slots) = octree_address([171, 312, 237], 512);
    assert_eq!(cell, [10, 19, 14]);
    assert_eq!(slots, vec![7, 1, 4, 5]);
    // A lookup of a stored voxel reads 6 arrays at R = 512 and 5 at R = 256.
    for (len, r, reads) in [(320, 512, 6), (200, 256, 5)] {
        let v = Volume::from_fn([len, 24, 24], [1.0; 3], |x, y, z| {
            let q =
                (x as f64 - 150.0).powi(2) + (y as f64 - 12.0).powi(2) + (z as f64 - 12.0).powi(2);
            if q < 64.0 {
                200u8
            } else {
                0
            }
        })
        .unwrap();
        let mats = MaterialTable::from_tfs(&[ramp(150.0, 200.0)]).unwrap();
        let go = GradientOctree::build(&v, &mats, EdgeRule::Boundary).unwrap();
        assert_eq!(go.structure.r, r);
        let (leaf, n) = go.structure.leaf([143, 12, 12]);
        assert!(leaf != 0);
        assert_eq!(n, reads, "R = {r}");
    }
}

#[test]
fn structure_is_rebuilt_losslessly_and_lookup_is_exact() {
    // Check 2 on a non-cubic noisy volume (R = 128).
    let v = blobs([100, 90, 70]);
    let mats = MaterialTable::from_tfs(&two_tfs()).unwrap();
    let go = GradientOctree::build(&v, &mats, EdgeRule::Boundary).unwrap();
    let s = &go.structure;
    assert_eq!(s.r, cube_side([100, 90, 70]));
    let (bits, b) = s.occupancy();
    let rebuilt = GoStructure::from_occupancy(s.r, &bits, &b).unwrap();
    assert_eq!(
        &rebuilt, s,
        "client rebuild differs from the server's structure"
    );
    let counts = s.node_counts();
    assert_eq!(
        b.iter().map(Vec::len).sum::<usize>(),
        counts[..counts.len() - 1].iter().sum::<usize>()
    );
    // n_l against an independent count of grey (R/l)^3 blocks.
    let edges = edge_set(&v, &mats);
    assert!(edges.len() > 1000);
    let depth = s.depth();
    for (t, &n) in counts.iter().enumerate() {
        let shift = depth - t;
        let blocks: HashSet<[u32; 3]> = edges.iter().map(|p| p.map(|c| c >> shift)).collect();
        assert_eq!(n, blocks.len(), "level {}", 32 << t);
    }
    assert_eq!(go.leaves.len() - 1, edges.len());
    // Exhaustive lookup over the cube: stored iff an edge voxel, with its material.
    for z in 0..s.r as u32 {
        for y in 0..s.r as u32 {
            for x in 0..s.r as u32 {
                let p = [x, y, z];
                let got = go.lookup(p);
                assert_eq!(got.is_some(), edges.contains(&p), "{p:?}");
                if let Some(code) = got {
                    let m = mats.material(v.at(x as usize, y as usize, z as usize));
                    assert_eq!(decode_voxel(code).0, m);
                }
            }
        }
    }
}

#[test]
fn sphere_edge_voxels_match_the_morphological_boundary() {
    // Check 3: binary sphere of radius 40 in 128^3, one TF opaque above 150.
    let n = 128;
    let inside = |x: isize, y: isize, z: isize| {
        let c = 63.5;
        (x as f64 - c).powi(2) + (y as f64 - c).powi(2) + (z as f64 - c).powi(2) <= 1600.0
    };
    let v = Volume::from_fn([n; 3], [1.0; 3], |x, y, z| {
        if inside(x as isize, y as isize, z as isize) {
            200u8
        } else {
            0
        }
    })
    .unwrap();
    let tf = PiecewiseTransferFunction::new(vec![(150.0, [1.0, 1.0, 1.0, 0.0]), (151.0, [1.0; 4])])
        .unwrap();
    let mats = MaterialTable::from_tfs(&[tf]).unwrap();
    let go = GradientOctree::build(&v, &mats, EdgeRule::Boundary).unwrap();
    // mask & ~erosion(mask, 6-connectivity, border 0).
    let mut boundary = 0usize;
    for z in 0..n as isize {
        for y in 0..n as isize {
            for x in 0..n as isize {
                let nb = [
                    (x - 1, y, z),
                    (x + 1, y, z),
                    (x, y - 1, z),
                    (x, y + 1, z),
                    (x, y, z - 1),
                    (x, y, z + 1),
                ];
                if inside(x, y, z) && nb.iter().any(|&(a, b, c)| !inside(a, b, c)) {
                    boundary += 1;
                }
            }
        }
    }
    assert_eq!(go.leaves.len() - 1, boundary);
    // Normals point along the radius (density decreases outwards: -radial).
    let (_, nrm) = decode_voxel(go.lookup([103, 64, 64]).unwrap());
    assert!(nrm[0] < -0.95, "{nrm:?}");
}

#[test]
fn roi_restriction_keeps_exactly_the_roi_leaves() {
    // Check 4: 20 random ROIs.
    let v = blobs([100, 90, 70]);
    let mats = MaterialTable::from_tfs(&two_tfs()).unwrap();
    let go = GradientOctree::build(&v, &mats, EdgeRule::Boundary).unwrap();
    let edges = edge_set(&v, &mats);
    let r = wscg_math::rng::uniform_vec(12, 120, 0.0, 1.0).unwrap();
    for k in 0..20 {
        let q = &r[6 * k..6 * k + 6];
        let dims = [100u32, 90, 70];
        let a: [u32; 3] = std::array::from_fn(|i| (q[i] * dims[i] as f64) as u32);
        let b: [u32; 3] =
            std::array::from_fn(|i| (a[i] + 1 + (q[i + 3] * 60.0) as u32).min(dims[i]));
        let roi = Roi::snapped(a, b, [100, 90, 70]).unwrap();
        let (rs, full) = go.structure.restrict(&roi);
        let d_r = go.roi_leaves(&roi);
        let expected = edges.iter().filter(|p| roi.contains(**p)).count();
        assert_eq!(d_r.len(), expected, "ROI {roi:?}");
        assert_eq!(full.len(), rs.leaves());
        let mut leaves = vec![[0u8; 3]];
        leaves.extend(&d_r);
        for z in (0..90).step_by(3) {
            for y in 0..90 {
                for x in 0..100 {
                    let p = [x, y, z];
                    let got = lookup(&rs, &leaves, p);
                    if roi.contains(p) {
                        assert_eq!(got, go.lookup(p), "{p:?} in {roi:?}");
                    } else {
                        assert_eq!(got, None, "{p:?} outside {roi:?}");
                    }
                }
            }
        }
    }
    // A ROI outside the volume or inverted is an error.
    assert!(Roi::snapped([120, 0, 0], [130, 10, 10], [100, 90, 70]).is_err());
    assert!(Roi::snapped([10, 10, 10], [5, 20, 20], [100, 90, 70]).is_err());
}

#[test]
fn wavelet_round_trip_pooling_and_resolutions() {
    // Check 5.
    let v = blobs([70, 50, 40]);
    let tfs = two_tfs();
    let pre = preprocess(&v, &tfs[0]).unwrap();
    assert_eq!(pre.dims(), [80, 64, 48]);
    let mut worst = 0.0f32;
    let mut worst_pool = 0.0f32;
    for b in 0..5 * 4 * 3 {
        let (bx, by, bz) = (b % 5, b / 5 % 4, b / 20);
        let mut blk = vec![0.0f32; 4096];
        for z in 0..16 {
            for y in 0..16 {
                for x in 0..16 {
                    blk[x + 16 * (y + 16 * z)] = pre.at(bx * 16 + x, by * 16 + y, bz * 16 + z);
                }
            }
        }
        let c = forward_block(&blk);
        let back = inverse_block(&c, 4);
        worst = back
            .iter()
            .zip(&blk)
            .map(|(a, b)| (a - b).abs())
            .fold(worst, f32::max);
        let low = inverse_block(&c, 2);
        worst_pool = low
            .iter()
            .zip(&pool(&blk, 16, 4))
            .map(|(a, b)| (a - b).abs())
            .fold(worst_pool, f32::max);
    }
    assert!(worst <= 1e-4, "round trip {worst}");
    assert!(worst_pool <= 1e-4, "pooling {worst_pool}");
    // Resolutions of the decoded volume: dims / 8, / 4, / 2, / 1 (of the padded size).
    let p = encode_blocks(&v, &tfs[0], &HaarQuant::default(), 4).unwrap();
    for w in 1..=4u8 {
        let low = decode_lowres(&p, w).unwrap();
        assert_eq!(low.dims(), [80, 64, 48].map(|d| d >> (4 - w)));
    }
    // Quantised V_W against pooling of the pre-processed volume: bounded by the quantisation
    // (root rounding 0.5, 7 details of error <= delta / 2 = 1 per step).
    let p2 = encode_blocks(&v, &tfs[0], &HaarQuant::default(), 2).unwrap();
    let low = decode_lowres(&p2, 2).unwrap();
    let mut err = 0.0f32;
    for z in 0..12 {
        for y in 0..16 {
            for x in 0..20 {
                let mut m = 0.0;
                for dz in 0..4 {
                    for dy in 0..4 {
                        for dx in 0..4 {
                            m += pre.at(4 * x + dx, 4 * y + dy, 4 * z + dz);
                        }
                    }
                }
                err = err.max((low.at(x, y, z) - m / 64.0).abs());
            }
        }
    }
    assert!(err <= 14.5, "{err}");
    // V_W (w = 2) costs under 1.6 % of the raw volume.
    assert!(
        p2.blocks.len() as f64 <= 0.016 * (70 * 50 * 40) as f64,
        "{}",
        p2.blocks.len()
    );
    // Bad input: w outside 1..=4, more steps than sent, truncated or corrupted streams.
    assert!(encode_blocks(&v, &tfs[0], &HaarQuant::default(), 0).is_err());
    assert!(encode_blocks(&v, &tfs[0], &HaarQuant::default(), 5).is_err());
    assert!(decode_lowres(&p2, 3).is_err());
    let mut cut = p2.clone();
    cut.blocks.truncate(cut.blocks.len() - 1);
    assert!(decode_lowres(&cut, 2).is_err());
    let mut bad = p2.clone();
    bad.blocks[0] = 9;
    assert!(decode_lowres(&bad, 2).is_err());
    let mut long = p2;
    long.blocks.push(0);
    assert!(decode_lowres(&long, 2).is_err());
}

#[test]
fn phantom_packages_and_sizes() {
    // Check 5 (size) and the first part of check 9 on the head phantom at the paper's size.
    use wscg_volren::phantoms::{head, head_tfs};
    let v = head([256, 256, 112], 1).unwrap();
    let tfs = head_tfs();
    let raw = v.len();
    let low = encode_blocks(&v, &tfs[0], &HaarQuant::default(), 2).unwrap();
    let mats = MaterialTable::from_tfs(&tfs).unwrap();
    let go = GradientOctree::build(&v, &mats, EdgeRule::Boundary).unwrap();
    let (bits, b) = go.structure.occupancy();
    let structure = bits.len() + b.iter().map(Vec::len).sum::<usize>();
    let leaves = 3 * (go.leaves.len() - 1);
    println!(
        "head {raw} B: V_W {} B ({:.2} %), octree structure {structure} B, leaves {leaves} B \
         ({:.1} % of raw)",
        low.blocks.len(),
        100.0 * low.blocks.len() as f64 / raw as f64,
        100.0 * (structure + leaves) as f64 / raw as f64
    );
    assert!(low.blocks.len() as f64 <= 0.016 * raw as f64);
    assert!(structure + leaves < raw);
}

/// Check 2 on the phantoms: exhaustive on the head (256 x 256 x 112), 10^6 random voxels of
/// the thorax (256^3): stored iff an edge voxel, with its material, and the client's rebuild
/// equals the server's structure.
#[test]
fn phantom_lookups_are_exact() {
    use wscg_volren::phantoms::{head, head_tfs, thorax, thorax_tfs};
    for (v, tfs, exhaustive) in [
        (head([256, 256, 112], 1).unwrap(), head_tfs(), true),
        (thorax([256; 3], 2).unwrap(), thorax_tfs(), false),
    ] {
        let mats = MaterialTable::from_tfs(&tfs).unwrap();
        let go = GradientOctree::build(&v, &mats, EdgeRule::Boundary).unwrap();
        let (bits, b) = go.structure.occupancy();
        assert_eq!(
            GoStructure::from_occupancy(go.structure.r, &bits, &b).unwrap(),
            go.structure
        );
        let edges = edge_set(&v, &mats);
        assert_eq!(go.leaves.len() - 1, edges.len());
        let r = go.structure.r as u32;
        let check = |p: [u32; 3]| {
            let got = go.lookup(p);
            assert_eq!(got.is_some(), edges.contains(&p), "{p:?}");
            if let Some(code) = got {
                let m = mats.material(v.at(p[0] as usize, p[1] as usize, p[2] as usize));
                assert_eq!(decode_voxel(code).0, m, "{p:?}");
            }
        };
        if exhaustive {
            for z in 0..r {
                for y in 0..r {
                    for x in 0..r {
                        check([x, y, z]);
                    }
                }
            }
        } else {
            let u = wscg_math::rng::uniform_vec(13, 3_000_000, 0.0, r as f64).unwrap();
            for q in u.chunks(3) {
                check([q[0] as u32, q[1] as u32, q[2] as u32]);
            }
        }
    }
}
