//! The "virtual material workshop" of paper 07 with the virtual observer in place of the
//! panel: render a hidden reference plate and a set of candidate microstructures (the runs of
//! a designed experiment), and score each candidate's similarity to the reference on the
//! paper's 0 (identical) ... 10 (different) scale. The caller fits the response surface
//! (`wscg-doe`) and reads the stationary point: the microstructure predicted to match.

use wscg_math::progress::Progress;
use wscg_math::{Error, Result};

use super::flakes::FlakeParams;
use super::layers::{DiscLight, PlateStack};
use super::observer::{features, Condition, VirtualObserver, DEFAULT_JND_LOG};
use super::plate::FlakePlate;
use super::render::{render, PaintRenderParams, Plate, Rect};
use crate::stereo::{Eye, StereoRig};

wscg_math::params! {
    /// What the workshop renders and how.
    #[derive(Clone, Debug)]
    pub struct WorkshopParams {
        /// Microstructure parameters other than radius and density.
        pub base: FlakeParams,
        /// The plate's layers.
        pub stack: PlateStack,
        /// The lamp: by default 1 degree, 75 degrees above the plate (towards its top edge), so that
        /// the plate seen from the front sparkles over a grey background.
        pub light: DiscLight,
        /// The viewing rig.
        pub rig: StereoRig,
        /// Rendering: a 10 x 10 mm patch at the plate's centre, magnified 4x (144 x 144 pixels),
        /// 64 samples per pixel.
        pub settings: PaintRenderParams,
        /// Renders of the reference (different microstructure seeds) that calibrate the
        /// observer: 4.
        pub reference_renders: usize,
        /// Viewing condition.
        pub condition: Condition,
        /// The observer's just-noticeable difference of a feature (log units), 0.25.
        pub jnd_log: f64,
        /// Draw the tile pool as large as the number of cells the region covers, so that the
        /// rendered patch shows (nearly) no repeated tile, as the paper's plate of distinct
        /// microstructures does; otherwise `base.tiles_in_pool` tiles. True.
        pub distinct_cells: bool,
    }
}

impl Default for WorkshopParams {
    fn default() -> Self {
        Self {
            base: FlakeParams::default(),
            stack: PlateStack::default(),
            light: DiscLight::from_elevation(75.0, 1.0),
            rig: StereoRig::default(),
            settings: PaintRenderParams {
                spp: 64,
                region_mm: Some(Rect::centred(0.0, 0.0, 10.0, 10.0)),
                magnification: 4.0,
                ..PaintRenderParams::default()
            },
            reference_renders: 4,
            condition: Condition::Stereo,
            jnd_log: DEFAULT_JND_LOG,
            distinct_cells: true,
        }
    }
}

impl WorkshopParams {
    /// Checks every part: `base` ([`FlakeParams::validate`]; the radius and density of each
    /// plate are checked where they are set), `stack`, `light`, `rig` and `settings`, at
    /// least 2 `reference_renders`, `jnd_log` finite and `>= 0`.
    pub fn validate(&self) -> Result<()> {
        self.base.validate()?;
        self.stack.validate()?;
        self.light.validate()?;
        self.rig.validate()?;
        self.settings.validate()?;
        if self.reference_renders < 2 {
            return Err(Error::invalid(
                "reference_renders",
                format!(
                    "at least 2 are needed to calibrate the observer, got {}",
                    self.reference_renders
                ),
            ));
        }
        if !(self.jnd_log.is_finite() && self.jnd_log >= 0.0) {
            return Err(Error::invalid(
                "jnd_log",
                format!("must be finite and >= 0, got {}", self.jnd_log),
            ));
        }
        Ok(())
    }
}

/// The scores of a workshop run.
#[derive(Clone, Debug)]
pub struct WorkshopScores {
    /// The observer calibrated on the reference renders.
    pub observer: VirtualObserver,
    /// Features of each reference render.
    pub reference_features: Vec<Vec<f64>>,
    /// Features of each candidate.
    pub features: Vec<Vec<f64>>,
    /// Score of each candidate (0 = identical to the reference ... 10 = different).
    pub scores: Vec<f64>,
}

/// The observer's features of a plate of flake `radius_um` and `density` whose
/// microstructure is drawn with `seed`, under the configuration's view and condition.
///
/// Errors: invalid parameters, configuration or rendering failures.
pub fn plate_features(
    radius_um: f64,
    density: f64,
    seed: u64,
    cfg: &WorkshopParams,
) -> Result<Vec<f64>> {
    cfg.validate()?;
    let mut params = FlakeParams {
        radius_um,
        density,
        ..cfg.base
    };
    if cfg.distinct_cells {
        let r = cfg.settings.region_mm.unwrap_or(Rect::centred(
            0.0,
            0.0,
            cfg.stack.size_mm.0,
            cfg.stack.size_mm.1,
        ));
        let cells = |a: f64, b: f64| ((b - a) * 1e3 / params.tile_um).ceil() + 1.0;
        params.tiles_in_pool = (cells(r.x0, r.x1) * cells(r.y0, r.y1)) as usize;
    }
    let micro = FlakePlate::new(&params, cfg.stack.size_mm, seed)?;
    let plate = Plate::new(cfg.stack.clone(), Box::new(micro))?;
    let view = |eye| render(&plate, &cfg.light, &cfg.rig, eye, &cfg.settings);
    match cfg.condition {
        Condition::Mono => features(&view(Eye::Cyclopean)?, None),
        Condition::Stereo => {
            let (l, r) = (view(Eye::Left)?, view(Eye::Right)?);
            features(&l, Some(&r))
        }
    }
}

/// Scores the candidate plates `runs` (`(radius_um, density)` each) against the hidden
/// reference `(radius_um, density)`: the reference is rendered `cfg.reference_renders` times
/// with seeds `seed, seed + 1, ...` to calibrate the observer; candidate `i` uses seed
/// `seed + 1000 + i`. `progress` counts renders.
///
/// Errors: fewer than two reference renders, an empty run list, invalid parameters.
pub fn score_runs(
    reference: (f64, f64),
    runs: &[(f64, f64)],
    cfg: &WorkshopParams,
    seed: u64,
    progress: &dyn Progress,
) -> Result<WorkshopScores> {
    cfg.validate()?;
    if runs.is_empty() {
        return Err(Error::Empty("runs"));
    }
    let total = (cfg.reference_renders + runs.len()) as u64;
    progress.begin("virtual workshop: renders", total);
    let mut reference_features = Vec::with_capacity(cfg.reference_renders);
    for k in 0..cfg.reference_renders {
        reference_features.push(plate_features(
            reference.0,
            reference.1,
            seed + k as u64,
            cfg,
        )?);
        progress.advance(1);
    }
    let observer = VirtualObserver::calibrate(&reference_features, cfg.jnd_log)?;
    let mut features = Vec::with_capacity(runs.len());
    let mut scores = Vec::with_capacity(runs.len());
    for (i, &(r, d)) in runs.iter().enumerate() {
        let f = plate_features(r, d, seed + 1000 + i as u64, cfg)?;
        scores.push(observer.score(&f)?);
        features.push(f);
        progress.advance(1);
    }
    progress.finish();
    Ok(WorkshopScores {
        observer,
        reference_features,
        features,
        scores,
    })
}
