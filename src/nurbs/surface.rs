//! Rational B-spline surfaces with derivatives up to second order.

use alloc::boxed::Box;
use alloc::vec::Vec;
use glam::{DVec2, DVec3, DVec4};

use super::knots::{KnotVector, MAX_DERIV};
use super::speed::speed_bound;
use super::{Aabb, NurbsError, Surface, SurfaceDerivs};

/// A (possibly rational) tensor-product B-spline surface.
///
/// Control points are stored homogeneous, row-major: index `i * count_v + j`,
/// `i` along u, `j` along v.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    ku: KnotVector,
    kv: KnotVector,
    points: Vec<DVec4>,
    rational: bool,
}

/// `$s.$method::<NU, NV>(p, q, args…)` in the scratch sizes
/// [`NurbsSurface::homogeneous_derivs`] picks for the surface's degrees
/// `(p, q)`: exact ones up to bicubic, else a class of 4, 8, 12 or
/// `MAX_DEGREE + 1` for both. The grid and iso-curve paths dispatch through it,
/// so they take the basis in the same scratch as a point does.
macro_rules! by_scratch_size {
    ($s:expr, $method:ident($($arg:expr),*)) => {
        match ($s.ku.degree(), $s.kv.degree()) {
            (1, 1) => $s.$method::<2, 2>(1, 1, $($arg),*),
            (1, 2) => $s.$method::<2, 3>(1, 2, $($arg),*),
            (2, 1) => $s.$method::<3, 2>(2, 1, $($arg),*),
            (2, 2) => $s.$method::<3, 3>(2, 2, $($arg),*),
            (1, 3) => $s.$method::<2, 4>(1, 3, $($arg),*),
            (3, 1) => $s.$method::<4, 2>(3, 1, $($arg),*),
            (2, 3) => $s.$method::<3, 4>(2, 3, $($arg),*),
            (3, 2) => $s.$method::<4, 3>(3, 2, $($arg),*),
            (3, 3) => $s.$method::<4, 4>(3, 3, $($arg),*),
            (p, q) => match p.max(q) {
                0..=3 => $s.$method::<4, 4>(p, q, $($arg),*),
                4..=7 => $s.$method::<8, 8>(p, q, $($arg),*),
                8..=11 => $s.$method::<12, 12>(p, q, $($arg),*),
                _ => $s.$method::<{ crate::nurbs::MAX_DEGREE + 1 }, { crate::nurbs::MAX_DEGREE + 1 }>(p, q, $($arg),*),
            },
        }
    };
}

impl NurbsSurface {
    /// Builds a surface from a grid of Euclidean points (`points[i][j]`, i along u)
    /// and optional weights of the same shape.
    ///
    /// # Errors
    /// Bad knot vectors (named `"u"`/`"v"` by the caller), shape mismatch,
    /// non-finite values, non-positive weights.
    pub fn try_new(
        degree: [usize; 2],
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        points: &[Vec<DVec3>],
        weights: Option<&[Vec<f64>]>,
    ) -> Result<Self, NurbsError> {
        let ku = KnotVector::try_new(degree[0], knots_u)?;
        let kv = KnotVector::try_new(degree[1], knots_v)?;
        Self::from_parts(ku, kv, points, weights)
    }

    /// As [`NurbsSurface::try_new`] with validated knot vectors.
    ///
    /// # Errors
    /// Shape mismatch, non-finite values, non-positive weights.
    pub fn from_parts(
        ku: KnotVector,
        kv: KnotVector,
        points: &[Vec<DVec3>],
        weights: Option<&[Vec<f64>]>,
    ) -> Result<Self, NurbsError> {
        let (nu, nv) = (ku.control_count(), kv.control_count());
        if points.len() != nu {
            return Err(NurbsError::CountMismatch {
                what: "control point rows (along u)".into(),
                found: points.len(),
                expected: nu,
            });
        }
        if let Some(w) = weights {
            if w.len() != nu {
                return Err(NurbsError::CountMismatch {
                    what: "weight rows (along u)".into(),
                    found: w.len(),
                    expected: nu,
                });
            }
        }
        let mut hp = Vec::with_capacity(nu * nv);
        for (i, row) in points.iter().enumerate() {
            if row.len() != nv {
                return Err(NurbsError::CountMismatch {
                    what: alloc::format!("control points in row {i} (along v)"),
                    found: row.len(),
                    expected: nv,
                });
            }
            let wrow = weights.map(|w| &w[i]);
            if let Some(wr) = wrow {
                if wr.len() != nv {
                    return Err(NurbsError::CountMismatch {
                        what: alloc::format!("weights in row {i} (along v)"),
                        found: wr.len(),
                        expected: nv,
                    });
                }
            }
            for (j, p) in row.iter().enumerate() {
                let index = i * nv + j;
                if !p.is_finite() {
                    return Err(NurbsError::NotFinite { what: "point", index });
                }
                let w = wrow.map_or(1.0, |wr| wr[j]);
                if !w.is_finite() {
                    return Err(NurbsError::NotFinite { what: "weight", index });
                }
                if w <= 0.0 {
                    return Err(NurbsError::BadWeight { index, found: w });
                }
                hp.push((*p * w).extend(w));
            }
        }
        Ok(Self { ku, kv, points: hp, rational: weights.is_some() })
    }

