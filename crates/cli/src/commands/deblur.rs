//! `wscg deblur`: paper 12 (gyroscope-driven multi-frame deblurring) on the user's own data.
//!
//! - `frames`: deblur one frame of a burst, or every frame of a folder, from its gyroscope log
//!   (multi-frame KM, or a single-frame method).
//! - `kernel`: render the blur kernel of a pixel as a PNG.
//! - `simulate`: render a synthetic shaken burst of an image (frames, gyro log, times,
//!   camera file).
//!
//! Gyroscope logs are CSV text, one sample per line: `t,wx,wy,wz` (seconds, rad/s in camera
//! axes); lines starting with `#` and a non-numeric header are skipped. Frame images are
//! grayscale (colour is converted) display values. Input files are only read.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use wscg_deblur::metrics::quality;
use wscg_deblur::synth::{self, BlurRenderParams, Burst, ShakeParams};
use wscg_deblur::{
    deblur_frame, deblur_multiframe, render_kernel, AlignMode, CameraFile, Gamma, GyroTrack,
    HyperLaplacianParams, Intrinsics, KernelParams, Method, MultiframeParams,
};
use wscg_math::{Error, Image, Result};

use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum DeblurCommand {
    /// Deblur one frame of a burst with the gyroscope log.
    Frames(FramesArgs),
    /// Render the blur kernel of one pixel as a PNG (scaled to its peak).
    Kernel(KernelArgs),
    /// Render a synthetic shaken burst of an image (frames, times, gyro.csv, camera.json).
    Simulate(SimulateArgs),
}

#[derive(Args, Debug)]
pub struct Camera {
    /// Gyroscope log (CSV: t,wx,wy,wz; seconds, rad/s, camera axes).
    #[arg(long)]
    gyro: PathBuf,
    /// Camera file (JSON): {"f": px, "cx": px, "cy": px, "exposure": s, "readout": s,
    /// "delay": s}; cx, cy default to the frame centre. Flags below override its values.
    #[arg(long)]
    camera: Option<PathBuf>,
    /// Focal length in pixels.
    #[arg(long)]
    f: Option<f64>,
    /// Principal point "cx,cy" in pixels (default: the frame centre).
    #[arg(long)]
    principal: Option<String>,
    /// Exposure time in seconds (default 0.03).
    #[arg(long)]
    exposure: Option<f64>,
    /// Rolling-shutter readout time in seconds (default 0: global shutter).
    #[arg(long)]
    readout: Option<f64>,
    /// Gyroscope-camera delay in seconds (default 0).
    #[arg(long)]
    delay: Option<f64>,
}

/// Intrinsics and exposure timing resolved from the flags and the camera file.
struct Setup {
    k: Intrinsics,
    exposure: f64,
    readout: f64,
    delay: f64,
}

impl Camera {
    fn setup(&self, width: usize, height: usize) -> Result<Setup> {
        let file = match &self.camera {
            Some(p) => CameraFile::read(p)?,
            None => CameraFile::default(),
        };
        let f = self.f.or(file.f).ok_or_else(|| {
            Error::invalid(
                "f",
                "intrinsics missing: give --f or a --camera file with \"f\"",
            )
        })?;
        let mut k = Intrinsics::centred(f, width, height);
        (k.cx, k.cy) = match &self.principal {
            Some(p) => parse_pair(p, "principal")?,
            None => (file.cx.unwrap_or(k.cx), file.cy.unwrap_or(k.cy)),
        };
        k.validate()?;
        Ok(Setup {
            k,
            exposure: self.exposure.or(file.exposure).unwrap_or(0.03),
            readout: self.readout.or(file.readout).unwrap_or(0.0),
            delay: self.delay.or(file.delay).unwrap_or(0.0),
        })
    }
}

