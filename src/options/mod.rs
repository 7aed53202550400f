//! Options of every mesher and the errors that reject them: plain structs,
//! documented defaults, validated at every entry. A leaf: it uses no other
//! module of the crate, so every layer can read its options from here.

mod quality;

use core::fmt;

pub use quality::{ElementSize, QualityMethod, QualityOptions};

/// When faces are re-parameterized before meshing (paper 001).
///
/// Auto by default: a flagged face's rebuild is kept only where its mesh
/// wins (no more triangles, better angles) and the original is meshed
/// otherwise, so the default never meshes a face worse than `Off`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reparam {
    /// Faces the ratio test flags (the default).
    #[default]
    Auto,
    /// Never.
    Off,
    /// Every face.
    Force,
}

/// What the mesher aims at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum MeshMode {
    /// Fewest triangles within the chordal tolerance (paper 000).
    #[default]
    Fast,
    /// Near-equilateral triangles of a chosen size for analysis (paper 003),
    /// set by [`MeshOptions::quality`].
    Quality,
}

/// How the chordal tolerance is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// Model units.
    Absolute(f64),
    /// Fraction of the model's bounding-box diagonal (of the trimmed geometry).
    Relative(f64),
}

/// Options for [`crate::mesh_model`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MeshOptions {
    /// Largest allowed distance between mesh and exact surface.
    /// Default: relative 1e-3.
    pub tolerance: Tolerance,
    /// Largest normal turn across one triangle and one boundary segment, radians.
    /// Default 0.5 (OCCT's usual angular deflection).
    pub angle: f64,
    /// Longest triangle edge allowed, model units. Default: none.
    pub max_edge: Option<f64>,
    /// Edges at or below this length are never split, model units. Default:
    /// 1e-3 × the absolute tolerance (guards singular points against endless refinement).
    pub min_edge: Option<f64>,
    /// Borders of different faces closer than this are sewn into one edge,
    /// model units. Default: 0.4 × the tolerance (each side then moves by
    /// at most half the gap, within what the mesher's safety margin leaves),
    /// and within one face (a seam) the smaller of half the tolerance and
    /// 1e-4 × the model diagonal.
    pub sew: Option<f64>,
    /// Refinement stops (with a warning) once the whole mesh holds this many triangles.
    /// Default 4,000,000: bounds memory in a browser tab.
    pub max_triangles: usize,
    /// Samples per triangle edge used to verify deviation (≥ 2). Default 4:
    /// vertices, edge points and interior points of a 4-step barycentric grid.
    pub measure_steps: usize,
    /// Fraction of the tolerance refinement aims at, so that what lies between
    /// verification samples stays within the tolerance too. Default 0.8.
    pub safety: f64,
    /// Re-parameterization of poorly parameterized faces before meshing
    /// (paper 001). Default [`Reparam::Auto`]: the faces the ratio test
    /// flags are rebuilt, each kept only where its mesh wins.
    pub reparam: Reparam,
    /// Fewest triangles ([`MeshMode::Fast`], default) or analysis quality.
    pub mode: MeshMode,
    /// Settings of [`MeshMode::Quality`]: element size, method, weights.
    pub quality: QualityOptions,
    /// `Some((index, count))`: mesh only share `index` of `count` of the
    /// model's bodies (see [`crate::share_of_faces`]), so that workers can mesh one
    /// model side by side. Bodies share no border, so the shares' meshes
    /// together are the whole model's mesh (`Report::bodies` says how many
    /// there are). A share given no body returns at once, its mesh empty and
    /// its report's tolerance 0. Default `None`: every face. Fast mode only.
    pub share: Option<(u32, u32)>,
}

impl Default for MeshOptions {
    fn default() -> Self {
        Self {
            tolerance: Tolerance::Relative(1e-3),
            angle: 0.5,
            max_edge: None,
            min_edge: None,
            sew: None,
            max_triangles: 4_000_000,
            measure_steps: 4,
            safety: 0.8,
            reparam: Reparam::Auto,
            mode: MeshMode::Fast,
            quality: QualityOptions::default(),
            share: None,
        }
    }
}