    /// Knot vector along u.
    pub fn knots_u(&self) -> &KnotVector {
        &self.ku
    }

    /// Knot vector along v.
    pub fn knots_v(&self) -> &KnotVector {
        &self.kv
    }

    /// Degrees `[p, q]`.
    pub fn degree(&self) -> [usize; 2] {
        [self.ku.degree(), self.kv.degree()]
    }

    /// Control point counts `[along u, along v]`.
    pub fn counts(&self) -> [usize; 2] {
        [self.ku.control_count(), self.kv.control_count()]
    }

    /// Whether weights were given.
    pub fn is_rational(&self) -> bool {
        self.rational
    }

    /// Homogeneous control point `(i, j)`.
    pub fn homogeneous(&self, i: usize, j: usize) -> DVec4 {
        self.points[i * self.kv.control_count() + j]
    }

    /// Euclidean control points, row-major.
    pub fn control_points(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.points.iter().map(|h| h.truncate() / h.w)
    }

    /// Bounds of `|S_u|` and `|S_v|` over the whole domain (`speed_bound`
    /// along each direction); `None` for a non-positive or non-finite weight.
    pub fn derivative_bounds(&self) -> Option<[f64; 2]> {
        let nv = self.kv.control_count();
        let along_u = speed_bound(&self.ku, &self.points, nv, self.kv.degree() + 1)?;
        let along_v = self.derivative_bound_v()?;
        Some([along_u.length(), along_v.length()])
    }

    /// [`speed_bound`] along v: each row of the net is a curve in v, the
    /// rows a span of u spans together making the block.
    fn derivative_bound_v(&self) -> Option<DVec3> {
        let (nu, nv) = (self.ku.control_count(), self.kv.control_count());
        let transposed: Vec<DVec4> = (0..nv).flat_map(|j| (0..nu).map(move |i| self.points[i * nv + j])).collect();
        speed_bound(&self.kv, &transposed, nu, self.ku.degree() + 1)
    }

    /// Box around the control net (contains the surface).
    pub fn bbox(&self) -> Aabb {
        Aabb::from_points(self.control_points())
    }

    /// Homogeneous derivatives `A^{(k,l)}` for `k + l <= order` (order ≤ 2;
    /// the others are left zero).
    ///
    /// Degrees up to 3 each way (planes, quadrics, bicubics: nearly every
    /// face) get scratch of exactly degree + 1, so both degrees are constants
    /// and every loop unrolls; the operations and their order are the same.
    fn homogeneous_derivs(&self, uv: DVec2, order: usize) -> [[DVec4; 3]; 3] {
        match (self.ku.degree(), self.kv.degree()) {
            (1, 1) => self.homogeneous_derivs_exact::<2, 2>(uv, order),
            (1, 2) => self.homogeneous_derivs_exact::<2, 3>(uv, order),
            (2, 1) => self.homogeneous_derivs_exact::<3, 2>(uv, order),
            (2, 2) => self.homogeneous_derivs_exact::<3, 3>(uv, order),
            (1, 3) => self.homogeneous_derivs_exact::<2, 4>(uv, order),
            (3, 1) => self.homogeneous_derivs_exact::<4, 2>(uv, order),
            (2, 3) => self.homogeneous_derivs_exact::<3, 4>(uv, order),
            (3, 2) => self.homogeneous_derivs_exact::<4, 3>(uv, order),
            (3, 3) => self.homogeneous_derivs_exact::<4, 4>(uv, order),
            (p, q) => match p.max(q) {
                0..=3 => self.homogeneous_derivs_class::<4>(uv, order),
                4..=7 => self.homogeneous_derivs_class::<8>(uv, order),
                8..=11 => self.homogeneous_derivs_class::<12>(uv, order),
                _ => self.homogeneous_derivs_class::<{ super::MAX_DEGREE + 1 }>(uv, order),
            },
        }
    }

    /// `S(u, v)` at every `(us[i], vs[j])`, `u` outer: the basis functions of
    /// each row and column are computed once instead of once per point.
    pub fn points_on_grid(&self, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        match self.ku.degree().max(self.kv.degree()) {
            0..=3 => self.points_on_grid_n::<4>(us, vs),
            4..=7 => self.points_on_grid_n::<8>(us, vs),
            8..=11 => self.points_on_grid_n::<12>(us, vs),
            _ => self.points_on_grid_n::<{ super::MAX_DEGREE + 1 }>(us, vs),
        }
    }

