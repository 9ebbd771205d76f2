//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::metrics::{ssim, ssim_plane, SsimParams};
use wscg_math::sparse::{pcg, CsrMatrix, IdentityPrecond, InitialGuess, PcgParams};
use wscg_math::{Image, ImageView, RefusedArgument};

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    assert!(PcgParams::default().validate().is_ok());
    assert!(PcgParams::default().max_iter(Some(0)).validate().is_ok());
    assert_eq!(
        PcgParams::default().tol(0.0).validate().refused_argument(),
        Some("tol")
    );
    assert_eq!(
        PcgParams::default()
            .tol(f64::NAN)
            .validate()
            .refused_argument(),
        Some("tol")
    );

    assert!(SsimParams::default().validate().is_ok());
    assert_eq!(
        SsimParams::default()
            .data_range(0.0)
            .validate()
            .refused_argument(),
        Some("data_range")
    );
    assert_eq!(
        SsimParams::default()
            .sigma(-1.0)
            .validate()
            .refused_argument(),
        Some("sigma")
    );
    assert_eq!(
        SsimParams::default()
            .truncate(f64::INFINITY)
            .validate()
            .refused_argument(),
        Some("truncate")
    );
    assert_eq!(
        SsimParams::default().k1(0.0).validate().refused_argument(),
        Some("k1")
    );
    assert_eq!(
        SsimParams::default()
            .k2(f64::NAN)
            .validate()
            .refused_argument(),
        Some("k2")
    );

    // The methods check their parameters before their data.
    let a = CsrMatrix::from_triplets(2, 2, &[(0, 0, 2.0), (1, 1, 3.0)]).unwrap();
    let bad = PcgParams::default().tol(-1.0);
    assert_eq!(
        pcg(&a, &[1.0], InitialGuess::Zero, &IdentityPrecond, &bad).refused_argument(),
        Some("tol")
    );
    let bad = SsimParams::default().sigma(0.0);
    assert_eq!(
        ssim_plane(
            ImageView::plane(1, 1, &[0.0]).unwrap(),
            ImageView::plane(1, 2, &[1.0, 1.0]).unwrap(),
            &bad
        )
        .refused_argument(),
        Some("sigma")
    );
    let img = Image::<f32>::filled(4, 4, 1, 0.5).unwrap();
    assert_eq!(ssim(&img, &img, &bad).refused_argument(), Some("sigma"));
}