/// A rejected option value.
#[derive(Debug, Clone, PartialEq)]
pub struct OptionsError {
    /// Option name as the CLI spells it.
    pub option: &'static str,
    /// What is wrong.
    pub message: &'static str,
}

impl fmt::Display for OptionsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "option {}: {}", self.option, self.message)
    }
}

impl core::error::Error for OptionsError {}

/// A word that names none of an option's values (the error of the option
/// enums' `FromStr`, which the CLI and the JS binding both parse with).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownWord {
    /// Option name, without dashes: `mode`, `reparam`, `method`.
    pub option: &'static str,
    /// The words it takes.
    pub allowed: &'static [&'static str],
}

impl fmt::Display for UnknownWord {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} must be ", self.option)?;
        let n = self.allowed.len();
        for (i, w) in self.allowed.iter().enumerate() {
            let sep = match i {
                0 => "",
                i if i + 1 == n => " or ",
                _ => ", ",
            };
            write!(f, "{sep}{w}")?;
        }
        Ok(())
    }
}

impl core::error::Error for UnknownWord {}

/// The value of `option` whose word (in `allowed`, in the order of `values`) is `s`.
pub(crate) fn parse_word<T: Copy>(
    s: &str,
    option: &'static str,
    allowed: &'static [&'static str],
    values: &[T],
) -> Result<T, UnknownWord> {
    allowed.iter().position(|w| *w == s).and_then(|i| values.get(i).copied()).ok_or(UnknownWord { option, allowed })
}

impl Reparam {
    /// The words `FromStr` takes, in declaration order.
    pub const WORDS: &'static [&'static str] = &["auto", "off", "force"];
}

impl core::str::FromStr for Reparam {
    type Err = UnknownWord;
    fn from_str(s: &str) -> Result<Self, UnknownWord> {
        parse_word(s, "reparam", Self::WORDS, &[Self::Auto, Self::Off, Self::Force])
    }
}

impl MeshMode {
    /// The words `FromStr` takes, in declaration order.
    pub const WORDS: &'static [&'static str] = &["fast", "quality"];
}

impl core::str::FromStr for MeshMode {
    type Err = UnknownWord;
    fn from_str(s: &str) -> Result<Self, UnknownWord> {
        parse_word(s, "mode", Self::WORDS, &[Self::Fast, Self::Quality])
    }
}

impl MeshOptions {
    /// Sets an absolute chordal tolerance.
    pub fn with_tolerance(mut self, tol: f64) -> Self {
        self.tolerance = Tolerance::Absolute(tol);
        self
    }

    /// Sets a chordal tolerance relative to the model diagonal.
    pub fn with_relative_tolerance(mut self, rel: f64) -> Self {
        self.tolerance = Tolerance::Relative(rel);
        self
    }

    /// Sets the angle limit (radians).
    pub fn with_angle(mut self, angle: f64) -> Self {
        self.angle = angle;
        self
    }

    /// Sets the longest edge allowed.
    pub fn with_max_edge(mut self, max_edge: Option<f64>) -> Self {
        self.max_edge = max_edge;
        self
    }

    /// Sets the shortest edge that may still be split.
    pub fn with_min_edge(mut self, min_edge: Option<f64>) -> Self {
        self.min_edge = min_edge;
        self
    }

    /// Sets the sewing distance between faces' borders.
    pub fn with_sew(mut self, sew: Option<f64>) -> Self {
        self.sew = sew;
        self
    }

    /// Sets the triangle budget.
    pub fn with_max_triangles(mut self, n: usize) -> Self {
        self.max_triangles = n;
        self
    }

    /// Meshes only share `index` of `count` of the bodies ([`MeshOptions::share`]).
    pub fn with_share(mut self, index: u32, count: u32) -> Self {
        self.share = Some((index, count));
        self
    }

