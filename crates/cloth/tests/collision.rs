//! Collisions (paper section 10): contacts with planes, spheres, capsules and triangle meshes
//! as inequality constraints with Coulomb friction, and self contacts.

use nalgebra::Vector3;
use wscg_cloth::{
    grid_triangles, ClothModel, Collider, Collisions, MeshCollider, Method, Simulation,
    SolverParams,
};
use wscg_math::vec3::{add, dist, dot, norm};

const H: f64 = 1.0 / 60.0;
const G: f64 = 9.81;

fn sim_with(model: ClothModel, collisions: Collisions) -> Simulation {
    let mut sim = Simulation::new(model, SolverParams::default()).unwrap();
    sim.set_collisions(collisions).unwrap();
    sim
}

/// A free `n x n` link cloth (1 m) at height `y`, nothing pinned.
fn free_cloth(n: usize, y: f64) -> ClothModel {
    let mut m = ClothModel::grid(n, n, (1.0, 1.0), 0.1, 2000.0, Some(2000.0), Some(200.0)).unwrap();
    for (p, w) in m.inv_mass.iter_mut().enumerate() {
        *w = 1.0 / (0.1 / (n * n) as f64);
        m.x[p] = add(m.x[p], [-0.5, y, -0.5]);
    }
    m
}

fn sphere_mesh(r: f64) -> MeshCollider {
    let (v, f) = parry3d::shape::Ball::new(r as f32).to_trimesh(48, 48);
    let v: Vec<[f64; 3]> = v
        .iter()
        .map(|p| [p.x as f64, p.y as f64, p.z as f64])
        .collect();
    let f: Vec<[usize; 3]> = f.iter().map(|t| t.map(|i| i as usize)).collect();
    MeshCollider::new(&v, &f).unwrap()
}

/// How far the 48 x 48 tessellated sphere lies inside the analytic one: the chord sag of a
/// face in both directions, `r (1 - cos^2(pi/48))`, plus single-precision rounding.
fn sag(r: f64) -> f64 {
    r * (1.0 - (std::f64::consts::PI / 48.0).cos().powi(2)) + 1e-5
}

#[test]
fn cloth_drapes_over_a_sphere_without_penetrating() {
    let (r, th) = (0.3, 0.005);
    for collider in [
        Collider::Sphere {
            center: [0.0; 3],
            radius: r,
        },
        Collider::Mesh(sphere_mesh(r)),
    ] {
        let analytic = matches!(collider, Collider::Sphere { .. });
        let mut sim = sim_with(
            free_cloth(21, 0.45),
            Collisions {
                colliders: vec![collider],
                thickness: th,
                friction: 0.5,
                self_collision: false,
            },
        );
        for _ in 0..150 {
            sim.step(H).unwrap();
        }
        let x = &sim.model().x;
        let min_dist = x.iter().map(|&p| norm(p)).fold(f64::INFINITY, f64::min);
        let centre = x[10 * 21 + 10];
        let lowest_corner = [0, 20, 21 * 20, 21 * 21 - 1]
            .iter()
            .map(|&p| x[p][1])
            .fold(f64::INFINITY, f64::min);
        println!(
            "analytic {analytic}: min distance to the centre {min_dist:.5} m (r + thickness \
             {:.3}), centre particle at y = {:.5}, lowest corner y = {lowest_corner:.3}",
            r + th,
            centre[1]
        );
        let tess = if analytic { 1e-9 } else { sag(r) };
        assert!(min_dist >= r + th - tess, "penetration: {min_dist}");
        assert!(
            (centre[1] - (r + th)).abs() < 2e-3 + tess,
            "centre at {}",
            centre[1]
        );
        assert!(
            lowest_corner < 0.0,
            "the cloth did not drape: corner at {lowest_corner}"
        );
    }
}

#[test]
fn mesh_signed_distance_matches_the_analytic_sphere() {
    let r = 0.3;
    let mesh = Collider::Mesh(sphere_mesh(r));
    let ball = Collider::Sphere {
        center: [0.0; 3],
        radius: r,
    };
    let u = wscg_math::rng::uniform_vec(4, 3 * 500, -0.6, 0.6).unwrap();
    let tess = sag(r);
    for q in u.chunks(3) {
        let p = [q[0], q[1], q[2]];
        let (dm, nm) = mesh.signed_distance(p);
        let (db, nb) = ball.signed_distance(p);
        assert!((dm - db).abs() <= tess, "{p:?}: mesh {dm} vs sphere {db}");
        if db.abs() > 0.05 {
            assert!(dot(nm, nb) > 0.95, "{p:?}: normals {nm:?} vs {nb:?}");
        }
    }
}

/// One particle resting on a plane inclined by `theta`: with `mu >= tan(theta)` it sticks,
/// otherwise it slides with acceleration `g (sin(theta) - mu cos(theta))`.
fn slide(theta: f64, mu: f64, steps: usize) -> f64 {
    let th = 0.01;
    let n = Vector3::new(-theta.sin(), theta.cos(), 0.0);
    let start = n * th;
    let m = ClothModel::new(vec![start.into()], &[0.01], &[]).unwrap();
    let mut sim = sim_with(
        m,
        Collisions {
            colliders: vec![Collider::plane(n.into(), [0.0; 3]).unwrap()],
            thickness: th,
            friction: mu,
            self_collision: false,
        },
    );
    for _ in 0..steps {
        let s = sim.step(H).unwrap();
        assert_eq!(s.contacts, 1);
    }
    let x = Vector3::from(sim.model().x[0]);
    assert!(
        (n.dot(&x) - th).abs() < 1e-12,
        "left the plane: {}",
        n.dot(&x)
    );
    // Distance slid down the slope.
    (start - x).dot(&Vector3::new(theta.cos(), theta.sin(), 0.0))
}

