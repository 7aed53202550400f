//! Trim curves in a surface's parameters from samples (paper 001 §3.4):
//! sample a model-space edge (or a parameter-space curve that needs a change
//! of parameters), find each sample's native coordinates on the surface,
//! make them continuous across seams, then interpolate them with a C¹ cubic
//! (Hermite pieces, tangents from neighbouring samples) and add samples
//! until the fitted curve, mapped onto the surface, stays within the
//! tolerance of the exact points at every interval's midpoint.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::surfaces::{AxisMap, SurfDef};
use crate::numeric::TINY;
use crate::nurbs::reparam::{map_points, segment};
use crate::nurbs::{NurbsCurve, Surface};

/// At least this many samples on every curve (paper 001 §3.4 uses 51).
pub(super) const MIN_SAMPLES: usize = 51;
/// At most this many samples on one curve.
pub(super) const MAX_SAMPLES: usize = 4096;

/// Samples of one trim curve in the surface's native coordinates.
#[derive(Debug, Clone)]
pub(super) struct Track {
    /// The source: a model-space curve (`model`) or a curve whose (x, y)
    /// already are native coordinates.
    pub curve: NurbsCurve,
    pub model: bool,
    pub ts: Vec<f64>,
    pub qs: Vec<DVec2>,
    /// Coordinates that are arbitrary at the first and at the last sample
    /// (on an axis or a pole): there the track may meet its neighbours at
    /// another value of that coordinate.
    pub free_ends: [[bool; 2]; 2],
    /// Whether a sample far off the surface may still be retried by a global search.
    retry: bool,
}

/// `q` moved by whole periods to lie nearest to `near`.
pub(super) fn unwrap_near(mut q: DVec2, near: DVec2, periods: [Option<f64>; 2]) -> DVec2 {
    for k in 0..2 {
        if let Some(p) = periods[k] {
            if p > 0.0 {
                q[k] += libm::round((near[k] - q[k]) / p) * p;
            }
        }
    }
    q
}

impl Track {
    /// Native coordinates at `t`, continuous with `near` (free coordinates
    /// taken from it, periods unwrapped towards it).
    pub(in crate::io) fn at(
        &mut self,
        def: &SurfDef,
        t: f64,
        near: Option<DVec2>,
        periods: [Option<f64>; 2],
    ) -> (DVec2, [bool; 2]) {
        let p = self.curve.point(t);
        if !self.model {
            let q = p.truncate();
            return (near.map_or(q, |n| unwrap_near(q, n, periods)), [false; 2]);
        }
        let nat = def.invert(p, near, &mut self.retry);
        let mut q = nat.q;
        if let Some(n) = near {
            for k in 0..2 {
                if nat.free[k] {
                    q[k] = n[k];
                }
            }
            q = unwrap_near(q, n, periods);
        }
        (q, nat.free)
    }

    /// A straight segment from `a` to `b` in native coordinates (a link
    /// along a seam, a pole or a boundary that the file leaves implicit).
    pub(in crate::io) fn link(a: DVec2, b: DVec2) -> Option<Self> {
        let curve = crate::nurbs::analytic::line(a.extend(0.0), b.extend(0.0), 0.0, 1.0).ok()?;
        let ts: Vec<f64> = (0..=16).map(|i| i as f64 / 16.0).collect();
        let qs = ts.iter().map(|&t| a.lerp(b, t)).collect();
        Some(Self { curve, model: false, ts, qs, free_ends: [[false; 2]; 2], retry: true })
    }

