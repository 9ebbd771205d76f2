//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::{Result, TriMesh};
use wscg_meshfilter::bmd::{bmd, BmdParams};
use wscg_meshfilter::{jbmd, JbmdParams};

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
    assert!(JbmdParams::default().validate().is_ok());
    for name in ["fandisk", "lion", "allegorie", "person1", "person2"] {
        assert!(
            JbmdParams::preset(name).unwrap().validate().is_ok(),
            "{name}"
        );
    }
    assert_eq!(field(JbmdParams::default().k(0).validate()), "k");
    assert_eq!(
        field(JbmdParams::default().sigma_d(0.0).validate()),
        "sigma_d"
    );
    assert_eq!(
        field(JbmdParams::default().sigma_o(f64::NAN).validate()),
        "sigma_o"
    );
    assert_eq!(
        field(JbmdParams::default().sigma_c(-30.0).validate()),
        "sigma_c"
    );
    assert_eq!(
        field(JbmdParams::default().lambda(1.5).validate()),
        "lambda"
    );
    assert_eq!(
        field(JbmdParams::default().lambda(0.0).validate()),
        "lambda"
    );
    // `k` must also be below the vertex count.
    assert!(JbmdParams::default().validate_for(21).is_ok());
    assert_eq!(field(JbmdParams::default().validate_for(20)), "k");

    assert!(BmdParams::default().validate().is_ok());
    assert_eq!(
        field(BmdParams::default().sigma_c(0.0).validate()),
        "sigma_c"
    );
    assert_eq!(
        field(BmdParams::default().sigma_s(f64::INFINITY).validate()),
        "sigma_s"
    );

    // The methods check their parameters before the mesh.
    let empty = TriMesh::default();
    assert_eq!(field(jbmd(&empty, &JbmdParams::default().k(0))), "k");
    assert_eq!(
        field(bmd(&empty, &BmdParams::default().sigma_s(-1.0))),
        "sigma_s"
    );
}
