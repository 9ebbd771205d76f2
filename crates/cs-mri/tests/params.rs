//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_cs_mri::sparsifier::{by_name, PriorParams};
use wscg_cs_mri::{
    CompositeParams, CsalsaParams, Fdct, FdctParams, Sflct, SflctParams, UdctParams,
};
use wscg_math::RefusedArgument;

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    assert!(CsalsaParams::default().validate().is_ok());
    assert!(CsalsaParams::default().max_iter(0).validate().is_ok());
    assert_eq!(
        CsalsaParams::default()
            .tau0(0.0)
            .validate()
            .refused_argument(),
        Some("tau0")
    );
    assert_eq!(
        CsalsaParams::default()
            .rho(0.5)
            .validate()
            .refused_argument(),
        Some("rho")
    );
    assert_eq!(
        CsalsaParams::default()
            .tau_cap(f64::NAN)
            .validate()
            .refused_argument(),
        Some("tau_cap")
    );
    assert_eq!(
        CsalsaParams::default()
            .epsilon(-1.0)
            .validate()
            .refused_argument(),
        Some("epsilon")
    );
    assert_eq!(
        CsalsaParams::default()
            .tol(-1e-3)
            .validate()
            .refused_argument(),
        Some("tol")
    );

    assert!(CompositeParams::default().validate().is_ok());
    assert_eq!(
        CompositeParams::default()
            .a(-1.0)
            .validate()
            .refused_argument(),
        Some("a")
    );
    assert_eq!(
        CompositeParams::default()
            .b(f64::NAN)
            .validate()
            .refused_argument(),
        Some("b")
    );
    assert_eq!(
        CompositeParams::default()
            .group_weight(-1.0)
            .validate()
            .refused_argument(),
        Some("group_weight")
    );
    assert_eq!(
        CompositeParams::default()
            .mu_g(f64::INFINITY)
            .validate()
            .refused_argument(),
        Some("mu_g")
    );
    assert_eq!(
        CompositeParams::default()
            .order(9)
            .validate()
            .refused_argument(),
        Some("order")
    );
    assert_eq!(
        CompositeParams::default()
            .levels(0)
            .validate()
            .refused_argument(),
        Some("levels")
    );

    assert!(UdctParams::default().validate().is_ok());
    assert_eq!(
        UdctParams::default()
            .wedges(vec![[4, 6]])
            .validate()
            .refused_argument(),
        Some("wedges")
    );
    assert_eq!(
        UdctParams::default()
            .alpha(0.5)
            .validate()
            .refused_argument(),
        Some("alpha")
    );
    assert_eq!(
        UdctParams::default()
            .radial([0.0, 1.0, 2.0, 3.0])
            .validate()
            .refused_argument(),
        Some("radial")
    );

    assert!(FdctParams::default().validate().is_ok());
    assert_eq!(FdctParams::default().validate_for(256, 256).unwrap(), 5);
    assert_eq!(
        FdctParams::default()
            .angles_coarse(10)
            .validate()
            .refused_argument(),
        Some("angles_coarse")
    );
    assert_eq!(
        FdctParams::default()
            .transition(0.0)
            .validate()
            .refused_argument(),
        Some("transition")
    );
    assert_eq!(
        FdctParams::default()
            .scales(Some(1))
            .validate()
            .refused_argument(),
        Some("scales")
    );
    // Valid on its own, too many scales for a small image.
    assert!(FdctParams::default().scales(Some(8)).validate().is_ok());
    assert_eq!(
        FdctParams::default()
            .scales(Some(8))
            .validate_for(64, 64)
            .refused_argument(),
        Some("scales")
    );
    assert_eq!(
        Fdct::new(64, 64, &FdctParams::default().transition(2.0)).refused_argument(),
        Some("transition")
    );

    assert!(SflctParams::default().validate().is_ok());
    assert_eq!(
        SflctParams::default()
            .dfb_levels(vec![])
            .validate()
            .refused_argument(),
        Some("dfb_levels")
    );
    assert_eq!(
        SflctParams::default()
            .dfb_levels(vec![3; 7])
            .validate()
            .refused_argument(),
        Some("dfb_levels")
    );
    assert_eq!(
        SflctParams::default()
            .dfb_levels(vec![3, 9])
            .validate()
            .refused_argument(),
        Some("dfb_levels")
    );
    assert_eq!(
        Sflct::new(64, 64, &SflctParams::default().dfb_levels(vec![])).refused_argument(),
        Some("dfb_levels")
    );

    assert!(PriorParams::default().validate().is_ok());
    assert_eq!(
        PriorParams::default()
            .udct(UdctParams::default().alpha(0.0))
            .validate()
            .refused_argument(),
        Some("alpha")
    );
    assert_eq!(
        PriorParams::default()
            .fdct(FdctParams::default().angles_coarse(4))
            .validate()
            .refused_argument(),
        Some("angles_coarse")
    );
    assert_eq!(
        PriorParams::default()
            .sflct_levels(vec![])
            .validate()
            .refused_argument(),
        Some("sflct_levels")
    );
    assert_eq!(
        PriorParams::default()
            .levels(0)
            .validate()
            .refused_argument(),
        Some("levels")
    );
    assert_eq!(
        by_name("db4", 64, 64, &PriorParams::default().levels(0)).refused_argument(),
        Some("levels")
    );
}
