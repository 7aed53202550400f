//! Length units: the names the readers give a file's unit, how many
//! millimetres each is, and meshing with the output in a unit asked for
//! (the file's own by default), as both doors offer it.

use alloc::format;
use alloc::string::ToString;

use crate::meshing::mesh_model_with_progress;
use crate::options::{ElementSize, MeshOptions, OptionsError, Tolerance};
use crate::report::MeshResult;
use crate::{Error, Model};

/// Millimetres per unit of the length unit `name`, as the readers name
/// units (`"mm"`, `"in"`, `"m"`, `"ft"`, ... or a STEP factor such as
/// `"0.5 mm"`) and as people write them (`"inch"`, `"metre"`); `None` for a
/// name this does not know.
pub fn mm_per_unit(name: &str) -> Option<f64> {
    let n = name.trim().to_ascii_lowercase();
    let mm = match n.as_str() {
        "mm" | "millimeter" | "millimeters" | "millimetre" | "millimetres" => 1.0,
        "cm" | "centimeter" | "centimeters" | "centimetre" | "centimetres" => 10.0,
        "m" | "meter" | "meters" | "metre" | "metres" => 1000.0,
        "km" | "kilometer" | "kilometers" | "kilometre" | "kilometres" => 1e6,
        "um" | "micron" | "microns" | "micrometer" | "micrometre" => 1e-3,
        "in" | "inch" | "inches" => 25.4,
        "ft" | "foot" | "feet" => 304.8,
        "mi" | "mile" | "miles" => 1_609_344.0,
        "mil" | "mils" => 0.0254,
        "uin" | "microinch" | "microinches" => 25.4e-6,
        _ => {
            // The STEP reader's name for an unusual unit: its size in millimetres.
            let x: f64 = n.strip_suffix("mm")?.trim().parse().ok()?;
            return (x > 0.0 && x.is_finite()).then_some(x);
        }
    };
    Some(mm)
}

/// The length unit a mesh is given in: the file's own, or one of the
/// common ones (the mesh's positions and every length of its report).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Units {
    /// The file's unit, whatever it is (nothing is scaled).
    #[default]
    File,
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
    /// Inches.
    In,
    /// Feet.
    Ft,
}

impl Units {
    /// `"file"`, `"mm"`, `"cm"`, `"m"`, `"in"` (or `"inch"`) or `"ft"`.
    ///
    /// # Errors
    /// Any other name, as the option `units`.
    pub fn from_name(name: &str) -> Result<Self, OptionsError> {
        Ok(match name {
            "file" => Self::File,
            "mm" => Self::Mm,
            "cm" => Self::Cm,
            "m" => Self::M,
            "in" | "inch" => Self::In,
            "ft" => Self::Ft,
            _ => {
                return Err(OptionsError {
                    option: "units",
                    message: "expected \"file\", \"mm\", \"cm\", \"m\", \"in\" or \"ft\"",
                })
            }
        })
    }

    /// The unit's short name, as the report gives it (`None` for [`Units::File`]).
    pub fn name(self) -> Option<&'static str> {
        match self {
            Self::File => None,
            Self::Mm => Some("mm"),
            Self::Cm => Some("cm"),
            Self::M => Some("m"),
            Self::In => Some("in"),
            Self::Ft => Some("ft"),
        }
    }
}

/// Meshes `model` with its lengths in `units`: [`Units::File`] is
/// [`mesh_model_with_progress`] itself; any other unit is the file's mesh
/// scaled into it, so the mesh's positions and the report's tolerance,
/// deviations and fit errors are in that unit and `report.units` names it.
/// The absolute lengths of `options` (tolerance, edge lengths, sewing
/// distance, element size) are taken in `units` too, as if the file had
/// been written in it; relative ones are unchanged.
///
/// # Errors
/// As [`mesh_model_with_progress`], or a file whose unit is not one
/// [`mm_per_unit`] knows when another unit is asked for.
pub fn mesh_model_in_units(
    model: &Model,
    options: &MeshOptions,
    units: Units,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<MeshResult, Error> {
    let Some(name) = units.name() else {
        return mesh_model_with_progress(model, options, progress);
    };
    let from = mm_per_unit(&model.units).ok_or_else(|| Error::Model {
        location: "model".into(),
        message: format!("its length unit '{}' is not one this knows, so it cannot be given in {name}", model.units),
    })?;
    let to = mm_per_unit(name).unwrap_or(1.0);
    // From the file's unit to the one asked for.
    let k = from / to;
    let mut result = mesh_model_with_progress(model, &scaled_options(options, 1.0 / k), progress)?;
    scale_result(&mut result, k);
    result.report.units = name.to_string();
    Ok(result)
}

/// `options` with every absolute length multiplied by `k`.
fn scaled_options(options: &MeshOptions, k: f64) -> MeshOptions {
    let mut o = options.clone();
    if let Tolerance::Absolute(t) = o.tolerance {
        o.tolerance = Tolerance::Absolute(t * k);
    }
    o.max_edge = o.max_edge.map(|x| x * k);
    o.min_edge = o.min_edge.map(|x| x * k);
    o.sew = o.sew.map(|x| x * k);
    if let ElementSize::Absolute(h) = o.quality.size {
        o.quality.size = ElementSize::Absolute(h * k);
    }
    o
}

/// The mesh's positions and the report's lengths multiplied by `k`.
fn scale_result(r: &mut MeshResult, k: f64) {
    for p in &mut r.mesh.positions {
        *p *= k;
    }
    let rep = &mut r.report;
    rep.tolerance *= k;
    rep.max_deviation *= k;
    rep.mean_deviation *= k;
    for f in &mut rep.reparameterized {
        f.fit_error *= k;
    }
    if let Some(q) = &mut rep.quality {
        q.size *= k;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_names_give_their_size_in_millimetres() {
        assert_eq!(mm_per_unit("in"), Some(25.4));
        assert_eq!(mm_per_unit("Inch"), Some(25.4));
        assert_eq!(mm_per_unit("m"), Some(1000.0));
        assert_eq!(mm_per_unit("0.5 mm"), Some(0.5));
        assert_eq!(mm_per_unit("furlong"), None);
        assert_eq!(mm_per_unit("-2 mm"), None);
        for u in ["mm", "cm", "m", "in", "ft"] {
            let named = Units::from_name(u).unwrap().name().unwrap();
            assert_eq!(named, u);
            assert!(mm_per_unit(named).is_some());
        }
        assert_eq!(Units::from_name("file"), Ok(Units::File));
        assert!(Units::from_name("yd").unwrap_err().to_string().starts_with("option units: expected"));
    }
}
