//! `wscg volren`: paper 03 (hybrid ROI visualisation) and paper 15 (`illum`, convolution-based
//! volume illumination, in [`illum`]) on the user's own volume.
//!
//! - `roi-serve`: prepares a volume (NIfTI, `.npy` or raw) for a set of transfer functions and
//!   serves the static and ROI packages over TCP.
//! - `roi-view`: a client: fetches the packages (from a server, or from an in-process server
//!   on a local volume), renders the hybrid image of a ROI to PNG and reports the bytes.
//!
//! Transfer functions are a JSON file `{"canonical": 0, "tfs": [[[d, r, g, b, a], ...], ...]}`
//! with densities in 0..=255 and colours and opacities in [0, 1]. A volume whose values are not
//! all integers in 0..=255 is rescaled linearly from its [min, max] to 0..=255.

mod illum;

use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::Arc;

use clap::{Args, Subcommand};
use wscg_math::io::RawType;
use wscg_math::{Error, Result, Volume};

use crate::commands::volume_file::{read_volume, RawSpec};
use wscg_volren::net::{serve, RemoteServer};
use wscg_volren::{Camera, HybridClient, HybridServer, RenderParams, ServerParams};

#[derive(Subcommand, Debug)]
pub enum VolrenCommand {
    /// Serve a volume's static and ROI packages over TCP.
    RoiServe(ServeArgs),
    /// Render the hybrid image of a ROI (from a server, or from a local volume).
    RoiView(ViewArgs),
    /// Render with convolution-based volume illumination (paper 15: ICS, SCS, PI-ICS,
    /// PI-SCS and ray-casting baselines), or run the slice-distance study. The volume's box
    /// bounds the light: outside it is empty, so light passes round an occluder that does not
    /// reach the box's sides (pad the volume with occluding voxels to block it).
    Illum(illum::IllumArgs),
}

#[derive(Args, Debug)]
pub struct VolumeArgs {
    /// Volume file (.nii, .nii.gz, .npy, .vti, a DICOM file or folder, or .raw with
    /// --raw-dims); only read.
    #[arg(long)]
    volume: Option<PathBuf>,
    /// Dimensions x,y,z of a .raw volume of unsigned bytes.
    #[arg(long, value_delimiter = ',')]
    raw_dims: Vec<usize>,
    /// Transfer functions (JSON: {"canonical": 0, "tfs": [[[d, r, g, b, a], ...], ...]}).
    #[arg(long)]
    tf: Option<PathBuf>,
    /// Wavelet steps in the static package (1..4; 2 gives a 1/64 context volume).
    #[arg(long, default_value_t = 2)]
    steps_sent: u8,
}

#[derive(Args, Debug)]
pub struct ServeArgs {
    #[command(flatten)]
    volume: VolumeArgs,
    /// Address to listen on (port 0 picks a free port, printed on the first line).
    #[arg(long, default_value = "127.0.0.1:7503")]
    addr: String,
    /// Stop after this many connections (default: serve forever).
    #[arg(long)]
    connections: Option<usize>,
}

#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    volume: VolumeArgs,
    /// Server address (without it, --volume and --tf are served in-process).
    #[arg(long)]
    server: Option<String>,
    /// Region of interest `x0:x1,y0:y1,z0:z1` (voxels, half-open, snapped to 16).
    #[arg(long)]
    roi: Option<String>,
    /// Transfer function index used inside the ROI.
    #[arg(long, default_value_t = 1)]
    roi_tf: usize,
    /// Output image (.png).
    #[arg(long)]
    out: PathBuf,
    /// Image side in pixels.
    #[arg(long, default_value_t = 512)]
    size: usize,
    /// Camera azimuth and elevation (degrees) around the volume centre, z up.
    #[arg(long, default_value_t = 30.0, allow_hyphen_values = true)]
    azimuth: f64,
    /// Camera elevation (degrees).
    #[arg(long, default_value_t = 20.0, allow_hyphen_values = true)]
    elevation: f64,
}

/// The raw spec of `--raw-dims` for a volume of unsigned bytes (`None` when not given).
pub(crate) fn u8_raw(raw_dims: &[usize]) -> Result<Option<RawSpec>> {
    if raw_dims.is_empty() {
        return Ok(None);
    }
    let dims: [usize; 3] = raw_dims
        .try_into()
        .map_err(|_| Error::invalid("raw_dims", "give three values x,y,z"))?;
    Ok(Some(RawSpec {
        dims,
        kind: RawType::U8,
    }))
}

