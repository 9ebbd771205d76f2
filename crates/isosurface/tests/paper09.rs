//! Acceptance checks of paper 09: Wood and Newman, isosurface orientation in
//! sparse grids with tetrahedral splines.

use std::collections::HashMap;

use wscg_math::VolumeView;

use wscg_isosurface::fields::{self, Field, Linear, Sphere, Torus};
use wscg_isosurface::study::{
    at_risk_configurations, compare_with_exact, compare_with_full_cd, config_divergence,
};
use wscg_isosurface::tables::number_of_rotation_classes;
use wscg_isosurface::{
    angular_errors, estimate_normals, marching_cubes, random_dropouts, rms,
    sparsify_for_isosurface, AmbiguousRule, IsoMesh, NormalMethod, ScalarGrid, SplineParams,
    TetSelection,
};

const CENTRE: [f64; 3] = [31.37, 32.21, 30.83];

fn sphere() -> fields::Sampled {
    fields::sample_voxels(
        &Sphere {
            centre: CENTRE,
            radius: 20.0,
        },
        [64; 3],
    )
    .unwrap()
}

fn torus_field() -> Torus {
    Torus {
        centre: CENTRE,
        major: 16.0,
        minor: 6.0,
    }
}

fn sparse_grid<'a>(values: &'a [f32], sides: &'a [u8], dims: [usize; 3]) -> ScalarGrid<'a> {
    ScalarGrid::new(dims, values)
        .unwrap()
        .with_side_hint(sides)
        .unwrap()
}

/// Every mesh edge shared by exactly two triangles (closed, no cracks) and the Euler
/// characteristic V - E + F.
fn closed_euler(mesh: &IsoMesh) -> (bool, i64) {
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &mesh.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let closed = edges.values().all(|&c| c == 2);
    let chi = mesh.vertices.len() as i64 - edges.len() as i64 + mesh.triangles.len() as i64;
    (closed, chi)
}

#[test]
fn check1_linear_fields_are_exact() {
    let a = [0.3, 0.5, 0.7];
    let f = Linear { a, b: 0.01 };
    let s = fields::sample_voxels(&f, [32; 3]).unwrap();
    let norm = (0.3f64 * 0.3 + 0.25 + 0.49).sqrt();
    let exact = a.map(|x| (x / norm) as f32);
    let g = s.grid().unwrap();
    // Five random isovalues inside the field's range (0.01 .. 46.5).
    let isos = wscg_math::rng::uniform_vec(9, 5, 3.0, 43.0).unwrap();
    for iso in isos.into_iter().map(|x| x as f32) {
        let (sparse, sides) = sparsify_for_isosurface(s.view(), iso).unwrap();
        let sparse = sparse.into_data();
        let sg = sparse_grid(&sparse, &sides, s.dims);
        let mesh = marching_cubes(&g, iso, NormalMethod::CentralDifference).unwrap();
        assert!(mesh.vertices.len() > 100);
        let check = |name: &str, n: &[[f32; 3]]| {
            let e = angular_errors(n, &vec![exact; n.len()]).unwrap();
            let worst = e.iter().fold(
                0.0f32,
                |m, &x| if x.is_nan() { f32::INFINITY } else { m.max(x) },
            );
            assert!(
                worst <= 1e-5,
                "{name} at iso {iso}: worst error {worst} rad"
            );
        };
        check("central (full)", &mesh.normals);
        for (label, grid) in [("full", &g), ("sparse", &sg)] {
            // Every tetrahedron choice and averaging of the spline is exact on a linear field.
            for selection in [TetSelection::NearestCorner, TetSelection::AverageBoth] {
                for normalize_before_mean in [false, true] {
                    let o = NormalMethod::Spline(
                        SplineParams::default()
                            .selection(selection)
                            .eq8_literal(false)
                            .normalize_before_mean(normalize_before_mean),
                    );
                    let (n, _) = estimate_normals(grid, iso, &mesh.vertex_edge, o).unwrap();
                    check(&format!("{o:?} ({label})"), &n);
                }
            }
            let (sp, st) =
                estimate_normals(grid, iso, &mesh.vertex_edge, NormalMethod::spline()).unwrap();
            println!(
                "{label} iso {iso}: {} fallbacks of {}",
                st.fallback,
                sp.len()
            );
            check(&format!("spline ({label})"), &sp);
            let (l, _) =
                estimate_normals(grid, iso, &mesh.vertex_edge, NormalMethod::lsn()).unwrap();
            check(&format!("lsn ({label})"), &l);
        }
    }
}

