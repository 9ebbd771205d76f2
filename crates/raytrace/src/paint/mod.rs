//! Metallic-flake paint (paper 07, sections 2.2-2.3): the flake microstructure, the plate's
//! layers and lamp, and the spectral renderer.

pub mod description;
mod disc;
pub mod flakes;
pub mod grid;
mod interface;
pub mod io;
pub mod layers;
mod microstructure;
pub mod observer;
pub mod photons;
pub mod plate;
pub mod render;
pub mod workshop;

pub use description::PaintDescription;
pub use flakes::{generate_tile, max_tilt, Flake, FlakeParams, FlakeTile, StackModel, TiltDist};
pub use io::{anaglyph, side_by_side, write_spectral_exr, write_xyz_exr};
pub use layers::{Coat, DiscLight, PlateStack};
pub use observer::{
    binocular_overlap, features, glint_stats, Condition, GlintStats, VirtualObserver,
};
pub use photons::{base_return, trace_photons, Photon, PhotonMap, PhotonParams, BASE_RETURN_RAYS};
pub use plate::{FlakePlate, PlacedFlake};
pub use render::{
    render, render_with_progress, ColourMode, FlakeHit, Microstructure, NoFlakes,
    PaintRenderParams, Plate, Rect, XyzImage, NO_FLAKE, RGB_BAND_NM,
};
pub use workshop::{plate_features, score_runs, WorkshopParams, WorkshopScores};