    fn points_on_grid_n<const N: usize>(&self, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        let (p, q) = (self.ku.degree(), self.kv.degree());
        let nv = self.kv.control_count();
        let columns: Vec<(usize, [f64; N])> = vs
            .iter()
            .map(|&v| {
                let mut b = [[0.0; N]; 3];
                let span = self.kv.basis_into(v, 0, &mut b);
                (span, b[0])
            })
            .collect();
        let mut out = Vec::with_capacity(us.len() * vs.len());
        for &u in us {
            let mut bu = [[0.0; N]; 3];
            let su = self.ku.basis_into(u, 0, &mut bu);
            for (sv, bv) in &columns {
                let mut a = DVec4::ZERO;
                for (r, wu) in bu[0].iter().enumerate().take(p + 1) {
                    let row = (su - p + r) * nv + sv - q;
                    for (s, wv) in bv.iter().enumerate().take(q + 1) {
                        a += self.points[row + s] * (wu * wv);
                    }
                }
                out.push(a.truncate() / a.w);
            }
        }
        out
    }

    /// `S(u, v)` at every `(us[i], vs[j])`, `u` outer, bit for bit what
    /// [`Surface::point`] gives at each: the same basis and the same sums in
    /// the same order, but each column's basis is computed once, and each
    /// row's basis and its contraction with the control rows (the sums over
    /// `u`, which depend on `u` alone) once per row instead of once per point.
    pub fn point_grid(&self, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        by_scratch_size!(self, point_grid_n(us, vs))
    }

    /// [`NurbsSurface::point_grid`] in the scratch sizes
    /// [`NurbsSurface::homogeneous_derivs`] picks for these degrees.
    fn point_grid_n<const NU: usize, const NV: usize>(&self, p: usize, q: usize, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        let nv = self.kv.control_count();
        let columns: Vec<(usize, [f64; NV])> = vs
            .iter()
            .map(|&v| {
                let mut b = [[0.0; NV]; MAX_DERIV + 1];
                let span = self.basis_pair::<NU, NV, NV>(false, p, q, v, 0, &mut b);
                (span, b[0])
            })
            .collect();
        // The control columns the points need: the sums over u are kept for these only.
        let first = columns.iter().map(|c| c.0.saturating_sub(q)).min().unwrap_or(0);
        let last = columns.iter().map(|c| c.0).max().unwrap_or(0).min(nv.saturating_sub(1));
        let mut line = alloc::vec![DVec4::ZERO; (last + 1).saturating_sub(first)];
        let mut out = Vec::with_capacity(us.len() * vs.len());
        for &u in us {
            let mut bu = [[0.0; NU]; MAX_DERIV + 1];
            let su = self.basis_pair::<NU, NV, NU>(true, p, q, u, 0, &mut bu);
            self.sum_rows(su, p, &bu[0], first, &mut line);
            for (sv, bv) in &columns {
                let from = sv.saturating_sub(q).saturating_sub(first);
                let mut a = DVec4::ZERO;
                for (t, w) in line.iter().skip(from).zip(bv).take(q + 1) {
                    a += *t * *w;
                }
                out.push(a.truncate() / a.w);
            }
        }
        out
    }

    /// `line[j]` = the sum over `r <= p` of `P[su - p + r][first + j]·w[r]`,
    /// from zero in `r`'s order as [`NurbsSurface::contract_u`] sums: the
    /// sums over u of the control columns from `first` on, for the grid and
    /// iso-curve paths. A row past the net adds nothing.
    fn sum_rows(&self, su: usize, p: usize, w: &[f64], first: usize, line: &mut [DVec4]) {
        line.fill(DVec4::ZERO);
        let nv = self.kv.control_count();
        for (r, &w) in w.iter().enumerate().take(p + 1) {
            let start = (su + r).saturating_sub(p) * nv + first;
            let Some(row) = self.points.get(start..start + line.len()) else {
                continue;
            };
            for (t, h) in line.iter_mut().zip(row) {
                *t += *h * w;
            }
        }
    }

    /// The basis along u (`along_u`) or v at `t` as
    /// [`NurbsSurface::homogeneous_derivs_n`] computes it for scratch sizes
    /// `NU` × `NV` (`N` the one of this direction), returning its span.
    #[inline(always)]
    fn basis_pair<const NU: usize, const NV: usize, const N: usize>(
        &self,
        along_u: bool,
        p: usize,
        q: usize,
        t: f64,
        order: usize,
        b: &mut [[f64; N]; MAX_DERIV + 1],
    ) -> usize {
        let k = if along_u { &self.ku } else { &self.kv };
        if p + 1 == NU && q + 1 == NV {
            k.basis_into(t, order, b)
        } else {
            k.basis_fast(None, t, order, b)
        }
    }

    /// Degrees `NU - 1` and `NV - 1` (the caller checked), as constants.
    fn homogeneous_derivs_exact<const NU: usize, const NV: usize>(&self, uv: DVec2, order: usize) -> [[DVec4; 3]; 3] {
        self.homogeneous_derivs_n::<NU, NV>(NU - 1, NV - 1, uv, order)
    }

    /// Any degrees below `N`.
    fn homogeneous_derivs_class<const N: usize>(&self, uv: DVec2, order: usize) -> [[DVec4; 3]; 3] {
        self.homogeneous_derivs_n::<N, N>(self.ku.degree(), self.kv.degree(), uv, order)
    }

