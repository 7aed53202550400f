//! Deviation of a triangle from the exact surface, as DESIGN.md defines it:
//! points on the triangle (edge points and interior samples of a barycentric
//! grid) projected onto the surface by Newton from their interpolated (u,v).

use glam::{DVec2, DVec3};

use crate::nurbs::{project_to_surface, ProjectionOptions, Surface};

/// What was measured on one triangle.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct TriMeasure {
    /// Largest sample distance.
    pub max: f64,
    /// Sum of sample distances; [`sample_count`] of them, known from the
    /// grid, so the measure cache need not hold a count per triangle.
    pub sum: f64,
}

/// How many points [`measure_triangle`] samples with `steps` divisions per
/// edge: the barycentric grid without its three corners.
pub(crate) fn sample_count(steps: usize) -> u32 {
    let n = steps.max(2);
    ((n + 1) * (n + 2) / 2 - 3) as u32
}

/// Projection settings for measuring: the hint is close, so few iterations do.
pub(crate) fn measure_projection() -> ProjectionOptions {
    ProjectionOptions { max_iterations: 8, parameter_tolerance: 1e-9, search_samples: 8 }
}

/// Nanoseconds spent in [`measure_triangle`] since the process started: the
/// scaling bench's share of the mesh time that measuring deviation takes.
/// Only with the `timing` feature (native builds: it reads the clock).
#[cfg(feature = "timing")]
pub(crate) static MEASURE_NANOS: core::sync::atomic::AtomicU64 = core::sync::atomic::AtomicU64::new(0);

/// Samples the barycentric grid with `steps` divisions per edge (corners skipped:
/// they are surface points by construction) and measures their distance;
/// `None` as soon as a sample lies farther than `limit` (a triangle that
/// fails anyway need not be measured to its end; infinite: never).
/// With `shared`, an edge's samples measured for the triangle across it are
/// taken from there, and this triangle's are left for the next one.
pub(crate) fn measure_triangle(
    surface: &dyn Surface,
    p: &[DVec3; 3],
    uv: &[DVec2; 3],
    steps: usize,
    opts: &ProjectionOptions,
    shared: Option<&mut EdgeSamples>,
    limit: f64,
) -> Option<TriMeasure> {
    #[cfg(feature = "timing")]
    let started = std::time::Instant::now();
    let m = sample_triangle(surface, p, uv, steps, opts, shared, limit);
    #[cfg(feature = "timing")]
    MEASURE_NANOS.fetch_add(
        u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX),
        core::sync::atomic::Ordering::Relaxed,
    );
    m
}

/// [`measure_triangle`]'s work. Each sample's distance depends only on its
/// point and (u,v) hint, and on an edge both are the same bits in the two
/// triangles that share it (one weight is zero, and the sum of the other two
/// products does not depend on their order), so an edge's distances measured
/// once serve both sides; they are summed in the grid's order as before.
fn sample_triangle(
    surface: &dyn Surface,
    p: &[DVec3; 3],
    uv: &[DVec2; 3],
    steps: usize,
    opts: &ProjectionOptions,
    shared: Option<&mut EdgeSamples>,
    limit: f64,
) -> Option<TriMeasure> {
    let mut m = TriMeasure::default();
    let n = steps.max(2);
    let inv = 1.0 / n as f64;
    let mut shared = shared.filter(|_| n - 1 <= EDGE_MAX);
    // Per edge `e` (corner e to corner e + 1), its samples' distances by the
    // weight on corner e (slot weight - 1), and whether the cache had them.
    let mut edge = [[f64::NAN; EDGE_MAX]; 3];
    let mut known = [false; 3];
    if let Some(cache) = shared.as_deref_mut() {
        for e in 0..3 {
            if let Some(d) = cache.take(p, uv, e, n) {
                edge[e] = d;
                known[e] = true;
            }
        }
    }
    for i in 0..=n {
        for j in 0..=(n - i) {
            let k = n - i - j;
            if i == n || j == n || k == n {
                continue;
            }
            let slot = match (i, j, k) {
                (_, _, 0) => Some((0, i - 1)),
                (0, _, _) => Some((1, j - 1)),
                (_, 0, _) => Some((2, k - 1)),
                _ => None,
            };
            let d = match slot {
                Some((e, w)) if known[e] => edge[e][w],
                _ => {
                    let (a, b, c) = (i as f64 * inv, j as f64 * inv, k as f64 * inv);
                    let q = p[0] * a + p[1] * b + p[2] * c;
                    let hint = uv[0] * a + uv[1] * b + uv[2] * c;
                    let d = distance_from_hint(surface, q, hint, opts);
                    if let Some((e, w)) = slot {
                        if let Some(x) = edge[e].get_mut(w) {
                            *x = d;
                        }
                    }
                    d
                }
            };
            if d > limit {
                return None;
            }
            m.max = m.max.max(d);
            m.sum += d;
        }
    }
    if let Some(cache) = shared {
        for e in (0..3).filter(|&e| !known[e]) {
            cache.put(p, uv, e, n, edge[e]);
        }
    }
    Some(m)
}