    /// The track cut inside sample interval `i` where coordinate `k` equals
    /// `target` (bisection on the curve's parameter): the part before and the
    /// part after, each `None` when it would hold a single sample.
    pub(in crate::io) fn split_in(
        &mut self,
        def: &SurfDef,
        i: usize,
        k: usize,
        target: f64,
        periods: [Option<f64>; 2],
    ) -> (Option<Self>, Option<Self>) {
        if i + 1 >= self.qs.len() {
            return (Some(self.clone()), None);
        }
        let x0 = self.qs[i][k];
        let (mut lo, mut hi) = (self.ts[i], self.ts[i + 1]);
        let mut near = self.qs[i];
        let mut at_hi = self.qs[i + 1];
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            let (q, _) = self.at(def, mid, Some(near), periods);
            if (q[k] - target) * (x0 - target) > 0.0 {
                lo = mid;
                near = q;
            } else {
                hi = mid;
                at_hi = q;
            }
        }
        let mut cut = at_hi;
        cut[k] = target;
        let t = hi;
        let mut a = Self {
            curve: self.curve.clone(),
            model: self.model,
            ts: self.ts[..=i].to_vec(),
            qs: self.qs[..=i].to_vec(),
            free_ends: [self.free_ends[0], [false; 2]],
            retry: self.retry,
        };
        let mut b = Self {
            curve: self.curve.clone(),
            model: self.model,
            ts: alloc::vec![t],
            qs: alloc::vec![cut],
            free_ends: [[false; 2], self.free_ends[1]],
            retry: self.retry,
        };
        let after = if self.ts[i + 1] > t { i + 1 } else { i + 2 };
        b.ts.extend_from_slice(self.ts.get(after..).unwrap_or(&[]));
        b.qs.extend_from_slice(self.qs.get(after..).unwrap_or(&[]));
        if t > self.ts[i] {
            a.ts.push(t);
            a.qs.push(cut);
        }
        ((a.ts.len() >= 2).then_some(a), (b.ts.len() >= 2).then_some(b))
    }

    /// The track cut at its sample `j`: the samples up to it and from it,
    /// each `None` when it would hold that sample alone.
    pub(in crate::io) fn cut_at_sample(&self, j: usize) -> (Option<Self>, Option<Self>) {
        let n = self.qs.len();
        let part = |r: core::ops::Range<usize>, free: [[bool; 2]; 2]| Self {
            curve: self.curve.clone(),
            model: self.model,
            ts: self.ts[r.clone()].to_vec(),
            qs: self.qs[r].to_vec(),
            free_ends: free,
            retry: self.retry,
        };
        let head = (j > 0 && j < n).then(|| part(0..j + 1, [self.free_ends[0], [false; 2]]));
        let tail = (j + 1 < n).then(|| part(j..n, [[false; 2], self.free_ends[1]]));
        (head, tail)
    }

    /// Samples `curve` at [`MIN_SAMPLES`] even parameters plus its inner
    /// knots; `start` is the native point the curve should continue from.
    pub fn sample(
        def: &SurfDef,
        curve: NurbsCurve,
        model: bool,
        start: Option<DVec2>,
        periods: [Option<f64>; 2],
    ) -> Self {
        let (a, b) = curve.domain();
        let mut ts: Vec<f64> = (0..MIN_SAMPLES).map(|i| a + (b - a) * i as f64 / (MIN_SAMPLES - 1) as f64).collect();
        let breaks = curve.knots().breakpoints();
        if breaks.len() < MAX_SAMPLES / 4 {
            ts.extend(breaks.iter().copied().filter(|&k| k > a && k < b));
            crate::sort::f64s(&mut ts);
            ts.dedup_by(|x, y| (*x - *y).abs() <= 1e-12 * (b - a));
        }
        let mut tr = Self { curve, model, ts, qs: Vec::new(), free_ends: [[false; 2]; 2], retry: true };
        let mut qs: Vec<DVec2> = Vec::with_capacity(tr.ts.len());
        let mut free: Vec<[bool; 2]> = Vec::with_capacity(tr.ts.len());
        let mut near = start;
        for i in 0..tr.ts.len() {
            let (q, f) = tr.at(def, tr.ts[i], near, periods);
            qs.push(q);
            free.push(f);
            near = Some(q);
        }
        // A coordinate free at the ends (the curve starts or ends on an
        // axis, at a pole) takes the value of the nearest sample that has
        // one, so the track leaves the pole along its own direction.
        for k in 0..2 {
            if let Some(i0) = free.iter().position(|f| !f[k]) {
                for i in 0..i0 {
                    qs[i][k] = qs[i0][k];
                }
            }
            if let Some(i1) = free.iter().rposition(|f| !f[k]) {
                for i in i1 + 1..qs.len() {
                    qs[i][k] = qs[i1][k];
                }
            }
        }
        if let (Some(f0), Some(f1)) = (free.first(), free.last()) {
            tr.free_ends = [*f0, *f1];
        }
        tr.qs = qs;
        tr
    }

    /// Moves every sample by `shift` (whole periods).
    pub fn shift(&mut self, shift: DVec2) {
        for q in &mut self.qs {
            *q += shift;
        }
    }

    /// Box of the samples.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for &q in &self.qs {
            lo = lo.min(q);
            hi = hi.max(q);
        }
        (lo, hi)
    }

    /// The cubic through the samples in the face surface's parameters
    /// (native coordinates mapped by `maps`), refined until its image on
    /// `surface` is within `tol` of the exact points at interval midpoints;
    /// control points are kept inside the surface's domain. Returns the curve
    /// and whether the tolerance was met within [`MAX_SAMPLES`].
    pub fn fit(
        &mut self,
        def: &SurfDef,
        surface: &dyn Surface,
        maps: &[AxisMap; 2],
        periods: [Option<f64>; 2],
        tol: f64,
    ) -> (Option<NurbsCurve>, bool) {
        if let Some(c) = self.exact_on_plane(def, maps, surface) {
            return (Some(c), true);
        }
        let map = |q: DVec2| DVec2::new(maps[0].apply(q.x), maps[1].apply(q.y));
        let mut points = Vec::new();
        let met = self.refine(def, surface, &map, periods, tol, &mut points);
        let mut ws: Vec<DVec2> = self.qs.iter().map(|&q| map(q)).collect();
        let mut ts = self.ts.clone();
        if met {
            (ts, ws) = coarsen(ts, ws, points, surface, 0.5 * tol);
        }
        let ms = tangents(&ts, &ws);
        let [lo, hi] = surface.domain();
        (hermite_curve(&ts, &ws, &ms, lo, hi), met)
    }

    /// Adds samples at the midpoints of the intervals where the cubic
    /// through the samples strays more than `tol` from the surface, round
    /// after round (24 at most); whether it ends within `tol`.
    ///
    /// Each evaluation is made once: `points[i]` is the surface's point at
    /// sample `i` (left `None` until needed, kept for [`coarsen`]), and an
    /// interval's [`Mid`] is kept until the interval is split, as projecting
    /// its midpoint again from the same hint gives the same result, and the
    /// same cubic midpoint the same distance. The kept midpoints are dropped
    /// if a projection gives up the global retry, which changes what
    /// projecting them again gives.
    fn refine(
        &mut self,
        def: &SurfDef,
        surface: &dyn Surface,
        map: &impl Fn(DVec2) -> DVec2,
        periods: [Option<f64>; 2],
        tol: f64,
        points: &mut Vec<Option<DVec3>>,
    ) -> bool {
        *points = alloc::vec![None; self.ts.len()];
        let mut mids: Vec<Option<Mid>> = alloc::vec![None; self.ts.len().saturating_sub(1)];
        let mut mids_retry = self.retry;
        for _ in 0..24 {
            let ws: Vec<DVec2> = self.qs.iter().map(|&q| map(q)).collect();
            let ms = tangents(&self.ts, &ws);
            let mut add: Vec<(usize, f64, DVec2, DVec3)> = Vec::new();
            for i in 0..self.ts.len().saturating_sub(1) {
                let (t0, t1) = (self.ts[i], self.ts[i + 1]);
                let h = t1 - t0;
                if h.is_nan() || h <= 1e-14 * (t0.abs() + t1.abs()).max(TINY) {
                    continue;
                }
                // Below this chord the samples resolve the file's own noise, not the curve.
                let a = *points[i].get_or_insert_with(|| surface.point(ws[i]));
                let b = *points[i + 1].get_or_insert_with(|| surface.point(ws[i + 1]));
                if a.distance(b) < 16.0 * tol {
                    continue;
                }
                if self.retry != mids_retry {
                    mids.fill(None);
                    mids_retry = self.retry;
                }
                let tm = 0.5 * (t0 + t1);
                let mid = match &mut mids[i] {
                    Some(m) => m,
                    slot => {
                        let (q, _) = self.at(def, tm, Some(0.5 * (self.qs[i] + self.qs[i + 1])), periods);
                        slot.insert(Mid { q, exact: surface.point(map(q)), checked: None })
                    }
                };
                let hm = (ws[i] + ws[i + 1]) * 0.5 + (ms[i] - ms[i + 1]) * (h / 8.0);
                let off = match mid.checked {
                    Some((at, off)) if at == hm => off,
                    _ => {
                        let off = surface.point(hm).distance(mid.exact) > tol;
                        mid.checked = Some((hm, off));
                        off
                    }
                };
                if off {
                    add.push((i, tm, mid.q, mid.exact));
                }
            }
            if add.is_empty() {
                return true;
            }
            if self.ts.len() + add.len() > MAX_SAMPLES {
                return false;
            }
            // A new sample's point is its midpoint's; the two halves' midpoints are new.
            for &(i, tm, qm, exact) in add.iter().rev() {
                self.ts.insert(i + 1, tm);
                self.qs.insert(i + 1, qm);
                points.insert(i + 1, Some(exact));
                mids[i] = None;
                mids.insert(i + 1, None);
            }
        }
        false
    }

    /// On a plane, a model-space curve's native coordinates are the curve
    /// under the plane's affine inverse: the same knots and weights with
    /// mapped control points, exact, where a fitted cubic needs dozens of
    /// pieces per circle (a plate of 1000 holes held 11 MB of them). `None`
    /// when that does not apply or the result leaves the surface's domain or
    /// misses the samples (the loop then gets the fitted cubic).
    fn exact_on_plane(&self, def: &SurfDef, maps: &[AxisMap; 2], surface: &dyn Surface) -> Option<NurbsCurve> {
        let SurfDef::Plane { .. } = def else { return None };
        if !self.model || maps.iter().any(|m| *m != AxisMap::Identity) {
            return None;
        }
        let (&t0, &t1) = (self.ts.first()?, self.ts.last()?);
        if t1.partial_cmp(&t0) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        let (a, b) = self.curve.domain();
        let piece = if t0 > a || t1 < b { segment(&self.curve, t0, t1).ok()? } else { self.curve.clone() };
        let c = map_points(&piece, |p| def.invert(p, None, &mut false).q.extend(0.0)).ok()?;
        let [lo, hi] = surface.domain();
        let slack = 1e-9 * (hi - lo).max_element();
        let inside =
            |q: DVec2| q.x >= lo.x - slack && q.y >= lo.y - slack && q.x <= hi.x + slack && q.y <= hi.y + slack;
        if !c.control_points().all(|p| inside(p.truncate())) {
            return None;
        }
        let size = (hi - lo).max_element().max(TINY);
        let through = self.ts.iter().zip(&self.qs).all(|(&t, q)| c.point(t).truncate().distance(*q) <= 1e-7 * size);
        through.then_some(c)
    }
}