    /// The tensor product for degrees `p < NU`, `q < NV` (equal to the knot
    /// vectors' degrees); inlined so that constant degrees specialize it.
    #[inline(always)]
    fn homogeneous_derivs_n<const NU: usize, const NV: usize>(
        &self,
        p: usize,
        q: usize,
        uv: DVec2,
        order: usize,
    ) -> [[DVec4; 3]; 3] {
        let (first, bu, bv) = self.bases::<NU, NV>(p, q, uv, order);
        // With wasm's SIMD the two passes pair up each point's lanes.
        #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
        {
            super::pairs::contract::<NU, NV>(&self.points, self.kv.control_count(), first, (p, q), &bu, &bv, order)
        }
        // The same bits either way. In wasm the engine keeps the one pass's
        // nine accumulators in memory, and measured in Node it meshed
        // bicubics 13% slower (bug28366_fuselage) and high degrees no faster
        // (BUC50025) than the two passes, which stay there.
        #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
        if cfg!(target_arch = "wasm32") {
            sum_v(&self.contract_u::<NU, NV>(first, p, q, &bu, order), &bv, q, order)
        } else {
            self.contract::<NU, NV>(first, p, q, &bu, &bv, order)
        }
    }

    /// The basis functions (and derivatives up to `order`) at `uv` along u
    /// and v, and the index of the first control point they weigh.
    #[inline(always)]
    fn bases<const NU: usize, const NV: usize>(
        &self,
        p: usize,
        q: usize,
        uv: DVec2,
        order: usize,
    ) -> (usize, [[f64; NU]; MAX_DERIV + 1], [[f64; NV]; MAX_DERIV + 1]) {
        let mut bu = [[0.0; NU]; 3];
        let mut bv = [[0.0; NV]; 3];
        // Exact scratch already unrolls the basis; a degree class gets the
        // basis in exact scratch (degrees up to 7) and copies it.
        let su = self.basis_pair::<NU, NV, NU>(true, p, q, uv.x, order, &mut bu);
        let sv = self.basis_pair::<NU, NV, NV>(false, p, q, uv.y, order, &mut bv);
        ((su - p) * self.kv.control_count() + sv - q, bu, bv)
    }

    /// `sum_v(contract_u(…))` in one pass, column by column: each column's
    /// sums over u are formed in registers and at once multiplied into the
    /// results, instead of being added up in memory row by row and read
    /// back. Every sum has the same terms in the same order (over `r`, then
    /// over `s`, each from zero), so the values are the same bits.
    #[inline(always)]
    #[cfg_attr(all(target_arch = "wasm32", target_feature = "simd128"), allow(dead_code))]
    fn contract<const NU: usize, const NV: usize>(
        &self,
        first: usize,
        p: usize,
        q: usize,
        bu: &[[f64; NU]; MAX_DERIV + 1],
        bv: &[[f64; NV]; MAX_DERIV + 1],
        order: usize,
    ) -> [[DVec4; 3]; 3] {
        let nv = self.kv.control_count();
        // The control rows `contract_u` reads: those whose q + 1 points lie in the net.
        let rows = (0..=p).take_while(|r| first + r * nv + q < self.points.len()).count();
        let mut out = [[DVec4::ZERO; 3]; 3];
        for s in 0..=q {
            let mut temp = [DVec4::ZERO; 3];
            for r in 0..rows {
                let Some(h) = self.points.get(first + r * nv + s) else { continue };
                for (t, b) in temp.iter_mut().zip(bu).take(order + 1) {
                    *t += *h * b[r];
                }
            }
            for (k, t) in temp.iter().enumerate().take(order + 1) {
                for (o, b) in out[k].iter_mut().zip(bv).take(order - k + 1) {
                    *o += *t * b[s];
                }
            }
        }
        out
    }

    /// `temp[k][s]` = sum over `r <= p` of `P[r][s]·Nu^(k)[r]` for `k <= order`
    /// and `s <= q`, control point `(r, s)` at `first + r·nv + s`: each control
    /// row is read once for all orders (sums in the same order as one order at a time).
    #[inline(always)]
    fn contract_u<const NU: usize, const NV: usize>(
        &self,
        first: usize,
        p: usize,
        q: usize,
        bu: &[[f64; NU]; MAX_DERIV + 1],
        order: usize,
    ) -> [[DVec4; NV]; 3] {
        let nv = self.kv.control_count();
        let mut temp = [[DVec4::ZERO; NV]; 3];
        for r in 0..=p {
            let Some(row) = self.points.get(first + r * nv..first + r * nv + q + 1) else {
                continue;
            };
            for k in 0..=order {
                let w = bu[k][r];
                for (t, h) in temp[k].iter_mut().zip(row) {
                    *t += *h * w;
                }
            }
        }
        temp
    }