/// Most samples per edge [`EdgeSamples`] holds: up to 8 measuring steps (the
/// default is 4); with more, every edge is measured from both sides.
const EDGE_MAX: usize = 7;

/// Most edges [`EdgeSamples`] holds before it starts over: its triangles'
/// neighbours are mostly measured soon after them (the grid's order, a
/// split's neighbours), and the room stays bounded (about 0.6 MB).
const EDGE_CAP: usize = 4096;

/// An edge's key: the measuring steps, then its two ends' point and (u,v)
/// bits, the lower end first.
type EdgeKey = [u64; 11];

/// Distances measured at the samples of triangle edges whose other triangle
/// has not been measured yet, by the edge's exact ends (point and (u,v)):
/// each is taken out when that triangle reads it, so an edge's samples are
/// measured once instead of twice. A moved end is another key, so an entry
/// never answers for what it was not measured on.
#[derive(Debug, Default)]
pub(crate) struct EdgeSamples {
    map: crate::collections::HashMap<EdgeKey, [f64; EDGE_MAX]>,
}

impl EdgeSamples {
    /// The key of edge `e` (corner e to corner e + 1) at `n` steps, and
    /// whether the key's lower end is its corner e + 1 (its samples then
    /// run the other way).
    fn key(p: &[DVec3; 3], uv: &[DVec2; 3], e: usize, n: usize) -> (EdgeKey, bool) {
        let end = |c: usize| {
            let (q, w) = (p[c % 3], uv[c % 3]);
            [q.x, q.y, q.z, w.x, w.y].map(f64::to_bits)
        };
        let (a, b) = (end(e), end(e + 1));
        let flip = b < a;
        let (lo, hi) = if flip { (b, a) } else { (a, b) };
        let mut k = [0u64; 11];
        k[0] = n as u64;
        k[1..6].copy_from_slice(&lo);
        k[6..].copy_from_slice(&hi);
        (k, flip)
    }

    /// Edge `e`'s distances by the weight on corner e, if the triangle
    /// across it left them; they are taken out.
    fn take(&mut self, p: &[DVec3; 3], uv: &[DVec2; 3], e: usize, n: usize) -> Option<[f64; EDGE_MAX]> {
        let (k, flip) = Self::key(p, uv, e, n);
        let mut d = self.map.remove(&k)?;
        if flip {
            d[..n - 1].reverse();
        }
        Some(d)
    }

    /// Leaves edge `e`'s distances `d` (by the weight on corner e) for the triangle across it.
    fn put(&mut self, p: &[DVec3; 3], uv: &[DVec2; 3], e: usize, n: usize, mut d: [f64; EDGE_MAX]) {
        let (k, flip) = Self::key(p, uv, e, n);
        if flip {
            d[..n - 1].reverse();
        }
        if self.map.len() >= EDGE_CAP {
            self.map.clear();
        }
        self.map.insert(k, d);
    }
}

