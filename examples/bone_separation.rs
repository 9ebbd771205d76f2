//! Paper 18 on the fractured-shell phantom: the solver variants of the paper's Fig. 9
//! (plain CG, Jacobi-PCG on one thread and on all, and the K-block Jacobi-PCG) with their
//! iterations and seconds per label, the Dice of the labels against the truth and the
//! geodesic nearest-seed baseline.
//!
//! `cargo run --release --example bone_separation [nx ny nz K [variants]]`; the default is the
//! size of the paper's case 1, 512×512×337 with 15 labels; `variants` is a comma list of
//! `block`, `block64`, `jacobi`, `jacobi1`, `cg` (default `block,jacobi`).

use std::time::Instant;

use wscg::volseg::{
    dice_multilabel, fractured_shell_phantom, nearest_seed_labels, BoneGraph, PhantomParams,
    Precision, RandomWalkParams, RandomWalkSession, Solver,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize, d: usize| -> Result<usize, std::num::ParseIntError> {
        args.get(i).map_or(Ok(d), |s| s.parse())
    };
    let dims = [num(0, 512)?, num(1, 512)?, num(2, 337)?];
    let k = num(3, 15)?;
    let variants = args.get(4).map_or("block,jacobi", String::as_str);
    let t = Instant::now();
    let ph = fractured_shell_phantom(&PhantomParams::default().dims(dims).fragments(k))?;
    println!(
        "phantom {dims:?}, K = {k}: built in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    // The paper's weights (its iteration counts and timings are what this compares with).
    let base = RandomWalkParams::paper();
    let t = Instant::now();
    let graph = BoneGraph::build(&ph.ct, &base)?;
    println!(
        "bone-only graph: {} nodes ({:.1} % of the voxels), {} edges, {:.0} MB, {:.2} s",
        graph.len(),
        100.0 * graph.len() as f64 / ph.ct.len() as f64,
        graph.edges(),
        graph.memory_bytes() as f64 / 1e6,
        t.elapsed().as_secs_f64()
    );
    let node_seeds: Vec<u16> = (0..graph.len())
        .map(|i| ph.seeds.data()[graph.voxel(i)])
        .collect();
    let mut ns = vec![0u16; ph.ct.len()];
    for (i, l) in nearest_seed_labels(&graph, &node_seeds)
        .into_iter()
        .enumerate()
    {
        ns[graph.voxel(i)] = l;
    }
    let dsc_ns = dice_multilabel(&ns, ph.truth.data())?;
    println!("geodesic nearest seed: DSC {dsc_ns:.4}");
    println!(
        "{:<34} {:>10} {:>12} {:>10} {:>8}",
        "solver", "mean iter", "s per label", "total s", "DSC"
    );
    for v in variants.split(',') {
        let (name, p) = match v {
            "block" => ("K-block Jacobi-PCG, f32, all threads", base),
            "block64" => (
                "K-block Jacobi-PCG, f64, all threads",
                base.precision(Precision::F64),
            ),
            "jacobi" => (
                "per-label Jacobi-PCG, all threads",
                base.solver(Solver::PerLabel),
            ),
            "jacobi1" => (
                "per-label Jacobi-PCG, one thread",
                base.solver(Solver::PerLabel).threads(Some(1)),
            ),
            "cg" => (
                "per-label plain CG, all threads",
                base.solver(Solver::PerLabel).jacobi(false),
            ),
            other => return Err(format!("unknown variant {other}").into()),
        };
        let mut s = RandomWalkSession::new(graph.clone(), p)?;
        s.set_seeds(&ph.seeds)?;
        let t = Instant::now();
        let r = s.solve(false)?;
        let total = t.elapsed().as_secs_f64();
        let mean = r.mean_iterations();
        let dsc = dice_multilabel(s.labels()?.data(), ph.truth.data())?;
        println!(
            "{name:<34} {mean:>10.1} {:>12.3} {total:>10.2} {dsc:>8.4}",
            total / r.iterations.len() as f64
        );
    }
    Ok(())
}
