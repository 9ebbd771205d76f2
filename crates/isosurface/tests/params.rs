//! Every parameter struct of the crate: its `Default` passes `validate()`. The fields of
//! [`SplineParams`] and [`LsnParams`] are choices and switches with no invalid value, so
//! every setting validates, and the extraction accepts them.

use wscg_isosurface::{
    marching_cubes, AmbiguousRule, LsnParams, NormalMethod, ScalarGrid, SplineParams, TetSelection,
};

#[test]
fn every_parameter_struct_validates_its_default_and_every_setting() {
    assert!(SplineParams::default().validate().is_ok());
    for selection in [
        TetSelection::MeshAware,
        TetSelection::NearestCorner,
        TetSelection::AverageBoth,
    ] {
        let p = SplineParams::default()
            .selection(selection)
            .eq8_literal(true)
            .normalize_before_mean(true);
        assert!(p.validate().is_ok());
        assert!(NormalMethod::Spline(p).validate().is_ok());
    }
    assert!(LsnParams::default().validate().is_ok());
    for rule in [AmbiguousRule::IsolateInside, AmbiguousRule::IsolateOutside] {
        let p = LsnParams::default().ambiguous_face(rule);
        assert!(p.validate().is_ok());
        assert!(NormalMethod::Lsn(p).validate().is_ok());
    }

    // The extraction runs with every estimator's defaults.
    let values: Vec<f32> = (0..8).map(|i| (i & 1) as f32).collect();
    let grid = ScalarGrid::new([2, 2, 2], &values).unwrap();
    for m in [NormalMethod::spline(), NormalMethod::lsn()] {
        let mesh = marching_cubes(&grid, 0.5, m).unwrap();
        assert_eq!(mesh.normals.len(), mesh.vertices.len());
    }
}
