//! Frame folders: a video as the PNG/JPEG files of a folder in name order, a hole as one mask
//! image (the same hole in every frame) or a folder of mask images (non-zero = hole).

use std::path::{Path, PathBuf};

use wscg_math::{Error, Result};

use crate::video::{Mask3, Video};

/// Image files (`.png`, `.jpg`, `.jpeg`, any case) of `dir`, sorted by name.
pub fn frame_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let rd = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut files: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_file()
                && p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                    matches!(e.to_ascii_lowercase().as_str(), "png" | "jpg" | "jpeg")
                })
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(Error::format(dir, "no .png or .jpg frames in the folder"));
    }
    Ok(files)
}

fn open(path: &Path) -> Result<image::DynamicImage> {
    let bytes = wscg_math::error::read_file(path)?;
    wscg_math::io::raster::decode_dynamic(&bytes, path)
}

/// Reads the frames of `dir` as an RGB video.
///
/// Errors: unreadable folder or file, no frames, frames of different sizes.
pub fn read_frames(dir: &Path) -> Result<Video> {
    let files = frame_files(dir)?;
    let mut data = Vec::new();
    let mut size = None;
    for f in &files {
        let img = open(f)?.to_rgb8();
        let s = (img.height() as usize, img.width() as usize);
        match size {
            None => size = Some(s),
            Some(first) if first != s => {
                return Err(Error::format(
                    f,
                    format!(
                        "frame of {} x {} where the first frame is {} x {}",
                        s.1, s.0, first.1, first.0
                    ),
                ))
            }
            _ => {}
        }
        data.extend_from_slice(img.as_raw());
    }
    let (h, w) = size.expect("at least one frame");
    Video::new(files.len(), h, w, 3, data)
}

/// Reads a video: the frames of a folder ([`read_frames`]), or a video file decoded by the
/// `ffmpeg` program (to PNG frames in a temporary folder, removed afterwards) when it is on the
/// `PATH`.
///
/// Errors: as [`read_frames`]; a file when `ffmpeg` is not available or fails on it.
pub fn read_video(path: &Path) -> Result<Video> {
    if path.is_dir() || !path.exists() {
        return read_frames(path);
    }
    let available = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !available {
        return Err(Error::UnsupportedFormat(format!(
            "{} is a file: decoding a video file needs the ffmpeg program on the PATH (or give a folder of PNG/JPEG frames)",
            path.display()
        )));
    }
    let dir = std::env::temp_dir().join(format!(
        "wscg-video-{}-{}",
        std::process::id(),
        path.file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("frames")
    ));
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let status = std::process::Command::new("ffmpeg")
        .args(["-loglevel", "error", "-i"])
        .arg(path)
        .arg(dir.join("%06d.png"))
        .status();
    let result = match status {
        Ok(s) if s.success() => read_frames(&dir),
        Ok(s) => Err(Error::format(path, format!("ffmpeg failed ({s})"))),
        Err(e) => Err(Error::io(path, e)),
    };
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// Reads a hole mask for a video of `frames x height x width`: a single image (the same hole in
/// every frame) or a folder with one image per frame; a pixel is in the hole when any channel
/// is non-zero.
///
/// Errors: unreadable input, a size or frame count that does not match the video.
pub fn read_mask(path: &Path, frames: usize, height: usize, width: usize) -> Result<Mask3> {
    let files = if path.is_dir() {
        frame_files(path)?
    } else {
        vec![path.to_path_buf()]
    };
    if files.len() != 1 && files.len() != frames {
        return Err(Error::format(
            path,
            format!(
                "{} mask images for {frames} frames (give one image or one per frame)",
                files.len()
            ),
        ));
    }
    let mut planes = Vec::with_capacity(files.len());
    for f in &files {
        let rgb = open(f)?.to_rgb8();
        if (rgb.height() as usize, rgb.width() as usize) != (height, width) {
            return Err(Error::format(
                f,
                format!(
                    "mask of {} x {} for frames of {width} x {height}",
                    rgb.width(),
                    rgb.height()
                ),
            ));
        }
        planes.push(
            rgb.pixels()
                .map(|p| p.0.iter().any(|&v| v != 0))
                .collect::<Vec<bool>>(),
        );
    }
    Ok(Mask3::from_fn(frames, height, width, |t, y, x| {
        let plane = if planes.len() == 1 {
            &planes[0]
        } else {
            &planes[t]
        };
        plane[y * width + x]
    }))
}

/// Writes the frames of `video` as `frame_00000.png`, ... into `dir` (created if missing).
///
/// Errors: the folder cannot be created or a file written.
pub fn write_frames(video: &Video, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut out = Vec::with_capacity(video.frames);
    for t in 0..video.frames {
        let path = dir.join(format!("frame_{t:05}.png"));
        let (w, h) = (video.width as u32, video.height as u32);
        let data = video.frame(t);
        let color = match video.channels {
            3 => image::ExtendedColorType::Rgb8,
            _ => image::ExtendedColorType::L8,
        };
        if data.len() != video.width * video.height * video.channels {
            return Err(Error::invalid("video", "frame buffer of the wrong size"));
        }
        wscg_math::io::atomic::write_with(&path, |out| {
            image::write_buffer_with_format(out, data, w, h, color, image::ImageFormat::Png)
                .map_err(|e| match e {
                    image::ImageError::IoError(e) => Error::io(&path, e),
                    e => Error::format(&path, e.to_string()),
                })
        })?;
        out.push(path);
    }
    Ok(out)
}