    /// [`Surface::point_normal`] along the iso-curve where the other
    /// parameter is `s` (`along_u`: `v = s` and the argument is `u`), bit
    /// for bit: the fixed parameter's basis is computed once, and with `u`
    /// fixed also its sums over `u`, once for every control column.
    pub fn iso_point_normal(&self, along_u: bool, s: f64) -> Box<dyn Fn(f64) -> (DVec3, DVec3) + '_> {
        by_scratch_size!(self, iso_n(along_u, s))
    }

    /// [`NurbsSurface::iso_point_normal`] in the scratch sizes
    /// [`NurbsSurface::homogeneous_derivs`] picks for these degrees.
    fn iso_n<const NU: usize, const NV: usize>(
        &self,
        p: usize,
        q: usize,
        along_u: bool,
        s: f64,
    ) -> Box<dyn Fn(f64) -> (DVec3, DVec3) + '_> {
        let finish = move |uv: DVec2, a: [[DVec4; 3]; 3]| {
            let (point, su, sv) = tangents_of(&a);
            (point, self.normal_from_tangents(uv, su, sv))
        };
        if along_u {
            let mut bv = [[0.0; NV]; MAX_DERIV + 1];
            let sv = self.basis_pair::<NU, NV, NV>(false, p, q, s, 1, &mut bv);
            Box::new(move |u: f64| {
                let mut bu = [[0.0; NU]; MAX_DERIV + 1];
                let su = self.basis_pair::<NU, NV, NU>(true, p, q, u, 1, &mut bu);
                let first = (su - p) * self.kv.control_count() + sv - q;
                let temp = self.contract_u::<NU, NV>(first, p, q, &bu, 1);
                finish(DVec2::new(u, s), sum_v(&temp, &bv, q, 1))
            })
        } else {
            let mut bu = [[0.0; NU]; MAX_DERIV + 1];
            let su = self.basis_pair::<NU, NV, NU>(true, p, q, s, 1, &mut bu);
            // The sums over u for every control column, as `contract_u` forms them.
            let nv = self.kv.control_count();
            let mut lines = [alloc::vec![DVec4::ZERO; nv], alloc::vec![DVec4::ZERO; nv]];
            for (line, w) in lines.iter_mut().zip(&bu) {
                self.sum_rows(su, p, w, 0, line);
            }
            Box::new(move |v: f64| {
                let mut bv = [[0.0; NV]; MAX_DERIV + 1];
                let sv = self.basis_pair::<NU, NV, NV>(false, p, q, v, 1, &mut bv);
                let mut temp = [[DVec4::ZERO; NV]; 3];
                for (tk, line) in temp.iter_mut().zip(&lines) {
                    for (t, h) in tk.iter_mut().zip(line.iter().skip(sv - q)) {
                        *t = *h;
                    }
                }
                finish(DVec2::new(s, v), sum_v(&temp, &bv, q, 1))
            })
        }
    }

    /// [`NurbsSurface::homogeneous_derivs`] as two passes, the sums over u
    /// of every row into `temp`, then over v: the tests' reference for [`NurbsSurface::contract`].
    #[cfg(test)]
    fn derivs_by_rows<const NU: usize, const NV: usize>(
        &self,
        p: usize,
        q: usize,
        uv: DVec2,
        order: usize,
    ) -> [[DVec4; 3]; 3] {
        let (first, bu, bv) = self.bases::<NU, NV>(p, q, uv, order);
        sum_v(&self.contract_u::<NU, NV>(first, p, q, &bu, order), &bv, q, order)
    }

    /// [`NurbsSurface::homogeneous_derivs`] as wasm's paired lanes sum it
    /// ([`super::pairs::contract`]), here with plain pairs of numbers.
    #[cfg(test)]
    fn derivs_by_pairs<const NU: usize, const NV: usize>(
        &self,
        p: usize,
        q: usize,
        uv: DVec2,
        order: usize,
    ) -> [[DVec4; 3]; 3] {
        let (first, bu, bv) = self.bases::<NU, NV>(p, q, uv, order);
        super::pairs::contract::<NU, NV>(&self.points, self.kv.control_count(), first, (p, q), &bu, &bv, order)
    }

    /// Inserts knot `t` once along u (`along_u`) or v; same shape.
    pub fn insert_knot(&self, along_u: bool, t: f64) -> Self {
        let kv = if along_u { &self.ku } else { &self.kv };
        let (a, b) = kv.domain();
        if !(t > a && t < b) {
            return self.clone();
        }
        self.insert_in_domain(along_u, t)
    }

    /// As [`NurbsSurface::insert_knot`], for `t` anywhere in the closed domain
    /// (its ends included, which clamping needs).
    fn insert_in_domain(&self, along_u: bool, t: f64) -> Self {
        let (nu, nv) = (self.ku.control_count(), self.kv.control_count());
        let kv = if along_u { &self.ku } else { &self.kv };
        let (a, b) = kv.domain();
        let p = kv.degree();
        if !(t >= a && t <= b) || kv.multiplicity(t) >= p {
            return self.clone();
        }
        let span = kv.span(t);
        let u = kv.knots();
        let alphas: Vec<f64> = (span - p + 1..=span)
            .map(|i| {
                let den = u[i + p] - u[i];
                if den > 0.0 {
                    (t - u[i]) / den
                } else {
                    0.0
                }
            })
            .collect();
        let refine = |line: &[DVec4]| -> Vec<DVec4> {
            let mut out = Vec::with_capacity(line.len() + 1);
            out.extend_from_slice(&line[..=span - p]);
            for (k, i) in (span - p + 1..=span).enumerate() {
                out.push(line[i] * alphas[k] + line[i - 1] * (1.0 - alphas[k]));
            }
            out.extend_from_slice(&line[span..]);
            out
        };
        let new_knots = kv.with_inserted(span, t);
        if along_u {
            let mut pts = alloc::vec![DVec4::ZERO; (nu + 1) * nv];
            for j in 0..nv {
                let col: Vec<DVec4> = (0..nu).map(|i| self.points[i * nv + j]).collect();
                for (i, x) in refine(&col).into_iter().enumerate() {
                    pts[i * nv + j] = x;
                }
            }
            Self { ku: new_knots, kv: self.kv.clone(), points: pts, rational: self.rational }
        } else {
            let mut pts = Vec::with_capacity(nu * (nv + 1));
            for i in 0..nu {
                pts.extend(refine(&self.points[i * nv..(i + 1) * nv]));
            }
            Self { ku: self.ku.clone(), kv: new_knots, points: pts, rational: self.rational }
        }
    }

    /// The same surface over the same domain with its knots along u
    /// (`along_u`) or v clamped: each end of the domain a knot of
    /// multiplicity degree + 1, so the first and last control rows lie on the
    /// surface's edges. A periodic (unclamped) B-spline from a file needs this
    /// before its seam can be moved.
    pub fn clamped(&self, along_u: bool) -> Self {
        let kv = if along_u { &self.ku } else { &self.kv };
        let (a, b) = kv.domain();
        let p = kv.degree();
        let mut s = self.clone();
        for t in [a, b] {
            for _ in 0..p {
                let before = s.points.len();
                s = s.insert_in_domain(along_u, t);
                if s.points.len() == before {
                    break;
                }
            }
        }
        let k = if along_u { s.ku.knots() } else { s.kv.knots() };
        let (Some(last_a), Some(first_b)) = (k.iter().rposition(|&x| x == a), k.iter().position(|&x| x == b)) else {
            return self.clone();
        };
        if last_a < p || first_b + p >= k.len() || (last_a - p == 0 && first_b + p + 1 == k.len()) {
            return s;
        }
        let (s0, e0) = (last_a - p, first_b + p);
        let mut knots: Vec<f64> = k[s0..=e0].to_vec();
        knots[0] = a;
        knots[e0 - s0] = b;
        let rows = knots.len() - p - 1;
        let Ok(kn) = KnotVector::try_new(p, knots) else { return self.clone() };
        let (nu, nv) = (s.ku.control_count(), s.kv.control_count());
        if along_u {
            let points = s.points[s0 * nv..(s0 + rows) * nv].to_vec();
            Self { ku: kn, kv: s.kv.clone(), points, rational: s.rational }
        } else {
            let mut points = Vec::with_capacity(nu * rows);
            for i in 0..nu {
                points.extend_from_slice(&s.points[i * nv + s0..i * nv + s0 + rows]);
            }
            Self { ku: s.ku.clone(), kv: kn, points, rational: s.rational }
        }
    }

    /// Splits at parameter `t` along u (`along_u`) or v into the two surfaces
    /// covering each side (knot insertion up to full multiplicity, then the
    /// control net is cut). `None` when `t` is not strictly inside the domain.
    pub fn split(&self, along_u: bool, t: f64) -> Option<(Self, Self)> {
        let kv = if along_u { &self.ku } else { &self.kv };
        let (a, b) = kv.domain();
        if !(t > a && t < b) {
            return None;
        }
        let p = kv.degree();
        let mut s = self.clone();
        loop {
            let k = if along_u { &s.ku } else { &s.kv };
            if k.multiplicity(t) >= p {
                break;
            }
            let before = s.points.len();
            s = s.insert_knot(along_u, t);
            if s.points.len() == before {
                return None;
            }
        }
        let k = if along_u { s.ku.knots() } else { s.kv.knots() };
        let first = k.iter().position(|&x| x == t)?;
        let mut k1: Vec<f64> = k[..first + p].to_vec();
        k1.push(t);
        let mut k2: Vec<f64> = alloc::vec![t];
        k2.extend_from_slice(&k[first..]);
        let n1 = k1.len() - p - 1;
        let (nu, nv) = (s.ku.control_count(), s.kv.control_count());
        let (kn1, kn2) = (KnotVector::try_new(p, k1).ok()?, KnotVector::try_new(p, k2).ok()?);
        if along_u {
            let left = s.points[..n1 * nv].to_vec();
            let right = s.points[(n1 - 1) * nv..].to_vec();
            Some((
                Self { ku: kn1, kv: s.kv.clone(), points: left, rational: s.rational },
                Self { ku: kn2, kv: s.kv.clone(), points: right, rational: s.rational },
            ))
        } else {
            let mut left = Vec::with_capacity(nu * n1);
            let mut right = Vec::with_capacity(nu * (nv - n1 + 1));
            for i in 0..nu {
                left.extend_from_slice(&s.points[i * nv..i * nv + n1]);
                right.extend_from_slice(&s.points[i * nv + n1 - 1..(i + 1) * nv]);
            }
            Some((
                Self { ku: s.ku.clone(), kv: kn1, points: left, rational: s.rational },
                Self { ku: s.ku.clone(), kv: kn2, points: right, rational: s.rational },
            ))
        }
    }
}

