//! The parameter struct of the crate: its `Default` passes `validate()`, and a field set out
//! of range fails with an error naming that field (also at the start of [`build`]).

use wscg_math::{Result, TriMesh};
use wscg_octree::{build, BuildParams, Cube};

/// The field an `Error::InvalidArgument` names; panics on success or another error.
fn field<T>(r: Result<T>) -> &'static str {
    match r {
        Err(e) => e
            .argument()
            .unwrap_or_else(|| panic!("expected an invalid-argument error, got {e}")),
        Ok(_) => panic!("expected an invalid-argument error, got a result"),
    }
}

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    assert!(BuildParams::default().validate().is_ok());
    assert!(BuildParams::default().max_depth(21).validate().is_ok());
    assert_eq!(
        field(BuildParams::default().max_depth(22).validate()),
        "max_depth"
    );
    assert_eq!(
        field(BuildParams::default().leaf_max_tris(0).validate()),
        "leaf_max_tris"
    );
    assert_eq!(
        field(BuildParams::default().index_bits(0).validate()),
        "index_bits"
    );
    assert_eq!(
        field(BuildParams::default().index_bits(31).validate()),
        "index_bits"
    );
    let flat = Cube {
        min: [0.0; 3],
        size: 0.0,
    };
    assert_eq!(
        field(BuildParams::default().domain(Some(flat)).validate()),
        "domain"
    );
    let unit = Cube {
        min: [0.0; 3],
        size: 1.0,
    };
    assert!(BuildParams::default().domain(Some(unit)).validate().is_ok());
    // The parameters are checked before the mesh.
    assert_eq!(
        field(build(
            &TriMesh::default(),
            &BuildParams::default().leaf_max_tris(0)
        )),
        "leaf_max_tris"
    );
}
