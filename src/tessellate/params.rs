//! Parameter lines of the iso-parametric grid (paper 000 §3.1).
//!
//! An interval is accepted when, on every tested iso-curve, the points at 1/4,
//! 2/4 and 3/4 of it lie within the tolerance of the chord (one midpoint alone
//! misses S-shaped cubic spans), the normal turns less than the angle limit and
//! the chord is not longer than the edge limit. The paper bisects a failing
//! interval; we split it into `n` equal parts with `n` estimated from the
//! measured sag (sag falls as 1/n²), so triangle counts follow the tolerance
//! smoothly instead of jumping by powers of two. Testing all iso-curves
//! together (paper §3.1.3: boundaries plus 1/4, 1/2, 3/4 interior lines) gives
//! one parameter set for both opposite sides, which is the paper's
//! equalization (§3.1.2) for free.

use alloc::vec::Vec;
use glam::{DVec2, DVec3};

use super::refine::FOLD_TURN;
use crate::collections::HashMap;
use crate::math::{ceil, sqrt};
use crate::nurbs::Surface;

/// One surface's points and normals as the grid's iso-curve tests evaluate
/// them, kept by the parameters' bits: the two passes of one grid, and the
/// trials of one face with other edge limits (`auto`'s rebuild trials),
/// test the same fine intervals of the same lines, and a value asked for
/// again gives the same bits without the evaluation. Kept for one surface
/// only; past [`Samples::MOST`] values new ones are evaluated, not kept.
#[derive(Default)]
pub(crate) struct Samples(
    core::cell::RefCell<HashMap<[u64; 2], (DVec3, DVec3)>>,
    /// The fine intervals' shapes ([`Samples::shape_with`]).
    core::cell::RefCell<HashMap<[u64; 7], Shape>>,
    /// Whether room for a direction's fine demand was made, along u and v.
    core::cell::Cell<[bool; 2]>,
    /// Times a value was kept in a full store (it grew), and shapes
    /// measured, for tests.
    #[cfg(test)]
    core::cell::Cell<[usize; 2]>,
);

impl Samples {
    /// Most values kept (about 70 bytes each).
    const MOST: usize = 1 << 20;

    /// The surface's point and unit normal at `uv`, evaluated once (by
    /// `eval`, which gives the bits [`Surface::point_normal`] gives and
    /// must not read this store). The key is hashed and looked up once,
    /// for the value and for the place a new one goes.
    fn point_normal_with(&self, uv: DVec2, eval: impl FnOnce() -> (DVec3, DVec3)) -> (DVec3, DVec3) {
        let key = [uv.x.to_bits(), uv.y.to_bits()];
        let mut kept = self.0.borrow_mut();
        let room = kept.len() < Self::MOST;
        #[cfg(test)]
        let full = kept.len() == kept.capacity();
        match kept.entry(key) {
            hashbrown::hash_map::Entry::Occupied(o) => *o.get(),
            hashbrown::hash_map::Entry::Vacant(slot) => {
                let x = eval();
                if room {
                    #[cfg(test)]
                    self.3.set([self.3.get()[0] + usize::from(full), self.3.get()[1]]);
                    slot.insert(x);
                }
                x
            }
        }
    }

    /// Room for the values the fine demand along u (`along_u`) or v of an
    /// evenly parameterized surface ([`fine_demand`]) evaluates on
    /// `probes` over `[t0, t1]`, made once per direction before the first
    /// is kept: each line's [`FINE`] intervals inside its pieces, tested
    /// at their ends and quarter points, and half as many again. Grown a value at a time, the store
    /// doubled and rehashed every value about fifteen times on the way.
    fn reserve_fine(&self, along_u: bool, probes: &[Probe<'_>], t0: f64, t1: f64) {
        let mut made = self.2.get();
        if made[usize::from(along_u)] || t1 <= t0 {
            return;
        }
        made[usize::from(along_u)] = true;
        self.2.set(made);
        let values = |p: &Probe<'_>| -> f64 {
            let Some(pieces) = &p.inside else { return (4 * FINE + 1) as f64 };
            let share: f64 = pieces.iter().map(|&(lo, hi)| ((hi.min(t1) - lo.max(t0)) / (t1 - t0)).max(0.0)).sum();
            share * (4 * FINE) as f64 + 2.0 * pieces.len() as f64
        };
        // Half as many again: the lines placed and the intervals split
        // after it test points of their own.
        let want: f64 = 1.5 * probes.iter().map(values).sum::<f64>();
        let mut kept = self.0.borrow_mut();
        let room = Self::MOST.saturating_sub(kept.len());
        kept.reserve((ceil(want) as usize).min(room));
    }

    /// How many values are kept.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.0.borrow().len()
    }

    /// How many times the store grew.
    #[cfg(test)]
    pub(crate) fn growths(&self) -> usize {
        self.3.get()[0]
    }

    /// How many fine intervals' shapes were measured.
    #[cfg(test)]
    pub(crate) fn shapes_measured(&self) -> usize {
        self.3.get()[1]
    }

    /// The shape of the fine interval `[a, b]` of the iso-line `line`
    /// (direction and fixed parameter) within the turn limit `angle` and
    /// `side`, measured by `measure` once: the grid of every trial of a
    /// rebuilt face (other tolerance shares and edge limits) sums the
    /// demand of the same fine intervals, and what it measures of them
    /// does not depend on those limits. `measure` must not use this store.
    fn shape_with(
        &self,
        line: [u64; 2],
        (a, b): (f64, f64),
        angle: f64,
        side: Side,
        measure: impl FnOnce() -> Shape,
    ) -> Shape {
        let (lo, hi) = side.piece.map_or((u64::MAX, u64::MAX), |(lo, hi)| (lo.to_bits(), hi.to_bits()));
        let one_sided = u64::from(side.one_sided) << 1;
        let key = [line[0] | one_sided, line[1], a.to_bits(), b.to_bits(), lo, hi, angle.to_bits()];
        if let Some(s) = self.1.borrow().get(&key) {
            return *s;
        }
        let s = measure();
        #[cfg(test)]
        self.3.set([self.3.get()[0], self.3.get()[1] + 1]);
        let mut kept = self.1.borrow_mut();
        if kept.len() < Self::MOST {
            kept.insert(key, s);
        }
        s
    }
}