/// `A^{(k,l)}` for `k + l <= order` from the sums over u ([`NurbsSurface::contract_u`]):
/// each a sum over `s <= q` of `temp[k][s]·Nv^(l)[s]`; the others zero.
#[inline(always)]
fn sum_v<const NV: usize>(
    temp: &[[DVec4; NV]; 3],
    bv: &[[f64; NV]; MAX_DERIV + 1],
    q: usize,
    order: usize,
) -> [[DVec4; 3]; 3] {
    let mut out = [[DVec4::ZERO; 3]; 3];
    for (k, tk) in temp.iter().enumerate().take(order + 1) {
        for l in 0..=(order - k) {
            let mut acc = DVec4::ZERO;
            for (s, t) in tk.iter().enumerate().take(q + 1) {
                acc += *t * bv[l][s];
            }
            out[k][l] = acc;
        }
    }
    out
}

/// `(S, Su, Sv)` from the homogeneous derivatives of first order (quotient rule).
#[inline(always)]
fn tangents_of(a: &[[DVec4; 3]; 3]) -> (DVec3, DVec3, DVec3) {
    let w = a[0][0].w;
    let s = a[0][0].truncate() / w;
    let su = (a[1][0].truncate() - s * a[1][0].w) / w;
    let sv = (a[0][1].truncate() - s * a[0][1].w) / w;
    (s, su, sv)
}

