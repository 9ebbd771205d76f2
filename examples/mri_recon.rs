//! Paper 11: reconstruct the analytic Shepp-Logan k-space from 40% Cartesian samples with
//! UDCSMRI (C-SALSA + UDCT, l1 and TV), C-SALSA with the FDCT, SFLCT and db4 priors (Table 2) and
//! the paper's baselines, and print PSNR / RLNE and the time of each.
//!
//! `cargo run --release --example mri_recon [size]`

use std::time::Instant;

use wscg::csmri::baselines::{self, CompositeParams};
use wscg::csmri::{
    csalsa, masks, metrics, phantom, sparsifier, CsalsaParams, FdctParams, FdctSparsifier, KSpace,
    Reconstruction, Regularizer, UdctParams, UdctSparsifier, WaveletSparsifier,
};
use wscg::math::progress::NoProgress;

fn main() -> wscg::math::Result<()> {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(256);
    let reference = phantom::shepp_logan_reference(n)?;
    let mask = masks::cartesian(n, n, 0.4, 0.08, 1)?;
    let data = KSpace::new(n, n, phantom::shepp_logan_kspace(n)?, mask)?;
    let udct = UdctSparsifier::new(n, n, &UdctParams::default())?;
    let db4 = WaveletSparsifier::new(n, n, 4, 4)?;
    let fdct = FdctSparsifier::new(n, n, &FdctParams::default())?;
    let curvelet = CsalsaParams::default().tau0(sparsifier::tuned_tau0("fdct"));
    let comp = CompositeParams::default()
        .a(0.004)
        .b(0.0025)
        .group_weight(0.0025);
    let wavelet = CsalsaParams::default().tau0(sparsifier::tuned_tau0("db4"));
    let sflct = |prior: &'static str| {
        let data = &data;
        move || {
            let psi = sparsifier::by_name(prior, n, n, &sparsifier::PriorParams::default())?;
            let p = CsalsaParams::default().tau0(sparsifier::tuned_tau0(prior));
            csalsa(
                data,
                psi.as_ref(),
                Regularizer::default(),
                &p,
                None,
                &NoProgress,
            )
        }
    };
    type Run<'a> = Box<dyn Fn() -> wscg::math::Result<Reconstruction> + 'a>;
    let runs: Vec<(&str, Run)> = vec![
        (
            "zero-filled",
            Box::new(|| Ok(baselines::zero_filled(&data))),
        ),
        (
            "FCSA",
            Box::new(|| baselines::fcsa(&data, &comp, None, &NoProgress)),
        ),
        (
            "TVCMRI (Condat-Vu)",
            Box::new(|| baselines::tvcmri(&data, &comp, None, &NoProgress)),
        ),
        (
            "WaTMRI",
            Box::new(|| baselines::watmri(&data, &comp, None, &NoProgress)),
        ),
        (
            "C-SALSA db4 (l1)",
            Box::new(|| {
                csalsa(
                    &data,
                    &db4,
                    Regularizer::default(),
                    &wavelet,
                    None,
                    &NoProgress,
                )
            }),
        ),
        (
            "C-SALSA FDCT (l1)",
            Box::new(|| {
                csalsa(
                    &data,
                    &fdct,
                    Regularizer::default(),
                    &curvelet,
                    None,
                    &NoProgress,
                )
            }),
        ),
        ("C-SALSA LRSFLCT (l1)", Box::new(sflct("lrsflct"))),
        ("C-SALSA MRSFLCT (l1)", Box::new(sflct("mrsflct"))),
        (
            "UDCSMRI(l1)",
            Box::new(|| {
                csalsa(
                    &data,
                    &udct,
                    Regularizer::default(),
                    &CsalsaParams::default(),
                    None,
                    &NoProgress,
                )
            }),
        ),
        (
            "UDCSMRI(TV)",
            Box::new(|| {
                csalsa(
                    &data,
                    &udct,
                    Regularizer::Tv { inner_iters: 20 },
                    &CsalsaParams::default(),
                    None,
                    &NoProgress,
                )
            }),
        ),
    ];
    println!(
        "Shepp-Logan {n}^2, {:.1}% Cartesian, 70 iterations",
        100.0 * data.rate()
    );
    println!(
        "{:<20} {:>9} {:>8} {:>9}",
        "method", "PSNR dB", "RLNE", "time s"
    );
    for (name, run) in runs {
        let t = Instant::now();
        let r = run()?;
        println!(
            "{name:<20} {:>9.2} {:>8.4} {:>9.3}",
            metrics::psnr(&reference, &r.image)?,
            metrics::rlne(&reference, &r.image)?,
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
