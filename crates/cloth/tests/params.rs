//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also where [`Simulation::new`] starts).

use wscg_cloth::{ClothModel, Method, Relaxation, Simulation, SolverParams};
use wscg_math::RefusedArgument;

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    let d = SolverParams::default;
    assert!(d().validate().is_ok());
    assert_eq!(
        d().iterations(0).validate().refused_argument(),
        Some("iterations")
    );
    assert_eq!(d().alpha(0.0).validate().refused_argument(), Some("alpha"));
    assert_eq!(d().beta(1.5).validate().refused_argument(), Some("beta"));
    assert_eq!(
        d().gamma(f64::NAN).validate().refused_argument(),
        Some("gamma")
    );
    assert_eq!(d().gamma(-1.0).validate().refused_argument(), Some("gamma"));
    assert_eq!(
        d().velocity_damping(2.0).validate().refused_argument(),
        Some("velocity_damping")
    );
    let method = |m| d().method(m).validate();
    assert_eq!(
        method(Method::PlainPbd { stiffness: 0.0 }).refused_argument(),
        Some("stiffness")
    );
    assert_eq!(
        method(Method::SymplecticEuler { substeps: 0 }).refused_argument(),
        Some("substeps")
    );
    assert_eq!(
        method(Method::GlobalCr {
            primal_residual: false,
            tol: f64::NAN
        })
        .refused_argument(),
        Some("tol")
    );
    assert_eq!(
        d().alpha(0.5)
            .method(Method::GlobalCr {
                primal_residual: false,
                tol: 1e-8
            })
            .validate()
            .refused_argument(),
        Some("method")
    );
    assert_eq!(
        method(Method::ImplicitEulerNewton { tol: 0.0 }).refused_argument(),
        Some("tol")
    );
    assert_eq!(
        method(Method::ImplicitEulerCg {
            tol: -1.0,
            max_iter: 10
        })
        .refused_argument(),
        Some("tol")
    );
    assert_eq!(
        method(Method::ImplicitEulerCg {
            tol: 1e-8,
            max_iter: 0
        })
        .refused_argument(),
        Some("max_iter")
    );
    assert!(method(Method::ImplicitEulerCg {
        tol: 1e-8,
        max_iter: 10
    })
    .is_ok());
    assert_eq!(
        d().relaxation(Relaxation::Jacobi { omega: 1.5 })
            .validate()
            .refused_argument(),
        Some("omega")
    );
    assert_eq!(
        d().relaxation(Relaxation::Sor { omega: 2.0 })
            .validate()
            .refused_argument(),
        Some("omega")
    );

    // The simulation refuses bad parameters when it is built.
    let model = ClothModel::grid(3, 3, (1.0, 1.0), 0.1, 2.0, None, None).unwrap();
    assert_eq!(
        Simulation::new(model.clone(), d().alpha(2.0)).refused_argument(),
        Some("alpha")
    );
    assert!(Simulation::new(model, d()).is_ok());
}