impl Surface for NurbsSurface {
    fn domain(&self) -> [DVec2; 2] {
        let (u0, u1) = self.ku.domain();
        let (v0, v1) = self.kv.domain();
        [DVec2::new(u0, v0), DVec2::new(u1, v1)]
    }

    fn point(&self, uv: DVec2) -> DVec3 {
        let a = self.homogeneous_derivs(uv, 0)[0][0];
        a.truncate() / a.w
    }

    fn tangents(&self, uv: DVec2) -> (DVec3, DVec3, DVec3) {
        // First order only: the same sums as in `derivs`, the second-order ones left out.
        tangents_of(&self.homogeneous_derivs(uv, 1))
    }

    fn derivs(&self, uv: DVec2) -> SurfaceDerivs {
        let a = self.homogeneous_derivs(uv, 2);
        let w = a[0][0].w;
        let s = a[0][0].truncate() / w;
        let su = (a[1][0].truncate() - s * a[1][0].w) / w;
        let sv = (a[0][1].truncate() - s * a[0][1].w) / w;
        let suu = (a[2][0].truncate() - su * (2.0 * a[1][0].w) - s * a[2][0].w) / w;
        let svv = (a[0][2].truncate() - sv * (2.0 * a[0][1].w) - s * a[0][2].w) / w;
        let suv = (a[1][1].truncate() - su * a[0][1].w - sv * a[1][0].w - s * a[1][1].w) / w;
        SurfaceDerivs { point: s, su, sv, suu, suv, svv }
    }

    fn point_grid(&self, us: &[f64], vs: &[f64]) -> Vec<DVec3> {
        NurbsSurface::point_grid(self, us, vs)
    }