/// Limits one interval must satisfy.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    /// Chordal tolerance for this pass.
    pub tol: f64,
    /// Normal (or tangent) turn limit, radians.
    pub angle: f64,
    /// Longest chord allowed.
    pub max_edge: f64,
    /// Chords at or below this length are accepted.
    pub min_edge: f64,
}

impl Limits {
    /// The same limits bit for bit (so an outline made for one serves the other).
    pub(crate) fn same_as(&self, o: &Self) -> bool {
        [self.tol, self.angle, self.max_edge, self.min_edge].map(f64::to_bits)
            == [o.tol, o.angle, o.max_edge, o.min_edge].map(f64::to_bits)
    }
}

/// Most parts one interval is split into at once, and the deepest recursion.
const MAX_SPLIT: usize = 64;
const MAX_DEPTH: usize = 24;
/// Most parameters produced along one direction (guards memory on hostile input).
pub(crate) const MAX_PARAMS: usize = 20_000;

/// How badly the interval `[a, b]` fails: the factor by which it must be
/// split (1.0 = accepted). `eval(t)` gives point and unit normal (or tangent).
fn interval_need(eval: &dyn Fn(f64) -> (DVec3, DVec3), a: f64, b: f64, lim: &Limits, side: Side) -> (f64, f64) {
    let (demand, sag) = interval_demand(eval, a, b, lim, side);
    (demand.max(1.0), sag)
}

/// How many chords `[a, b]` needs, as a fraction, and its largest sag: sag
/// falls as the square of the step, turn and length as the step, so over
/// short intervals the demand adds up along the curve. 0 at or below the
/// shortest edge. With `side`, see [`Side`].
fn interval_demand(eval: &dyn Fn(f64) -> (DVec3, DVec3), a: f64, b: f64, lim: &Limits, side: Side) -> (f64, f64) {
    let d = demand_parts(eval, a, b, lim, side);
    (d.smooth.max(d.fold), d.sag)
}

/// An interval's demand in two parts: what falls with the step (sag, a
/// turn that spreads over the interval, length), and a turn past a right
/// angle within a quarter of it: a fold of the surface (a pleat, where the
/// control net doubles back and the normal reverses within a band far
/// narrower than any interval; on a curve across it, a cusp), which no
/// equal split of a longer interval lowers where it is. Over a chord
/// within the tolerance a fold asks for nothing, as refinement stops there
/// too (`Criteria::short_for_angle`).
struct Demand {
    smooth: f64,
    fold: f64,
    sag: f64,
}

/// How an interval of a probe is judged: `one_sided` as [`Probe::one_sided`],
/// and `piece`, the run of the iso-line inside the trim loops it lies in
/// (`None`: the whole line counts).
#[derive(Clone, Copy)]
struct Side {
    one_sided: bool,
    piece: Option<(f64, f64)>,
}

/// [`interval_demand`] with the fold's part apart ([`Demand`]).
fn demand_parts(eval: &dyn Fn(f64) -> (DVec3, DVec3), a: f64, b: f64, lim: &Limits, side: Side) -> Demand {
    judge(&shape(eval, a, b, lim.angle, side), lim)
}

/// What [`demand_parts`] measures of an interval, whatever the tolerance
/// and edge limits: its chord's length, largest sag, the normal's turn
/// (judged from inside where it turns more than `angle`, see [`shape`])
/// and whether that turn is a fold, and for a turn by a trim border the
/// nearer piece end's distance. A rebuild's trials test the same fine
/// intervals within other limits ([`Samples::shape_with`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Shape {
    len: f64,
    sag: f64,
    turn: f64,
    /// The turn is past a right angle between neighbouring samples.
    fold: bool,
    /// Distance from the interval's nearer end to its piece's end, where
    /// the turn is judged against a trim border; infinite elsewhere.
    gap: f64,
}

