//! Python bindings of wscg: the native module `wscg._native`, one submodule per crate.
//!
//! The Python package (`py/python/wscg`) exposes them as `wscg.math`, ...: a function whose
//! Python layer would only convert and check its arguments is defined here, with its
//! signature, defaults and documentation, and re-exported as it is (its arguments go
//! through [`args`]); the others keep a Python wrapper where Python adds something (result
//! classes, estimators, pure-Python conveniences), which coerces inputs to C-contiguous
//! arrays of the dtype the native side expects. Errors from Rust become `ValueError` (bad arguments),
//! `OSError` (files), `MemoryError` (a size that does not fit in memory) or
//! `KeyboardInterrupt` (Ctrl-C during a call); a Rust panic in a binding's work (a bug)
//! surfaces as `RuntimeError` with the panic's message (`pool::detach` catches it), never a
//! crash.
#![warn(missing_docs)]

use pyo3::prelude::*;

mod args;
mod biometrics;
mod cfg;
mod cloth;
mod convert;
mod csmri;
mod deblur;
mod doe;
mod ear;
mod errors;
mod gait;
mod handpose;
mod hdr;
mod illum;
mod isosurface;
mod limits;
mod logs;
mod manylight;
mod math;
mod meshfilter;
mod motion;
mod octree;
mod pool;
mod raytrace;
mod sfa;
mod state;
mod video;
mod volren;
mod volseg;

/// The native extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    wscg_math::faer_par::fix_faer_parallelism();
    pool::register(m)?;
    limits::register(m)?;
    logs::install(m.py())?;
    type Register = fn(&Bound<'_, PyModule>) -> PyResult<()>;
    let subs: [(&str, Register); 17] = [
        ("math", math::register),
        ("biometrics", biometrics::register),
        ("cloth", cloth::register),
        ("meshfilter", meshfilter::register),
        ("volren", volren::register),
        ("video", video::register),
        ("raytrace", raytrace::register),
        ("doe", doe::register),
        ("isosurface", isosurface::register),
        ("octree", octree::register),
        ("csmri", csmri::register),
        ("deblur", deblur::register),
        ("hdr", hdr::register),
        ("ear", ear::register),
        ("motion", motion::register),
        ("gait", gait::register),
        ("volseg", volseg::register),
    ];
    // Each submodule is importable by its full name (`wscg._native.cloth`, ...), the
    // `__module__` of its classes and functions, so that pickle finds them by reference:
    // the native objects pickle by naming a class or a function of their submodule.
    let modules = m.py().import("sys")?.getattr("modules")?;
    for (name, register) in subs {
        let full = format!("wscg._native.{name}");
        let sub = PyModule::new(m.py(), &full)?;
        register(&sub)?;
        m.add(name, &sub)?;
        modules.set_item(&full, &sub)?;
    }
    Ok(())
}