#[test]
fn check2_sparsification_protocol_on_the_sphere() {
    let s = sphere();
    let full = s.grid().unwrap();
    let reference = marching_cubes(&full, 0.0, NormalMethod::CentralDifference).unwrap();
    let (sparse, sides) = sparsify_for_isosurface(s.view(), 0.0).unwrap();
    let sparse = sparse.into_data();
    assert!(sparse.iter().filter(|v| v.is_nan()).count() > sparse.len() * 9 / 10);
    let sg = sparse_grid(&sparse, &sides, s.dims);
    // The same mesh with side hints, and without them (sides inferred from neighbours).
    let hinted = marching_cubes(&sg, 0.0, NormalMethod::spline()).unwrap();
    let bare = ScalarGrid::new(s.dims, &sparse).unwrap();
    let inferred = marching_cubes(&bare, 0.0, NormalMethod::spline()).unwrap();
    for m in [&hinted, &inferred] {
        assert_eq!(m.vertices, reference.vertices);
        assert_eq!(m.triangles, reference.triangles);
        assert_eq!(m.stats.skipped_cells, 0);
        assert_eq!(
            m.stats.undefined, 0,
            "spline normals defined at every vertex"
        );
        assert_eq!(m.stats.fallback, 0);
    }
    let (_, cd) = estimate_normals(
        &sg,
        0.0,
        &hinted.vertex_edge,
        NormalMethod::CentralDifference,
    )
    .unwrap();
    let defined = 1.0 - cd.undefined as f64 / hinted.vertices.len() as f64;
    println!(
        "sphere: {} vertices, CD defined at {:.4}% on the sparse grid",
        hinted.vertices.len(),
        100.0 * defined
    );
    assert!(defined < 0.01, "CD defined at {defined}");
    // A closed genus-0 surface: no cracks, Euler characteristic 2.
    assert_eq!(closed_euler(&reference), (true, 2));
}

#[test]
fn check3_sphere_accuracy() {
    let s = sphere();
    let f = Sphere {
        centre: CENTRE,
        radius: 20.0,
    };
    let c = compare_with_exact(&f, &s, 0.0).unwrap();
    println!(
        "sphere vs exact ({} vertices): CD(full) {:.5}, spline {:.5}, LSN {:.5}",
        c.vertices, c.cd_full.rms, c.spline.rms, c.lsn.rms
    );
    assert!(c.cd_full.rms <= 0.001);
    assert!(c.spline.rms <= 0.015);
    assert!(c.lsn.rms <= 0.03);
    assert!(c.spline.rms < c.lsn.rms);
    assert_eq!(c.spline.undefined, 0);
}

#[test]
fn check4_torus_accuracy() {
    let f = torus_field();
    let s = fields::sample_voxels(&f, [64; 3]).unwrap();
    let c = compare_with_exact(&f, &s, 0.0).unwrap();
    println!(
        "torus vs exact ({} vertices): CD(full) {:.5}, spline {:.5}, LSN {:.5}",
        c.vertices, c.cd_full.rms, c.spline.rms, c.lsn.rms
    );
    assert!(c.spline.rms <= 0.04);
    assert!(c.lsn.rms <= 0.07);
    assert!(c.spline.rms < c.lsn.rms);
    let mesh = marching_cubes(&s.grid().unwrap(), 0.0, NormalMethod::None).unwrap();
    assert_eq!(
        closed_euler(&mesh),
        (true, 0),
        "a torus has Euler characteristic 0"
    );
}

