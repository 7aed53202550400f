//! Float functions through `libm`, so the core needs no `std` (with it, the
//! square root is the processor's).

/// Square root: with `std`, the processor's instruction (`f64.sqrt` on
/// wasm32, where libm's portable routine is a software loop with 128-bit
/// products: a fifth of a mesh's time in Node); without it, libm.
#[inline]
pub(crate) fn sqrt(x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.sqrt()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::sqrt(x)
    }
}

#[inline]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    libm::atan2(y, x)
}

/// Rounding up: with `std`, the processor's instruction (`f64.ceil` on
/// wasm32, where libm's is a bit-twiddling routine); without it, libm. Both
/// are exact, so the results are the same.
#[inline]
pub(crate) fn ceil(x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.ceil()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::ceil(x)
    }
}

/// Rounding down, as [`ceil`]: the instruction with `std`, else libm.
#[inline]
pub(crate) fn floor(x: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.floor()
    }
    #[cfg(not(feature = "std"))]
    {
        libm::floor(x)
    }
}

/// Angle in radians between two vectors; 0 when either is zero.
pub(crate) fn angle_between(a: glam::DVec3, b: glam::DVec3) -> f64 {
    let la = a.length();
    let lb = b.length();
    if la <= 0.0 || lb <= 0.0 {
        return 0.0;
    }
    atan2(a.cross(b).length(), a.dot(b))
}

/// Twice the area over the longest side: how wide a triangle is (a sliver
/// between faces is narrow however long).
pub(crate) fn triangle_width(p: [glam::DVec3; 3]) -> f64 {
    let longest = (0..3).map(|k| p[k].distance(p[(k + 1) % 3])).fold(0.0, f64::max);
    (p[1] - p[0]).cross(p[2] - p[0]).length() / longest.max(f64::MIN_POSITIVE)
}