/// Reads the volume as unsigned bytes.
fn load_volume(a: &VolumeArgs) -> Result<Volume<u8>> {
    let path = a
        .volume
        .as_ref()
        .ok_or_else(|| Error::invalid("volume", "--volume is required"))?;
    let v = read_volume(path, u8_raw(&a.raw_dims)?, None)?;
    let d = v.data();
    let bytes = d
        .iter()
        .all(|&x| x.fract() == 0.0 && (0.0..=255.0).contains(&x));
    if bytes {
        return Ok(v.map(|x| x as u8));
    }
    let (lo, hi) = d
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(Error::invalid("volume", "has non-finite values"));
    }
    let scale = if hi > lo { 255.0 / (hi - lo) } else { 0.0 };
    eprintln!("volume values in [{lo}, {hi}] rescaled to 0..=255");
    Ok(v.map(|x| ((x - lo) * scale).round() as u8))
}

fn server_from(a: &VolumeArgs) -> Result<HybridServer> {
    let v = load_volume(a)?;
    let tf =
        a.tf.as_ref()
            .ok_or_else(|| Error::invalid("tf", "--tf is required"))?;
    let (tfs, canonical) = wscg_volren::tf::read_tf_list(tf)?;
    let opts = ServerParams::default().steps_sent(a.steps_sent);
    HybridServer::new(&v, tfs, canonical, opts)
}

/// `x0:x1,y0:y1,z0:z1` as min and max corners.
fn parse_roi(text: &str) -> Result<([u32; 3], [u32; 3])> {
    let bad = || Error::invalid("roi", format!("{text:?}: expected x0:x1,y0:y1,z0:z1"));
    let parts: Vec<(u32, u32)> = text
        .split(',')
        .map(|p| {
            let (a, b) = p.split_once(':').ok_or_else(bad)?;
            Ok((
                a.trim().parse().map_err(|_| bad())?,
                b.trim().parse().map_err(|_| bad())?,
            ))
        })
        .collect::<Result<_>>()?;
    match parts.as_slice() {
        [x, y, z] => Ok(([x.0, y.0, z.0], [x.1, y.1, z.1])),
        _ => Err(bad()),
    }
}

/// Runs a `wscg volren` command.
pub fn run(cmd: VolrenCommand) -> Result<()> {
    match cmd {
        VolrenCommand::Illum(a) => illum::run(a),
        VolrenCommand::RoiServe(a) => {
            let server = Arc::new(server_from(&a.volume)?);
            let listener = TcpListener::bind(&a.addr)
                .map_err(|e| Error::invalid("addr", format!("{}: {e}", a.addr)))?;
            let addr = listener
                .local_addr()
                .map_err(|e| Error::invalid("addr", e.to_string()))?;
            println!("listening on {addr}");
            serve(server, listener, a.connections)
        }
        VolrenCommand::RoiView(a) => {
            let inputs = [&a.volume.volume, &a.volume.tf];
            crate::commands::overwrite::check_file("out", &a.out, inputs.into_iter().flatten())?;
            let (stat, roi_pkg) = match &a.server {
                Some(addr) => {
                    let mut remote = RemoteServer::connect(addr.as_str())?;
                    let stat = remote.static_package()?;
                    let roi = match &a.roi {
                        Some(r) => {
                            let (lo, hi) = parse_roi(r)?;
                            Some(remote.roi_package(lo, hi)?)
                        }
                        None => None,
                    };
                    remote.close()?;
                    (stat, roi)
                }
                None => {
                    let s = server_from(&a.volume)?;
                    let roi = match &a.roi {
                        Some(r) => {
                            let (lo, hi) = parse_roi(r)?;
                            Some(s.roi_package(lo, hi)?)
                        }
                        None => None,
                    };
                    (s.static_package(), roi)
                }
            };
            let mut client = HybridClient::from_static(&stat)?;
            if let Some(p) = &roi_pkg {
                client.set_roi(p)?;
            }
            let cam = Camera::orbit(client.dims, a.azimuth, a.elevation, a.size);
            let img = client.render(&cam, a.roi_tf, &RenderParams::default())?;
            wscg_volren::render::rgb(&img)?.save(&a.out)?;
            println!(
                "static package {} bytes, ROI package {} bytes; image written to {}",
                stat.len(),
                roi_pkg.as_ref().map_or(0, Vec::len),
                a.out.display()
            );
            Ok(())
        }
    }
}