/// What [`Track::refine`] found at an interval's midpoint: its native
/// coordinates `q` (the curve's midpoint projected) and the surface's point
/// there, and the last cubic midpoint checked against it (in the face
/// surface's parameters) with whether it was farther than the tolerance.
#[derive(Debug, Clone, Copy)]
struct Mid {
    q: DVec2,
    exact: DVec3,
    checked: Option<(DVec2, bool)>,
}

/// Drops samples the cubic does not need: repeatedly tries to remove every
/// other inner sample, keeping those where the cubic through the rest
/// passes farther than `tol` (on the surface) from the removed exact point.
/// `points[i]` is the surface's point at `ws[i]` when already known. A
/// sample kept because the cubic missed it is not checked again while the
/// cubic's point there stays the same (a round that removed nothing near it).
fn coarsen(
    mut ts: Vec<f64>,
    mut ws: Vec<DVec2>,
    mut points: Vec<Option<DVec3>>,
    surface: &dyn Surface,
    tol: f64,
) -> (Vec<f64>, Vec<DVec2>) {
    points.resize(ts.len(), None);
    // Per sample: the last cubic point checked against it and whether it was within `tol`.
    let mut checked: Vec<Option<(DVec2, bool)>> = alloc::vec![None; ts.len()];
    loop {
        let n = ts.len();
        if n <= 2 {
            break;
        }
        // Candidates: odd inner indices.
        let keep_idx: Vec<usize> = (0..n).filter(|&i| i % 2 == 0 || i == n - 1).collect();
        let kt: Vec<f64> = keep_idx.iter().map(|&i| ts[i]).collect();
        let kw: Vec<DVec2> = keep_idx.iter().map(|&i| ws[i]).collect();
        let km = tangents(&kt, &kw);
        let mut keep = alloc::vec![true; n];
        let mut removed = 0;
        for (k, w) in keep_idx.windows(2).enumerate() {
            let (a, b) = (w[0], w[1]);
            let h = ts[b] - ts[a];
            for i in a + 1..b {
                let s = if h > 0.0 { (ts[i] - ts[a]) / h } else { 0.5 };
                let (s2, s3) = (s * s, s * s * s);
                let hp = kw[k] * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + km[k] * (h * (s3 - 2.0 * s2 + s))
                    + kw[k + 1] * (3.0 * s2 - 2.0 * s3)
                    + km[k + 1] * (h * (s3 - s2));
                let within = match checked[i] {
                    Some((at, within)) if at == hp => within,
                    _ => {
                        let exact = *points[i].get_or_insert_with(|| surface.point(ws[i]));
                        let within = surface.point(hp).distance(exact) <= tol;
                        checked[i] = Some((hp, within));
                        within
                    }
                };
                if within {
                    keep[i] = false;
                    removed += 1;
                }
            }
        }
        if removed == 0 {
            break;
        }
        retain_kept(&mut ts, &keep);
        retain_kept(&mut ws, &keep);
        retain_kept(&mut points, &keep);
        retain_kept(&mut checked, &keep);
    }
    (ts, ws)
}