    fn iso_point_normal(&self, along_u: bool, s: f64) -> Box<dyn Fn(f64) -> (DVec3, DVec3) + '_> {
        NurbsSurface::iso_point_normal(self, along_u, s)
    }

    fn breaks(&self, along_u: bool) -> Vec<f64> {
        if along_u {
            self.ku.breakpoints()
        } else {
            self.kv.breakpoints()
        }
    }

    fn bounding_box(&self) -> Aabb {
        self.bbox()
    }

    fn derivative_bounds(&self) -> Option<[f64; 2]> {
        NurbsSurface::derivative_bounds(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    /// A wavy rational surface of degrees `p` × `q` with uneven inner knots
    /// (one doubled, one a sliver), for comparing evaluation paths.
    fn wavy(p: usize, q: usize) -> NurbsSurface {
        let knots = |d: usize, inner: &[f64]| {
            let mut k = vec![0.0; d + 1];
            k.extend_from_slice(inner);
            k.extend(core::iter::repeat_n(1.0, d + 1));
            k
        };
        let ku = knots(p, &[0.2, 0.45, 0.45, 0.7]);
        let kv = knots(q, &[0.3, 0.3 + 1e-17, 0.55, 0.8]);
        let (nu, nv) = (ku.len() - p - 1, kv.len() - q - 1);
        let pts: Vec<Vec<DVec3>> = (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| {
                        let (x, y) = (i as f64 * 1.3, j as f64 * 0.7);
                        DVec3::new(x, y, libm::sin(x + 2.0 * y) + 0.1 * (i * j) as f64)
                    })
                    .collect()
            })
            .collect();
        let w: Vec<Vec<f64>> =
            (0..nu).map(|i| (0..nv).map(|j| 1.0 + 0.3 * ((i + 2 * j) % 3) as f64).collect()).collect();
        NurbsSurface::try_new([p, q], ku, kv, &pts, Some(&w)).unwrap()
    }

    /// The grid gives bit for bit the points `point` gives, for exact and
    /// degree-class scratch sizes, at knots, inside slivers and outside the
    /// domain (clamped), in any order of the parameters.
    #[test]
    fn point_grid_equals_point_bitwise() {
        let ts = [-0.1, 0.0, 0.1, 0.2, 0.3, 0.3 + 5e-18, 0.31, 0.45, 0.5, 0.551, 0.7, 0.9999, 1.0, 1.2, 0.05];
        for (p, q) in [(1, 1), (1, 2), (2, 1), (2, 2), (3, 3), (1, 3), (3, 2), (2, 4), (5, 5), (1, 8), (8, 11), (4, 13)]
        {
            let s = wavy(p, q);
            for (us, vs) in [(&ts[..], &ts[..]), (&ts[2..3], &ts[..]), (&ts[..], &ts[5..6]), (&ts[..0], &ts[..])] {
                let grid = s.point_grid(us, vs);
                assert_eq!(grid.len(), us.len() * vs.len());
                for (i, &u) in us.iter().enumerate() {
                    for (j, &v) in vs.iter().enumerate() {
                        let want = Surface::point(&s, DVec2::new(u, v));
                        let got = grid[i * vs.len() + j];
                        assert_eq!(
                            got.to_array().map(f64::to_bits),
                            want.to_array().map(f64::to_bits),
                            "({p},{q}) at ({u},{v})"
                        );
                    }
                }
            }
        }
    }

    /// The homogeneous derivatives of every order, formed column by column,
    /// and as wasm sums them two lanes at a time (`pairs::contract`,
    /// here on plain pairs), are bit for bit the two-pass sums (rows over u,
    /// then over v), for exact and degree-class scratch sizes, at knots,
    /// inside slivers and outside the domain: the lanes only pair
    /// operations, never reorder them.
    #[test]
    fn homogeneous_derivs_equal_two_passes_bitwise() {
        let ts = [-0.1, 0.0, 0.1, 0.2, 0.3, 0.3 + 5e-18, 0.31, 0.45, 0.5, 0.551, 0.7, 0.9999, 1.0, 1.2];
        let bits = |a: [[DVec4; 3]; 3]| a.map(|r| r.map(|h| h.to_array().map(f64::to_bits)));
        for (p, q) in
            [(1, 1), (1, 2), (2, 1), (2, 2), (3, 3), (1, 3), (3, 2), (2, 4), (5, 5), (7, 7), (1, 8), (8, 11), (4, 13)]
        {
            let s = wavy(p, q);
            for &u in &ts {
                for &v in &ts {
                    let uv = DVec2::new(u, v);
                    for order in 0..=2 {
                        let want = by_scratch_size!(s, derivs_by_rows(uv, order));
                        assert_eq!(
                            bits(s.homogeneous_derivs(uv, order)),
                            bits(want),
                            "({p},{q}) at {uv} order {order}"
                        );
                        let paired = by_scratch_size!(s, derivs_by_pairs(uv, order));
                        assert_eq!(bits(paired), bits(want), "lanes: ({p},{q}) at {uv} order {order}");
                    }
                }
            }
        }
    }

    /// Points and normals along iso-curves are bit for bit those of
    /// `point_normal`, either parameter fixed, for exact and degree-class
    /// scratch sizes, at knots, inside slivers and outside the domain.
    #[test]
    fn iso_point_normal_equals_point_normal_bitwise() {
        let ts = [-0.1, 0.0, 0.1, 0.2, 0.3, 0.3 + 5e-18, 0.31, 0.45, 0.5, 0.551, 0.7, 0.9999, 1.0, 1.2];
        let bits = |(p, n): (DVec3, DVec3)| [p.to_array(), n.to_array()].map(|a| a.map(f64::to_bits));
        for (p, q) in [(1, 1), (1, 2), (2, 1), (2, 2), (3, 3), (1, 3), (3, 2), (2, 4), (5, 5), (1, 8), (8, 11), (4, 13)]
        {
            let s = wavy(p, q);
            for along_u in [true, false] {
                for &fixed in &ts {
                    let iso = s.iso_point_normal(along_u, fixed);
                    for &t in &ts {
                        let uv = if along_u { DVec2::new(t, fixed) } else { DVec2::new(fixed, t) };
                        assert_eq!(bits(iso(t)), bits(s.point_normal(uv)), "({p},{q}) at {uv}");
                    }
                }
            }
        }
    }
}
