//! Paint description files (JSON): a paint of paper 07 (section 3: flake radius, density and
//! tilt, the layer's thickness and model, the binder and the clear coat) as any subset of
//! these keys, the others keeping the values they are applied to. Example:
//! `{"radius_um": 26, "density": 7.3, "binder_absorption_per_mm": 0, "layer_um": 20.24,
//! "thickness_um": 0.5, "tilt_deg": 8, "model": "boolean", "seed": 1}`.

use std::path::Path;

use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::flakes::{FlakeParams, StackModel, TiltDist};
use super::layers::PlateStack;

/// Largest paint description file read (1 MiB: a dozen numbers need a few hundred bytes).
pub const MAX_PAINT_BYTES: u64 = 1 << 20;

/// A paint description: every key optional; unknown keys are refused.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct PaintDescription {
    /// Mean flake radius (µm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius_um: Option<f64>,
    /// Flake density: mean number of flakes above a point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Standard deviation of the half-normal flake tilt (degrees).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tilt_deg: Option<f64>,
    /// Height model of the flake layer: `"boolean"` or `"deposit"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// Flake thickness (µm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thickness_um: Option<f64>,
    /// Thickness of the flake layer, which is the binder's (µm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layer_um: Option<f64>,
    /// Binder absorption coefficient (1/mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub binder_absorption_per_mm: Option<f64>,
    /// Binder refractive index.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub binder_ior: Option<f64>,
    /// Lambertian albedo of the base.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_albedo: Option<f64>,
    /// Refractive index of the clear coat (1: no coat).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coat_ior: Option<f64>,
    /// Clear coat thickness (µm).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coat_um: Option<f64>,
    /// Microstructure seed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

impl PaintDescription {
    /// Reads a paint description file (see [`PaintDescription::from_json_bytes`]).
    ///
    /// Errors: [`Error::Io`] when unreadable; [`Error::LimitExceeded`] above
    /// [`MAX_PAINT_BYTES`]; the format errors of [`PaintDescription::from_json_bytes`].
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes =
            wscg_math::error::read_file_at_most(path, MAX_PAINT_BYTES, "paint descriptions")?;
        Self::from_json_bytes(&bytes, path)
    }

    /// Parses a paint description held in memory; `origin` names the file in errors.
    ///
    /// Errors ([`Error::Format`] naming `origin`, the line and the column): text that is not
    /// a JSON object of the keys above, an unknown key, a value of the wrong type; and the
    /// errors of [`PaintDescription::validate`].
    pub fn from_json_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let d: Self =
            serde_json::from_slice(bytes).map_err(|e| Error::format(origin, e.to_string()))?;
        d.validate()
            .map_err(|e| Error::format(origin, e.to_string()))?;
        Ok(d)
    }

    /// Writes the description as JSON (atomically), only the keys it sets.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::invalid("paint", e.to_string()))?;
        wscg_math::io::atomic::write(path, text)
    }

    /// Checks the description on the paper's defaults: what [`FlakeParams::validate`] and
    /// [`PlateStack::validate`] refuse once it is applied (a radius or density out of range, a
    /// flake thicker than its layer, an index below 1, ...), and an unknown model.
    pub fn validate(&self) -> Result<()> {
        let mut flakes = FlakeParams::default();
        let mut stack = PlateStack::default();
        self.apply(&mut flakes, &mut stack)
    }

    /// Applies the description on top of `flakes` and `stack` (the keys it sets replace their
    /// values; the binder takes the flake layer's thickness; `coat_ior` 1 removes the coat),
    /// then validates both.
    ///
    /// Errors: an unknown model; whatever [`FlakeParams::validate`] and
    /// [`PlateStack::validate`] refuse.
    pub fn apply(&self, flakes: &mut FlakeParams, stack: &mut PlateStack) -> Result<()> {
        let set = |dst: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *dst = v;
            }
        };
        set(&mut flakes.radius_um, self.radius_um);
        set(&mut flakes.density, self.density);
        if let Some(v) = self.tilt_deg {
            flakes.tilt = TiltDist::HalfNormal { sigma_deg: v };
        }
        if let Some(m) = &self.model {
            flakes.model = match m.as_str() {
                "boolean" => StackModel::Boolean,
                "deposit" => StackModel::Deposit,
                other => {
                    return Err(Error::invalid(
                        "model",
                        format!(
                            "{other:?} is not a valid model; valid models are \"boolean\", \
                             \"deposit\""
                        ),
                    ))
                }
            };
        }
        set(&mut flakes.thickness_um, self.thickness_um);
        set(&mut flakes.layer_um, self.layer_um);
        stack.binder_um = flakes.layer_um;
        set(
            &mut stack.binder_sigma_a_per_mm,
            self.binder_absorption_per_mm,
        );
        set(&mut stack.binder_ior, self.binder_ior);
        set(&mut stack.base_albedo, self.base_albedo);
        match (self.coat_ior, &mut stack.coat) {
            (Some(1.0), _) => stack.coat = None,
            (Some(v), Some(c)) => c.ior = v,
            _ => {}
        }
        if let (Some(v), Some(c)) = (self.coat_um, &mut stack.coat) {
            c.thickness_um = v;
        }
        flakes.validate()?;
        stack.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_description_overrides_only_its_keys() {
        let o = Path::new("paint.json");
        let d = PaintDescription::from_json_bytes(
            br#"{"radius_um": 26, "density": 7.3, "layer_um": 30, "coat_ior": 1, "seed": 4}"#,
            o,
        )
        .unwrap();
        let (mut f, mut st) = (FlakeParams::default(), PlateStack::default());
        let tilt = f.tilt;
        d.apply(&mut f, &mut st).unwrap();
        assert_eq!((f.radius_um, f.density, f.layer_um), (26.0, 7.3, 30.0));
        assert_eq!(st.binder_um, 30.0);
        assert!(st.coat.is_none());
        assert_eq!(f.tilt, tilt);
        assert_eq!(d.seed, Some(4));
    }

    #[test]
    fn bad_descriptions_are_format_errors_naming_the_file() {
        let o = Path::new("paint.json");
        for bad in [
            &br#"{"radius_um": 26,"#[..],
            br#"{"radius": 26}"#,
            br#"{"density": "high"}"#,
            br#"{"model": "sprayed"}"#,
            br#"{"radius_um": -1}"#,
            br#"{"thickness_um": 30, "layer_um": 20}"#,
            br#"[1, 2]"#,
            b"\xff",
        ] {
            let e = PaintDescription::from_json_bytes(bad, o).unwrap_err();
            assert!(matches!(e, Error::Format { .. }), "{e}");
            assert!(e.to_string().contains("paint.json"), "{e}");
        }
    }

    #[test]
    fn a_description_round_trips_through_its_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("paint.json");
        let d = PaintDescription {
            radius_um: Some(26.5),
            model: Some("deposit".into()),
            seed: Some(3),
            ..PaintDescription::default()
        };
        d.write(&p).unwrap();
        assert_eq!(PaintDescription::read(&p).unwrap(), d);
        assert!(PaintDescription::read(dir.path().join("none.json"))
            .unwrap_err()
            .is_io());
    }
}
