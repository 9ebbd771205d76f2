//! Check 8: the size of the paper's case 1 (512×512×337, K = 15). Mean CG iterations
//! per label at tol 3e-3 in the paper's range (Fig. 9: 45-136, mean 83; accepted window
//! [45, 200]). The time per label is printed; its target (≤ 3 s per label on 2 cores) is
//! checked by `benches/volseg.rs`, not here.

use std::time::Instant;

use wscg_volseg::{
    fractured_shell_phantom, BoneGraph, PhantomParams, RandomWalkParams, RandomWalkSession,
};

#[test]
fn case_one_size_converges_in_the_papers_iteration_range() {
    let t = Instant::now();
    let ph = fractured_shell_phantom(&PhantomParams::default().dims([512, 512, 337]).fragments(15))
        .unwrap();
    let t_phantom = t.elapsed().as_secs_f64();
    let p = RandomWalkParams::paper();
    let t = Instant::now();
    let g = BoneGraph::build(&ph.ct, &p).unwrap();
    let t_graph = t.elapsed().as_secs_f64();
    let n = g.len();
    let mut s = RandomWalkSession::new(g, p).unwrap();
    s.set_seeds(&ph.seeds).unwrap();
    let t = Instant::now();
    let r = s.solve(false).unwrap();
    let t_solve = t.elapsed().as_secs_f64();
    let mean = r.mean_iterations();
    println!(
        "512x512x337, K = 15: {n} bone voxels; phantom {t_phantom:.1} s, graph {t_graph:.2} s, \
         solve {t_solve:.1} s ({:.2} s per label); iterations per label {:?} (mean {mean:.1})",
        t_solve / 15.0,
        r.iterations
    );
    assert_eq!(r.iterations.len(), 15);
    assert!(r.converged.iter().all(|&c| c), "{r:?}");
    assert!((45.0..=200.0).contains(&mean), "{mean}");
}
