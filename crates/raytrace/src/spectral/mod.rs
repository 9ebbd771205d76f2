//! Spectral rendering support for paper 07 (section 2.3: "rendered within the visible
//! spectrum interval [380nm-780nm] with a wavelength step of 5nm"): sampled spectra, the CIE
//! 1931 observer and daylight illuminants, colour conversion to display RGB, the optical
//! constants of aluminium and the Fresnel equations.

pub mod colour;
pub mod fresnel;
pub mod metal;
pub mod spectrum;
pub mod tables;

pub use colour::{srgb_oetf, xyz_to_rgb, xyz_to_xy, BRADFORD, XYZ_TO_SRGB};
pub use fresnel::{fresnel_conductor, fresnel_dielectric};
pub use metal::{aluminium_rakic_ld, MetalIor};
pub use spectrum::{blackbody, cie1931_2deg, daylight_d, to_xyz, SpectralGrid, Spectrum};
