//! Options of the quality mesher (paper 003): element size, method, the
//! splitting function's weights, and the improvement passes.

use super::{parse_word, OptionsError, UnknownWord};

/// The wanted element size H (edge length), in model units or relative to the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ElementSize {
    /// Model units.
    Absolute(f64),
    /// Fraction of the diagonal of the model's (trimmed) bounding box.
    Relative(f64),
}

/// How each face's region is filled with triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum QualityMethod {
    /// Paper 003's looping method: loops split recursively by the line of
    /// lowest splitting function until every loop is a triangle.
    Looping,
    /// The baseline: spade's constrained Delaunay refinement (angle limit and
    /// largest area) over the same boundary nodes.
    Delaunay,
    /// Both per face; the mesh whose triangles and edges score better is kept.
    Best,
}

impl QualityMethod {
    /// The words `FromStr` takes, in declaration order.
    pub const WORDS: &'static [&'static str] = &["looping", "delaunay", "best"];
}

impl core::str::FromStr for QualityMethod {
    type Err = UnknownWord;
    fn from_str(s: &str) -> Result<Self, UnknownWord> {
        parse_word(s, "method", Self::WORDS, &[Self::Looping, Self::Delaunay, Self::Best])
    }
}

/// Options for [`crate::MeshOptions::quality`], used when the mode is
/// [`crate::MeshMode::Quality`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct QualityOptions {
    /// Element size H. Default: relative 0.02.
    pub size: ElementSize,
    /// Filling method. Default [`QualityMethod::Looping`].
    pub method: QualityMethod,
    /// Weight c1 of the splitting function's angle term (the angles a line
    /// makes with the loop at both ends). Default 1.0.
    pub c1: f64,
    /// Weight c2 of the length term (the line against the diagonal of the
    /// loop's box). Default 0.3.
    pub c2: f64,
    /// Weight c3 of the density term (how well the line's division fits the
    /// element size wanted along it). Default 0.6.
    pub c3: f64,
    /// Weight c4 of the smallest-angle term (the smallest of the four angles
    /// the line makes). Default 1.0.
    pub c4: f64,
    /// Rounds of improvement after filling (each: size correction if on,
    /// edge swaps, Laplacian smoothing on the surface). Default 6; 0 keeps
    /// the filled mesh as it is.
    pub passes: usize,
    /// Splits interior edges longer than 4/3 of the wanted size and collapses
    /// those shorter than 4/5 of it, measured in model space, during the
    /// improvement rounds: the re-mapped plane of a curved face cannot keep
    /// lengths exactly (beyond paper 003, which has no such step). Default true.
    pub size_correction: bool,
    /// Largest number of triangles the whole model may need at this size;
    /// beyond it meshing stops before starting, with an error. Default 2,000,000.
    pub max_triangles: usize,
}

impl Default for QualityOptions {
    fn default() -> Self {
        Self {
            size: ElementSize::Relative(0.02),
            method: QualityMethod::Looping,
            c1: 1.0,
            c2: 0.3,
            c3: 0.6,
            c4: 1.0,
            passes: 6,
            size_correction: true,
            max_triangles: 2_000_000,
        }
    }
}

impl QualityOptions {
    /// Sets an absolute element size.
    pub fn with_size(mut self, size: f64) -> Self {
        self.size = ElementSize::Absolute(size);
        self
    }

    /// Sets the element size relative to the model's diagonal.
    pub fn with_relative_size(mut self, rel: f64) -> Self {
        self.size = ElementSize::Relative(rel);
        self
    }

    /// Sets the filling method.
    pub fn with_method(mut self, method: QualityMethod) -> Self {
        self.method = method;
        self
    }

    /// Sets the splitting function's weights c1..c4.
    pub fn with_weights(mut self, c: [f64; 4]) -> Self {
        [self.c1, self.c2, self.c3, self.c4] = c;
        self
    }

    /// Sets the number of improvement rounds.
    pub fn with_passes(mut self, passes: usize) -> Self {
        self.passes = passes;
        self
    }

    /// Turns the size correction on or off.
    pub fn with_size_correction(mut self, on: bool) -> Self {
        self.size_correction = on;
        self
    }

    /// Sets the triangle limit.
    pub fn with_max_triangles(mut self, n: usize) -> Self {
        self.max_triangles = n;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// The first field out of range.
    pub fn validate(&self) -> Result<(), OptionsError> {
        match self.size {
            ElementSize::Absolute(h) if !(h.is_finite() && h > 0.0) => {
                return Err(OptionsError { option: "--size", message: "must be a finite number > 0" })
            }
            ElementSize::Relative(r) if !(r.is_finite() && r > 0.0 && r <= 1.0) => {
                return Err(OptionsError { option: "--size-rel", message: "must be in (0, 1]" })
            }
            _ => {}
        }
        for (option, c) in [("c1", self.c1), ("c2", self.c2), ("c3", self.c3), ("c4", self.c4)] {
            if !(c.is_finite() && (0.0..=1e3).contains(&c)) {
                return Err(OptionsError { option, message: "must be a number in [0, 1000]" });
            }
        }
        if self.passes > 100 {
            return Err(OptionsError { option: "passes", message: "must be at most 100" });
        }
        if self.max_triangles < 2 {
            return Err(OptionsError { option: "max_triangles", message: "must be at least 2" });
        }
        Ok(())
    }
}
