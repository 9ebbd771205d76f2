//! Paper 03 demo: the hybrid ROI scheme on the head phantom at the paper's skull size
//! (256 x 256 x 112): pictures of the low-resolution context, the hybrid client, the Gradient
//! Octree alone and the full-resolution reference, and the bytes of every scheme of the
//! paper's Table 1 measured on serialized packages.

use std::path::Path;

use wscg_math::progress::Progress;
use wscg_math::{Image, Result};
use wscg_volren::phantoms::{head, head_tfs};
use wscg_volren::render::rgb;
use wscg_volren::{
    render_reference, Camera, HybridClient, HybridServer, RenderParams, Roi, ServerParams,
};

use super::figures::montage;
use super::{Demo, Figure, Report, Row};

/// Registration of this demo.
pub const DEMO: Demo = Demo {
    name: "volren-roi",
    paper: "03",
    title: "Hybrid ROI-based visualisation of medical volumes: packages, sizes and images",
    run,
};

fn run(out: &Path, progress: &dyn Progress) -> Result<Report> {
    let dims = [256, 256, 112];
    let mut rep = Report {
        summary: "The head phantom (3-D modified Shepp-Logan, 256 x 256 x 112 like the \
                  paper's skull) with a soft-tissue transfer function as the context and a \
                  bone transfer function in a 128 x 64 x 64 region of interest. The server \
                  sends a static package (transfer functions, the 1/64 wavelet volume, the \
                  Gradient Octree structure at one bit per node) and one ROI package (3 bytes \
                  a boundary voxel); all sizes are lengths of the serialized packages."
            .into(),
        ..Default::default()
    };
    progress.begin("volren demo", 5);
    let v = head(dims, 1)?;
    let tfs = head_tfs();
    let server = rep.time("server: wavelets + gradient octree (s)", || {
        HybridServer::new(&v, tfs.clone(), 0, ServerParams::default())
    })?;
    progress.advance(1);
    let (lo, hi) = ([128, 128, 32], [256, 192, 96]);
    let stat = server.static_package();
    let roi_pkg = rep.time("server: ROI package (s)", || server.roi_package(lo, hi))?;
    let mut client = rep.time("client: static package decode and rebuild (s)", || {
        HybridClient::from_static(&stat)
    })?;
    rep.time("client: ROI package (s)", || client.set_roi(&roi_pkg))?;
    progress.advance(1);
    let cam = Camera::orbit(dims, 30.0, 20.0, 256);
    let opts = RenderParams::default();
    let roi = Roi { min: lo, max: hi };
    let hybrid = rep.time("client: hybrid frame 256 x 256 (s)", || {
        client.render(&cam, 1, &opts)
    })?;
    let context = rep.time("wavelet context alone, frame 256 x 256 (s)", || {
        client.render_context(&cam, &opts)
    })?;
    let octree = client.render_octree(&cam, 1, &opts)?;
    // The Gradient Octree scheme's client: the whole octree received, rendered everywhere.
    let mut go_client = HybridClient::from_static(&stat)?;
    go_client.set_roi(&server.roi_package([0; 3], dims.map(|d| d as u32))?)?;
    rep.time("Gradient Octree scheme, frame 256 x 256 (s)", || {
        go_client.render_octree(&cam, 1, &opts)
    })?;
    // The wavelet scheme's client: every step received, full resolution inside the ROI.
    let full = wscg_volren::wavelet::decode_lowres(
        &wscg_volren::wavelet::encode_blocks(&v, &tfs[0], &Default::default(), 4)?,
        4,
    )?;
    rep.time("wavelet scheme, frame 256 x 256 (s)", || {
        client.render_wavelet_scheme(&full, &cam, 1, &opts)
    })?;
    let reference = rep.time("reference full-resolution frame 256 x 256 (s)", || {
        render_reference(&v, &tfs[0], Some((&roi, &tfs[1])), &cam, &opts)
    })?;
    progress.advance(1);
    let tiles = [&context, &hybrid, &octree, &reference]
        .iter()
        .map(|i| rgb(i))
        .collect::<Result<Vec<_>>>()?;
    montage(&tiles, 4, 1)?.save(out.join("views.png"))?;
    rep.figures.push(Figure {
        file: "views.png".into(),
        caption: "Left to right: the wavelet context alone (1/64 of the voxels, soft-tissue \
                  transfer function, unlit); the hybrid client (bone in the ROI from the \
                  Gradient Octree, shaded with its 18-bit normals); the ROI's octree alone; \
                  the full-resolution reference with the same transfer functions."
            .into(),
    });
    let r = server.size_report(lo, hi, 1, Some(&Camera::orbit(dims, 30.0, 20.0, 512)))?;
    progress.advance(1);
    let mb = |b: usize| format!("{:.2} MB ({:.1} %)", b as f64 / 1e6, 100.0 * r.rate(b));
    let paper = "Table 1, skull 256 x 256 x 112";
    for (scheme, bytes, reported) in [
        ("raw volume (Volume Viewer)", r.raw, "7.3 MB (100 %)"),
        ("wavelet scheme, all steps", r.wavelets, "1.91 MB (32 %)"),
        (
            "Gradient Octree, whole volume",
            r.gradient_octree,
            "3.8 MB (22 %)",
        ),
    ] {
        rep.table.push(Row::new(scheme, mb(bytes), reported, paper));
    }
    rep.table.push(Row::new(
        "hybrid: static + ROI package",
        format!(
            "{} = {} + {} B",
            mb(r.hybrid()),
            r.hybrid_static,
            r.hybrid_roi
        ),
        "2.04 MB (18 %)",
        paper,
    ));
    if let Some(f) = r.thin_client_frame {
        rep.table.push(Row::new(
            "thin client: one JPEG frame, 512 x 512, q 85 (B)",
            f.to_string(),
            "0.18 MB at 1080 x 1920",
            paper,
        ));
        for (name, b, p) in [
            ("wavelets", r.wavelets, "11"),
            ("Gradient Octree", r.gradient_octree, "21"),
            ("hybrid", r.hybrid(), "11"),
        ] {
            rep.table.push(Row::new(
                format!("break-even thin-client frames: {name}"),
                format!("{:.0}", b as f64 / f as f64),
                p,
                "bytes / bytes of one frame (our frame is smaller)",
            ));
        }
    }
    // ROI pixels: where the rays meet the ROI box.
    let mask: Vec<bool> = (0..256 * 256)
        .map(|p| {
            (0..3).any(|k| {
                (hybrid.data()[4 * p + k] - context.data()[4 * p + k]).abs() > 1e-6
                    || (reference.data()[4 * p + k] - context.data()[4 * p + k]).abs() > 0.02
            })
        })
        .collect();
    let pick = |img: &Image<f32>| -> Vec<f32> {
        mask.iter()
            .enumerate()
            .filter(|(_, &m)| m)
            .flat_map(|(p, _)| img.data()[4 * p..4 * p + 3].to_vec())
            .collect()
    };
    let refp = pick(&reference);
    for (name, img) in [("hybrid", &hybrid), ("context only", &context)] {
        rep.table.push(Row::new(
            format!("PSNR on ROI pixels vs the full-resolution reference: {name} (dB)"),
            format!("{:.2}", wscg_math::metrics::psnr(&refp, &pick(img), 1.0)?),
            "",
            "required: the hybrid gains >= 2 dB over the context alone",
        ));
    }
    progress.advance(1);
    progress.finish();
    Ok(rep)
}