/// [`Shape`] of `[a, b]` on `eval` with the turn limit `angle`.
fn shape(eval: &dyn Fn(f64) -> (DVec3, DVec3), a: f64, b: f64, angle: f64, side: Side) -> Shape {
    let one_sided = side.one_sided;
    let (pa, na) = eval(a);
    let (pb, nb) = eval(b);
    let chord = pb - pa;
    let len = chord.length();
    let mut sag: f64 = 0.0;
    let mut mids = [DVec3::ZERO; 3];
    for (k, f) in [0.25, 0.5, 0.75].into_iter().enumerate() {
        let (p, n) = eval(a + (b - a) * f);
        sag = sag.max(dist_to_segment(p, pa, pb));
        mids[k] = n;
    }
    let turn_of = |na: DVec3, nb: DVec3| {
        mids.iter().fold(crate::math::angle_between(na, nb), |t, &n| {
            t.max(crate::math::angle_between(na, n)).max(crate::math::angle_between(n, nb))
        })
    };
    let mut turn = turn_of(na, nb);
    let mut ends = (na, nb);
    if one_sided && turn > angle {
        // On a crease (a C0 knot: a folded strip, a polyline's corner) an
        // end's own normal or tangent is the next piece's: the interval
        // turns by what it sees from inside, or it is split down to the
        // shortest edge for a turn it does not have. A rounding error
        // inside, so that at a pole the normal is still the fallback the
        // end itself gets (a step inside would see the pole's fan turn);
        // and only ever less, so no interval is split more than before.
        let e = (b - a) * 1e-12;
        let inside = (eval(a + e).1, eval(b - e).1);
        let seen = turn_of(inside.0, inside.1);
        if seen < turn {
            (turn, ends) = (seen, inside);
        }
    }
    // A fold turns past a right angle between two neighbouring samples (a
    // quarter of the interval); a bend that turns as far over the whole
    // interval turns less between them, and an equal split serves it. On
    // a curve (a trim curve, an untrimmed face's border) only the inner
    // samples count, as an end's tangent may be the next piece's (a
    // corner at a knot).
    let sharp = || {
        let n = [ends.0, mids[0], mids[1], mids[2], ends.1];
        let pairs = if one_sided { &n[..] } else { &n[1..4] };
        pairs.windows(2).any(|w| crate::math::angle_between(w[0], w[1]) > FOLD_TURN)
    };
    let fold = turn > FOLD_TURN && sharp();
    let mut gap = f64::INFINITY;
    if !fold && turn > 0.0 && one_sided {
        if let Some((lo, hi)) = side.piece {
            let end_gap = |t: f64, p: DVec3, end: f64| if t == end { 0.0 } else { p.distance(eval(end).0) };
            gap = end_gap(a, pa, lo).min(end_gap(b, pb, hi));
        }
    }
    Shape { len, sag, turn, fold, gap }
}

/// The demand of an interval of shape `s` within `lim` (whose turn limit
/// `s` was measured with).
fn judge(s: &Shape, lim: &Limits) -> Demand {
    let Shape { len, sag, turn, fold: folds, gap } = *s;
    if len <= lim.min_edge {
        return Demand { smooth: 0.0, fold: 0.0, sag };
    }
    let mut demand: f64 = 0.0;
    let mut fold: f64 = 0.0;
    if sag > 0.0 {
        demand = demand.max(sqrt(sag / lim.tol));
    }
    if folds {
        if len > lim.tol {
            fold = turn / lim.angle;
        }
    } else if turn > 0.0 {
        // Within a tenth of this pass's tolerance of a trim border, a turn
        // is split no finer than that: refinement splits a triangle for it
        // down to a tenth of the whole tolerance (`Criteria::short_for_angle`),
        // and lines packed into a curl of the surface along the border leave
        // slivers between them and the border, whose facets fold on the
        // surface's bend along them.
        let floor = BEND_FLOOR * lim.tol;
        let at_border = gap <= floor;
        let most = if at_border { len / floor } else { f64::INFINITY };
        demand = demand.max((turn / lim.angle).min(most));
    }
    if len > 0.0 {
        demand = demand.max(len / lim.max_edge);
    }
    Demand { smooth: demand, fold, sag }
}

/// The shortest part, as a fraction of the pass's tolerance (half to all of
/// the face's), an interval by a trim border is split into for its normal's
/// turn: at most refinement's floor for a bend. A floor of the whole
/// tolerance left parts refinement still split, at many more triangles.
const BEND_FLOOR: f64 = 0.1;

/// Distance from `p` to the segment `ab`.
pub(crate) fn dist_to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let l2 = ab.length_squared();
    if l2 <= 0.0 {
        return p.distance(a);
    }
    let t = ((p - a).dot(ab) / l2).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// One curve an interval is tested on: its evaluator (point and unit normal
/// or tangent) and, when only part of it matters, the parameter intervals
/// that do (an iso-line's pieces inside a face's trim loops).
pub(crate) struct Probe<'e> {
    pub eval: &'e dyn Fn(f64) -> (DVec3, DVec3),
    pub inside: Option<Vec<(f64, f64)>>,
    /// Whether an interval's turn is judged from inside it where its ends
    /// disagree (a surface's iso-lines across a crease). Trim curves are
    /// not: [`coarsen`] judges their runs by the ends' own tangents.
    pub one_sided: bool,
    /// For an iso-line of a surface, where its fine intervals' shapes are
    /// kept and the line's key there ([`Samples::shape_with`]).
    pub line: Option<(&'e Samples, [u64; 2])>,
}

/// Each of `evals` as a probe tested over the whole interval, on both sides.
#[cfg(feature = "std")]
fn whole_curves<'e>(evals: &[&'e dyn Fn(f64) -> (DVec3, DVec3)]) -> Vec<Probe<'e>> {
    evals.iter().map(|&eval| Probe { eval, inside: None, one_sided: false, line: None }).collect()
}

/// Subdivides `[t0, t1]` (already split at `breaks`) until every interval passes
/// for all curves in `evals`. Returns ascending parameters including both ends,
/// and the largest sag left in an accepted interval.
#[cfg(feature = "std")]
pub(crate) fn subdivide(evals: &[&dyn Fn(f64) -> (DVec3, DVec3)], breaks: &[f64], lim: &Limits) -> (Vec<f64>, f64) {
    let probes = whole_curves(evals);
    subdivide_probes(&probes, breaks, lim, MAX_PARAMS)
}