    /// Sets when poorly parameterized faces are rebuilt (paper 001).
    pub fn with_reparam(mut self, mode: Reparam) -> Self {
        self.reparam = mode;
        self
    }

    /// Sets the meshing mode.
    pub fn with_mode(mut self, mode: MeshMode) -> Self {
        self.mode = mode;
        self
    }

    /// Sets the quality mode's settings.
    pub fn with_quality(mut self, quality: QualityOptions) -> Self {
        self.quality = quality;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// The first field out of range.
    pub fn validate(&self) -> Result<(), OptionsError> {
        match self.tolerance {
            Tolerance::Absolute(t) if !(t.is_finite() && t > 0.0) => {
                return Err(OptionsError { option: "--tol", message: "must be a finite number > 0" })
            }
            Tolerance::Relative(t) if !(t.is_finite() && t > 0.0 && t <= 1.0) => {
                return Err(OptionsError { option: "--tol-rel", message: "must be in (0, 1]" })
            }
            _ => {}
        }
        if !(self.angle.is_finite() && self.angle > 0.0 && self.angle <= core::f64::consts::PI) {
            return Err(OptionsError { option: "--angle", message: "must be in (0, pi] radians" });
        }
        if let Some(m) = self.max_edge {
            if !(m.is_finite() && m > 0.0) {
                return Err(OptionsError { option: "--max-edge", message: "must be a finite number > 0" });
            }
        }
        if let Some(m) = self.min_edge {
            if !(m.is_finite() && m >= 0.0) {
                return Err(OptionsError { option: "--min-edge", message: "must be a finite number >= 0" });
            }
            if let Some(x) = self.max_edge {
                if m >= x {
                    return Err(OptionsError { option: "--min-edge", message: "must be below --max-edge" });
                }
            }
        }
        if let Some((i, n)) = self.share {
            if n == 0 || i >= n {
                return Err(OptionsError { option: "share", message: "index must be below a count of at least 1" });
            }
            if self.mode == MeshMode::Quality {
                return Err(OptionsError { option: "share", message: "meshes fast mode only" });
            }
        }
        if let Some(s) = self.sew {
            if !(s.is_finite() && s > 0.0) {
                return Err(OptionsError { option: "--sew", message: "must be a finite number > 0" });
            }
        }
        if self.max_triangles < 2 {
            return Err(OptionsError { option: "--max-triangles", message: "must be at least 2" });
        }
        if !(2..=16).contains(&self.measure_steps) {
            return Err(OptionsError { option: "measure_steps", message: "must be in 2..=16" });
        }
        if !(self.safety.is_finite() && self.safety > 0.1 && self.safety <= 1.0) {
            return Err(OptionsError { option: "safety", message: "must be in (0.1, 1]" });
        }
        self.quality.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::ToString;

    /// Every word parses to its own value, and a word of none says which it takes.
    #[test]
    fn option_words_parse_to_their_values() {
        let modes: alloc::vec::Vec<MeshMode> = MeshMode::WORDS.iter().map(|w| w.parse().unwrap()).collect();
        assert_eq!(modes, [MeshMode::Fast, MeshMode::Quality]);
        let reparams: alloc::vec::Vec<Reparam> = Reparam::WORDS.iter().map(|w| w.parse().unwrap()).collect();
        assert_eq!(reparams, [Reparam::Auto, Reparam::Off, Reparam::Force]);
        let methods: alloc::vec::Vec<QualityMethod> = QualityMethod::WORDS.iter().map(|w| w.parse().unwrap()).collect();
        assert_eq!(methods, [QualityMethod::Looping, QualityMethod::Delaunay, QualityMethod::Best]);
        let e = "Fast".parse::<MeshMode>().unwrap_err();
        assert_eq!(e, UnknownWord { option: "mode", allowed: MeshMode::WORDS });
        assert_eq!(e.to_string(), "mode must be fast or quality");
        assert_eq!("x".parse::<QualityMethod>().unwrap_err().to_string(), "method must be looping, delaunay or best");
    }
}