#[test]
fn check5_degenerate_spike() {
    let dims = [9usize; 3];
    let mut v = vec![-1.0f32; 729];
    v[4 + 9 * (4 + 9 * 4)] = 0.0;
    let g = ScalarGrid::new(dims, &v).unwrap();
    let lsn = marching_cubes(&g, 0.0, NormalMethod::lsn()).unwrap();
    assert_eq!(lsn.vertices.len(), 6);
    assert!(lsn.vertices.iter().all(|p| *p == [4.0, 4.0, 4.0]));
    assert_eq!(lsn.stats.undefined, 6, "all LSN normals are zero");
    assert!(lsn.normals.iter().all(|n| *n == [0.0; 3]));
    let spline = marching_cubes(&g, 0.0, NormalMethod::spline()).unwrap();
    assert_eq!(spline.stats.undefined, 0);
    for (e, n) in spline.vertex_edge.iter().zip(&spline.normals) {
        let a = e.axis as usize;
        // The edge's outer end is the low end when the centre is its high end.
        let towards_centre = if e.point[a] == 3 { 1.0 } else { -1.0 };
        let mut want = [0.0f32; 3];
        want[a] = towards_centre;
        assert_eq!(*n, want, "edge {e:?}");
    }
    // Full-data central differences vanish at the spike too (t = 1 uses the centre's gradient).
    let cd = marching_cubes(&g, 0.0, NormalMethod::CentralDifference).unwrap();
    assert_eq!(cd.stats.undefined, 6);
}

#[test]
fn check5_noisy_8bit_sphere_table5_behaviour() {
    for (seed, iso) in [(11u64, 128.0f32), (12, 40.0)] {
        let s = fields::noisy_sphere_u8([64; 3], CENTRE, 20.0, 1.5, 3.0, seed).unwrap();
        let c = compare_with_full_cd(s.view(), iso).unwrap();
        let frac = c.lsn_undefined as f64 / c.vertices as f64;
        println!(
            "noisy sphere iso {iso}: {} vertices, LSN zero {} ({:.2}%), spline zero {}, RMS vs full CD spline {:.4} LSN {:.4}",
            c.vertices,
            c.lsn_undefined,
            100.0 * frac,
            c.spline_undefined,
            c.spline.rms,
            c.lsn.rms
        );
        assert!(c.lsn_undefined > 0 && frac <= 0.05);
        assert_eq!(c.spline_undefined, 0);
        assert!(c.spline.rms < c.lsn.rms);
    }
}

#[test]
fn check6_spline_normals_never_point_through_their_edge() {
    let ml = fields::sample(
        &fields::MarschnerLobb::default(),
        [41; 3],
        [-1.0; 3],
        [1.0; 3],
    )
    .unwrap();
    let noisy = fields::noisy_sphere_u8([48; 3], [23.4, 24.1, 22.8], 15.0, 1.5, 3.0, 5).unwrap();
    for (s, iso) in [(&ml, 0.5f32), (&noisy, 40.0), (&noisy, 128.0)] {
        let (sparse, sides) = sparsify_for_isosurface(s.view(), iso).unwrap();
        let sparse = sparse.into_data();
        let g = ScalarGrid::with_spacing(s.dims, s.spacing, &sparse)
            .unwrap()
            .with_side_hint(&sides)
            .unwrap();
        let m = marching_cubes(&g, iso, NormalMethod::spline()).unwrap();
        assert!(!m.vertices.is_empty());
        let violations = m
            .vertex_edge
            .iter()
            .zip(&m.normals)
            .filter(|(e, n)| {
                let (fp, fq) = (g.value(e.low()).unwrap(), g.value(e.high()).unwrap());
                n[e.axis as usize] * (fq - fp).signum() <= 0.0
            })
            .count();
        assert_eq!(violations, 0);
    }
}

