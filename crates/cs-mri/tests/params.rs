//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_cs_mri::sparsifier::{by_name, PriorParams};
use wscg_cs_mri::{
    CompositeParams, CsalsaParams, Fdct, FdctParams, Sflct, SflctParams, UdctParams,
};
use wscg_math::Result;

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
    assert!(CsalsaParams::default().validate().is_ok());
    assert!(CsalsaParams::default().max_iter(0).validate().is_ok());
    assert_eq!(field(CsalsaParams::default().tau0(0.0).validate()), "tau0");
    assert_eq!(field(CsalsaParams::default().rho(0.5).validate()), "rho");
    assert_eq!(
        field(CsalsaParams::default().tau_cap(f64::NAN).validate()),
        "tau_cap"
    );
    assert_eq!(
        field(CsalsaParams::default().epsilon(-1.0).validate()),
        "epsilon"
    );
    assert_eq!(field(CsalsaParams::default().tol(-1e-3).validate()), "tol");

    assert!(CompositeParams::default().validate().is_ok());
    assert_eq!(field(CompositeParams::default().a(-1.0).validate()), "a");
    assert_eq!(
        field(CompositeParams::default().b(f64::NAN).validate()),
        "b"
    );
    assert_eq!(
        field(CompositeParams::default().group_weight(-1.0).validate()),
        "group_weight"
    );
    assert_eq!(
        field(CompositeParams::default().mu_g(f64::INFINITY).validate()),
        "mu_g"
    );
    assert_eq!(
        field(CompositeParams::default().order(9).validate()),
        "order"
    );
    assert_eq!(
        field(CompositeParams::default().levels(0).validate()),
        "levels"
    );

    assert!(UdctParams::default().validate().is_ok());
    assert_eq!(
        field(UdctParams::default().wedges(vec![[4, 6]]).validate()),
        "wedges"
    );
    assert_eq!(field(UdctParams::default().alpha(0.5).validate()), "alpha");
    assert_eq!(
        field(
            UdctParams::default()
                .radial([0.0, 1.0, 2.0, 3.0])
                .validate()
        ),
        "radial"
    );

    assert!(FdctParams::default().validate().is_ok());
    assert_eq!(FdctParams::default().validate_for(256, 256).unwrap(), 5);
    assert_eq!(
        field(FdctParams::default().angles_coarse(10).validate()),
        "angles_coarse"
    );
    assert_eq!(
        field(FdctParams::default().transition(0.0).validate()),
        "transition"
    );
    assert_eq!(
        field(FdctParams::default().scales(Some(1)).validate()),
        "scales"
    );
    // Valid on its own, too many scales for a small image.
    assert!(FdctParams::default().scales(Some(8)).validate().is_ok());
    assert_eq!(
        field(FdctParams::default().scales(Some(8)).validate_for(64, 64)),
        "scales"
    );
    assert_eq!(
        field(Fdct::new(64, 64, &FdctParams::default().transition(2.0))),
        "transition"
    );

    assert!(SflctParams::default().validate().is_ok());
    assert_eq!(
        field(SflctParams::default().dfb_levels(vec![]).validate()),
        "dfb_levels"
    );
    assert_eq!(
        field(SflctParams::default().dfb_levels(vec![3; 7]).validate()),
        "dfb_levels"
    );
    assert_eq!(
        field(SflctParams::default().dfb_levels(vec![3, 9]).validate()),
        "dfb_levels"
    );
    assert_eq!(
        field(Sflct::new(
            64,
            64,
            &SflctParams::default().dfb_levels(vec![])
        )),
        "dfb_levels"
    );

    assert!(PriorParams::default().validate().is_ok());
    assert_eq!(
        field(
            PriorParams::default()
                .udct(UdctParams::default().alpha(0.0))
                .validate()
        ),
        "alpha"
    );
    assert_eq!(
        field(
            PriorParams::default()
                .fdct(FdctParams::default().angles_coarse(4))
                .validate()
        ),
        "angles_coarse"
    );
    assert_eq!(
        field(PriorParams::default().sflct_levels(vec![]).validate()),
        "sflct_levels"
    );
    assert_eq!(field(PriorParams::default().levels(0).validate()), "levels");
    assert_eq!(
        field(by_name("db4", 64, 64, &PriorParams::default().levels(0))),
        "levels"
    );
}
