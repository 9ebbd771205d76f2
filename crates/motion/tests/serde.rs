//! A serialised action library is the library, every field bit for bit; a library of
//! inconsistent sizes is refused by `validate`.

use wscg_motion::stepwise::{fit_stepwise, ActionLibrary, StepwiseParams};
use wscg_motion::walker::{reach_walk, WalkerParams};

fn library() -> ActionLibrary {
    let (data, _) = reach_walk(&WalkerParams::default().n_trials(6)).unwrap();
    let mut p = StepwiseParams::default();
    p.demix = p.demix.restarts(1).max_iter(40);
    fit_stepwise(&data, &p).unwrap()
}

#[test]
fn serialised_library_is_identical() {
    let a = library();
    let b: ActionLibrary = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
    b.validate().unwrap();
    assert_eq!(a.sources, b.sources);
    assert_eq!(a.delays, b.delays);
    assert_eq!(a.actions, b.actions);
    assert_eq!(a.params, b.params);
    assert_eq!(a.progress, b.progress);
    assert_eq!(a.q_total.to_bits(), b.q_total.to_bits());
    assert_eq!(a.demix_first.weights, b.demix_first.weights);
    for (r, act) in [(0, 0), (2, 1), (5, 2)] {
        assert_eq!(a.weight_vector(act, r), b.weight_vector(act, r));
    }
}

#[test]
fn inconsistent_library_is_refused() {
    let a = library();
    a.validate().unwrap();
    let mut b = a.clone();
    b.delays.pop();
    assert!(b.validate().is_err());
    let mut b = a.clone();
    b.actions[1].weights.pop();
    assert!(b.validate().is_err());
    let mut b = a;
    b.progress.clear();
    assert!(b.validate().is_err());
}