#[derive(Args, Debug)]
pub struct FramesArgs {
    /// Frame images in time order, or one folder of frames (sorted by name; its times.txt is
    /// used when --times is not given).
    #[arg(required = true)]
    frames: Vec<PathBuf>,
    #[command(flatten)]
    camera: Camera,
    /// Frame time stamps "t0,t1,..." in seconds, or a text file with one per line.
    #[arg(long)]
    times: Option<String>,
    /// Index of the frame to deblur (default: the middle one; every frame when --out is a folder).
    #[arg(long)]
    main: Option<usize>,
    /// Method: multi (multi-frame KM), krishnan, wiener, rl or global.
    #[arg(long, default_value = "multi")]
    method: String,
    /// Data weight lambda of the hyper-Laplacian solver (the paper's 2000; the noise-aware
    /// weight of the library's uniform-kernel deconvolution loses here, on gyro kernels).
    #[arg(long, default_value_t = 2000.0)]
    lambda: f32,
    /// Weight mu of the multi-frame prior.
    #[arg(long, default_value_t = MultiframeParams::default().mu)]
    mu: f32,
    /// Align neighbours with the gyroscope only (no ECC refinement).
    #[arg(long)]
    gyro_align: bool,
    /// Treat pixel values as linear (no gamma 2.2 camera response).
    #[arg(long)]
    linear: bool,
    /// Frames on each side used by the multi-frame method.
    #[arg(long, default_value_t = 2)]
    radius: usize,
    /// Sharp reference image to report PSNR/SSIM against (16 px border excluded).
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Output image, or a folder: then every frame is deblurred and written there under its
    /// input name (PNG).
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct KernelArgs {
    #[command(flatten)]
    camera: Camera,
    /// Frame time stamp in seconds.
    #[arg(long)]
    time: f64,
    /// Pixel "x,y".
    #[arg(long)]
    at: String,
    /// Frame height in rows (rolling-shutter timing).
    #[arg(long)]
    height: usize,
    /// Frame width (for the default principal point).
    #[arg(long)]
    width: usize,
    /// Output PNG.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Sharp image (display values; colour is converted to gray).
    image: PathBuf,
    /// Number of frames.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Shake: rate standard deviations "pitch,yaw,roll" in rad/s.
    #[arg(long, default_value = "0.35,0.35,0.1")]
    shake: String,
    /// Focal length in pixels.
    #[arg(long, default_value_t = 600.0)]
    f: f64,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output folder: frames/frame_NN.png and frames/times.txt, gyro.csv, camera.json, sharp.png.
    #[arg(long)]
    out_dir: PathBuf,
}

fn parse_list(s: &str, name: &'static str) -> Result<Vec<f64>> {
    s.split(',')
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .map_err(|_| Error::invalid(name, format!("{v:?} is not a number")))
        })
        .collect()
}

fn parse_pair(s: &str, name: &'static str) -> Result<(f64, f64)> {
    match parse_list(s, name)?.as_slice() {
        [a, b] => Ok((*a, *b)),
        _ => Err(Error::invalid(
            name,
            format!("expected two numbers \"a,b\", got {s:?}"),
        )),
    }
}

/// Frame times from a file (`wscg_deblur::gyro::read_frame_times`) or a comma list.
pub(super) fn read_times(s: &str) -> Result<Vec<f64>> {
    let p = Path::new(s);
    if p.is_file() {
        wscg_deblur::gyro::read_frame_times(p)
    } else {
        parse_list(s, "times")
    }
}

/// Image files of a folder, sorted by name.
fn frame_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                matches!(
                    e.to_ascii_lowercase().as_str(),
                    "png" | "jpg" | "jpeg" | "tif" | "tiff" | "exr" | "bmp"
                )
            })
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(Error::invalid(
            "frames",
            format!("no image files in {}", dir.display()),
        ));
    }
    Ok(files)
}

fn load_gray(path: &Path) -> Result<Image<f32>> {
    Ok(Image::load(path)?.to_gray())
}