/// Distance from `q` to the surface, starting at `hint` (the triangle's own
/// interpolated (u,v), so already close): Newton steps, accepted only while
/// they bring a surface point closer. The result is always the distance to an
/// actual surface point, so it can only over-state the deviation, never hide
/// it; iterations stop once a step gains less than 1e-4 of the distance, or
/// when the next step is predicted to gain less than [`SETTLED`] of it. Falls
/// back to the general projection if the steps cannot start.
///
/// Derivatives cost about three point evaluations and are needed only where
/// another step starts. The first step from the hint nearly always lands
/// where Newton has converged: its end point is evaluated with first
/// derivatives only (about two thirds of the cost of second ones), enough
/// for the Gauss-Newton model `½|r + J·s|²` to predict what one more step
/// could gain (near the surface, within `distance × curvature` of Newton's
/// prediction). A typical sample so costs one evaluation with second
/// derivatives and one with first ones, where measuring the second step
/// took two with second derivatives and a point. Later steps' end points
/// are evaluated first as points and with derivatives only if the search goes on.
pub(crate) fn distance_from_hint(surface: &dyn Surface, q: DVec3, hint: DVec2, opts: &ProjectionOptions) -> f64 {
    let [lo, hi] = surface.domain();
    let mut uv = hint.clamp(lo, hi);
    let first = surface.derivs(uv);
    let mut best = first.point.distance(q);
    // Distances this small are rounding in the evaluated points.
    let floor = 1e-15 * q.abs().max_element();
    // Derivatives at `uv` when already evaluated.
    let mut ready = Some(first);
    for iteration in 0..opts.max_iterations {
        let d = ready.take().unwrap_or_else(|| surface.derivs(uv));
        let r = d.point - q;
        let g = DVec2::new(d.su.dot(r), d.sv.dot(r));
        let a = d.su.length_squared();
        let b = d.su.dot(d.sv);
        let c = d.sv.length_squared();
        // Full Newton where the Hessian is positive definite, else Gauss-Newton.
        let (h00, h01, h11) = (a + d.suu.dot(r), b + d.suv.dot(r), c + d.svv.dot(r));
        let det = h00 * h11 - h01 * h01;
        let step = if det > 0.0 && h00 > 0.0 {
            DVec2::new(-(h11 * g.x - h01 * g.y) / det, -(h00 * g.y - h01 * g.x) / det)
        } else {
            let det = a * c - b * b;
            if det <= 0.0 {
                return best.min(project_to_surface(surface, q, Some(uv), opts).distance);
            }
            DVec2::new(-(c * g.x - b * g.y) / det, -(a * g.y - b * g.x) / det)
        };
        if !step.is_finite() {
            break;
        }
        let next = (uv + step).clamp(lo, hi);
        // A step that gets no closer where the Gauss-Newton model still
        // promises a gain: the model does not hold (a pole's fan, where the
        // hint's interpolated (u,v) lies far round from the foot point, or a
        // step clamped at the domain's edge); the general projection takes over.
        let stuck = |best: f64| {
            if settled(r, d.su, d.sv, best, floor) {
                best
            } else {
                best.min(project_to_surface(surface, q, Some(uv), opts).distance)
            }
        };
        if iteration == 0 {
            let (p, su, sv) = surface.tangents(next);
            let dist = p.distance(q);
            if dist >= best {
                return stuck(best);
            }
            let gain = best - dist;
            uv = next;
            best = dist;
            if gain <= 1e-4 * best || settled(p - q, su, sv, best, floor) {
                break;
            }
            continue;
        }
        let dist = surface.point(next).distance(q);
        if dist >= best {
            return stuck(best);
        }
        let gain = best - dist;
        uv = next;
        best = dist;
        if gain <= 1e-4 * best {
            break;
        }
    }
    best
}

/// Largest gain, as a fraction of the distance, that [`distance_from_hint`]
/// leaves to a further step (so it over-states a distance by about this much at most).
pub(crate) const SETTLED: f64 = 1e-6;