/// Keeps the items of `v` whose `keep` entry is true.
fn retain_kept<T>(v: &mut Vec<T>, keep: &[bool]) {
    let mut i = 0;
    v.retain(|_| {
        i += 1;
        keep.get(i - 1).copied().unwrap_or(true)
    });
}

/// Derivatives at the samples, shape-preserving per coordinate (Fritsch
/// and Butland): zero where a coordinate turns, a weighted harmonic mean of
/// the neighbouring slopes elsewhere, so each cubic piece is monotone in u
/// and in v between its samples. The fit never overshoots its samples, and
/// noise in the samples (a file's edge lying slightly off its surface)
/// cannot fold it into loops.
fn tangents(ts: &[f64], ws: &[DVec2]) -> Vec<DVec2> {
    let n = ts.len();
    if n < 2 {
        return alloc::vec![DVec2::ZERO; n];
    }
    let slope = |i: usize| {
        let h = ts[i + 1] - ts[i];
        if h > 0.0 {
            (ws[i + 1] - ws[i]) / h
        } else {
            DVec2::ZERO
        }
    };
    if n == 2 {
        return alloc::vec![slope(0); 2];
    }
    let mut m = alloc::vec![DVec2::ZERO; n];
    for i in 1..n - 1 {
        let (h0, h1) = (ts[i] - ts[i - 1], ts[i + 1] - ts[i]);
        let (d0, d1) = (slope(i - 1), slope(i));
        for k in 0..2 {
            let (a, b) = (d0[k], d1[k]);
            m[i][k] = if a * b > 0.0 { 3.0 * (h0 + h1) / ((2.0 * h1 + h0) / a + (h1 + 2.0 * h0) / b) } else { 0.0 };
        }
    }
    // Ends: the three-point formula, kept monotone.
    let end = |h0: f64, h1: f64, d0: DVec2, d1: DVec2| {
        let mut e = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
        for k in 0..2 {
            if e[k] * d0[k] <= 0.0 {
                e[k] = 0.0;
            } else if d0[k] * d1[k] < 0.0 && e[k].abs() > 3.0 * d0[k].abs() {
                e[k] = 3.0 * d0[k];
            }
        }
        e
    };
    m[0] = end(ts[1] - ts[0], ts[2] - ts[1], slope(0), slope(1));
    m[n - 1] = end(ts[n - 1] - ts[n - 2], ts[n - 2] - ts[n - 3], slope(n - 2), slope(n - 3));
    m
}

