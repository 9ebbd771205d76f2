//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::Result;
use wscg_video::complete::check_input;
use wscg_video::{
    wexler_complete, CompletionParams, LocalSearchParams, LowResParams, Mask3, PatchSize,
    PcaKdParams, RefineParams, SearchMethod, Video, WexlerParams,
};

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
    let even = PatchSize {
        px: 4,
        ..PatchSize::default()
    };

    assert!(PcaKdParams::default().validate().is_ok());
    assert_eq!(field(PcaKdParams::default().dims(0).validate()), "dims");
    assert_eq!(field(PcaKdParams::default().rerank(0).validate()), "rerank");
    assert_eq!(
        field(PcaKdParams::default().max_checks(0).validate()),
        "max_checks"
    );
    assert_eq!(
        field(PcaKdParams::default().samples(0).validate()),
        "samples"
    );

    assert!(LowResParams::default().validate().is_ok());
    assert_eq!(
        field(LowResParams::default().target_width(0).validate()),
        "target_width"
    );
    assert_eq!(
        field(LowResParams::default().patch(even).validate()),
        "patch"
    );
    assert_eq!(
        field(LowResParams::default().iters(vec![]).validate()),
        "iters"
    );
    assert_eq!(
        field(LowResParams::default().min_changed(-1.0).validate()),
        "min_changed"
    );
    assert_eq!(
        field(LowResParams::default().min_energy_drop(f64::NAN).validate()),
        "min_energy_drop"
    );
    assert_eq!(
        field(
            LowResParams::default()
                .search(SearchMethod::PcaKdTree(PcaKdParams::default().rerank(0)))
                .validate()
        ),
        "rerank"
    );

    assert!(RefineParams::default().validate().is_ok());
    assert!(RefineParams::default().iterations(0).validate().is_ok());
    assert_eq!(
        field(RefineParams::default().initial_fraction(0.0).validate()),
        "initial_fraction"
    );
    assert_eq!(
        field(RefineParams::default().initial_fraction(1.5).validate()),
        "initial_fraction"
    );
    assert_eq!(
        field(RefineParams::default().decrement(-0.2).validate()),
        "decrement"
    );

    assert!(LocalSearchParams::default().validate().is_ok());
    assert_eq!(
        field(LocalSearchParams::default().windows(vec![]).validate()),
        "windows"
    );
    assert_eq!(
        field(
            LocalSearchParams::default()
                .windows(vec![17, 12])
                .validate()
        ),
        "windows"
    );
    assert_eq!(
        field(
            LocalSearchParams::default()
                .min_energy_drop(-1.0)
                .validate()
        ),
        "min_energy_drop"
    );

    assert!(CompletionParams::default().validate().is_ok());
    assert!(CompletionParams::default().refine(None).validate().is_ok());
    assert_eq!(
        field(
            CompletionParams::default()
                .low(LowResParams::default().target_width(0))
                .validate()
        ),
        "target_width"
    );
    assert_eq!(
        field(
            CompletionParams::default()
                .refine(Some(RefineParams::default().decrement(f64::NAN)))
                .validate()
        ),
        "decrement"
    );
    assert_eq!(
        field(
            CompletionParams::default()
                .local(LocalSearchParams::default().windows(vec![0]))
                .validate()
        ),
        "windows"
    );

    assert!(WexlerParams::default().validate().is_ok());
    assert_eq!(
        field(WexlerParams::default().patch(even).validate()),
        "patch"
    );
    assert_eq!(
        field(WexlerParams::default().decay(0.0).validate()),
        "decay"
    );

    // The methods check their parameters first.
    let video = Video::new(6, 16, 16, 3, vec![0; 6 * 16 * 16 * 3]).unwrap();
    let hole = Mask3::empty(6, 16, 16);
    let bad = CompletionParams::default().local(LocalSearchParams::default().windows(vec![4]));
    assert_eq!(field(check_input(&video, &hole, &bad)), "windows");
    assert_eq!(
        field(wexler_complete(
            &video,
            &hole,
            &WexlerParams::default().decay(-1.0)
        )),
        "decay"
    );
}