/// Whether one more step from a surface point at residual `r` (tangents `su`,
/// `sv`, distance `dist`) is predicted to gain at most [`SETTLED`] of the
/// distance, or less than `floor`: the Gauss-Newton step lowers `½|r|²` by
/// `½ gᵀ(JᵀJ)⁻¹g` with `g = Jᵀr`, i.e. the distance by that over `dist`.
fn settled(r: DVec3, su: DVec3, sv: DVec3, dist: f64, floor: f64) -> bool {
    let g = DVec2::new(su.dot(r), sv.dot(r));
    let (a, b, c) = (su.length_squared(), su.dot(sv), sv.length_squared());
    let det = a * c - b * b;
    if det.is_nan() || det <= 0.0 {
        return false;
    }
    let drop = 0.5 * (c * g.x * g.x - 2.0 * b * g.x * g.y + a * g.y * g.y) / det;
    drop <= (SETTLED * dist + floor) * dist
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::{Aabb, SurfaceDerivs};
    use alloc::vec::Vec;
    use core::cell::Cell;
    use libm::{cos, sin};

    /// The sphere of radius `r` about the origin away from its poles (u:
    /// longitude, v: polar angle), exact, counting its evaluations.
    struct Sphere {
        r: f64,
        points: Cell<usize>,
        tangents: Cell<usize>,
        derivs: Cell<usize>,
    }

    impl Sphere {
        fn new(r: f64) -> Self {
            Self { r, points: Cell::new(0), tangents: Cell::new(0), derivs: Cell::new(0) }
        }
        fn reset(&self) {
            self.points.set(0);
            self.tangents.set(0);
            self.derivs.set(0);
        }
        fn exact(&self, uv: DVec2) -> SurfaceDerivs {
            let (su, cu, sv, cv) = (sin(uv.x), cos(uv.x), sin(uv.y), cos(uv.y));
            let r = self.r;
            SurfaceDerivs {
                point: self.at(uv),
                su: r * DVec3::new(-sv * su, sv * cu, 0.0),
                sv: r * DVec3::new(cv * cu, cv * su, -sv),
                suu: r * DVec3::new(-sv * cu, -sv * su, 0.0),
                suv: r * DVec3::new(-cv * su, cv * cu, 0.0),
                svv: r * DVec3::new(-sv * cu, -sv * su, -cv),
            }
        }
        fn at(&self, uv: DVec2) -> DVec3 {
            self.r * DVec3::new(sin(uv.y) * cos(uv.x), sin(uv.y) * sin(uv.x), cos(uv.y))
        }
    }

    impl Surface for Sphere {
        fn domain(&self) -> [DVec2; 2] {
            [DVec2::new(0.0, 0.3), DVec2::new(6.0, 2.8)]
        }
        fn point(&self, uv: DVec2) -> DVec3 {
            self.points.set(self.points.get() + 1);
            self.at(uv)
        }
        fn derivs(&self, uv: DVec2) -> SurfaceDerivs {
            self.derivs.set(self.derivs.get() + 1);
            self.exact(uv)
        }
        fn tangents(&self, uv: DVec2) -> (DVec3, DVec3, DVec3) {
            self.tangents.set(self.tangents.get() + 1);
            let d = self.exact(uv);
            (d.point, d.su, d.sv)
        }
        fn breaks(&self, _along_u: bool) -> Vec<f64> {
            Vec::new()
        }
        fn bounding_box(&self) -> Aabb {
            Aabb::from_points([DVec3::splat(-self.r), DVec3::splat(self.r)])
        }
    }

    /// Points off the sphere along its normal are found at their distance
    /// (over-stated by at most [`SETTLED`] of it) from a hint some way off
    /// their foot point, and the search evaluates second derivatives only at
    /// the hint and where a later step starts (each such step then costs a
    /// point evaluation), first derivatives once, at the first step's end.
    #[test]
    fn distance_from_hint_is_exact_and_spares_derivatives() {
        let s = Sphere::new(10.0);
        let opts = measure_projection();
        let (mut samples, mut derivs, mut points) = (0usize, 0usize, 0usize);
        for i in 0..12 {
            for j in 0..8 {
                let foot = DVec2::new(0.4 + 0.45 * i as f64, 0.5 + 0.28 * j as f64);
                for (k, off) in [-0.3, 0.02, 0.25].into_iter().enumerate() {
                    let q = s.at(foot) * (1.0 + off / s.r);
                    let hint = foot + DVec2::new(0.01, -0.008) * (k as f64 + 1.0);
                    s.reset();
                    let got = distance_from_hint(&s, q, hint, &opts);
                    let want = libm::fabs(off);
                    assert!(
                        got >= want - 1e-12 && got - want <= 1e-9 * s.r + 2.0 * SETTLED * want,
                        "{foot} {off}: {got} vs {want}"
                    );
                    let (d, t, p) = (s.derivs.get(), s.tangents.get(), s.points.get());
                    assert!(d == p + 1 && t <= 1, "{foot} {off}: {d} with derivatives, {t} tangents, {p} points");
                    (samples, derivs, points) = (samples + 1, derivs + d, points + p);
                }
            }
        }
        // These hints are far enough off that some samples need more steps.
        assert!(points > 0 && derivs > samples, "{samples} samples: {derivs} with derivatives, {points} points");
    }

    /// A measuring hint (the triangle's interpolated (u,v), close to the
    /// foot point) costs one evaluation with second derivatives and one with
    /// first ones: the first step settles it, and the result is the distance.
    #[test]
    fn close_hints_settle_after_one_step() {
        let s = Sphere::new(10.0);
        let opts = measure_projection();
        let (mut samples, mut settled) = (0usize, 0usize);
        for i in 0..12 {
            for j in 0..8 {
                let foot = DVec2::new(0.4 + 0.45 * i as f64, 0.5 + 0.28 * j as f64);
                for off in [-1e-3, 2e-4, 1e-3] {
                    let q = s.at(foot) * (1.0 + off / s.r);
                    let hint = foot + DVec2::new(2e-4, -1e-4);
                    s.reset();
                    let got = distance_from_hint(&s, q, hint, &opts);
                    let want = libm::fabs(off);
                    assert!(got >= want - 1e-12 && got - want <= 1e-12 + 2.0 * SETTLED * want, "{got} vs {want}");
                    samples += 1;
                    if (s.derivs.get(), s.tangents.get(), s.points.get()) == (1, 1, 0) {
                        settled += 1;
                    }
                }
            }
        }
        assert!(settled * 10 >= samples * 9, "{settled} of {samples} settled after one step");
    }

    /// The mean deviation divides the sum by [`sample_count`]: it must be
    /// the number of points sampled, here each exactly `h` off a plane.
    #[test]
    fn sample_count_is_the_number_of_points_measured() {
        let corner = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let plane = crate::nurbs::analytic::bilinear(
            [[corner(-10.0, -10.0), corner(-10.0, 10.0)], [corner(10.0, -10.0), corner(10.0, 10.0)]],
            [-10.0, 10.0],
            [-10.0, 10.0],
        )
        .unwrap();
        let h = 0.25;
        let uv = [DVec2::new(0.0, 0.0), DVec2::new(4.0, 0.0), DVec2::new(0.0, 3.0)];
        let p = uv.map(|q| DVec3::new(q.x, q.y, h));
        for steps in 0..7 {
            let m = measure_triangle(&plane, &p, &uv, steps, &measure_projection(), None, f64::INFINITY).unwrap();
            assert!((m.max - h).abs() < 1e-12);
            assert!((m.sum / h - f64::from(sample_count(steps))).abs() < 1e-9, "steps {steps}: {}", m.sum / h);
        }
    }

    /// Edge samples shared between neighbours give each triangle the very
    /// measure it gets alone (bit for bit: the sum's order is the grid's),
    /// whichever corners the shared edge joins in each triangle and which
    /// way it runs, for every step count; where steps allow, the second
    /// triangle on an edge measures its samples no more (fewer evaluations).
    /// Corners lie off the sphere by different amounts, so every sample's
    /// distance differs.
    #[test]
    fn shared_edge_samples_equal_fresh_ones() {
        let s = Sphere::new(10.0);
        let opts = measure_projection();
        let uv = |i: usize, j: usize| DVec2::new(0.5 + 0.3 * i as f64, 0.6 + 0.25 * j as f64);
        let node = |i: usize, j: usize| {
            let off = 0.01 * ((3 * i + 5 * j) % 7) as f64 - 0.02;
            (s.at(uv(i, j)) * (1.0 + off / s.r), uv(i, j))
        };
        // A 4 × 4 grid of cells, two triangles each, their corners rotated
        // by the cell so that shared edges fall at every corner pair.
        let mut tris = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let (a, b, c, d) = (node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1));
                let mut t1 = [a, b, c];
                let mut t2 = [a, c, d];
                t1.rotate_left((i + j) % 3);
                t2.rotate_left((2 * i + j) % 3);
                tris.push(t1);
                tris.push(t2);
            }
        }
        for steps in [2, 3, 4, 8, 9] {
            let mut shared = EdgeSamples::default();
            let (mut alone, mut sharing) = (0usize, 0usize);
            for t in &tris {
                let (p, w) = (t.map(|x| x.0), t.map(|x| x.1));
                s.reset();
                let fresh = measure_triangle(&s, &p, &w, steps, &opts, None, f64::INFINITY).unwrap();
                alone += s.derivs.get();
                s.reset();
                let got = measure_triangle(&s, &p, &w, steps, &opts, Some(&mut shared), f64::INFINITY).unwrap();
                sharing += s.derivs.get();
                assert_eq!(got.max.to_bits(), fresh.max.to_bits(), "steps {steps}");
                assert_eq!(got.sum.to_bits(), fresh.sum.to_bits(), "steps {steps}");
            }
            if steps - 1 <= EDGE_MAX {
                assert!(sharing < alone * 4 / 5, "steps {steps}: {sharing} against {alone}");
            } else {
                assert_eq!(sharing, alone, "steps {steps}");
            }
        }
    }

    /// A limit gives up only where a sample lies beyond it: at the largest
    /// distance or above, the measure is the full one; below it, `None`,
    /// and the samples measured before it are not left for a neighbour.
    #[test]
    fn a_limit_gives_up_only_past_a_sample() {
        let s = Sphere::new(10.0);
        let opts = measure_projection();
        let w = [DVec2::new(0.5, 1.0), DVec2::new(0.9, 1.0), DVec2::new(0.7, 1.3)];
        let p = w.map(|x| s.at(x) * 1.002);
        let full = measure_triangle(&s, &p, &w, 4, &opts, None, f64::INFINITY).unwrap();
        assert!(full.max > 0.0);
        assert_eq!(measure_triangle(&s, &p, &w, 4, &opts, None, full.max), Some(full));
        let mut shared = EdgeSamples::default();
        assert_eq!(measure_triangle(&s, &p, &w, 4, &opts, Some(&mut shared), 0.5 * full.max), None);
        assert!(shared.map.is_empty());
    }

    /// Two triangles on one seam edge, its ends at the same points but at
    /// other (u,v) in each (one chart each side): the second measures its own
    /// samples, from its own hints.
    #[test]
    fn a_seam_edge_is_not_shared_across_charts() {
        let s = Sphere::new(10.0);
        let opts = measure_projection();
        let w1 = [DVec2::new(0.5, 1.0), DVec2::new(0.5, 1.4), DVec2::new(0.2, 1.2)];
        let w2 = [DVec2::new(0.5, 1.4), DVec2::new(0.5, 1.0), DVec2::new(0.8, 1.2)];
        let p1 = w1.map(|x| s.at(x) * 1.001);
        let p2 = [p1[1], p1[0], s.at(w2[2])];
        // The second triangle's corners at the same points, another chart.
        let w2_other = [w2[0] + DVec2::new(1e-3, 0.0), w2[1] + DVec2::new(1e-3, 0.0), w2[2]];
        let mut shared = EdgeSamples::default();
        measure_triangle(&s, &p1, &w1, 4, &opts, Some(&mut shared), f64::INFINITY);
        s.reset();
        let fresh = measure_triangle(&s, &p2, &w2_other, 4, &opts, None, f64::INFINITY).unwrap();
        let alone = s.derivs.get();
        s.reset();
        let got = measure_triangle(&s, &p2, &w2_other, 4, &opts, Some(&mut shared), f64::INFINITY).unwrap();
        assert_eq!(s.derivs.get(), alone);
        assert_eq!(got.max.to_bits(), fresh.max.to_bits());
        assert_eq!(got.sum.to_bits(), fresh.sum.to_bits());
        // In the same chart the edge is shared.
        s.reset();
        measure_triangle(&s, &p2, &w2, 4, &opts, Some(&mut shared), f64::INFINITY);
        assert!(s.derivs.get() < alone);
    }

    /// A flat cap about a pole (the end of a tube of rectangular section,
    /// its rows from the centre out to the rectangle): a triangle with a
    /// corner at the pole lies on the cap, but its samples' interpolated
    /// (u,v) lie far round the fan from their foot points, where Newton's
    /// first step got no closer and the hint's distance (up to 0.1 of the
    /// rectangle, far over any tolerance) stood as the deviation.
    #[test]
    fn samples_round_a_pole_are_found_on_the_surface() {
        use crate::nurbs::NurbsSurface;
        let rect = [(-0.45, 18.0), (-0.45, -18.0), (0.45, -18.0), (0.45, 18.0), (-0.45, 18.0)];
        let ring: Vec<DVec3> = rect.iter().map(|&(x, z)| DVec3::new(x, 0.0, z)).collect();
        let pts = alloc::vec![alloc::vec![DVec3::ZERO; 5], ring.clone(), ring];
        let kv = alloc::vec![0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0];
        let s = NurbsSurface::try_new([2, 1], alloc::vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], kv, &pts, None).unwrap();
        let a = 0.015;
        let uv = [DVec2::new(a, 0.75), DVec2::new(0.0, 0.75), DVec2::new(a, 0.5)];
        let p = uv.map(|x| s.point(x));
        let m = measure_triangle(&s, &p, &uv, 4, &measure_projection(), None, f64::INFINITY).unwrap();
        assert!(m.max < 1e-9, "{}", m.max);
        // The hints are far off: the search had work to do.
        let hint = uv[1] * 0.25 + uv[2] * 0.75;
        assert!(s.point(hint).distance(p[1] * 0.25 + p[2] * 0.75) > 0.1);
    }
}