#[test]
fn check7_case_analysis() {
    assert_eq!(number_of_rotation_classes(), 23);
    for rule in [AmbiguousRule::IsolateInside, AmbiguousRule::IsolateOutside] {
        let risk = at_risk_configurations(rule, std::f32::consts::FRAC_PI_2);
        let worst = (0..=255u8)
            .map(|c| config_divergence(c, rule))
            .fold(0.0f32, f32::max);
        println!(
            "{rule:?}: {} of 256 configurations at risk (paper: 146); largest divergence {worst:.3} rad",
            risk.len()
        );
        // One inside corner: the padded grid holds an inside octant. At the vertex (1.5, 1, 1)
        // central differences give (-1, -1/2, -1/2) and the four LSN perps sum to
        // -(9/4, 3/4, 3/4) (worked by hand); the other vertices are symmetric.
        let (a, b) = ([1.0f64, 0.5, 0.5], [2.25f64, 0.75, 0.75]);
        let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        let norm = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let want = (dot / (norm(&a) * norm(&b))).acos() as f32;
        assert!((config_divergence(1, rule) - want).abs() < 1e-5);
        assert!((config_divergence(254, rule) - want).abs() < 1e-5);
        // Empty configurations have no vertices.
        assert_eq!(config_divergence(0, rule), 0.0);
    }
}

#[test]
fn check8_random_dropouts() {
    let mut s = sphere();
    let f = Sphere {
        centre: CENTRE,
        radius: 20.0,
    };
    let removed = random_dropouts(&mut s.values, 0.1, 2015).unwrap();
    assert!((0.09..0.11).contains(&(removed as f64 / s.values.len() as f64)));
    let g = s.grid().unwrap();
    let m = marching_cubes(&g, 0.0, NormalMethod::spline()).unwrap();
    println!(
        "10% dropouts: {} vertices, {} cells skipped, {} fallbacks",
        m.vertices.len(),
        m.stats.skipped_cells,
        m.stats.fallback
    );
    assert!(m.stats.skipped_cells > 0);
    for e in &m.vertex_edge {
        assert!(g.value(e.low()).is_some() && g.value(e.high()).is_some());
    }
    assert_eq!(m.stats.undefined, 0);
    assert!(m.normals.iter().all(|n| *n != [0.0; 3]));
    let exact = s.exact_normals(&f, &m.vertices);
    let r = rms(&angular_errors(&m.normals, &exact).unwrap());
    println!("10% dropouts: spline RMS vs exact {:.5}", r.rms);
    assert!(r.rms <= 0.03);
}

#[test]
fn triangles_face_along_the_gradient() {
    let s = sphere();
    let f = Sphere {
        centre: CENTRE,
        radius: 20.0,
    };
    let m = marching_cubes(&s.grid().unwrap(), 0.0, NormalMethod::None).unwrap();
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.vertices[i as usize].map(|x| x as f64));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let centroid = [0, 1, 2].map(|i| (a[i] + b[i] + c[i]) / 3.0);
        let g = f.gradient(centroid);
        assert!(n[0] * g[0] + n[1] * g[1] + n[2] * g[2] >= 0.0);
    }
}

#[test]
fn anisotropic_spacing() {
    // The sphere sampled with unequal spacing: positions and normals are in world units.
    let f = Sphere {
        centre: [0.0; 3],
        radius: 0.8,
    };
    let s = fields::sample(&f, [40, 27, 57], [-1.0; 3], [1.0; 3]).unwrap();
    let c = compare_with_exact(&f, &s, 0.0).unwrap();
    println!(
        "anisotropic sphere: CD {:.4}, spline {:.4}, LSN {:.4}",
        c.cd_full.rms, c.spline.rms, c.lsn.rms
    );
    let m = marching_cubes(&s.grid().unwrap(), 0.0, NormalMethod::None).unwrap();
    for v in &m.vertices {
        let p = s.to_field(*v);
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        assert!((r - 0.8).abs() < 0.01, "vertex at radius {r}");
    }
    // Measured 0.0136 / 0.0265 / 0.0011; normals computed in index units instead of world
    // units are off by tenths of a radian on this grid.
    assert!(c.spline.rms < 0.02 && c.lsn.rms < 0.04 && c.cd_full.rms < 0.002);
}

