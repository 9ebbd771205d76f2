//! A serialised simulation (model, parameters, multipliers, step count, obstacles) steps
//! exactly as the original; damaged states are refused.

use wscg_cloth::{
    ClothModel, Collider, Collisions, LambdaMode, MeshCollider, Method, Relaxation, Simulation,
    SolverParams,
};

/// A closed octahedron of radius `r` around `c`.
fn octahedron(c: [f64; 3], r: f64) -> MeshCollider {
    let v: Vec<[f64; 3]> = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ]
    .iter()
    .map(|p| [c[0] + p[0] * r, c[1] + p[1] * r, c[2] + p[2] * r])
    .collect();
    let f = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    MeshCollider::new(&v, &f).unwrap()
}

fn running(method: Method, relaxation: Relaxation, fem: bool) -> Simulation {
    let mut m = if fem {
        ClothModel::fem_grid(7, 6, (1.0, 1.0), 0.1, 1000.0, 0.3).unwrap()
    } else {
        ClothModel::grid(7, 6, (1.0, 1.0), 0.1, 2000.0, Some(500.0), Some(50.0)).unwrap()
    };
    let projection = matches!(method, Method::SoftProjection | Method::PlainPbd { .. });
    if projection {
        // A hard constraint (the global solves take soft ones only).
        m.add_roller(5, [0.0, 1.0, 0.0], 0.0).unwrap();
    }
    let mut cfg = SolverParams::default()
        .method(method)
        .relaxation(relaxation)
        .iterations(12)
        .lambda_mode(LambdaMode::Accumulate);
    if method == Method::SoftProjection {
        cfg = cfg.alpha(0.8).gamma(0.01);
    }
    let mut s = Simulation::new(m, cfg).unwrap();
    if projection {
        s.set_collisions(Collisions {
            colliders: vec![
                Collider::Mesh(octahedron([0.5, -0.4, 0.5], 0.3)),
                Collider::Sphere {
                    center: [0.2, -0.3, 0.2],
                    radius: 0.15,
                },
                Collider::plane([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]).unwrap(),
            ],
            thickness: 0.01,
            friction: 0.3,
            self_collision: true,
        })
        .unwrap();
    }
    for _ in 0..6 {
        s.step(0.01).unwrap();
    }
    s
}

#[test]
fn serialised_simulation_steps_identically() {
    for (method, relaxation, fem) in [
        (Method::SoftProjection, Relaxation::GaussSeidel, false),
        (Method::SoftProjection, Relaxation::ColoredGaussSeidel, true),
        (
            Method::SoftProjection,
            Relaxation::Jacobi { omega: 0.15 },
            false,
        ),
        (
            Method::PlainPbd { stiffness: 0.9 },
            Relaxation::GaussSeidel,
            false,
        ),
        (
            Method::GlobalCr {
                primal_residual: true,
                tol: 1e-10,
            },
            Relaxation::GaussSeidel,
            true,
        ),
    ] {
        let mut a = running(method, relaxation, fem);
        let json = serde_json::to_string(&a).unwrap();
        let mut b: Simulation = serde_json::from_str(&json).unwrap();
        assert_eq!(b.steps(), a.steps());
        assert_eq!(b.multipliers(), a.multipliers());
        assert_eq!(b.config(), a.config());
        assert_eq!(
            b.collisions().colliders.len(),
            a.collisions().colliders.len()
        );
        for _ in 0..5 {
            a.step(0.01).unwrap();
            b.step(0.01).unwrap();
        }
        assert_eq!(a.model(), b.model(), "{method:?}");
        assert_eq!(a.multipliers(), b.multipliers(), "{method:?}");
    }
}

#[test]
fn mesh_collider_round_trips() {
    let c = Collider::Mesh(octahedron([0.1, 0.2, 0.3], 0.5));
    let d: Collider = serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
    for p in [[0.0, 0.0, 0.0], [1.0, 0.2, 0.3], [0.3, 0.4, -0.2]] {
        assert_eq!(c.signed_distance(p), d.signed_distance(p));
    }
}

#[test]
fn inconsistent_state_is_refused() {
    let a = running(Method::SoftProjection, Relaxation::GaussSeidel, false);
    let mut v = serde_json::to_value(&a).unwrap();
    v["lambda"].as_array_mut().unwrap().pop();
    assert!(serde_json::from_value::<Simulation>(v).is_err());
    let mut v = serde_json::to_value(&a).unwrap();
    v["model"]["v"].as_array_mut().unwrap().pop();
    assert!(serde_json::from_value::<Simulation>(v).is_err());
    let mut v = serde_json::to_value(&a).unwrap();
    v["collisions"]["colliders"][0]["Mesh"]["faces"][0][0] = serde_json::json!(99);
    assert!(serde_json::from_value::<Simulation>(v).is_err());
}
