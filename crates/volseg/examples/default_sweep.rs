//! Sweep of the random-walk weights' ε, the regulariser κ and the sharpness β (paper eq. 1
//! and section 2.4) on fractured-shell phantoms: Dice against the truth, mean CG iterations
//! per label and seconds, beside the geodesic nearest-seed baseline; with `warm`, the label
//! agreement of a warm-started re-solve (half of every stroke first, then the rest) with a
//! cold solve; with `tol`, the label agreement and largest probability difference of a
//! tolerance against an `f64` solve to 1e-9.
//!
//! `cargo run --release -p wscg-volseg --example default_sweep -- [sweep|warm|tol] SIZE:K:SEED ...`
//! (lists in the environment: `BETA`, `EPS`, `KAPPA`, `TOL`; `SURFACE=1` paints the strokes
//! on the outer surface).

use std::time::Instant;

use wscg_volseg::{
    dice_multilabel, fractured_shell_phantom, nearest_seed_labels, BoneGraph, Phantom,
    PhantomParams, Precision, RandomWalkParams, RandomWalkSession,
};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn solve(ph: &Phantom, p: RandomWalkParams) -> Res<(Vec<u16>, RandomWalkSession, f64, f64)> {
    let t = Instant::now();
    let g = BoneGraph::build(&ph.ct, &p)?;
    let mut s = RandomWalkSession::new(g, p)?;
    s.set_seeds(&ph.seeds)?;
    let r = s.solve(false)?;
    let secs = t.elapsed().as_secs_f64();
    Ok((s.labels()?.into_data(), s, r.mean_iterations(), secs))
}

fn nearest(ph: &Phantom, s: &RandomWalkSession) -> Vec<u16> {
    let g = s.graph();
    let node_seeds: Vec<u16> = (0..g.len()).map(|i| ph.seeds.data()[g.voxel(i)]).collect();
    let mut out = vec![0u16; ph.truth.len()];
    for (i, l) in nearest_seed_labels(g, &node_seeds).into_iter().enumerate() {
        out[g.voxel(i)] = l;
    }
    out
}

/// Fraction of the bone nodes where both label vectors agree.
fn agreement(a: &[u16], b: &[u16], truth: &[u16]) -> f64 {
    let (mut same, mut n) = (0usize, 0usize);
    for i in 0..truth.len() {
        if truth[i] != 0 {
            n += 1;
            same += usize::from(a[i] == b[i]);
        }
    }
    same as f64 / n.max(1) as f64
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = args.first().map_or("sweep", String::as_str);
    let cases: Vec<(usize, usize, u64)> = args[1..]
        .iter()
        .map(|c| {
            let v: Vec<u64> = c.split(':').map(|x| x.parse().unwrap()).collect();
            (v[0] as usize, v[1] as usize, v[2])
        })
        .collect();
    let env_list = |name: &str, d: &[f64]| -> Vec<f64> {
        std::env::var(name).map_or(d.to_vec(), |s| {
            s.split(',').map(|x| x.parse().unwrap()).collect()
        })
    };
    let epss = env_list("EPS", &[1e-2, 1e-3, 1e-4, 1e-6, 1e-10]);
    let kappas = env_list("KAPPA", &[1e-3, 1e-6, 0.0]);
    let betas = env_list("BETA", &[1000.0, 3000.0, 10000.0]);
    let tols = env_list("TOL", &[3e-3, 1e-3, 3e-4, 1e-4]);
    for &(n, k, seed) in &cases {
        let ph = fractured_shell_phantom(
            &PhantomParams::default()
                .dims([n; 3])
                .fragments(k)
                .seed(seed)
                .surface_strokes(std::env::var("SURFACE").is_ok_and(|v| v == "1")),
        )?;
        let truth = ph.truth.data();
        let mut ns_done = false;
        for &beta in &betas {
            for &eps in &epss {
                for &kappa in &kappas {
                    let p = RandomWalkParams::default().eps(eps).kappa(kappa).beta(beta);
                    let (labels, s, it, secs) = solve(&ph, p)?;
                    if !ns_done {
                        let d = dice_multilabel(&nearest(&ph, &s), truth)?;
                        println!(
                            "case {n}^3 K={k} seed={seed} nodes={} nearest {d:.4}",
                            s.graph().len()
                        );
                        ns_done = true;
                    }
                    let dsc = dice_multilabel(&labels, truth)?;
                    match mode {
                        "sweep" => println!(
                            "row {n} {k} {seed} beta={beta} eps={eps:e} kappa={kappa:e} dsc={dsc:.4} it={it:.1} s={secs:.3}"
                        ),
                        "warm" => {
                            // Half of every stroke, solve, then the rest with a warm start.
                            let g = BoneGraph::build(&ph.ct, &p)?;
                            let mut w = RandomWalkSession::new(g, p)?;
                            let mut first = ph.seeds.clone();
                            let mut rest: Vec<Vec<usize>> = vec![Vec::new(); k + 1];
                            let mut count = vec![0usize; k + 1];
                            for (v, l) in first.data_mut().iter_mut().enumerate() {
                                if *l != 0 {
                                    count[*l as usize] += 1;
                                    if count[*l as usize].is_multiple_of(2) {
                                        rest[*l as usize].push(v);
                                        *l = 0;
                                    }
                                }
                            }
                            w.set_seeds(&first)?;
                            w.solve(false)?;
                            for (l, vox) in rest.iter().enumerate().skip(1) {
                                w.add_seeds(vox, l as u16)?;
                            }
                            let t = Instant::now();
                            let r = w.solve(true)?;
                            let wl = w.labels()?.into_data();
                            println!(
                                "warm {n} {k} {seed} beta={beta} eps={eps:e} kappa={kappa:e} dsc={dsc:.4} cold_it={it:.1} warm_it={:.1} warm_s={:.3} agree={:.5}",
                                r.mean_iterations(),
                                t.elapsed().as_secs_f64(),
                                agreement(&wl, &labels, truth)
                            );
                        }
                        _ => {
                            let (rl, rs, rit, _) =
                                solve(&ph, p.precision(Precision::F64).tol(1e-9))?;
                            let m = rs.graph().len();
                            let kk = rs.n_labels() as u16;
                            for &tol in &tols {
                                for prec in [Precision::F32, Precision::F64] {
                                    let (l, s2, it2, secs2) =
                                        solve(&ph, p.precision(prec).tol(tol))?;
                                    let mut dmax = 0.0f64;
                                    for lab in 1..=kk {
                                        let a = s2.node_probabilities(lab);
                                        let b = rs.node_probabilities(lab);
                                        for i in 0..m {
                                            dmax = dmax.max((a[i] - b[i]).abs());
                                        }
                                    }
                                    println!(
                                        "tol {n} {k} {seed} beta={beta} eps={eps:e} kappa={kappa:e} {prec:?} tol={tol:e} it={it2:.1} ref_it={rit:.1} s={secs2:.3} agree={:.5} dprob={dmax:.2e} dsc={:.4}",
                                        agreement(&l, &rl, truth),
                                        dice_multilabel(&l, truth)?
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    Ok(())
}