pub fn run(cmd: DeblurCommand) -> Result<()> {
    match cmd {
        DeblurCommand::Frames(a) => frames(a),
        DeblurCommand::Kernel(a) => {
            let inputs = [Some(&a.camera.gyro), a.camera.camera.as_ref()];
            crate::commands::overwrite::check_file("out", &a.out, inputs.into_iter().flatten())?;
            let setup = a.camera.setup(a.width, a.height)?;
            let k = setup.k;
            let track =
                GyroTrack::from_camera_rates(&wscg_deblur::gyro::read_gyro_csv(&a.camera.gyro)?)?;
            let timing = wscg_deblur::Timing {
                t_frame: a.time,
                t_exposure: setup.exposure,
                t_readout: setup.readout,
                t_delay: setup.delay,
                height: a.height,
            };
            let kern = render_kernel(
                &track,
                &timing,
                &k,
                parse_pair(&a.at, "at")?,
                &KernelParams::default(),
            )?;
            let peak = kern.data.iter().cloned().fold(0f32, f32::max).max(1e-12);
            Image::from_fn(kern.size, kern.size, |i, j| {
                kern.data[i * kern.size + j] / peak
            })?
            .save(&a.out)?;
            let (cx, cy) = kern.centroid();
            println!(
                "kernel {}x{} px, origin {:?}, centroid ({cx:.2}, {cy:.2}) px, blurriness {:.2} px; wrote {}",
                kern.size,
                kern.size,
                kern.origin,
                wscg_deblur::blurriness(&kern),
                a.out.display()
            );
            Ok(())
        }
        DeblurCommand::Simulate(a) => {
            crate::commands::overwrite::check_folder("out-dir", &a.out_dir, [&a.image])?;
            let display = load_gray(&a.image)?;
            let mut sharp = display.clone();
            Gamma::default().linearise(sharp.data_mut());
            let std = parse_list(&a.shake, "shake")?;
            let [p, y, r] = std[..] else {
                return Err(Error::invalid(
                    "shake",
                    "expected three numbers pitch,yaw,roll",
                ));
            };
            if a.frames == 0 {
                return Err(Error::invalid("frames", "must be >= 1"));
            }
            let burst = Burst {
                frames: a.frames,
                f: a.f,
                ..Default::default()
            };
            let ou = ShakeParams::default().std([p, y, r]);
            let sb = synth::make_burst(
                &sharp,
                &burst,
                &ou,
                a.frames / 2,
                0.002,
                &BlurRenderParams::default(),
                a.seed,
            )?;
            let dir = a.out_dir.join("frames");
            std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
            for (i, fr) in sb.frames.iter().enumerate() {
                fr.image.save(dir.join(format!("frame_{i:02}.png")))?;
            }
            sb.sharp_display.save(a.out_dir.join("sharp.png"))?;
            wscg_deblur::gyro::write_gyro_csv(a.out_dir.join("gyro.csv"), &sb.measured)?;
            let times: String = sb.frames.iter().map(|f| format!("{:.6}\n", f.t)).collect();
            wscg_math::io::atomic::write(dir.join("times.txt"), times)?;
            let mut camera = CameraFile::default();
            camera.f = Some(burst.f);
            camera.exposure = Some(burst.t_exposure);
            camera.readout = Some(burst.t_readout);
            camera.delay = Some(burst.t_delay);
            camera.write(a.out_dir.join("camera.json"))?;
            println!(
                "wrote {} frames and times.txt to {}, gyro.csv, camera.json and sharp.png to {} (f = {}, exposure {} s, delay {} s)",
                a.frames,
                dir.display(),
                a.out_dir.display(),
                a.f,
                burst.t_exposure,
                burst.t_delay
            );
            Ok(())
        }
    }
}

