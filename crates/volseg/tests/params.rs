//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::Result;
use wscg_volseg::{fractured_shell_phantom, IntensityNorm, PhantomParams, RandomWalkParams};

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
    assert!(RandomWalkParams::default().validate().is_ok());
    assert_eq!(
        field(RandomWalkParams::default().t_bone(f64::NAN).validate()),
        "t_bone"
    );
    assert_eq!(
        field(RandomWalkParams::default().beta(-1.0).validate()),
        "beta"
    );
    assert_eq!(
        field(RandomWalkParams::default().eps(f64::INFINITY).validate()),
        "eps"
    );
    assert_eq!(
        field(RandomWalkParams::default().kappa(-1e-3).validate()),
        "kappa"
    );
    assert_eq!(
        field(RandomWalkParams::default().tol(0.0).validate()),
        "tol"
    );
    assert_eq!(
        field(RandomWalkParams::default().max_iter(0).validate()),
        "max_iter"
    );
    assert_eq!(
        field(RandomWalkParams::default().threads(Some(0)).validate()),
        "threads"
    );
    let flipped = IntensityNorm::Window { lo: 1.0, hi: 0.0 };
    assert_eq!(
        field(RandomWalkParams::default().norm(flipped).validate()),
        "norm"
    );

    assert!(PhantomParams::default().validate().is_ok());
    assert_eq!(
        field(PhantomParams::default().fragments(1).validate()),
        "fragments"
    );
    assert_eq!(
        field(PhantomParams::default().dims([64, 15, 64]).validate()),
        "dims"
    );
    assert_eq!(
        field(PhantomParams::default().blur_sigma(17.0).validate()),
        "blur_sigma"
    );
    assert_eq!(
        field(PhantomParams::default().bone_hu(f64::NAN).validate()),
        "bone_hu"
    );
    assert_eq!(
        field(PhantomParams::default().gap_width(-0.5).validate()),
        "gap_width"
    );
    assert_eq!(
        field(PhantomParams::default().noise_hu(-1.0).validate()),
        "noise_hu"
    );
    assert_eq!(
        field(
            PhantomParams::default()
                .stroke_margin(f64::INFINITY)
                .validate()
        ),
        "stroke_margin"
    );
    assert_eq!(
        field(PhantomParams::default().shell([0.7, 0.6]).validate()),
        "shell"
    );
    assert_eq!(
        field(fractured_shell_phantom(
            &PhantomParams::default().stroke_radius(-2.0)
        )),
        "stroke_radius"
    );
}