#[test]
fn check10_bad_input() {
    let v = vec![0.0f32; 27];
    assert!(ScalarGrid::new([1, 3, 9], &v).is_err());
    assert!(ScalarGrid::new([3, 3, 4], &v).is_err());
    assert!(ScalarGrid::with_spacing([3; 3], [1.0, -1.0, 1.0], &v).is_err());
    assert!(ScalarGrid::with_spacing([3; 3], [1.0, f32::INFINITY, 1.0], &v).is_err());
    let g = ScalarGrid::new([3; 3], &v).unwrap();
    assert!(g.with_side_hint(&[0u8; 3]).is_err());
    assert!(marching_cubes(&g, f32::NAN, NormalMethod::spline()).is_err());
    assert!(
        sparsify_for_isosurface(VolumeView::new([3; 3], [1.0; 3], &v).unwrap(), f32::NAN).is_err()
    );
    // An isovalue outside the data range and an all-missing grid give empty meshes.
    let m = marching_cubes(&g, 5.0, NormalMethod::spline()).unwrap();
    assert!(m.vertices.is_empty() && m.triangles.is_empty());
    let nan = vec![f32::NAN; 27];
    let m = marching_cubes(
        &ScalarGrid::new([3; 3], &nan).unwrap(),
        0.0,
        NormalMethod::lsn(),
    )
    .unwrap();
    assert!(m.vertices.is_empty() && m.stats.skipped_cells == 0);
    // Normals of edges that do not cross are refused.
    let s = sphere();
    let m = marching_cubes(&s.grid().unwrap(), 0.0, NormalMethod::None).unwrap();
    assert!(estimate_normals(
        &s.grid().unwrap(),
        3.0,
        &m.vertex_edge,
        NormalMethod::spline()
    )
    .is_err());
    assert!(NormalMethod::parse("sobel").is_err());
}

#[test]
fn spline_normals_in_the_extraction_equal_the_per_vertex_route() {
    let ml = fields::sample(
        &fields::MarschnerLobb::default(),
        [41, 37, 45],
        [-1.0; 3],
        [1.0; 3],
    )
    .unwrap();
    let (sparse, sides) = sparsify_for_isosurface(ml.view(), 0.5).unwrap();
    let sparse = sparse.into_data();
    let mut dropped = ml.values.clone();
    random_dropouts(&mut dropped, 0.15, 3).unwrap();
    let grids = [
        ScalarGrid::with_spacing(ml.dims, ml.spacing, &ml.values).unwrap(),
        ScalarGrid::with_spacing(ml.dims, ml.spacing, &sparse)
            .unwrap()
            .with_side_hint(&sides)
            .unwrap(),
        ScalarGrid::with_spacing(ml.dims, ml.spacing, &dropped).unwrap(),
    ];
    for g in &grids {
        for selection in [
            TetSelection::MeshAware,
            TetSelection::NearestCorner,
            TetSelection::AverageBoth,
        ] {
            for (eq8_literal, normalize_before_mean) in
                [(false, false), (true, false), (false, true)]
            {
                let m = NormalMethod::Spline(
                    SplineParams::default()
                        .selection(selection)
                        .eq8_literal(eq8_literal)
                        .normalize_before_mean(normalize_before_mean),
                );
                let mesh = marching_cubes(g, 0.5, m).unwrap();
                let (n, st) = estimate_normals(g, 0.5, &mesh.vertex_edge, m).unwrap();
                assert_eq!(st.fallback, mesh.stats.fallback);
                let e = angular_errors(&n, &mesh.normals).unwrap();
                let worst = e.iter().fold(0.0f32, |a, &x| a.max(x));
                assert!(worst < 1e-5, "{m:?}: {worst}");
            }
        }
    }
}

