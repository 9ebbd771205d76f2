//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::RefusedArgument;
use wscg_video::complete::check_input;
use wscg_video::{
    wexler_complete, CompletionParams, LocalSearchParams, LowResParams, Mask3, PatchSize,
    PcaKdParams, RefineParams, SearchMethod, Video, WexlerParams,
};

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    let even = PatchSize {
        px: 4,
        ..PatchSize::default()
    };

    assert!(PcaKdParams::default().validate().is_ok());
    assert_eq!(
        PcaKdParams::default().dims(0).validate().refused_argument(),
        Some("dims")
    );
    assert_eq!(
        PcaKdParams::default()
            .rerank(0)
            .validate()
            .refused_argument(),
        Some("rerank")
    );
    assert_eq!(
        PcaKdParams::default()
            .max_checks(0)
            .validate()
            .refused_argument(),
        Some("max_checks")
    );
    assert_eq!(
        PcaKdParams::default()
            .samples(0)
            .validate()
            .refused_argument(),
        Some("samples")
    );

    assert!(LowResParams::default().validate().is_ok());
    assert_eq!(
        LowResParams::default()
            .target_width(0)
            .validate()
            .refused_argument(),
        Some("target_width")
    );
    assert_eq!(
        LowResParams::default()
            .patch(even)
            .validate()
            .refused_argument(),
        Some("patch")
    );
    assert_eq!(
        LowResParams::default()
            .iters(vec![])
            .validate()
            .refused_argument(),
        Some("iters")
    );
    assert_eq!(
        LowResParams::default()
            .min_changed(-1.0)
            .validate()
            .refused_argument(),
        Some("min_changed")
    );
    assert_eq!(
        LowResParams::default()
            .min_energy_drop(f64::NAN)
            .validate()
            .refused_argument(),
        Some("min_energy_drop")
    );
    assert_eq!(
        LowResParams::default()
            .search(SearchMethod::PcaKdTree(PcaKdParams::default().rerank(0)))
            .validate()
            .refused_argument(),
        Some("rerank")
    );

    assert!(RefineParams::default().validate().is_ok());
    assert!(RefineParams::default().iterations(0).validate().is_ok());
    assert_eq!(
        RefineParams::default()
            .initial_fraction(0.0)
            .validate()
            .refused_argument(),
        Some("initial_fraction")
    );
    assert_eq!(
        RefineParams::default()
            .initial_fraction(1.5)
            .validate()
            .refused_argument(),
        Some("initial_fraction")
    );
    assert_eq!(
        RefineParams::default()
            .decrement(-0.2)
            .validate()
            .refused_argument(),
        Some("decrement")
    );

    assert!(LocalSearchParams::default().validate().is_ok());
    assert_eq!(
        LocalSearchParams::default()
            .windows(vec![])
            .validate()
            .refused_argument(),
        Some("windows")
    );
    assert_eq!(
        LocalSearchParams::default()
            .windows(vec![17, 12])
            .validate()
            .refused_argument(),
        Some("windows")
    );
    assert_eq!(
        LocalSearchParams::default()
            .hypothesis_window(2)
            .validate()
            .refused_argument(),
        Some("hypothesis_window")
    );
    assert_eq!(
        LocalSearchParams::default()
            .min_energy_drop(-1.0)
            .validate()
            .refused_argument(),
        Some("min_energy_drop")
    );

    assert!(CompletionParams::default().validate().is_ok());
    assert!(CompletionParams::default().refine(None).validate().is_ok());
    assert_eq!(
        CompletionParams::default()
            .low(LowResParams::default().target_width(0))
            .validate()
            .refused_argument(),
        Some("target_width")
    );
    assert_eq!(
        CompletionParams::default()
            .refine(Some(RefineParams::default().decrement(f64::NAN)))
            .validate()
            .refused_argument(),
        Some("decrement")
    );
    assert_eq!(
        CompletionParams::default()
            .local(LocalSearchParams::default().windows(vec![0]))
            .validate()
            .refused_argument(),
        Some("windows")
    );

    assert!(WexlerParams::default().validate().is_ok());
    assert_eq!(
        WexlerParams::default()
            .patch(even)
            .validate()
            .refused_argument(),
        Some("patch")
    );
    assert_eq!(
        WexlerParams::default()
            .decay(0.0)
            .validate()
            .refused_argument(),
        Some("decay")
    );

    // The methods check their parameters first.
    let video = Video::new(6, 16, 16, 3, vec![0; 6 * 16 * 16 * 3]).unwrap();
    let hole = Mask3::empty(6, 16, 16);
    let bad = CompletionParams::default().local(LocalSearchParams::default().windows(vec![4]));
    assert_eq!(
        check_input(&video, &hole, &bad).refused_argument(),
        Some("windows")
    );
    assert_eq!(
        wexler_complete(&video, &hole, &WexlerParams::default().decay(-1.0)).refused_argument(),
        Some("decay")
    );
}
