//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also where [`Sim::new`] starts).

use wscg_cloth::{ClothModel, Method, Relaxation, Sim, SolverParams};
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
    let d = SolverParams::default;
    assert!(d().validate().is_ok());
    assert_eq!(field(d().iterations(0).validate()), "iterations");
    assert_eq!(field(d().alpha(0.0).validate()), "alpha");
    assert_eq!(field(d().beta(1.5).validate()), "beta");
    assert_eq!(field(d().gamma(f64::NAN).validate()), "gamma");
    assert_eq!(field(d().gamma(-1.0).validate()), "gamma");
    assert_eq!(
        field(d().velocity_damping(2.0).validate()),
        "velocity_damping"
    );
    let method = |m| d().method(m).validate();
    assert_eq!(
        field(method(Method::PlainPbd { stiffness: 0.0 })),
        "stiffness"
    );
    assert_eq!(
        field(method(Method::SymplecticEuler { substeps: 0 })),
        "substeps"
    );
    assert_eq!(
        field(method(Method::GlobalCr {
            primal_residual: false,
            tol: f64::NAN
        })),
        "tol"
    );
    assert_eq!(
        field(
            d().alpha(0.5)
                .method(Method::GlobalCr {
                    primal_residual: false,
                    tol: 1e-8
                })
                .validate()
        ),
        "method"
    );
    assert_eq!(
        field(method(Method::ImplicitEulerNewton { tol: 0.0 })),
        "tol"
    );
    assert_eq!(
        field(method(Method::ImplicitEulerCg {
            tol: -1.0,
            max_iter: 10
        })),
        "tol"
    );
    assert_eq!(
        field(method(Method::ImplicitEulerCg {
            tol: 1e-8,
            max_iter: 0
        })),
        "max_iter"
    );
    assert!(method(Method::ImplicitEulerCg {
        tol: 1e-8,
        max_iter: 10
    })
    .is_ok());
    assert_eq!(
        field(d().relaxation(Relaxation::Jacobi { omega: 1.5 }).validate()),
        "omega"
    );
    assert_eq!(
        field(d().relaxation(Relaxation::Sor { omega: 2.0 }).validate()),
        "omega"
    );

    // The simulation refuses bad parameters when it is built.
    let model = ClothModel::grid(3, 3, (1.0, 1.0), 0.1, 2.0, None, None).unwrap();
    assert_eq!(field(Sim::new(model.clone(), d().alpha(2.0))), "alpha");
    assert!(Sim::new(model, d()).is_ok());
}