#[test]
fn per_class_and_restricted_errors_cover_the_mesh() {
    use wscg_isosurface::metrics::class_rms;
    use wscg_isosurface::study::restricted_rms;
    let f = torus_field();
    let s = fields::sample_voxels(&f, [48; 3]).unwrap();
    let m = marching_cubes(&s.grid().unwrap(), 0.0, NormalMethod::spline()).unwrap();
    let e = angular_errors(&m.normals, &s.exact_normals(&f, &m.vertices)).unwrap();
    // Every vertex lies in some triangulated cell: all configurations give the plain RMS.
    let all: std::collections::HashSet<u8> = (0..=255).collect();
    let r = restricted_rms(&m, &e, s.dims, &all).unwrap();
    let plain = rms(&e);
    assert_eq!(r.count, plain.count);
    assert!((r.rms - plain.rms).abs() < 1e-12);
    assert_eq!(
        restricted_rms(&m, &e, s.dims, &Default::default())
            .unwrap()
            .count,
        0
    );
    // Per class, a vertex counts once per cell around it: the counts add up to the crossing
    // edges of all cells.
    let classes = class_rms(&m, &e, s.dims).unwrap();
    assert_eq!(classes.len(), 23);
    let crossings: usize = m
        .cell_config
        .iter()
        .map(|&(_, c)| {
            wscg_isosurface::tables::case_table()[c as usize]
                .edge_mask
                .count_ones() as usize
        })
        .sum();
    assert_eq!(classes.iter().map(|c| c.count).sum::<usize>(), crossings);
    assert!(restricted_rms(&m, &e[1..], s.dims, &all).is_err());
}

#[test]
fn literal_eq8_on_a_linear_field() {
    // The seed's eq. 8 keeps half the derivative along the vertex's edge and lambda_0 / 2 of
    // the others, lambda_0 being the barycentric weight of the tetrahedron's corner. With the
    // nearer corner chosen, lambda_0 = max(t, 1 - t) in every cell, so on f = a.x the normal
    // is (a_e, lambda_0 a_m, lambda_0 a_n) normalised (e the edge axis).
    let a = [0.3, 0.5, 0.7];
    let s = fields::sample_voxels(&Linear { a, b: 0.01 }, [16; 3]).unwrap();
    let g = s.grid().unwrap();
    let o = NormalMethod::Spline(
        SplineParams::default()
            .selection(TetSelection::NearestCorner)
            .eq8_literal(true)
            .normalize_before_mean(false),
    );
    let iso = 9.37f32;
    let m = marching_cubes(&g, iso, o).unwrap();
    assert!(m.vertices.len() > 50);
    let mut worst = 0.0f32;
    for (e, n) in m.vertex_edge.iter().zip(&m.normals) {
        let (fp, fq) = (g.value(e.low()).unwrap(), g.value(e.high()).unwrap());
        let t = ((iso - fp) / (fq - fp)) as f64;
        let l0 = t.max(1.0 - t);
        let want = [0, 1, 2].map(|i| {
            (if i == e.axis as usize {
                a[i]
            } else {
                l0 * a[i]
            }) as f32
        });
        worst = worst.max(wscg_isosurface::metrics::angle(*n, want));
    }
    assert!(worst < 1e-5, "worst {worst}");
    // ... which is not the exact gradient.
    let exact = rms(&angular_errors(&m.normals, &vec![[0.3, 0.5, 0.7]; m.normals.len()]).unwrap());
    assert!(exact.rms > 0.05, "{}", exact.rms);
}