/// Drops nodes of an accepted subdivision `ts` that the limits do not need:
/// the knot breaks [`subdivide`] starts from force a node per break group
/// even where the curve is straight (a 3 mm cubic with 27 knot spans took 16
/// segments at a 0.18 tolerance). A run of fine intervals becomes one when
/// its chord passes the same tests, on the fine nodes and the quarter points
/// of every fine interval: the samples the fine intervals were accepted on.
#[cfg(feature = "std")]
pub(crate) fn coarsen(
    evals: &[&dyn Fn(f64) -> (DVec3, DVec3)],
    straight: &dyn Fn(f64, f64) -> bool,
    ts: &[f64],
    lim: &Limits,
) -> Vec<f64> {
    let n = ts.len();
    if n < 3 || evals.is_empty() {
        return ts.to_vec();
    }
    // Samples: node i at 4i, the quarter points of interval i at 4i+1..4i+3.
    let params: Vec<f64> = (0..4 * (n - 1) + 1)
        .map(|s| {
            let (i, q) = (s / 4, s % 4);
            if q == 0 {
                ts[i]
            } else {
                ts[i] + (ts[i + 1] - ts[i]) * q as f64 * 0.25
            }
        })
        .collect();
    let samples: Vec<Vec<(DVec3, DVec3)>> = evals.iter().map(|e| params.iter().map(|&t| e(t)).collect()).collect();
    let passes = |i: usize, k: usize| -> bool {
        let (pa, pb) = (samples[0][4 * i].0, samples[0][4 * k].0);
        let len = pa.distance(pb);
        if len <= lim.min_edge {
            return true;
        }
        if len > lim.max_edge {
            return false;
        }
        straight(ts[i], ts[k])
            && samples.iter().all(|sm| {
                let (na, nb) = (sm[4 * i].1, sm[4 * k].1);
                crate::math::angle_between(na, nb) <= lim.angle
                    && sm[4 * i + 1..4 * k].iter().all(|&(p, d)| {
                        dist_to_segment(p, pa, pb) <= lim.tol
                            && crate::math::angle_between(na, d) <= lim.angle
                            && crate::math::angle_between(d, nb) <= lim.angle
                    })
            })
    };
    // From the first node, each run reaches as far as its chord passes:
    // steps double while they pass, then halve back to the last that does,
    // so a straight run of L intervals costs O(L log L) samples, not O(L²).
    let mut out = Vec::with_capacity(n);
    out.push(ts[0]);
    let mut i = 0;
    while i + 1 < n {
        let mut k = i + 1;
        let mut step = 1;
        while k + step < n && passes(i, k + step) {
            k += step;
            step *= 2;
        }
        while step > 1 {
            step /= 2;
            if k + step < n && passes(i, k + step) {
                k += step;
            }
        }
        out.push(ts[k]);
        i = k;
    }
    out
}

