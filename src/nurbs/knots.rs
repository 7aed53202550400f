//! Validated knot vectors and B-spline basis functions.

use alloc::vec::Vec;

use super::{NurbsError, MAX_DEGREE};

/// A non-decreasing knot vector together with the degree it serves.
///
/// Invariants (checked by [`KnotVector::try_new`]): `1 <= degree <= MAX_DEGREE`,
/// at least `2 * (degree + 1)` finite knots, non-decreasing, no inner multiplicity
/// above `degree + 1`, and a non-empty parameter range `[knots[p], knots[n]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    degree: usize,
    knots: Vec<f64>,
}

impl KnotVector {
    /// Builds a knot vector, checking every invariant.
    ///
    /// # Errors
    /// [`NurbsError`] naming the offending knot index.
    pub fn try_new(degree: usize, knots: Vec<f64>) -> Result<Self, NurbsError> {
        if degree == 0 || degree > MAX_DEGREE {
            return Err(NurbsError::BadDegree { degree });
        }
        let needed = 2 * (degree + 1);
        if knots.len() < needed {
            return Err(NurbsError::TooFewKnots { found: knots.len(), needed });
        }
        for (i, k) in knots.iter().enumerate() {
            if !k.is_finite() {
                return Err(NurbsError::NotFinite { what: "knot", index: i });
            }
        }
        let mut run = 1;
        for i in 1..knots.len() {
            if knots[i] < knots[i - 1] {
                return Err(NurbsError::DecreasingKnots { index: i });
            }
            if knots[i] == knots[i - 1] {
                run += 1;
                if run > degree + 1 {
                    return Err(NurbsError::BadMultiplicity { index: i });
                }
            } else {
                run = 1;
            }
        }
        let n = knots.len() - degree - 1;
        if knots[n] <= knots[degree] {
            return Err(NurbsError::BadMultiplicity { index: n });
        }
        Ok(Self { degree, knots })
    }

    /// Uniform clamped knot vector for `count` control points (`count > degree`).
    ///
    /// # Errors
    /// As [`KnotVector::try_new`].
    pub fn clamped_uniform(degree: usize, count: usize) -> Result<Self, NurbsError> {
        let mut knots = Vec::with_capacity(count + degree + 1);
        let spans = count.saturating_sub(degree).max(1);
        knots.extend(core::iter::repeat_n(0.0, degree + 1));
        for i in 1..spans {
            knots.push(i as f64 / spans as f64);
        }
        knots.extend(core::iter::repeat_n(1.0, degree + 1));
        Self::try_new(degree, knots)
    }

