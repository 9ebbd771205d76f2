//! Demos on built-in data: one or more per paper, each writing pictures and a table of
//! measured figures next to the paper's (or an analytic) reference. `wscg demo NAME` runs one;
//! `wscg gallery` runs them all and writes an HTML report (see [`crate::gallery`]).

use std::path::Path;
use std::time::Instant;

use wscg_math::progress::Progress;
use wscg_math::Result;

pub mod biometrics;
pub mod bonesplit;
pub mod cloth;
pub mod deblur;
pub mod ear;
pub mod figures;
pub mod gait;
pub mod hdr;
pub mod illum;
pub mod isosurface;
pub mod manylight;
pub mod math;
pub mod meshfilter;
pub mod motion;
pub mod mri;
pub mod octree;
pub mod paint;
pub mod sfa;
pub mod video;
pub mod volren;

/// A picture written by a demo.
#[derive(Clone, Debug)]
pub struct Figure {
    /// File name relative to the demo's output folder.
    pub file: String,
    /// What the picture shows.
    pub caption: String,
}

/// One row of a demo's results table: our measured figure next to the reference figure.
#[derive(Clone, Debug)]
pub struct Row {
    /// What is measured (with units).
    pub quantity: String,
    /// Our value.
    pub ours: String,
    /// The paper's reported figure, or an analytic value; empty when there is none.
    pub reference: String,
    /// Where the reference comes from, or a remark.
    pub note: String,
}

impl Row {
    /// A row from its four cells.
    pub fn new(
        quantity: impl Into<String>,
        ours: impl Into<String>,
        reference: impl Into<String>,
        note: impl Into<String>,
    ) -> Self {
        Self {
            quantity: quantity.into(),
            ours: ours.into(),
            reference: reference.into(),
            note: note.into(),
        }
    }
}

/// What a demo produced.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// A paragraph on what was run.
    pub summary: String,
    /// Pictures, in display order.
    pub figures: Vec<Figure>,
    /// Measured figures against references.
    pub table: Vec<Row>,
    /// Named wall-clock timings in seconds.
    pub timings: Vec<(String, f64)>,
}

impl Report {
    /// Runs `f`, records its wall-clock time under `label`, and returns its result.
    pub fn time<T>(&mut self, label: &str, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let v = f();
        self.timings
            .push((label.to_string(), t.elapsed().as_secs_f64()));
        v
    }
}

/// A registered demo.
#[derive(Clone, Copy)]
pub struct Demo {
    /// Name used on the command line (`wscg demo NAME`).
    pub name: &'static str,
    /// The paper it belongs to (e.g. "01"), or "-" for the shared math crate.
    pub paper: &'static str,
    /// Title shown in the gallery.
    pub title: &'static str,
    /// Runs the demo, writing its figures into the given folder.
    pub run: fn(&Path, &dyn Progress) -> Result<Report>,
}

/// Every demo, in gallery order.
pub fn registry() -> Vec<Demo> {
    vec![
        math::DEMO,
        biometrics::DEMO,
        sfa::DEMO,
        cloth::DEMO,
        volren::DEMO,
        meshfilter::DEMO,
        video::DEMO,
        paint::DEMO,
        manylight::DEMO,
        isosurface::DEMO,
        octree::DEMO,
        mri::DEMO,
        deblur::DEMO,
        hdr::DEMO,
        ear::DEMO,
        illum::DEMO,
        motion::DEMO,
        gait::DEMO,
        bonesplit::DEMO,
    ]
}

/// The demo named `name`, if any.
pub fn find(name: &str) -> Option<Demo> {
    registry().into_iter().find(|d| d.name == name)
}