/// As [`subdivide`], each curve tested only on the parts of an interval where
/// it matters, splitting no more once `cap` parameters are placed.
pub(crate) fn subdivide_probes(probes: &[Probe<'_>], breaks: &[f64], lim: &Limits, cap: usize) -> (Vec<f64>, f64) {
    let mut out: Vec<f64> = Vec::new();
    let mut worst: f64 = 0.0;
    let Some(&first) = breaks.first() else { return (out, 0.0) };
    out.push(first);
    for w in breaks.windows(2) {
        if w[1] > w[0] {
            split_rec(probes, w[0], w[1], lim, 0, cap, &mut out, &mut worst);
        }
    }
    (out, worst)
}

#[allow(clippy::too_many_arguments)]
fn split_rec(
    probes: &[Probe<'_>],
    a: f64,
    b: f64,
    lim: &Limits,
    depth: usize,
    cap: usize,
    out: &mut Vec<f64>,
    worst: &mut f64,
) {
    let (need, sag) = need_all(probes, a, b, lim);
    if need <= 1.0 || depth >= MAX_DEPTH || out.len() >= cap || b - a <= (a.abs() + b.abs()) * 1e-12 {
        *worst = worst.max(sag);
        out.push(b);
        return;
    }
    // Equal parts; when a part still fails, raise the count for the whole
    // interval by that part's need rather than bisecting just it, so the
    // interval keeps equal steps and close to the fewest that pass.
    // A part that fails only for a fold ([`Demand`]) fails at every count:
    // raising the whole interval's count for it covered a pleated patch's
    // every knot span with 64 lines. Such parts are split on their own,
    // the others kept as they are.
    let mut n = (ceil(need) as usize).clamp(2, MAX_SPLIT);
    for _ in 0..6 {
        let mut part_need: f64 = 1.0;
        let mut part_sag: f64 = 0.0;
        let mut folded = false;
        for k in 0..n {
            let (t0, t1) = (a + (b - a) * k as f64 / n as f64, a + (b - a) * (k + 1) as f64 / n as f64);
            let d = demand_all(probes, t0, t1, lim);
            part_need = part_need.max(d.smooth);
            part_sag = part_sag.max(d.sag);
            folded |= d.fold > 1.0;
        }
        if part_need <= 1.0 && folded {
            let mut prev = a;
            for k in 1..=n {
                let t = if k == n { b } else { a + (b - a) * k as f64 / n as f64 };
                split_rec(probes, prev, t, lim, depth + 1, cap, out, worst);
                prev = t;
            }
            return;
        }
        if part_need <= 1.0 {
            for k in 1..=n {
                out.push(if k == n { b } else { a + (b - a) * k as f64 / n as f64 });
            }
            *worst = worst.max(part_sag);
            return;
        }
        if n >= MAX_SPLIT {
            break;
        }
        n = ((ceil(n as f64 * part_need) as usize).max(n + 1)).min(MAX_SPLIT);
    }
    let mut prev = a;
    for k in 1..=n {
        let t = if k == n { b } else { a + (b - a) * k as f64 / n as f64 };
        split_rec(probes, prev, t, lim, depth + 1, cap, out, worst);
        prev = t;
    }
}

fn need_all(probes: &[Probe<'_>], a: f64, b: f64, lim: &Limits) -> (f64, f64) {
    over_probes(probes, a, b, lim, interval_need, 1.0)
}

/// [`need_all`] with the folds' part apart: the largest of each part over
/// the probes (0 where nothing is asked, not 1).
fn demand_all(probes: &[Probe<'_>], a: f64, b: f64, lim: &Limits) -> Demand {
    let mut all = Demand { smooth: 0.0, fold: 0.0, sag: 0.0 };
    let mut take = |d: Demand| {
        all.smooth = all.smooth.max(d.smooth);
        all.fold = all.fold.max(d.fold);
        all.sag = all.sag.max(d.sag);
    };
    each_part(probes, a, b, |p, x, y, side| take(demand_parts(p.eval, x, y, lim, side)));
    all
}

/// A test of one interval of one curve: a need and the largest sag.
type IntervalTest = fn(&dyn Fn(f64) -> (DVec3, DVec3), f64, f64, &Limits, Side) -> (f64, f64);

/// The largest `test` over the parts of `[a, b]` where each probe matters, starting from `floor`.
fn over_probes(probes: &[Probe<'_>], a: f64, b: f64, lim: &Limits, test: IntervalTest, floor: f64) -> (f64, f64) {
    let mut need: f64 = floor;
    let mut sag: f64 = 0.0;
    let mut take = |(n, s): (f64, f64)| {
        need = need.max(n);
        sag = sag.max(s);
    };
    each_part(probes, a, b, |p, x, y, side| take(test(p.eval, x, y, lim, side)));
    (need, sag)
}

/// Calls `f` with each probe and each part `[x, y]` of `[a, b]` where it
/// matters: the whole interval, or only the parts inside the probe's
/// region (a piece a rounding error long says nothing), with how to judge it.
fn each_part<'e>(probes: &[Probe<'e>], a: f64, b: f64, mut f: impl FnMut(&Probe<'e>, f64, f64, Side)) {
    for p in probes {
        match &p.inside {
            None => f(p, a, b, Side { one_sided: p.one_sided, piece: None }),
            Some(pieces) => {
                let eps = (b - a) * 1e-9;
                for &(lo, hi) in pieces {
                    let (x, y) = (a.max(lo), b.min(hi));
                    if y - x > eps {
                        f(p, x, y, Side { one_sided: p.one_sided, piece: Some((lo, hi)) });
                    }
                }
            }
        }
    }
}

/// Fine intervals whose demand [`equidistribute`] sums.
const FINE: usize = 256;

/// Parameters over `[t0, t1]` of a surface with even parameters (paper
/// 001's rebuild), where knots mark no feature: the fractional chord demand
/// of [`FINE`] equal intervals is summed and the lines put at equal shares
/// of it (equidistribution), so the rows follow curvature without the
/// rounding up that one equal split per knot group costs. An interval that
/// still fails raises the demand under it and the lines are placed again;
/// after four rounds what fails is split as [`subdivide_probes`] splits.
/// Below [`MAX_PARAMS`], a `cap` the summed demand already passes returns
/// `cap + 1` even parameters at once (and an infinite sag): a grid that
/// many lines make is refused anyway, and placing them costs as much again.
/// `demand`: the fine demand when [`even_demand`] already measured it.
fn equidistribute(
    probes: &[Probe<'_>],
    t0: f64,
    t1: f64,
    lim: &Limits,
    cap: usize,
    demand: Option<Vec<f64>>,
) -> (Vec<f64>, f64) {
    let xs = fine_params(t0, t1);
    let mut demand = demand.filter(|d| d.len() == FINE).unwrap_or_else(|| fine_demand(probes, &xs, lim));
    let gap = (t1 - t0) * 1e-9;
    for round in 0..4 {
        let mut cum = Vec::with_capacity(FINE + 1);
        cum.push(0.0);
        for d in &demand {
            cum.push(cum.last().copied().unwrap_or(0.0) + d);
        }
        let total = cum[FINE];
        if cap < MAX_PARAMS && total >= cap as f64 {
            let ts = (0..=cap).map(|k| if k == cap { t1 } else { t0 + (t1 - t0) * k as f64 / cap as f64 }).collect();
            return (ts, f64::INFINITY);
        }
        if !(total.is_finite() && total < MAX_PARAMS as f64) {
            break;
        }
        let n = (ceil(total) as usize).max(1);
        let mut ts = Vec::with_capacity(n + 1);
        ts.push(t0);
        for k in 1..n {
            let target = total * k as f64 / n as f64;
            let i = cum.partition_point(|&c| c <= target).clamp(1, FINE) - 1;
            let w = if cum[i + 1] > cum[i] { (target - cum[i]) / (cum[i + 1] - cum[i]) } else { 0.0 };
            let t = xs[i] + (xs[i + 1] - xs[i]) * w.clamp(0.0, 1.0);
            if t > ts.last().copied().unwrap_or(t0) + gap && t < t1 - gap {
                ts.push(t);
            }
        }
        ts.push(t1);
        let needs: Vec<(f64, f64)> = ts.windows(2).map(|w| need_all(probes, w[0], w[1], lim)).collect();
        if needs.iter().all(|&(nd, _)| nd <= 1.0) || round == 3 {
            let mut out = Vec::with_capacity(ts.len());
            out.push(t0);
            let mut worst: f64 = 0.0;
            for (w, &(nd, sag)) in ts.windows(2).zip(&needs) {
                if nd <= 1.0 {
                    worst = worst.max(sag);
                    out.push(w[1]);
                } else {
                    split_rec(probes, w[0], w[1], lim, 0, cap, &mut out, &mut worst);
                }
            }
            return (out, worst);
        }
        // The fine intervals under a failing one take its need (sag falls as h², so
        // its square root scales the step), and a little over against rounding.
        for (w, &(nd, _)) in ts.windows(2).zip(&needs) {
            if nd > 1.0 {
                for (k, d) in demand.iter_mut().enumerate() {
                    if xs[k + 1] > w[0] && xs[k] < w[1] {
                        *d *= nd * 1.02;
                    }
                }
            }
        }
    }
    subdivide_probes(probes, &[t0, t1], lim, cap)
}

/// A curve with even parameters (a trim curve of paper 001's rebuild,
/// interpolated at equal arc length) discretized by [`equidistribute`] over
/// `[t0, t1]`: its knots are sample sites, not features, so the nodes go
/// at equal shares of the chord demand instead of one split per knot group.
#[cfg(feature = "std")]
pub(crate) fn subdivide_even(
    evals: &[&dyn Fn(f64) -> (DVec3, DVec3)],
    t0: f64,
    t1: f64,
    lim: &Limits,
) -> (Vec<f64>, f64) {
    let probes = whole_curves(evals);
    equidistribute(&probes, t0, t1, lim, MAX_PARAMS, None)
}

/// The ends of [`FINE`] equal intervals over `[t0, t1]`.
fn fine_params(t0: f64, t1: f64) -> Vec<f64> {
    (0..=FINE).map(|k| if k == FINE { t1 } else { t0 + (t1 - t0) * k as f64 / FINE as f64 }).collect()
}

/// The fractional chord demand of each interval between `xs`.
/// A probe's intervals are measured once per surface and turn limit (see
/// [`Samples::shape_with`]) and judged within `lim`: the same demand,
/// bit for bit, as [`interval_demand`] gives.
fn fine_demand(probes: &[Probe<'_>], xs: &[f64], lim: &Limits) -> Vec<f64> {
    if let (Some((kept, line)), Some(&t0), Some(&t1)) = (probes.first().and_then(|p| p.line), xs.first(), xs.last()) {
        kept.reserve_fine(line[0] == 1, probes, t0, t1);
    }
    xs.windows(2)
        .map(|w| {
            let mut need: f64 = 0.0;
            each_part(probes, w[0], w[1], |p, x, y, side| {
                let s = match p.line {
                    Some((kept, line)) => {
                        kept.shape_with(line, (x, y), lim.angle, side, || shape(p.eval, x, y, lim.angle, side))
                    }
                    None => shape(p.eval, x, y, lim.angle, side),
                };
                let d = judge(&s, lim);
                need = need.max(d.smooth.max(d.fold));
            });
            need
        })
        .collect()
}

/// The iso-curves one direction is tested on: at `lines + 1` even steps of
/// the other parameter, each with its point-and-normal evaluator. Each keeps
/// what it evaluated (by the parameter's bits): neighbouring intervals share
/// their ends, and a part of a split interval is tested again as it is
/// split in turn.
#[allow(clippy::type_complexity)]
fn iso_curves<'s>(
    (surface, samples): (&'s dyn Surface, &'s Samples),
    lo: DVec2,
    hi: DVec2,
    along_u: bool,
    lines: usize,
) -> Vec<(f64, impl Fn(f64) -> (DVec3, DVec3) + 's)> {
    let (s0, s1) = if along_u { (lo.y, hi.y) } else { (lo.x, hi.x) };
    // The iso-curve's evaluator (the fixed parameter's work done once) is
    // made at the first sample the store does not hold.
    let make = move |s: f64| {
        let iso = core::cell::OnceCell::new();
        move |t: f64| {
            let uv = if along_u { DVec2::new(t, s) } else { DVec2::new(s, t) };
            samples.point_normal_with(uv, || iso.get_or_init(|| surface.iso_point_normal(along_u, s))(t))
        }
    };
    (0..=lines).map(|k| s0 + (s1 - s0) * k as f64 / lines as f64).map(|s| (s, make(s))).collect()
}

/// `f` of the probes one direction is tested on (see [`grid_params`]): the
/// iso-curves at every quarter of the rectangle, or every eighth on a
/// trimmed face, each limited to where it runs inside `region`.
fn with_probes<R>(
    surface: (&dyn Surface, &Samples),
    lo: DVec2,
    hi: DVec2,
    along_u: bool,
    region: Option<Region<'_>>,
    f: impl FnOnce(&[Probe<'_>]) -> R,
) -> R {
    let curves = iso_curves(surface, lo, hi, along_u, if region.is_some() { 8 } else { 4 });
    let probes: Vec<Probe<'_>> = curves
        .iter()
        .map(|(s, c)| Probe {
            eval: c,
            inside: region.map(|r| r(along_u, *s)),
            one_sided: true,
            line: Some((surface.1, [u64::from(along_u), s.to_bits()])),
        })
        .collect();
    f(&probes)
}

/// For a surface with even parameters (see [`equidistribute`]), the fine
/// chord demand along one direction that [`grid_params`] starts from: its
/// sum is about the lines that direction takes, known before any is placed.
/// `None` for other surfaces.
pub(crate) fn even_demand(
    surface: (&dyn Surface, &Samples),
    lo: DVec2,
    hi: DVec2,
    along_u: bool,
    lim: &Limits,
    region: Option<Region<'_>>,
) -> Option<Vec<f64>> {
    let (t0, t1) = if along_u { (lo.x, hi.x) } else { (lo.y, hi.y) };
    if !(surface.0.even_parameters() && t1 > t0) {
        return None;
    }
    Some(with_probes(surface, lo, hi, along_u, region, |probes| fine_demand(probes, &fine_params(t0, t1), lim)))
}

/// Initial intervals along one direction: the knot breaks inside `[lo, hi]`,
/// thinned to at most `max_groups` groups so surfaces with hundreds of knot
/// spans do not force hundreds of rows where they are flat.
pub(crate) fn initial_breaks(breaks: &[f64], lo: f64, hi: f64, max_groups: usize) -> Vec<f64> {
    // Breaks closer to an end or to each other than 1e-9 of the range would
    // only make slivers (a knot a rounding error away from a trim edge).
    let gap = (hi - lo) * 1e-9;
    let mut inner: Vec<f64> = Vec::new();
    for &t in breaks {
        if t > lo + gap && t < hi - gap && inner.last().is_none_or(|&l| t > l + gap) {
            inner.push(t);
        }
    }
    if inner.len() + 1 > max_groups {
        let step = (inner.len() + 1) as f64 / max_groups as f64;
        let mut thinned = Vec::with_capacity(max_groups);
        let mut k = 1;
        while k < max_groups {
            let idx = (step * k as f64) as usize;
            if idx >= 1 && idx <= inner.len() {
                thinned.push(inner[idx - 1]);
            }
            k += 1;
        }
        thinned.dedup();
        inner = thinned;
    }
    let mut out = Vec::with_capacity(inner.len() + 2);
    out.push(lo);
    out.extend(inner);
    out.push(hi);
    out
}

/// The parameter intervals of an iso-line inside a face's trimmed region:
/// `region(along_u, s)` gives, for the line at `s` (v = s when `along_u`, else
/// u = s), the pieces of its running parameter that lie inside.
pub(crate) type Region<'r> = &'r dyn Fn(bool, f64) -> Vec<(f64, f64)>;

/// Parameters along u (`along_u`) or v over the rectangle `[lo, hi]`, tested on
/// the two boundary iso-curves and the interior ones at 1/4, 1/2 and 3/4
/// (paper 000 §3.1.3). On a trimmed face (`region` given) each line is tested
/// only where it runs inside the loops, and at every eighth of the rectangle:
/// what lies outside the trim (a fold, a pole, a wild corner of the base
/// surface) must not set the grid of the part that is kept. Once `cap`
/// parameters are placed no interval is split further; `demand` is
/// [`even_demand`]'s for these limits when the caller measured it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn grid_params(
    (surface, samples): (&dyn Surface, &Samples),
    lo: DVec2,
    hi: DVec2,
    along_u: bool,
    lim: &Limits,
    region: Option<Region<'_>>,
    cap: usize,
    demand: Option<Vec<f64>>,
) -> (Vec<f64>, f64) {
    let cap = cap.min(MAX_PARAMS);
    let (t0, t1) = if along_u { (lo.x, hi.x) } else { (lo.y, hi.y) };
    with_probes((surface, samples), lo, hi, along_u, region, |probes| {
        if surface.even_parameters() && t1 > t0 {
            return equidistribute(probes, t0, t1, lim, cap, demand);
        }
        let breaks = initial_breaks(&surface.breaks(along_u), t0, t1, 16);
        subdivide_probes(probes, &breaks, lim, cap)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A knot a rounding error away from the range's end (a trim edge that
    /// stops 8e-15 past a C0 knot, as in the hammer's faces) or from another
    /// knot starts no interval: such an interval only makes slivers.
    #[test]
    fn breaks_next_to_an_end_or_each_other_are_dropped() {
        let b = initial_breaks(&[-1.02, -2.2e-15, 0.0029], -1.02, 5.8e-15, 16);
        assert_eq!(b, [-1.02, 5.8e-15]);
        let b = initial_breaks(&[0.0, 0.25, 0.25 + 1e-12, 0.5, 1.0], 0.0, 1.0, 16);
        assert_eq!(b, [0.0, 0.25, 0.5, 1.0]);
    }

    fn lim(tol: f64) -> Limits {
        Limits { tol, angle: 0.5, max_edge: f64::INFINITY, min_edge: tol * 1e-3 }
    }

    /// A straight line split at 16 knot groups is one chord after coarsening;
    /// an arc keeps as many nodes as its sag and turn need, and every chord
    /// left stays within the tolerance of the arc.
    #[test]
    fn coarsening_keeps_only_the_nodes_the_limits_need() {
        let line = |t: f64| (DVec3::new(3.0 * t, 1.0, 0.0), DVec3::X);
        let breaks: Vec<f64> = (0..=16).map(|k| k as f64 / 16.0).collect();
        let (ts, _) = subdivide(&[&line], &breaks, &lim(0.01));
        assert_eq!(ts.len(), 17);
        let all = |_: f64, _: f64| true;
        assert_eq!(coarsen(&[&line], &all, &ts, &lim(0.01)), [0.0, 1.0]);

        let r = 5.0;
        let arc = |t: f64| (DVec3::new(r * t.cos(), r * t.sin(), 0.0), DVec3::new(-t.sin(), t.cos(), 0.0));
        let breaks: Vec<f64> = (0..=16).map(|k| k as f64 * core::f64::consts::PI / 16.0).collect();
        let tol = 0.2;
        let (ts, _) = subdivide(&[&arc], &breaks, &lim(tol));
        let coarse = coarsen(&[&arc], &all, &ts, &lim(tol));
        assert!(coarse.len() < ts.len(), "{} of {}", coarse.len(), ts.len());
        // sag of a chord over angle a on radius r: r (1 - cos(a/2)).
        let need = (core::f64::consts::PI / (2.0 * (1.0 - tol / r).acos())).ceil() as usize;
        assert!(coarse.len() > need, "{} chords, {need} needed", coarse.len() - 1);
        for w in coarse.windows(2) {
            let sag = r * (1.0 - (0.5 * (w[1] - w[0])).cos());
            assert!(sag <= tol, "chord {w:?} sags {sag}");
            assert!(w[1] - w[0] <= 0.5 + 1e-12, "chord {w:?} turns too far");
        }
        // A chord the caller rejects (a straight (u,v) segment off the surface) is not taken.
        let none = |_: f64, _: f64| false;
        assert_eq!(coarsen(&[&line], &none, &ts_line(), &lim(0.01)).len(), 17);
    }

    /// An iso-line across a pleat (the surface runs out along x, folds
    /// back within a hair at t = 0.37 and its normal reverses there) gets
    /// lines where its sag needs them and a few more about the fold, not
    /// the 64 equal parts per interval that raising the whole interval's
    /// count for the fold gave; every interval but the fold's passes.
    #[test]
    fn a_fold_is_split_where_it_is() {
        let fold = 0.37;
        let pleat = |t: f64| {
            let x = 10.0 * (t - fold);
            // Out to the fold and back over itself; the normal turns over
            // within 1e-6 of the parameter about the fold.
            let p = DVec3::new(-x * x, 0.0, t);
            let s = ((t - fold) / 1e-6).clamp(-1.0, 1.0);
            (p, DVec3::new((1.0 - s * s).sqrt(), 0.0, -s).normalize())
        };
        let probes = [Probe { eval: &pleat, inside: None, one_sided: true, line: None }];
        let l = lim(0.05);
        let (ts, _) = subdivide_probes(&probes, &[0.0, 0.5, 1.0], &l, MAX_PARAMS);
        assert!(ts.len() < 40, "{} lines: {ts:?}", ts.len());
        let across = |w: &[f64]| w[0] <= fold && fold <= w[1];
        for w in ts.windows(2) {
            let (need, _) = need_all(&probes, w[0], w[1], &l);
            if across(w) {
                assert!(
                    pleat(w[0]).0.distance(pleat(w[1]).0) <= l.tol,
                    "fold interval {w:?} longer than the tolerance"
                );
            } else {
                assert!(need <= 1.0, "interval {w:?} fails: {need}");
            }
        }
        // A bend as far over the whole interval (half a circle) is split evenly as before.
        let bend = |t: f64| {
            let a = core::f64::consts::PI * t;
            (DVec3::new(a.cos(), a.sin(), 0.0), DVec3::new(a.cos(), a.sin(), 0.0))
        };
        let probes = [Probe { eval: &bend, inside: None, one_sided: true, line: None }];
        let (ts, _) = subdivide_probes(&probes, &[0.0, 1.0], &l, MAX_PARAMS);
        let steps: Vec<f64> = ts.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(steps.iter().all(|d| (d - steps[0]).abs() < 1e-12), "{ts:?}");
    }

    /// A surface that curls over within a hair of its trim border (the
    /// iso-line runs straight, then its normal turns 80° over its last
    /// 0.002, and the loop cuts it inside that curl): lines are not packed
    /// into the curl against the border, where they left slivers between
    /// them and the border that folded once refined. The same curl inside
    /// the loops, away from any border, is still split for its turn.
    #[test]
    fn a_curl_at_a_trim_border_gets_no_packed_lines() {
        let curl_at = |c: f64| {
            move |t: f64| {
                let s = ((t - c) / 0.002).clamp(0.0, 1.0);
                let a = 1.4 * s;
                (DVec3::new(t, 0.0, 0.0), DVec3::new(0.0, a.sin(), a.cos()))
            }
        };
        let l = lim(0.05);
        let floor = BEND_FLOOR * l.tol;
        let (edge, border) = (curl_at(0.9985), 0.9995);
        let probes = [Probe { eval: &edge, inside: Some(alloc::vec![(0.0, border)]), one_sided: true, line: None }];
        let (ts, _) = subdivide_probes(&probes, &[0.0, 1.0], &l, MAX_PARAMS);
        let packed = ts.iter().filter(|&&t| t < border && border - t < 0.5 * floor).count();
        assert!(packed == 0, "{packed} lines within {} of the border: {ts:?}", 0.5 * floor);
        let inner = curl_at(0.5);
        let probes = [Probe { eval: &inner, inside: Some(alloc::vec![(0.0, border)]), one_sided: true, line: None }];
        let (ts, _) = subdivide_probes(&probes, &[0.0, 1.0], &l, MAX_PARAMS);
        let across = ts.iter().filter(|&&t| (0.5..=0.502).contains(&t)).count();
        assert!(across >= 2, "{ts:?}");
    }

    /// On a curve whose bend is concentrated (a parabola sharp at one end),
    /// equidistributed lines all pass, and are fewer than equal splits of 16
    /// knot groups give: those round up in every group.
    #[test]
    fn equidistributed_lines_pass_with_fewer_intervals() {
        let curve = |t: f64| {
            let x = 3.0 * t;
            let p = DVec3::new(x, 0.0, 2.0 * (1.0 - t) * (1.0 - t) * (1.0 - t));
            let d = DVec3::new(3.0, 0.0, -6.0 * (1.0 - t) * (1.0 - t)).normalize();
            (p, DVec3::new(-d.z, 0.0, d.x))
        };
        let probes = [Probe { eval: &curve, inside: None, one_sided: false, line: None }];
        let l = lim(1e-3);
        let (even, _) = equidistribute(&probes, 0.0, 1.0, &l, MAX_PARAMS, None);
        let breaks: Vec<f64> = (0..=16).map(|k| k as f64 / 16.0).collect();
        let (grouped, _) = subdivide_probes(&probes, &breaks, &l, MAX_PARAMS);
        assert!(even.len() < grouped.len(), "{} lines against {}", even.len(), grouped.len());
        assert!(even.windows(2).all(|w| w[1] > w[0]), "{even:?}");
        assert_eq!((even[0], even[even.len() - 1]), (0.0, 1.0));
        for w in even.windows(2) {
            assert!(need_all(&probes, w[0], w[1], &l).0 <= 1.0, "interval {w:?} fails");
        }
    }

    fn ts_line() -> Vec<f64> {
        (0..=16).map(|k| k as f64 / 16.0).collect()
    }
}
