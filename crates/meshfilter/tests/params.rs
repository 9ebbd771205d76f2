//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::{RefusedArgument, TriMesh};
use wscg_meshfilter::bmd::{bmd, BmdParams};
use wscg_meshfilter::{jbmd, JbmdParams};

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    assert!(JbmdParams::default().validate().is_ok());
    for name in ["fandisk", "lion", "allegorie", "person1", "person2"] {
        assert!(
            JbmdParams::preset(name).unwrap().validate().is_ok(),
            "{name}"
        );
    }
    assert_eq!(
        JbmdParams::default().k(0).validate().refused_argument(),
        Some("k")
    );
    assert_eq!(
        JbmdParams::default()
            .sigma_d(0.0)
            .validate()
            .refused_argument(),
        Some("sigma_d")
    );
    assert_eq!(
        JbmdParams::default()
            .sigma_o(f64::NAN)
            .validate()
            .refused_argument(),
        Some("sigma_o")
    );
    assert_eq!(
        JbmdParams::default()
            .sigma_c(-30.0)
            .validate()
            .refused_argument(),
        Some("sigma_c")
    );
    assert_eq!(
        JbmdParams::default()
            .lambda(1.5)
            .validate()
            .refused_argument(),
        Some("lambda")
    );
    assert_eq!(
        JbmdParams::default()
            .lambda(0.0)
            .validate()
            .refused_argument(),
        Some("lambda")
    );
    // `k` must also be below the vertex count.
    assert!(JbmdParams::default().validate_for(21).is_ok());
    assert_eq!(
        JbmdParams::default().validate_for(20).refused_argument(),
        Some("k")
    );

    assert!(BmdParams::default().validate().is_ok());
    assert_eq!(
        BmdParams::default()
            .sigma_c(0.0)
            .validate()
            .refused_argument(),
        Some("sigma_c")
    );
    assert_eq!(
        BmdParams::default()
            .sigma_s(f64::INFINITY)
            .validate()
            .refused_argument(),
        Some("sigma_s")
    );

    // The methods check their parameters before the mesh.
    let empty = TriMesh::default();
    assert_eq!(
        jbmd(&empty, &JbmdParams::default().k(0)).refused_argument(),
        Some("k")
    );
    assert_eq!(
        bmd(&empty, &BmdParams::default().sigma_s(-1.0)).refused_argument(),
        Some("sigma_s")
    );
}
