//! The parameter struct of the crate: its `Default` passes `validate()`, and a field set out
//! of range fails with an error naming that field (also at the start of [`build`]).

use wscg_math::{RefusedArgument, TriMesh};
use wscg_octree::{build, BuildParams, Cube};

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    assert!(BuildParams::default().validate().is_ok());
    assert!(BuildParams::default().max_depth(21).validate().is_ok());
    assert_eq!(
        BuildParams::default()
            .max_depth(22)
            .validate()
            .refused_argument(),
        Some("max_depth")
    );
    assert_eq!(
        BuildParams::default()
            .leaf_max_tris(0)
            .validate()
            .refused_argument(),
        Some("leaf_max_tris")
    );
    assert_eq!(
        BuildParams::default()
            .index_bits(0)
            .validate()
            .refused_argument(),
        Some("index_bits")
    );
    assert_eq!(
        BuildParams::default()
            .index_bits(31)
            .validate()
            .refused_argument(),
        Some("index_bits")
    );
    let flat = Cube {
        min: [0.0; 3],
        size: 0.0,
    };
    assert_eq!(
        BuildParams::default()
            .domain(Some(flat))
            .validate()
            .refused_argument(),
        Some("domain")
    );
    let unit = Cube {
        min: [0.0; 3],
        size: 1.0,
    };
    assert!(BuildParams::default().domain(Some(unit)).validate().is_ok());
    // The parameters are checked before the mesh.
    assert_eq!(
        build(
            &TriMesh::default(),
            &BuildParams::default().leaf_max_tris(0)
        )
        .refused_argument(),
        Some("leaf_max_tris")
    );
}