#[test]
fn coulomb_friction_on_an_incline() {
    let theta = 20f64.to_radians();
    let steps = 60;
    assert!(
        slide(theta, 0.5, steps).abs() < 1e-12,
        "static friction failed"
    );
    for mu in [0.0, 0.1, 0.3] {
        let s = slide(theta, mu, steps);
        let a = G * (theta.sin() - mu * theta.cos());
        // Semi-implicit position update: s = a h^2 n (n + 1) / 2 after n steps.
        let n = steps as f64;
        let expected = a * H * H * n * (n + 1.0) / 2.0;
        println!("mu {mu}: slid {s:.6} m, expected {expected:.6} m");
        assert!(
            (s - expected).abs() < 1e-9 * expected.max(1.0),
            "mu {mu}: {s} vs {expected}"
        );
    }
}

#[test]
fn particle_rests_on_a_capsule() {
    let (r, th) = (0.1, 0.002);
    let m = ClothModel::new(vec![[0.2, 0.5, 0.0]], &[0.01], &[]).unwrap();
    let capsule = Collider::Capsule {
        a: [-1.0, 0.0, 0.0],
        b: [1.0, 0.0, 0.0],
        radius: r,
    };
    let mut sim = sim_with(
        m,
        Collisions {
            colliders: vec![capsule],
            thickness: th,
            friction: 0.3,
            self_collision: false,
        },
    );
    sim.run(H, 120).unwrap();
    let x = sim.model().x[0];
    assert!(
        (x[1] - (r + th)).abs() < 1e-9 && x[2].abs() < 1e-12,
        "{x:?}"
    );
    assert!((x[0] - 0.2).abs() < 1e-12, "slid along the axis: {}", x[0]);
}

/// Two cloths, one 3 cm above the other, fall on the floor: with self contacts the upper one
/// stays `thickness` above the lower one.
#[test]
fn self_contacts_keep_layers_apart() {
    let n = 11;
    let th = 0.02;
    let mut v = Vec::new();
    for layer in 0..2 {
        for p in 0..n * n {
            let (i, j) = (p % n, p / n);
            v.push([0.05 * i as f64, 0.03 * layer as f64 + th, 0.05 * j as f64]);
        }
    }
    let mut faces = grid_triangles(n, n);
    let upper: Vec<[usize; 3]> = faces.iter().map(|f| f.map(|p| p + n * n)).collect();
    faces.extend(upper);
    let model = ClothModel::from_trimesh(&v, &faces, 0.2, None, 500.0, None).unwrap();
    let gap = |self_collision: bool| {
        let mut sim = sim_with(
            model.clone(),
            Collisions {
                colliders: vec![Collider::plane([0.0, 1.0, 0.0], [0.0; 3]).unwrap()],
                thickness: th,
                friction: 0.5,
                self_collision,
            },
        );
        sim.run(H, 60).unwrap();
        let x = &sim.model().x;
        (0..n * n)
            .flat_map(|a| (n * n..2 * n * n).map(move |b| (a, b)))
            .map(|(a, b)| dist(x[a], x[b]))
            .fold(f64::INFINITY, f64::min)
    };
    let (with, without) = (gap(true), gap(false));
    println!("closest particles of the two layers: {with:.4} m with self contacts, {without:.4} m without");
    assert!(with >= th - 1e-9, "{with}");
    assert!(without < 0.5 * th, "{without}");
}

#[test]
fn bad_collision_settings_are_rejected() {
    let m = free_cloth(3, 0.0);
    let mut sim = Simulation::new(m.clone(), SolverParams::default()).unwrap();
    for bad in [
        Collisions {
            thickness: -1.0,
            ..Default::default()
        },
        Collisions {
            friction: f64::NAN,
            ..Default::default()
        },
        Collisions {
            colliders: vec![Collider::Sphere {
                center: [0.0; 3],
                radius: f64::NAN,
            }],
            ..Default::default()
        },
        Collisions {
            colliders: vec![Collider::Plane {
                normal: [0.0, 2.0, 0.0],
                offset: 0.0,
            }],
            ..Default::default()
        },
    ] {
        assert!(sim.set_collisions(bad).is_err());
    }
    assert!(Collider::plane([0.0; 3], [0.0; 3]).is_err());
    assert!(MeshCollider::new(&[[0.0; 3]], &[[0, 1, 2]]).is_err());
    assert!(MeshCollider::new(&[], &[]).is_err());
    let mut ncg = Simulation::new(
        m,
        SolverParams::default().method(Method::Ncg {
            variant: wscg_cloth::NcgVariant::Consistent,
        }),
    )
    .unwrap();
    let err = ncg
        .set_collisions(Collisions {
            self_collision: true,
            ..Default::default()
        })
        .unwrap_err();
    assert!(err.to_string().contains("projection"), "{err}");
}
