//! A many-light scene rebuilt from its parts (triangles, albedo, emission, skipped count)
//! is the same scene: bit-identical renders; bad parts are refused.

use wscg_math::progress::NoProgress;
use wscg_raytrace::manylight::scenes::cornell_box;
use wscg_raytrace::manylight::{
    run, ImportanceCachingParams, ManyLightParams, Method, Scene, Triangle, VplParams,
};

fn parts(s: &Scene) -> (Vec<Triangle>, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let n = s.len() as u32;
    (
        s.triangles().to_vec(),
        (0..n).map(|i| s.albedo(i)).collect(),
        (0..n).map(|i| s.emission(i)).collect(),
    )
}

#[test]
fn scene_from_its_parts_renders_identically() {
    let (scene, cam) = cornell_box(2, 24, 18).unwrap();
    let (t, a, e) = parts(&scene);
    // The triangles through their fields, as the Python pickle carries them.
    let t: Vec<Triangle> = t
        .iter()
        .map(|t| Triangle::from_edges(t.p0, t.e1, t.e2).unwrap())
        .collect();
    let rebuilt = Scene::from_parts(t, a, e, scene.skipped_degenerate).unwrap();
    assert_eq!(rebuilt.emitters(), scene.emitters());
    let s = ManyLightParams::default()
        .vpl(VplParams::default().n_paths(60).seed(1))
        .ic(ImportanceCachingParams::default().n_cache(30).spp(4));
    for method in [Method::Power, Method::Adaptive] {
        let x = run(&scene, &cam, method, &s, &NoProgress).unwrap().image;
        let y = run(&rebuilt, &cam, method, &s, &NoProgress).unwrap().image;
        assert_eq!(x.data(), y.data(), "{method:?}");
    }
}

#[test]
fn bad_parts_are_refused() {
    let (scene, _) = cornell_box(1, 8, 8).unwrap();
    let (t, a, e) = parts(&scene);
    assert!(Scene::from_parts(Vec::new(), Vec::new(), Vec::new(), 0).is_err());
    assert!(Scene::from_parts(t.clone(), a[1..].to_vec(), e.clone(), 0).is_err());
    let mut bright = a.clone();
    bright[0] = [1.5, 0.0, 0.0];
    assert!(Scene::from_parts(t.clone(), bright, e.clone(), 0).is_err());
    let mut nan = t;
    nan[0].p0 = [f64::NAN, 0.0, 0.0];
    assert!(Scene::from_parts(nan, a, e, 0).is_err());
    let z = [0.0; 3];
    assert!(Triangle::from_edges(z, [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]).is_none());
}