/// `wscg deblur frames`: one frame (file output) or every frame (folder output).
fn frames(a: FramesArgs) -> Result<()> {
    let to_folder = a.main.is_none() && (a.out.is_dir() || a.out.extension().is_none());
    let mut inputs: Vec<&Path> = a.frames.iter().map(PathBuf::as_path).collect();
    let more = [
        Some(&a.camera.gyro),
        a.camera.camera.as_ref(),
        a.reference.as_ref(),
    ];
    inputs.extend(more.into_iter().flatten().map(PathBuf::as_path));
    inputs.extend(a.times.as_deref().map(Path::new));
    if to_folder {
        crate::commands::overwrite::check_folder("out", &a.out, &inputs)?;
    } else {
        crate::commands::overwrite::check_file("out", &a.out, &inputs)?;
    }
    let (paths, folder) = match a.frames.as_slice() {
        [dir] if dir.is_dir() => (frame_files(dir)?, Some(dir.clone())),
        files => (files.to_vec(), None),
    };
    let images: Vec<Image<f32>> = paths.iter().map(|p| load_gray(p)).collect::<Result<_>>()?;
    let times = match (&a.times, &folder) {
        (Some(t), _) => read_times(t)?,
        (None, Some(dir)) if dir.join("times.txt").is_file() => {
            read_times(&dir.join("times.txt").to_string_lossy())?
        }
        _ => {
            return Err(Error::invalid(
                "times",
                "frame times missing: give --times (or a times.txt in the frame folder)",
            ))
        }
    };
    if times.len() != images.len() {
        return Err(Error::invalid(
            "times",
            format!("{} frames but {} time stamps", images.len(), times.len()),
        ));
    }
    let (h, w) = (images[0].height(), images[0].width());
    let setup = a.camera.setup(w, h)?;
    let track = GyroTrack::from_camera_rates(&wscg_deblur::gyro::read_gyro_csv(&a.camera.gyro)?)?;
    let hl = HyperLaplacianParams::paper().lambda(Some(a.lambda));
    let gamma = (!a.linear).then(Gamma::default);
    let opts = MultiframeParams::default()
        .t_exposure(setup.exposure)
        .t_readout(setup.readout)
        .t_delay(setup.delay)
        .gamma(gamma)
        .hl(hl)
        .mu(a.mu)
        .radius(Some(a.radius))
        .align(if a.gyro_align {
            AlignMode::Gyro
        } else {
            MultiframeParams::default().align
        });
    let input: Vec<_> = images
        .into_iter()
        .zip(&times)
        .map(|(image, &t)| wscg_deblur::FrameInput { image, t })
        .collect();
    let deblur_one = |main: usize| -> Result<Image<f32>> {
        if main >= input.len() {
            return Err(Error::invalid(
                "main",
                format!("index {main} is out of range for {} frames", input.len()),
            ));
        }
        if a.method == "multi" {
            let out =
                deblur_multiframe(&input, main, &track, &setup.k, &opts, &Bars::new("deblur"))?;
            for wmsg in &out.warnings {
                eprintln!("warning: {wmsg}");
            }
            println!(
                "frame {main}: multi-frame with frames {:?}",
                out.used_frames
            );
            return Ok(out.image);
        }
        let method = match Method::by_name(&a.method)? {
            Method::HyperLaplacian(_) => Method::HyperLaplacian(hl),
            Method::GlobalUniform(_) => Method::GlobalUniform(hl),
            m => m,
        };
        Ok(deblur_frame(&input[main], &track, &setup.k, &method, &opts)?.0)
    };
    if to_folder {
        std::fs::create_dir_all(&a.out).map_err(|e| Error::io(&a.out, e))?;
        for (i, p) in paths.iter().enumerate() {
            let name = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| format!("frame_{i:02}"));
            let target = a.out.join(format!("{name}.png"));
            deblur_one(i)?.save(&target)?;
            println!("wrote {}", target.display());
        }
        return Ok(());
    }
    let main = a.main.unwrap_or(input.len() / 2);
    let result = deblur_one(main)?;
    if let Some(r) = &a.reference {
        let truth = load_gray(r)?;
        let (p0, s0) = quality(&input[main].image, &truth, 16)?;
        let (p, s) = quality(&result, &truth, 16)?;
        println!("blurry input: PSNR {p0:.2} dB, SSIM {s0:.3}");
        println!("result:       PSNR {p:.2} dB, SSIM {s:.3}");
    }
    result.save(&a.out)?;
    println!("wrote {}", a.out.display());
    Ok(())
}
