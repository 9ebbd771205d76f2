//! A serialised session (graph, seeds, last solution) re-solves exactly as the original:
//! the warm start travels with it; damaged states are refused.

use wscg_volseg::{fractured_shell_phantom, PhantomParams, RandomWalkParams, RandomWalkSession};

fn session() -> RandomWalkSession {
    let ph =
        fractured_shell_phantom(&PhantomParams::default().dims([28, 28, 28]).fragments(3)).unwrap();
    let p = RandomWalkParams::default().tol(1e-5);
    let g = wscg_volseg::BoneGraph::build(&ph.ct, &p).unwrap();
    let mut s = RandomWalkSession::new(g, p).unwrap();
    s.set_seeds(&ph.seeds).unwrap();
    s.solve(false).unwrap();
    s
}

#[test]
fn serialised_session_re_solves_identically() {
    let mut a = session();
    let json = serde_json::to_string(&a).unwrap();
    let mut b: RandomWalkSession = serde_json::from_str(&json).unwrap();
    assert_eq!(a.graph().len(), b.graph().len());
    assert_eq!(a.graph().edges(), b.graph().edges());
    for v in [0, 5000, 28 * 28 * 28 - 1] {
        assert_eq!(a.graph().node(v), b.graph().node(v));
    }
    assert_eq!(a.node_labels(), b.node_labels());
    // A stroke of a new label, then warm re-solves: same iterations, same probabilities.
    let stroke: Vec<usize> = (0..a.graph().len())
        .step_by(97)
        .map(|i| a.graph().voxel(i))
        .collect();
    a.add_seeds(&stroke, 4).unwrap();
    b.add_seeds(&stroke, 4).unwrap();
    let (ra, rb) = (a.solve(true).unwrap(), b.solve(true).unwrap());
    assert_eq!(ra.iterations, rb.iterations);
    assert_eq!(ra.residuals, rb.residuals);
    for l in 1..=4 {
        assert_eq!(a.node_probabilities(l), b.node_probabilities(l));
    }
}

#[test]
fn inconsistent_state_is_refused() {
    let a = session();
    let mut v: serde_json::Value = serde_json::to_value(&a).unwrap();
    // One seed short of the graph.
    v["seeds"].as_array_mut().unwrap().pop();
    assert!(serde_json::from_value::<RandomWalkSession>(v).is_err());
    let mut v: serde_json::Value = serde_json::to_value(&a).unwrap();
    // A node id out of range.
    v["graph"]["nbr"][0][0] = serde_json::json!(1u64 << 31);
    assert!(serde_json::from_value::<RandomWalkSession>(v).is_err());
    let mut v: serde_json::Value = serde_json::to_value(&a).unwrap();
    // Two nodes on one voxel.
    v["graph"]["voxel_of_node"][1] = v["graph"]["voxel_of_node"][0].clone();
    assert!(serde_json::from_value::<RandomWalkSession>(v).is_err());
}