    /// The degree the knot vector serves.
    #[inline]
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knot values.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Number of control points this knot vector takes.
    #[inline]
    pub fn control_count(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// Parameter range `[knots[p], knots[n]]`.
    #[inline]
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.control_count()])
    }

    /// Distinct knot values inside and at the ends of the domain, ascending.
    pub fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut out: Vec<f64> = Vec::new();
        for &k in &self.knots {
            if k >= a && k <= b && out.last().is_none_or(|&l| k > l) {
                out.push(k);
            }
        }
        out
    }

    /// Clamps `t` into the domain (NaN goes to the start).
    ///
    /// Compares instead of calling `f64::clamp`, whose check of its bounds
    /// (always ordered here) kept this out of line in the wasm build, where a
    /// call per basis evaluation cost more than the span search itself.
    #[inline]
    pub fn clamp(&self, t: f64) -> f64 {
        let (a, b) = self.domain();
        if t.is_nan() || t < a {
            a
        } else if t > b {
            b
        } else {
            t
        }
    }

    /// Knot span index `i` with `knots[i] <= t < knots[i+1]` (the last non-empty
    /// span at the domain's end); `t` is clamped first. Binary search.
    #[inline]
    pub fn span(&self, t: f64) -> usize {
        let p = self.degree;
        let n = self.control_count() - 1;
        let t = self.clamp(t);
        if t >= self.knots[n + 1] {
            // Last non-empty span.
            let mut i = n;
            while i > p && self.knots[i] >= self.knots[n + 1] {
                i -= 1;
            }
            return i;
        }
        let (mut lo, mut hi) = (p, n + 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if t < self.knots[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    /// The span whose polynomial piece evaluates the B-spline at `t`: the
    /// [`KnotVector::span`] holding `t`, unless that span is a sliver no
    /// wider than the rounding of its knots ([`SLIVER`]), a knot written twice
    /// a few units in the last place apart (a surface split next to its own
    /// knot). Its derivatives are the rounding of its control points over
    /// that width (any size, any direction: normals turned at random, and a
    /// grid split down to its cap), so `t` is evaluated as if the sliver's
    /// two ends were one knot: on the next span, or at the domain's end on
    /// the last span before the sliver.
    #[inline]
    pub(crate) fn eval_span(&self, t: f64) -> usize {
        let span = self.span(t);
        let u = &self.knots;
        let (a, b) = self.domain();
        // The larger of values never NaN nor -0 by comparison: `f64::max` is
        // a call to `fmax` in wasm, once per evaluation here.
        let larger = |x: f64, y: f64| if x > y { x } else { y };
        let sliver = SLIVER * larger(larger(a.abs(), b.abs()), b - a);
        if u[span + 1] - u[span] > sliver {
            return span;
        }
        let last = self.control_count() - 1;
        // The next span wider than a sliver, else the one before.
        (span + 1..=last)
            .find(|&i| u[i + 1] - u[i] > sliver)
            .or_else(|| (self.degree..span).rev().find(|&i| u[i + 1] - u[i] > sliver))
            .unwrap_or(span)
    }

    /// Non-zero basis functions and their derivatives up to order `nd` at `t`.
    ///
    /// Writes `ders[k][j]` = k-th derivative of `N_{span-p+j}` for `k <= nd`,
    /// `j <= p`, and returns the span (Piegl & Tiller, The NURBS Book, A2.3).
    pub fn basis_ders(&self, t: f64, nd: usize, ders: &mut BasisDers) -> usize {
        self.basis_into(t, nd, &mut ders.0)
    }

    /// As [`KnotVector::basis_ders`] into scratch sized for the degree class
    /// (`N > degree`, else nothing is written and the span is still returned):
    /// zeroing 17×17 tables on every call costs more than the arithmetic for
    /// low degrees, so hot paths pick a small `N`.
    pub(crate) fn basis_into<const N: usize>(&self, t: f64, nd: usize, ders: &mut [[f64; N]; MAX_DERIV + 1]) -> usize {
        let t = self.clamp(t);
        let span = self.eval_span(t);
        self.basis_in_span(span, t, nd, ders);
        span
    }

    /// As [`KnotVector::basis_into`] (or, given `span`, as
    /// [`KnotVector::basis_in_span`], returning that span), computed in
    /// scratch of exactly degree + 1 for degrees up to 7 (then the loops
    /// unroll) and copied into `ders`; the values are the same.
    pub(crate) fn basis_fast<const N: usize>(
        &self,
        span: Option<usize>,
        t: f64,
        nd: usize,
        ders: &mut [[f64; N]; MAX_DERIV + 1],
    ) -> usize {
        match self.degree {
            1 => self.basis_exact::<2, N>(span, t, nd, ders),
            2 => self.basis_exact::<3, N>(span, t, nd, ders),
            3 => self.basis_exact::<4, N>(span, t, nd, ders),
            4 => self.basis_exact::<5, N>(span, t, nd, ders),
            5 => self.basis_exact::<6, N>(span, t, nd, ders),
            6 => self.basis_exact::<7, N>(span, t, nd, ders),
            7 => self.basis_exact::<8, N>(span, t, nd, ders),
            _ => self.basis_at(span, t, nd, ders),
        }
    }

    /// [`KnotVector::basis_fast`] for degree `M - 1` (`M <= N`).
    fn basis_exact<const M: usize, const N: usize>(
        &self,
        span: Option<usize>,
        t: f64,
        nd: usize,
        ders: &mut [[f64; N]; MAX_DERIV + 1],
    ) -> usize {
        if M > N {
            return self.basis_at(span, t, nd, ders);
        }
        let mut exact = [[0.0; M]; MAX_DERIV + 1];
        let span = self.basis_at(span, t, nd, &mut exact);
        for (to, from) in ders.iter_mut().zip(&exact).take(nd.min(MAX_DERIV) + 1) {
            if let Some(to) = to.get_mut(..M) {
                to.copy_from_slice(from);
            }
        }
        span
    }

    /// [`KnotVector::basis_in_span`] in `span` when given (returning it),
    /// else [`KnotVector::basis_into`].
    fn basis_at<const N: usize>(
        &self,
        span: Option<usize>,
        t: f64,
        nd: usize,
        ders: &mut [[f64; N]; MAX_DERIV + 1],
    ) -> usize {
        match span {
            Some(s) => {
                self.basis_in_span(s, t, nd, ders);
                s
            }
            None => self.basis_into(t, nd, ders),
        }
    }

    /// As [`KnotVector::basis_into`] with the polynomial piece of span `span`
    /// (clamped to `degree..control_count()`) instead of the span holding `t`.
    pub(crate) fn basis_in_span<const N: usize>(
        &self,
        span: usize,
        t: f64,
        nd: usize,
        ders: &mut [[f64; N]; MAX_DERIV + 1],
    ) {
        if self.degree >= N {
            return;
        }
        // Scratch of exactly degree + 1: the degree is then a constant and
        // the loops unroll (the same operations in the same order).
        if self.degree + 1 == N {
            self.basis_of_degree::<N>(N - 1, span, t, nd, ders);
        } else {
            self.basis_of_degree::<N>(self.degree, span, t, nd, ders);
        }
    }

    /// The body of [`KnotVector::basis_in_span`] for degree `p` (`p < N`,
    /// equal to `self.degree`); inlined so that a constant `p` specializes it.
    #[inline(always)]
    fn basis_of_degree<const N: usize>(
        &self,
        p: usize,
        span: usize,
        t: f64,
        nd: usize,
        ders: &mut [[f64; N]; MAX_DERIV + 1],
    ) {
        let nd = nd.min(MAX_DERIV);
        let t = self.clamp(t);
        let span = span.clamp(p, self.control_count() - 1);
        let u = &self.knots;
        // A2.2's in-place rows instead of A2.3's full triangle: the
        // derivatives need only the degree p-1 and p-2 rows and the knot
        // differences of the last two rows, kept element by element as the
        // loop reads and forms them; no N×N table to clear per call. Same
        // operations, same order. (Copying a whole row just written one
        // element at a time read it back wider than it was stored, a stall
        // per copy that cost more than a bicubic's arithmetic.)
        let mut left = [0.0f64; N];
        let mut right = [0.0f64; N];
        let mut row = [0.0f64; N];
        let mut row1 = [0.0f64; N];
        let mut row2 = [0.0f64; N];
        // `gap_p[r]`, `gap_q[r]`: the knot difference A2.3's triangle holds
        // at `[p][r]` and `[p - 1][r]`; a zero one drops its term.
        let mut gap_p = [0.0f64; N];
        let mut gap_q = [0.0f64; N];
        row[0] = 1.0;
        for j in 1..=p {
            left[j] = t - u[span + 1 - j];
            right[j] = u[span + j] - t;
            let mut saved = 0.0;
            for r in 0..j {
                let old = row[r];
                let gap = right[r + 1] + left[j - r];
                if j + 1 == p {
                    row2[r] = old;
                    gap_q[r] = gap;
                }
                if j == p {
                    row1[r] = old;
                    gap_p[r] = gap;
                }
                let temp = if gap != 0.0 { old / gap } else { 0.0 };
                row[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            row[j] = saved;
        }
        for (d, x) in ders[0].iter_mut().zip(&row).take(p + 1) {
            *d = *x;
        }
        if nd == 0 {
            return;
        }
        // First and second derivatives from the degree p-1 and p-2 functions
        // (The NURBS Book eq. 2.9, the terms of A2.3 for k <= 2 written out).
        let over = |x: f64, gap: f64| if gap != 0.0 { x / gap } else { 0.0 };
        // Each r reads its own entries once and carries them to r + 1 and
        // r + 2: no two neighbours are loaded together from rows stored one
        // element at a time (the stall above).
        let pf = p as f64;
        // 1 / gap(p, r - 1), row1[r - 1], and row2, gap_q at r - 1 and r - 2.
        let (mut inv_1, mut row1_1) = (0.0, 0.0);
        let (mut row2_1, mut row2_2, mut gap_1, mut gap_2) = (0.0, 0.0, 0.0, 0.0);
        for r in 0..=p {
            // 1 / gap(p, r), shared by the coefficients of neighbours r and r + 1.
            let inv = if r < p { over(1.0, gap_p[r]) } else { 0.0 };
            // Coefficients of the degree p-1 functions in N', as A2.3's a[.][0] and a[.][1].
            let c0 = if r >= 1 { inv_1 } else { 0.0 };
            let c1 = if r < p { -inv } else { 0.0 };
            let row1_0 = if r < p { row1[r] } else { 0.0 };
            let mut d1 = 0.0;
            if r >= 1 {
                d1 += c0 * row1_1;
            }
            if r < p {
                d1 += c1 * row1_0;
            }
            ders[1][r] = pf * d1;
            let (row2_0, gap_0) = if r + 2 <= p { (row2[r], gap_q[r]) } else { (0.0, 0.0) };
            if nd >= 2 {
                if p < 2 {
                    ders[2][r] = 0.0;
                } else {
                    let mut d2 = 0.0;
                    if r >= 2 {
                        d2 += over(c0, gap_2) * row2_2;
                    }
                    if r >= 1 && r < p {
                        d2 += over(c1 - c0, gap_1) * row2_1;
                    }
                    if r + 2 <= p {
                        d2 += over(-c1, gap_0) * row2_0;
                    }
                    ders[2][r] = pf * (pf - 1.0) * d2;
                }
            }
            (inv_1, row1_1) = (inv, row1_0);
            (row2_2, row2_1, gap_2, gap_1) = (row2_1, row2_0, gap_1, gap_0);
        }
    }

    /// The Cox-de Boor triangle of A2.3 (for the tests' reference) for the piece of span `span`
    /// (clamped to `degree..control_count()`) at `t` (clamped): `[r][j]` for
    /// `r <= j` is the degree-`j` function `N_{span-j+r}`, `[j][r]` for `r < j`
    /// the knot difference it was divided by; `p` is the degree. Needs
    /// `N > degree`.
    #[cfg(test)]
    fn basis_triangle<const N: usize>(&self, p: usize, span: usize, t: f64) -> [[f64; N]; N] {
        let t = self.clamp(t);
        let span = span.clamp(p, self.control_count() - 1);
        let u = &self.knots;
        let mut ndu = [[0.0f64; N]; N];
        let mut left = [0.0f64; N];
        let mut right = [0.0f64; N];
        ndu[0][0] = 1.0;
        for j in 1..=p {
            left[j] = t - u[span + 1 - j];
            right[j] = u[span + j] - t;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = if ndu[j][r] != 0.0 { ndu[r][j - 1] / ndu[j][r] } else { 0.0 };
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        ndu
    }

    /// Inserts knot `t` once (no validation of multiplicity beyond the degree);
    /// used by curve and surface knot insertion.
    pub(crate) fn with_inserted(&self, span: usize, t: f64) -> Self {
        let mut knots = self.knots.clone();
        knots.insert(span + 1, t);
        Self { degree: self.degree, knots }
    }

    /// Multiplicity of the value `t` in the knot vector.
    pub fn multiplicity(&self, t: f64) -> usize {
        self.knots.iter().filter(|&&k| k == t).count()
    }
}

/// Widest knot span, as a share of the larger of the knot vector's end
/// magnitudes and its domain length, that [`KnotVector::eval_span`] treats
/// as a rounding of one knot written twice: about 450 units in the last
/// place, where a parameter written with 15 significant digits is off by 5.
pub(crate) const SLIVER: f64 = 1e-13;

/// Highest derivative order computed by [`KnotVector::basis_ders`].
pub const MAX_DERIV: usize = 2;

/// Scratch for basis functions: `[order][j]`.
#[derive(Debug, Clone)]
pub struct BasisDers(pub [[f64; MAX_DEGREE + 1]; MAX_DERIV + 1]);

impl Default for BasisDers {
    fn default() -> Self {
        Self([[0.0; MAX_DEGREE + 1]; MAX_DERIV + 1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The NURBS Book's A2.3 derivative loop as written there, for any order,
    /// on the same triangle: the oracle the written-out k <= 2 terms are checked against.
    fn reference(kv: &KnotVector, span: usize, t: f64, nd: usize) -> [[f64; MAX_DEGREE + 1]; MAX_DERIV + 1] {
        const N: usize = MAX_DEGREE + 1;
        let p = kv.degree;
        let mut ders = [[0.0f64; N]; MAX_DERIV + 1];
        let ndu = kv.basis_triangle::<N>(kv.degree, span, t);
        for j in 0..=p {
            ders[0][j] = ndu[j][p];
        }
        let mut a = [[0.0f64; N]; 2];
        for r in 0..=p {
            let (mut s1, mut s2) = (0usize, 1usize);
            a[0][0] = 1.0;
            for k in 1..=nd {
                if k > p {
                    ders[k][r] = 0.0;
                    continue;
                }
                let mut d = 0.0;
                let rk = r as isize - k as isize;
                let pk = p - k;
                if rk >= 0 {
                    let den = ndu[pk + 1][rk as usize];
                    a[s2][0] = if den != 0.0 { a[s1][0] / den } else { 0.0 };
                    d = a[s2][0] * ndu[rk as usize][pk];
                }
                let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2 = if (r as isize - 1) <= pk as isize { k - 1 } else { p - r };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    let den = ndu[pk + 1][idx];
                    a[s2][j] = if den != 0.0 { (a[s1][j] - a[s1][j - 1]) / den } else { 0.0 };
                    d += a[s2][j] * ndu[idx][pk];
                }
                if r <= pk {
                    let den = ndu[pk + 1][r];
                    a[s2][k] = if den != 0.0 { -a[s1][k - 1] / den } else { 0.0 };
                    d += a[s2][k] * ndu[r][pk];
                }
                ders[k][r] = d;
                core::mem::swap(&mut s1, &mut s2);
            }
        }
        let mut factor = p as f64;
        for k in 1..=nd {
            for j in 0..=p {
                ders[k][j] *= factor;
            }
            factor *= (p as f64) - k as f64;
        }
        ders
    }

    /// Degrees 1 to 9 over uniform, clamped, repeated and uneven knots, at
    /// parameters inside spans, on knots and at the ends, every order: the
    /// written-out derivatives equal the general algorithm's, also in the
    /// scratch sizes the hot paths use.
    #[test]
    fn derivatives_match_the_general_algorithm() {
        let mut next = crate::testing::uniform(0x2545_f491_4f6c_dd1du64);
        let mut checked = 0;
        for p in 1..=9usize {
            for shape in 0..4 {
                let inner: Vec<f64> = match shape {
                    0 => (1..6).map(|i| i as f64 / 6.0).collect(),
                    1 => Vec::new(),
                    2 => alloc::vec![0.3, 0.3, 0.5, 0.5, 0.5, 0.9].into_iter().filter(|_| p >= 3).collect(),
                    _ => (0..5).map(|_| next()).collect(),
                };
                let mut inner = inner;
                crate::sort::f64s(&mut inner);
                let mut knots = alloc::vec![0.0; p + 1];
                knots.extend(&inner);
                knots.extend(alloc::vec![1.0; p + 1]);
                let Ok(kv) = KnotVector::try_new(p, knots.clone()) else { continue };
                let mut ts: Vec<f64> = (0..12).map(|_| next()).collect();
                ts.extend(inner.iter().copied());
                ts.extend([0.0, 1.0]);
                for &t in &ts {
                    for nd in 0..=MAX_DERIV {
                        let span = kv.span(t);
                        let want = reference(&kv, span, t, nd);
                        let mut got = [[0.0; MAX_DEGREE + 1]; MAX_DERIV + 1];
                        kv.basis_in_span(span, t, nd, &mut got);
                        let mut small = [[0.0; 12]; MAX_DERIV + 1];
                        kv.basis_in_span(span, t, nd, &mut small);
                        for k in 0..=nd {
                            for j in 0..=p {
                                let scale = 1.0 + want[k][j].abs();
                                assert!(
                                    (got[k][j] - want[k][j]).abs() <= 1e-12 * scale,
                                    "p {p} knots {knots:?} t {t} order {k} j {j}: {} against {}",
                                    got[k][j],
                                    want[k][j]
                                );
                                if p < 12 {
                                    assert_eq!(small[k][j], got[k][j]);
                                }
                            }
                        }
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 1000, "{checked} cases");
    }

    /// The basis and its first two derivatives are exactly A2.3's (the same
    /// operations in the same order; a zero may differ in sign), in every
    /// scratch size the hot paths use, for degrees 1 to 12 at knots, inside
    /// spans, in zero-width spans and outside the domain: however the loops
    /// are arranged for speed, the values stay the textbook's.
    #[test]
    fn basis_equals_a2_3_exactly() {
        let mut next = crate::testing::uniform(0x9e37_79b9_7f4a_7c15u64);
        let mut checked = 0;
        for p in 1..=12usize {
            let mut inner: Vec<f64> = (0..6).map(|_| next()).collect();
            inner.push(inner[0]);
            crate::sort::f64s(&mut inner);
            let mut knots = alloc::vec![0.0; p + 1];
            knots.extend(&inner);
            knots.extend(alloc::vec![1.0; p + 1]);
            let Ok(kv) = KnotVector::try_new(p, knots) else { continue };
            let mut ts: Vec<f64> = (0..40).map(|_| 1.2 * next() - 0.1).collect();
            ts.extend(inner.iter().copied());
            for &t in &ts {
                for span in p..kv.control_count() {
                    for nd in 0..=MAX_DERIV {
                        let want = reference(&kv, span, t, nd);
                        let row = |d: &[f64]| d.iter().take(p + 1).copied().collect::<Vec<_>>();
                        macro_rules! check {
                            ($($n:literal),*) => {$(
                                if p < $n {
                                    let mut got = [[0.0; $n]; MAX_DERIV + 1];
                                    kv.basis_in_span(span, t, nd, &mut got);
                                    for k in 0..=nd {
                                        assert_eq!(row(&got[k]), row(&want[k]), "p {p} scratch {} t {t} span {span} order {k}", $n);
                                    }
                                    checked += 1;
                                }
                            )*};
                        }
                        check!(2, 3, 4, 5, 8, 12, 17);
                    }
                }
            }
        }
        assert!(checked > 10_000, "{checked} cases");
    }

    /// A quarter circle whose knot vector starts with a sliver (0.25 written
    /// once rounded and once exactly, with three control points rounding the
    /// same point): at the domain's start the tangent is the circle's, as
    /// without the sliver; evaluated in the sliver it pointed anywhere.
    #[test]
    fn a_sliver_span_evaluates_as_one_knot() {
        use crate::nurbs::NurbsCurve;
        use glam::DVec3;
        let a = 0.25 - 5e-16;
        let h = core::f64::consts::FRAC_1_SQRT_2;
        let knots = alloc::vec![a, a, a, 0.25, 0.25, 0.5, 0.5, 0.5];
        let corner = DVec3::new(1.0, 1.0, 0.0);
        let pts = alloc::vec![
            DVec3::X,
            DVec3::new(1.0 + 4.4e-16, 1e-16, 0.0),
            DVec3::new(1.0, -1e-16, 0.0),
            corner,
            DVec3::Y
        ];
        let c = NurbsCurve::try_new(2, knots, pts, Some(alloc::vec![1.0, 1.0, 1.0, h, 1.0])).unwrap();
        let kv = KnotVector::try_new(2, alloc::vec![a, a, a, 0.25, 0.25, 0.5, 0.5, 0.5]).unwrap();
        assert_eq!(kv.span(a), 2, "the sliver holds the domain's start");
        assert_eq!(kv.eval_span(a), 4, "evaluated on the span after it");
        for t in [a, 0.25 - 2e-16, 0.25] {
            let d = c.derivs(t);
            assert!(d.point.distance(DVec3::X) < 1e-12, "{t}: {:?}", d.point);
            let along = d.d1.normalize();
            assert!(along.distance(DVec3::Y) < 1e-9, "{t}: tangent {along:?}");
        }
        // Clean vectors and zero-width spans (multiple knots) are left alone.
        let clean = KnotVector::try_new(2, alloc::vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0]).unwrap();
        for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
            assert_eq!(clean.eval_span(t), clean.span(t));
        }
    }
}