/// The C¹ cubic through `ws` at `ts` with derivatives `ms`, as Bézier
/// pieces (inner knots of multiplicity 3), control points clamped to `lo..hi`.
fn hermite_curve(ts: &[f64], ws: &[DVec2], ms: &[DVec2], lo: DVec2, hi: DVec2) -> Option<NurbsCurve> {
    let mut keep: Vec<usize> = Vec::with_capacity(ts.len());
    for i in 0..ts.len() {
        if keep.last().is_none_or(|&j| ts[i] > ts[j]) {
            keep.push(i);
        }
    }
    if keep.len() < 2 {
        return None;
    }
    let clamp = |p: DVec2| p.clamp(lo, hi).extend(0.0);
    let first = keep[0];
    let mut knots: Vec<f64> = alloc::vec![ts[first]; 4];
    let mut pts: Vec<DVec3> = alloc::vec![clamp(ws[first])];
    for w in keep.windows(2) {
        let (i, j) = (w[0], w[1]);
        let h = ts[j] - ts[i];
        pts.push(clamp(ws[i] + ms[i] * (h / 3.0)));
        pts.push(clamp(ws[j] - ms[j] * (h / 3.0)));
        pts.push(clamp(ws[j]));
        knots.extend([ts[j]; 3]);
    }
    knots.push(ts[keep[keep.len() - 1]]);
    NurbsCurve::try_new(3, knots, pts, None).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nurbs::analytic::circle_arc;
    use crate::nurbs::{Aabb, NurbsSurface, SurfaceDerivs};
    use alloc::boxed::Box;
    use core::cell::RefCell;

    /// `s`, remembering the parameters of every point asked of it.
    struct Seen<'a> {
        s: &'a dyn Surface,
        uvs: RefCell<Vec<[u64; 2]>>,
    }

    impl Surface for Seen<'_> {
        fn domain(&self) -> [DVec2; 2] {
            self.s.domain()
        }
        fn point(&self, uv: DVec2) -> DVec3 {
            self.uvs.borrow_mut().push([uv.x.to_bits(), uv.y.to_bits()]);
            self.s.point(uv)
        }
        fn derivs(&self, uv: DVec2) -> SurfaceDerivs {
            self.s.derivs(uv)
        }
        fn breaks(&self, along_u: bool) -> Vec<f64> {
            self.s.breaks(along_u)
        }
        fn bounding_box(&self) -> Aabb {
            self.s.bounding_box()
        }
    }

    /// A biquadratic bump over the square [0, 2]², 2 high in the middle.
    fn dome() -> NurbsSurface {
        let pts: Vec<Vec<DVec3>> = (0..3)
            .map(|i| (0..3).map(|j| DVec3::new(i as f64, j as f64, if i == 1 && j == 1 { 2.0 } else { 0.0 })).collect())
            .collect();
        let k = alloc::vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        NurbsSurface::try_new([2, 2], k.clone(), k, &pts, None).unwrap()
    }

    /// Refining a fitted trim curve asks the surface for each point once
    /// (a sample's point serves both intervals it ends, and an interval a
    /// round leaves unchanged keeps its midpoint), and coarsening the result
    /// asks for none of the samples' points again, nor for a cubic point
    /// that an earlier round checked.
    #[test]
    fn fitting_evaluates_no_point_of_the_surface_twice() {
        let s = dome();
        let def = SurfDef::Nurbs { surface: s.clone(), periods: [None; 2], natural: None, facts: Box::default() };
        let arc = circle_arc(DVec3::new(1.0, 1.0, 1.2), DVec3::X, DVec3::Y, 0.7, 0.0, 4.5).unwrap();
        let mut tr = Track::sample(&def, arc, true, None, [None; 2]);
        let tol = 1e-7;
        let repeats = |seen: Seen<'_>| {
            let mut uvs = seen.uvs.take();
            let asked = uvs.len();
            uvs.sort_unstable();
            uvs.dedup();
            (asked - uvs.len(), uvs)
        };
        let seen = Seen { s: &s, uvs: RefCell::default() };
        let mut points = Vec::new();
        assert!(tr.refine(&def, &seen, &|q| q, [None; 2], tol, &mut points));
        assert!(tr.ts.len() > MIN_SAMPLES, "the fit refined: {} samples", tr.ts.len());
        assert_eq!(repeats(seen).0, 0, "refining asked for a point twice");
        let seen = Seen { s: &s, uvs: RefCell::default() };
        let (ts, _) = coarsen(tr.ts.clone(), tr.qs.clone(), points, &seen, 0.5 * tol);
        assert!(ts.len() < tr.ts.len(), "coarsening removed samples");
        let (again, uvs) = repeats(seen);
        assert_eq!(again, 0, "coarsening asked for a point twice");
        let samples: Vec<[u64; 2]> = tr.qs.iter().map(|q| [q.x.to_bits(), q.y.to_bits()]).collect();
        assert!(!uvs.iter().any(|uv| samples.contains(uv)), "coarsening asked for a sample's point again");
    }
}
