//! NURBS module: knot vectors, basis functions, curves, surfaces, projection,
//! normals and boxes. Expected values come from formulas written here
//! independently of the library (Cox–de Boor recursion, Bernstein and
//! textbook closed forms, finite differences, analytic shapes).

use glam::{DVec2, DVec3};
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use surfmesh::{
    project_to_surface, BasisDers, KnotVector, NurbsCurve, NurbsError, NurbsSurface, ProjectionOptions, Surface,
    MAX_DEGREE,
};

use crate::shapes;

/// Fixed seed, no regression files: every run tries the same cases.
fn config(cases: u32) -> Config {
    Config { cases, rng_seed: RngSeed::Fixed(0x5eed_2024), failure_persistence: None, ..Config::default() }
}

// ---------------------------------------------------------------------------
// Independent reference: Cox–de Boor recursion
// ---------------------------------------------------------------------------

/// Index of the knot span holding `t` (`k_s <= t < k_{s+1}`, non-empty),
/// the last non-empty span of the domain when `t` is at its end.
fn ref_span(knots: &[f64], p: usize, t: f64) -> usize {
    let n = knots.len() - p - 2;
    (p..=n).rev().find(|&i| knots[i] <= t && knots[i] < knots[i + 1]).expect("t inside the domain")
}

/// k-th derivative of `N_{i,p}` at `t` by the recursion
/// `N_{i,0} = [i = span]`,
/// `N_{i,p} = (t−k_i)/(k_{i+p}−k_i)·N_{i,p−1} + (k_{i+p+1}−t)/(k_{i+p+1}−k_{i+1})·N_{i+1,p−1}`,
/// `N^{(k)}_{i,p} = p·(N^{(k−1)}_{i,p−1}/(k_{i+p}−k_i) − N^{(k−1)}_{i+1,p−1}/(k_{i+p+1}−k_{i+1}))`,
/// with 0/0 taken as 0.
fn ref_basis(knots: &[f64], span: usize, i: usize, p: usize, k: usize, t: f64) -> f64 {
    if p == 0 {
        return if k == 0 && i == span { 1.0 } else { 0.0 };
    }
    let d1 = knots[i + p] - knots[i];
    let d2 = knots[i + p + 1] - knots[i + 1];
    let mut s = 0.0;
    if k == 0 {
        if d1 > 0.0 {
            s += (t - knots[i]) / d1 * ref_basis(knots, span, i, p - 1, 0, t);
        }
        if d2 > 0.0 {
            s += (knots[i + p + 1] - t) / d2 * ref_basis(knots, span, i + 1, p - 1, 0, t);
        }
    } else {
        if d1 > 0.0 {
            s += p as f64 * ref_basis(knots, span, i, p - 1, k - 1, t) / d1;
        }
        if d2 > 0.0 {
            s -= p as f64 * ref_basis(knots, span, i + 1, p - 1, k - 1, t) / d2;
        }
    }
    s
}

/// Rational surface point from the definition, independently of the library.
fn ref_surface_point(g: &SurfGen, uv: DVec2) -> DVec3 {
    let (ku, kv) = (&g.knots_u, &g.knots_v);
    let (su, sv) = (ref_span(ku, g.pu, uv.x), ref_span(kv, g.pv, uv.y));
    let (mut num, mut den) = (DVec3::ZERO, 0.0);
    for (i, row) in g.points.iter().enumerate() {
        let nu = ref_basis(ku, su, i, g.pu, 0, uv.x);
        for (j, p) in row.iter().enumerate() {
            let b = nu * ref_basis(kv, sv, j, g.pv, 0, uv.y) * g.weights[i][j];
            num += *p * b;
            den += b;
        }
    }
    num / den
}

// ---------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------

/// Raw material for a knot vector: degree, start, scale, interior steps
/// (`(gap, repeat)`: `repeat` makes the knot equal to the previous interior
/// knot while the multiplicity stays ≤ p) and whether the ends are clamped.
#[derive(Debug, Clone)]
struct KnotGen {
    p: usize,
    knots: Vec<f64>,
}

#[allow(clippy::too_many_arguments)]
fn make_knots(
    p: usize,
    max_mult: usize,
    start: f64,
    scale: f64,
    steps: &[(f64, bool)],
    ends: &[f64],
    clamped: bool,
) -> Vec<f64> {
    let mut k = Vec::new();
    let mut x = start;
    if clamped {
        k.extend(std::iter::repeat_n(start, p + 1));
    } else {
        let mut pre: Vec<f64> = Vec::new();
        let mut y = start;
        for e in ends.iter().take(p) {
            y -= e * scale;
            pre.push(y);
        }
        k.extend(pre.iter().rev());
        k.push(start);
    }
    let mut run = 1usize;
    let mut first = true;
    for &(gap, repeat) in steps {
        if repeat && !first && run < max_mult {
            run += 1;
        } else {
            x += gap * scale;
            run = 1;
        }
        first = false;
        k.push(x);
    }
    x += steps.first().map_or(0.5, |s| s.0.max(0.3)) * scale;
    if clamped {
        k.extend(std::iter::repeat_n(x, p + 1));
    } else {
        k.push(x);
        for e in ends.iter().skip(p).take(p) {
            x += e * scale;
            k.push(x);
        }
    }
    k
}

fn knot_gen(max_p: usize, max_inner: usize) -> impl Strategy<Value = KnotGen> {
    knot_gen_smooth(max_p, max_inner, false)
}

/// As [`knot_gen`]; with `smooth` inner knots repeat at most p − 1 times
/// (the spline stays C¹: no creases).
fn knot_gen_smooth(max_p: usize, max_inner: usize, smooth: bool) -> impl Strategy<Value = KnotGen> {
    (
        1..=max_p,
        -5.0f64..5.0,
        0.1f64..10.0,
        vec((0.05f64..1.0, prop::bool::weighted(0.25)), 0..=max_inner),
        vec(0.05f64..1.0, 2 * max_p),
        prop::bool::weighted(0.75),
    )
        .prop_map(move |(p, start, scale, steps, ends, clamped)| {
            let max_mult = if smooth { p.saturating_sub(1).max(1) } else { p };
            KnotGen { p, knots: make_knots(p, max_mult, start, scale, &steps, &ends, clamped) }
        })
}

/// A random rational surface: control points in [-10,10]³, weights in `w_range`.
#[derive(Debug, Clone)]
struct SurfGen {
    pu: usize,
    pv: usize,
    knots_u: Vec<f64>,
    knots_v: Vec<f64>,
    points: Vec<Vec<DVec3>>,
    weights: Vec<Vec<f64>>,
}

impl SurfGen {
    fn build(&self) -> NurbsSurface {
        NurbsSurface::try_new(
            [self.pu, self.pv],
            self.knots_u.clone(),
            self.knots_v.clone(),
            &self.points,
            Some(&self.weights),
        )
        .expect("generated surface is valid")
    }
}

const POOL: usize = 128;

fn surf_gen(max_p: usize, weights: core::ops::Range<f64>) -> impl Strategy<Value = SurfGen> {
    (knot_gen(max_p, 4), knot_gen(max_p, 4), vec(-10.0f64..10.0, 3 * POOL), vec(weights, POOL)).prop_map(
        |(ku, kv, coords, ws)| {
            let nu = ku.knots.len() - ku.p - 1;
            let nv = kv.knots.len() - kv.p - 1;
            let points = (0..nu)
                .map(|i| {
                    (0..nv)
                        .map(|j| {
                            let k = (i * nv + j) % POOL;
                            DVec3::new(coords[3 * k], coords[3 * k + 1], coords[3 * k + 2])
                        })
                        .collect()
                })
                .collect();
            let weights = (0..nu).map(|i| (0..nv).map(|j| ws[(i * nv + j) % POOL]).collect()).collect();
            SurfGen { pu: ku.p, pv: kv.p, knots_u: ku.knots, knots_v: kv.knots, points, weights }
        },
    )
}

/// A random rational 3-D curve.
fn curve_gen(max_p: usize) -> impl Strategy<Value = NurbsCurve> {
    (knot_gen(max_p, 6), vec(-10.0f64..10.0, 3 * 16), vec(0.3f64..3.0, 16)).prop_map(|(k, coords, ws)| {
        let n = k.knots.len() - k.p - 1;
        let points = (0..n).map(|i| DVec3::new(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2])).collect();
        let weights = ws[..n].to_vec();
        NurbsCurve::try_new(k.p, k.knots, points, Some(weights)).expect("generated curve is valid")
    })
}

/// A gently waving rational height field over a jittered grid spacing 10:
/// a graph over (x, y), so every point has one parameter pair.
/// With `smooth`, no creases (inner knot multiplicity below the degree).
fn graph_gen(smooth: bool) -> impl Strategy<Value = SurfGen> {
    (
        knot_gen_smooth(3, 3, smooth).prop_filter("degree >= 2", |k| k.p >= 2),
        knot_gen_smooth(3, 3, smooth).prop_filter("degree >= 2", |k| k.p >= 2),
        vec(-1.0f64..1.0, 3 * POOL),
        vec(0.7f64..1.4, POOL),
    )
        .prop_map(|(ku, kv, r, ws)| {
            let nu = ku.knots.len() - ku.p - 1;
            let nv = kv.knots.len() - kv.p - 1;
            let points = (0..nu)
                .map(|i| {
                    (0..nv)
                        .map(|j| {
                            let k = (i * nv + j) % POOL;
                            let x = 10.0 * i as f64 + 2.0 * r[3 * k];
                            let y = 10.0 * j as f64 + 2.0 * r[3 * k + 1];
                            DVec3::new(x, y, 3.0 * r[3 * k + 2])
                        })
                        .collect()
                })
                .collect();
            let weights = (0..nu).map(|i| (0..nv).map(|j| ws[(i * nv + j) % POOL]).collect()).collect();
            SurfGen { pu: ku.p, pv: kv.p, knots_u: ku.knots, knots_v: kv.knots, points, weights }
        })
}

/// Parameter strictly inside one knot span: span number `pick` (mod the
/// number of spans), at fraction `f` of it. Returns `(t, span length)`.
fn inside_span(breaks: &[f64], pick: usize, f: f64) -> (f64, f64) {
    let s = pick % (breaks.len() - 1);
    let (a, b) = (breaks[s], breaks[s + 1]);
    (a + (b - a) * f, b - a)
}

fn lerp(a: f64, b: f64, f: f64) -> f64 {
    a + (b - a) * f
}

/// First derivative of `f` at 0 by central differences with Richardson
/// extrapolation (error O(h⁴)).
fn fd1(f: impl Fn(f64) -> DVec3, h: f64) -> DVec3 {
    let d = |h: f64| (f(h) - f(-h)) / (2.0 * h);
    (4.0 * d(h / 2.0) - d(h)) / 3.0
}

/// Second derivative of `f` at 0 by central differences with Richardson extrapolation.
fn fd2(f: impl Fn(f64) -> DVec3, h: f64) -> DVec3 {
    let d = |h: f64| (f(h) - 2.0 * f(0.0) + f(-h)) / (h * h);
    (4.0 * d(h / 2.0) - d(h)) / 3.0
}

// ---------------------------------------------------------------------------
// Knot vectors
// ---------------------------------------------------------------------------

#[test]
fn knot_vector_rejects_bad_input_and_names_the_index() {
    assert_eq!(KnotVector::try_new(0, vec![0.0, 1.0]), Err(NurbsError::BadDegree { degree: 0 }));
    let long = [vec![0.0; MAX_DEGREE + 2], vec![1.0; MAX_DEGREE + 2]].concat();
    assert_eq!(KnotVector::try_new(MAX_DEGREE + 1, long.clone()), Err(NurbsError::BadDegree { degree: 17 }));
    assert!(KnotVector::try_new(MAX_DEGREE, long[1..long.len() - 1].to_vec()).is_ok());
    assert_eq!(
        KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0]),
        Err(NurbsError::TooFewKnots { found: 5, needed: 6 })
    );
    let e = KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 0.5, 0.4, 1.0, 1.0, 1.0]).unwrap_err();
    assert_eq!(e, NurbsError::DecreasingKnots { index: 4 });
    assert!(e.to_string().contains("index 4"), "{e}");
    // Four equal inner knots for degree 2: the run ends at index 6.
    let e = KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0]).unwrap_err();
    assert_eq!(e, NurbsError::BadMultiplicity { index: 6 });
    assert!(e.to_string().contains('6'), "{e}");
    // Four equal end knots for degree 2.
    assert_eq!(
        KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0]),
        Err(NurbsError::BadMultiplicity { index: 3 })
    );
    // p + 1 equal inner knots are allowed (a break in the curve).
    assert!(KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0]).is_ok());
    let e = KnotVector::try_new(2, vec![0.0, 0.0, 0.0, f64::NAN, 1.0, 1.0, 1.0]).unwrap_err();
    assert_eq!(e, NurbsError::NotFinite { what: "knot", index: 3 });
    assert!(e.to_string().contains("knot 3"), "{e}");
    assert_eq!(
        KnotVector::try_new(1, vec![0.0, 0.0, 1.0, f64::INFINITY]),
        Err(NurbsError::NotFinite { what: "knot", index: 3 })
    );
    // Empty parameter range [k_p, k_n] = [1, 1].
    assert!(matches!(KnotVector::try_new(1, vec![0.0, 1.0, 1.0, 2.0]), Err(NurbsError::BadMultiplicity { .. })));
    assert!(matches!(KnotVector::try_new(1, vec![1.0, 1.0, 1.0, 1.0]), Err(NurbsError::BadMultiplicity { .. })));
}

#[test]
fn knot_vector_domain_span_and_breakpoints() {
    let k = KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0]).unwrap();
    assert_eq!(k.degree(), 2);
    assert_eq!(k.control_count(), 5);
    assert_eq!(k.domain(), (0.0, 3.0));
    assert_eq!(k.breakpoints(), vec![0.0, 1.0, 2.0, 3.0]);
    // k_s <= t < k_{s+1}; interior knots belong to the span on their right.
    for (t, s) in [(0.0, 2), (0.5, 2), (1.0, 3), (1.5, 3), (2.0, 4), (2.999, 4)] {
        assert_eq!(k.span(t), s, "t = {t}");
    }
    // The domain's end belongs to the last non-empty span; outside values clamp.
    assert_eq!(k.span(3.0), 4);
    assert_eq!(k.span(-1.0), 2);
    assert_eq!(k.span(7.0), 4);
    assert_eq!(k.span(f64::NAN), 2);
    assert_eq!(k.clamp(-1.0), 0.0);
    assert_eq!(k.clamp(4.0), 3.0);
    assert_eq!(k.clamp(f64::NAN), 0.0);
    assert_eq!(k.multiplicity(0.0), 3);
    assert_eq!(k.multiplicity(1.0), 1);
    assert_eq!(k.multiplicity(0.5), 0);

    // A double inner knot: t = 1 lies in the span after the run.
    let k = KnotVector::try_new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0]).unwrap();
    assert_eq!(k.span(1.0), 4);
    assert_eq!(k.span(0.999), 2);
    assert_eq!(k.span(2.0), 4);
    assert_eq!(k.breakpoints(), vec![0.0, 1.0, 2.0]);

    // Unclamped: the domain is [k_p, k_n], and its end is in span n - 1.
    let k = KnotVector::try_new(2, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
    assert_eq!(k.control_count(), 4);
    assert_eq!(k.domain(), (2.0, 4.0));
    assert_eq!(k.span(2.0), 2);
    assert_eq!(k.span(3.0), 3);
    assert_eq!(k.span(4.0), 3);
    assert_eq!(k.breakpoints(), vec![2.0, 3.0, 4.0]);

    let k = KnotVector::clamped_uniform(3, 7).unwrap();
    assert_eq!(k.knots(), &[0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0]);
}

// ---------------------------------------------------------------------------
// Basis functions
// ---------------------------------------------------------------------------

/// Degree 2 on [0,0,0,1,2,3,3,3] at t = 1.5 (span 3, functions N_1..N_3).
/// On [1,2): N_1 = (2−t)²/2, N_2 = 1 − N_1 − N_3, N_3 = (t−1)²/2 (textbook
/// closed forms from the recursion), so the values are 1/8, 3/4, 1/8,
/// the first derivatives −(2−t), ·, (t−1) = −1/2, 0, 1/2 and the second 1, −2, 1.
#[test]
fn basis_degree2_hand_values() {
    let knots = vec![0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0];
    let k = KnotVector::try_new(2, knots.clone()).unwrap();
    let mut d = BasisDers::default();
    let span = k.basis_ders(1.5, 2, &mut d);
    assert_eq!(span, 3);
    let expected = [[0.125, 0.75, 0.125], [-0.5, 0.0, 0.5], [1.0, -2.0, 1.0]];
    for (order, row) in expected.iter().enumerate() {
        for (j, &e) in row.iter().enumerate() {
            assert!((d.0[order][j] - e).abs() < 1e-14, "N^({order})_{} = {} != {e}", j + 1, d.0[order][j]);
            // The same number from the recursion written in this file.
            let r = ref_basis(&knots, ref_span(&knots, 2, 1.5), j + 1, 2, order, 1.5);
            assert!((r - e).abs() < 1e-14, "reference recursion disagrees with the hand value");
        }
    }
    // At t = 0.5 (span 2), from the recursion on [0,1):
    // N_0 = (1−t)², N_2 = t²/2, N_1 = 1 − N_0 − N_2 = 5/8.
    let span = k.basis_ders(0.5, 1, &mut d);
    assert_eq!(span, 2);
    let (n0, n2) = (0.25, 0.125);
    for (j, e) in [n0, 1.0 - n0 - n2, n2].into_iter().enumerate() {
        assert!((d.0[0][j] - e).abs() < 1e-14);
    }
    // Derivatives: −2(1−t) = −1, t = 0.5, and the middle one makes the sum 0.
    for (j, e) in [-1.0, 0.5, 0.5].into_iter().enumerate() {
        assert!((d.0[1][j] - e).abs() < 1e-14, "N'_{j} = {}", d.0[1][j]);
    }
    // At the end of a clamped vector only the last function is 1.
    let span = k.basis_ders(3.0, 0, &mut d);
    assert_eq!(span, 4);
    assert_eq!(&d.0[0][..3], &[0.0, 0.0, 1.0]);
}

/// Degree 3 on [0,0,0,0,1,1,1,1] is the Bernstein basis: values and both derivatives.
#[test]
fn basis_cubic_bezier_is_bernstein() {
    let k = KnotVector::try_new(3, vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]).unwrap();
    let mut d = BasisDers::default();
    for step in 0..=20 {
        let t = step as f64 / 20.0;
        let s = 1.0 - t;
        let b = [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t];
        let b1 = [-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t];
        let b2 = [6.0 * s, 18.0 * t - 12.0, 6.0 - 18.0 * t, 6.0 * t];
        assert_eq!(k.basis_ders(t, 2, &mut d), 3);
        for j in 0..4 {
            assert!((d.0[0][j] - b[j]).abs() < 1e-14, "t={t} j={j}");
            assert!((d.0[1][j] - b1[j]).abs() < 1e-13, "t={t} j={j}");
            assert!((d.0[2][j] - b2[j]).abs() < 1e-12, "t={t} j={j}");
        }
    }
    // Degree 1 has no second derivative.
    let k = KnotVector::try_new(1, vec![0.0, 0.0, 1.0, 1.0]).unwrap();
    k.basis_ders(0.3, 2, &mut d);
    assert_eq!((d.0[0][0], d.0[0][1]), (0.7, 0.3));
    assert_eq!((d.0[1][0], d.0[1][1]), (-1.0, 1.0));
    assert_eq!((d.0[2][0], d.0[2][1]), (0.0, 0.0));
}

proptest! {
    #![proptest_config(config(256))]

    /// Values and derivatives equal the Cox–de Boor recursion; partition of
    /// unity, non-negativity, derivatives summing to zero.
    #[test]
    fn basis_matches_recursion_and_partitions_unity(
        k in knot_gen(5, 7), f in 0.0f64..=1.0, at_knot in any::<bool>(), pick in 0usize..64,
    ) {
        let kv = KnotVector::try_new(k.p, k.knots.clone()).unwrap();
        let (a, b) = kv.domain();
        let t = if at_knot {
            let inside: Vec<f64> = k.knots.iter().copied().filter(|&x| x >= a && x <= b).collect();
            inside[pick % inside.len()]
        } else {
            lerp(a, b, f)
        };
        let mut d = BasisDers::default();
        let span = kv.basis_ders(t, 2, &mut d);
        let p = k.p;
        prop_assert_eq!(span, ref_span(&k.knots, p, t));
        for (order, row) in d.0.iter().enumerate() {
            let scale: f64 = row[..=p].iter().map(|x| x.abs()).sum::<f64>().max(1.0);
            let mut sum = 0.0;
            for (j, &got) in row[..=p].iter().enumerate() {
                let r = ref_basis(&k.knots, span, span - p + j, p, order, t);
                prop_assert!((got - r).abs() <= 1e-11 * scale, "order {} j {}: {} vs {}", order, j, got, r);
                sum += got;
            }
            if order == 0 {
                prop_assert!((sum - 1.0).abs() <= 1e-14 * (p as f64 + 1.0), "sum = {}", sum);
            } else {
                prop_assert!(sum.abs() <= 1e-11 * scale, "derivatives of order {} sum to {}", order, sum);
            }
        }
        for j in 0..=p {
            prop_assert!(d.0[0][j] >= 0.0, "N_{} = {}", j, d.0[0][j]);
        }
    }
}

// ---------------------------------------------------------------------------
// Curves and surfaces: evaluation and derivatives
// ---------------------------------------------------------------------------

#[test]
fn curve_and_surface_constructors_reject_bad_data() {
    let pts = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
    let knots = vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    assert!(NurbsCurve::try_new(2, knots.clone(), pts.clone(), None).is_ok());
    assert!(matches!(
        NurbsCurve::try_new(2, knots.clone(), pts[..2].to_vec(), None),
        Err(NurbsError::CountMismatch { found: 2, expected: 3, .. })
    ));
    assert_eq!(
        NurbsCurve::try_new(2, knots.clone(), pts.clone(), Some(vec![1.0, 0.0, 1.0])),
        Err(NurbsError::BadWeight { index: 1, found: 0.0 })
    );
    assert!(matches!(
        NurbsCurve::try_new(2, knots.clone(), pts.clone(), Some(vec![1.0, 1.0])),
        Err(NurbsError::CountMismatch { found: 2, expected: 3, .. })
    ));
    assert_eq!(
        NurbsCurve::try_new(2, knots.clone(), vec![DVec3::ZERO, DVec3::NAN, DVec3::Y], None),
        Err(NurbsError::NotFinite { what: "point", index: 1 })
    );
    let grid = vec![pts.clone(), pts.clone(), pts.clone()];
    assert!(NurbsSurface::try_new([2, 2], knots.clone(), knots.clone(), &grid, None).is_ok());
    assert!(matches!(
        NurbsSurface::try_new([2, 2], knots.clone(), knots.clone(), &grid[..2], None),
        Err(NurbsError::CountMismatch { found: 2, expected: 3, .. })
    ));
    let ragged = vec![pts.clone(), pts[..2].to_vec(), pts.clone()];
    let e = NurbsSurface::try_new([2, 2], knots.clone(), knots.clone(), &ragged, None).unwrap_err();
    assert!(e.to_string().contains("row 1"), "{e}");
    let w = vec![vec![1.0; 3], vec![1.0, 1.0, -2.0], vec![1.0; 3]];
    assert_eq!(
        NurbsSurface::try_new([2, 2], knots.clone(), knots, &grid, Some(&w)),
        Err(NurbsError::BadWeight { index: 5, found: -2.0 })
    );
}

proptest! {
    #![proptest_config(config(128))]

    /// S(u,v) equals the rational definition evaluated with the recursion above.
    #[test]
    fn surface_point_matches_definition(g in surf_gen(4, 0.3..3.0), fu in 0.0f64..=1.0, fv in 0.0f64..=1.0) {
        let s = g.build();
        let [lo, hi] = s.domain();
        let uv = DVec2::new(lerp(lo.x, hi.x, fu), lerp(lo.y, hi.y, fv));
        let got = s.point(uv);
        let want = ref_surface_point(&g, uv);
        prop_assert!(got.distance(want) <= 1e-12 * 20.0, "{} vs {}", got, want);
        prop_assert!(s.derivs(uv).point.distance(got) <= 1e-12 * 20.0);
    }

    /// A grid evaluated by rows and columns holds the rational definition at every node,
    /// including parameters outside the domain (clamped, as `point` does).
    #[test]
    fn surface_grid_points_match_definition(g in surf_gen(9, 0.3..3.0), us in vec(-0.1f64..=1.1, 1..6), vs in vec(-0.1f64..=1.1, 1..6)) {
        let s = g.build();
        let [lo, hi] = s.domain();
        let us: Vec<f64> = us.iter().map(|&f| lerp(lo.x, hi.x, f)).collect();
        let vs: Vec<f64> = vs.iter().map(|&f| lerp(lo.y, hi.y, f)).collect();
        let grid = s.points_on_grid(&us, &vs);
        prop_assert_eq!(grid.len(), us.len() * vs.len());
        for (i, &u) in us.iter().enumerate() {
            for (j, &v) in vs.iter().enumerate() {
                let uv = DVec2::new(u.clamp(lo.x, hi.x), v.clamp(lo.y, hi.y));
                let want = ref_surface_point(&g, uv);
                let got = grid[i * vs.len() + j];
                prop_assert!(got.distance(want) <= 1e-12 * 20.0, "({}, {}): {} vs {}", u, v, got, want);
            }
        }
    }

    /// Curve C', C'' equal central differences of C and C' inside a knot span.
    #[test]
    fn curve_derivatives_match_finite_differences(c in curve_gen(5), pick in 0usize..16, f in 0.05f64..0.95) {
        let (t, len) = inside_span(&c.knots().breakpoints(), pick, f);
        let h = 1e-3 * len;
        let d = c.derivs(t);
        prop_assert!(d.point.distance(c.point(t)) <= 1e-12 * 20.0);
        let tol1 = 1e-7 * (d.d1.length() + 20.0 / len);
        let tol2 = 1e-6 * (d.d2.length() + 20.0 / (len * len));
        let from_points = fd1(|x| c.point(t + x), h);
        prop_assert!((from_points - d.d1).length() <= tol1, "C' {} vs fd {}", d.d1, from_points);
        let from_d1 = fd1(|x| c.derivs(t + x).d1, h);
        prop_assert!((from_d1 - d.d2).length() <= tol2, "C'' {} vs fd of C' {}", d.d2, from_d1);
        let from_points = fd2(|x| c.point(t + x), 2.0 * h);
        prop_assert!((from_points - d.d2).length() <= tol2, "C'' {} vs fd {}", d.d2, from_points);
    }

    /// Su, Sv, Suu, Svv and Suv (both ways) equal central differences.
    #[test]
    fn surface_derivatives_match_finite_differences(
        g in surf_gen(4, 0.3..3.0), pu in 0usize..16, pv in 0usize..16, fu in 0.05f64..0.95, fv in 0.05f64..0.95,
    ) {
        let s = g.build();
        let (u, lu) = inside_span(&s.breaks(true), pu, fu);
        let (v, lv) = inside_span(&s.breaks(false), pv, fv);
        let (hu, hv) = (1e-3 * lu, 1e-3 * lv);
        let uv = DVec2::new(u, v);
        let d = s.derivs(uv);
        let close = |name: &str, got: DVec3, fd: DVec3, reference: f64| -> Result<(), TestCaseError> {
            let tol = 1e-6 * (got.length() + reference);
            prop_assert!((got - fd).length() <= tol, "{}: {} vs fd {} (tol {})", name, got, fd, tol);
            Ok(())
        };
        let at = |du: f64, dv: f64| s.point(uv + DVec2::new(du, dv));
        let der = |du: f64, dv: f64| s.derivs(uv + DVec2::new(du, dv));
        close("Su", d.su, fd1(|x| at(x, 0.0), hu), 20.0 / lu)?;
        close("Sv", d.sv, fd1(|x| at(0.0, x), hv), 20.0 / lv)?;
        close("Suu", d.suu, fd1(|x| der(x, 0.0).su, hu), 20.0 / (lu * lu))?;
        close("Svv", d.svv, fd1(|x| der(0.0, x).sv, hv), 20.0 / (lv * lv))?;
        close("Suv", d.suv, fd1(|x| der(0.0, x).su, hv), 20.0 / (lu * lv))?;
        close("Svu", d.suv, fd1(|x| der(x, 0.0).sv, hu), 20.0 / (lu * lv))?;
        // Second order straight from points, independent of Su and Sv.
        close("Suu from points", d.suu, fd2(|x| at(x, 0.0), 2.0 * hu), 20.0 / (lu * lu))?;
        close("Svv from points", d.svv, fd2(|x| at(0.0, x), 2.0 * hv), 20.0 / (lv * lv))?;
        let mixed = |k: f64| (at(k * hu, k * hv) - at(k * hu, -k * hv) - at(-k * hu, k * hv) + at(-k * hu, -k * hv)) / (4.0 * k * k * hu * hv);
        let suv_points = (4.0 * mixed(1.0) - mixed(2.0)) / 3.0;
        close("Suv from points", d.suv, suv_points, 20.0 / (lu * lv))?;
    }
}

// ---------------------------------------------------------------------------
// Knot insertion and splitting
// ---------------------------------------------------------------------------

fn max_curve_gap(a: &NurbsCurve, b: &NurbsCurve, t0: f64, t1: f64) -> f64 {
    (0..=200).map(|k| lerp(t0, t1, k as f64 / 200.0)).map(|t| a.point(t).distance(b.point(t))).fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(config(128))]

    /// Inserting knots (new values and existing ones) keeps the curve's shape
    /// and adds one control point per accepted insertion.
    #[test]
    fn curve_knot_insertion_keeps_shape(c in curve_gen(5), fs in vec(0.0f64..1.0, 1..6), reuse in any::<bool>()) {
        let (a, b) = c.domain();
        let mut r = c.clone();
        for (n, f) in fs.iter().enumerate() {
            let t = if reuse && n % 2 == 1 {
                // An existing inner knot, if any.
                let inner: Vec<f64> = r.knots().knots().iter().copied().filter(|&x| x > a && x < b).collect();
                if inner.is_empty() { lerp(a, b, *f) } else { inner[(f * inner.len() as f64) as usize % inner.len()] }
            } else {
                lerp(a, b, *f)
            };
            let before = r.knots().multiplicity(t);
            let count = r.homogeneous_points().len();
            let next = r.insert_knot(t);
            if t > a && t < b && before < r.degree() {
                prop_assert_eq!(next.homogeneous_points().len(), count + 1);
                prop_assert_eq!(next.knots().multiplicity(t), before + 1);
            } else {
                prop_assert_eq!(&next, &r);
            }
            r = next;
        }
        prop_assert_eq!(r.domain(), (a, b));
        let gap = max_curve_gap(&c, &r, a, b);
        prop_assert!(gap <= 1e-11 * 30.0, "shape moved by {}", gap);
    }

    /// Splitting gives [a, t] and [t, b] pieces that reproduce the original.
    #[test]
    fn curve_split_reproduces_original(c in curve_gen(5), f in 0.01f64..0.99, at_knot in any::<bool>()) {
        let (a, b) = c.domain();
        let inner: Vec<f64> = c.knots().knots().iter().copied().filter(|&x| x > a && x < b).collect();
        let t = if at_knot && !inner.is_empty() { inner[(f * inner.len() as f64) as usize % inner.len()] } else { lerp(a, b, f) };
        let (left, right) = c.split(t).expect("t is inside the domain");
        prop_assert_eq!(left.domain(), (a, t));
        prop_assert_eq!(right.domain(), (t, b));
        prop_assert_eq!(left.degree(), c.degree());
        let gl = max_curve_gap(&c, &left, a, t);
        let gr = max_curve_gap(&c, &right, t, b);
        prop_assert!(gl <= 1e-11 * 30.0 && gr <= 1e-11 * 30.0, "left off by {}, right by {}", gl, gr);
        prop_assert!(left.point(t).distance(right.point(t)) <= 1e-11 * 30.0);
        prop_assert!(c.split(a).is_none() && c.split(b).is_none() && c.split(f64::NAN).is_none());
    }

    /// Inserting knots along u and v keeps the surface's shape.
    #[test]
    fn surface_knot_insertion_keeps_shape(
        g in surf_gen(4, 0.3..3.0), ins in vec((any::<bool>(), 0.0f64..1.0), 1..5),
    ) {
        let s = g.build();
        let [lo, hi] = s.domain();
        let mut r = s.clone();
        for (along_u, f) in ins {
            let (a, b) = if along_u { (lo.x, hi.x) } else { (lo.y, hi.y) };
            let t = lerp(a, b, f);
            let kv = if along_u { r.knots_u() } else { r.knots_v() };
            let grows = t > a && t < b && kv.multiplicity(t) < kv.degree();
            let [nu, nv] = r.counts();
            r = r.insert_knot(along_u, t);
            let expected = match (grows, along_u) {
                (false, _) => [nu, nv],
                (true, true) => [nu + 1, nv],
                (true, false) => [nu, nv + 1],
            };
            prop_assert_eq!(r.counts(), expected);
        }
        prop_assert_eq!(r.domain(), s.domain());
        let mut worst = 0.0f64;
        for i in 0..=24 {
            for j in 0..=24 {
                let uv = lo + (hi - lo) * DVec2::new(i as f64 / 24.0, j as f64 / 24.0);
                worst = worst.max(s.point(uv).distance(r.point(uv)));
            }
        }
        prop_assert!(worst <= 1e-11 * 30.0, "shape moved by {}", worst);
    }
}

// ---------------------------------------------------------------------------
// Projection
// ---------------------------------------------------------------------------

/// Largest absolute principal curvature at `uv` (first and second fundamental forms).
fn max_curvature(s: &dyn Surface, uv: DVec2) -> f64 {
    let d = s.derivs(uv);
    let n = d.su.cross(d.sv).normalize();
    let (e, f, g) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
    let (l, m, nn) = (d.suu.dot(n), d.suv.dot(n), d.svv.dot(n));
    let det1 = e * g - f * f;
    let mean = (e * nn - 2.0 * f * m + g * l) / (2.0 * det1);
    let gauss = (l * nn - m * m) / det1;
    let disc = (mean * mean - gauss).max(0.0).sqrt();
    mean.abs() + disc
}

proptest! {
    #![proptest_config(config(128))]

    /// On smooth (C¹) surfaces S(u,v) projects back to (u,v), with and
    /// without a hint; S(u,v) + d·n projects to distance |d| (from a hint in
    /// the same knot cell: exactly there; from the coarse search: never
    /// farther than |d|).
    #[test]
    fn surface_projection_round_trip(
        g in graph_gen(true), fu in 0.05f64..0.95, fv in 0.05f64..0.95, fd in -1.0f64..1.0,
        hu in -0.02f64..0.02, hv in -0.02f64..0.02,
    ) {
        let s = g.build();
        let [lo, hi] = s.domain();
        let size = hi - lo;
        let uv0 = lo + size * DVec2::new(fu, fv);
        let opts = ProjectionOptions::default();
        let p0 = s.point(uv0);
        let uv_tol = 1e-8 * size.max_element();

        // A hint in the same knot cell as uv0 (across a crease the hint's own
        // basin may hold a local minimum of its own).
        let cell = |breaks: Vec<f64>, x: f64| {
            let a = breaks.iter().copied().filter(|&k| k <= x).fold(f64::NEG_INFINITY, f64::max);
            let b = breaks.iter().copied().filter(|&k| k > x).fold(f64::INFINITY, f64::min);
            (a, b)
        };
        let (cu, cv) = (cell(s.breaks(true), uv0.x), cell(s.breaks(false), uv0.y));
        let near = (uv0 + size * DVec2::new(hu, hv)).clamp(DVec2::new(cu.0, cv.0), DVec2::new(cu.1, cv.1));
        for (what, hint) in [("hint", Some(near)), ("no hint", None)] {
            let pr = project_to_surface(&s, p0, hint, &opts);
            prop_assert!(pr.distance <= 1e-10, "{}: distance {}", what, pr.distance);
            prop_assert!((pr.uv - uv0).abs().max_element() <= uv_tol, "{}: uv {} vs {}", what, pr.uv, uv0);
            prop_assert!(pr.point.distance(s.point(pr.uv)) <= 1e-12 * 100.0);
        }

        let kappa = max_curvature(&s, uv0);
        let d = fd * (0.3 / kappa.max(1e-9)).min(2.0);
        let n = s.normal(uv0);
        let target = p0 + n * d;
        let pr = project_to_surface(&s, target, Some(near), &opts);
        prop_assert!((pr.distance - d.abs()).abs() <= 1e-9 * (1.0 + d.abs()), "hint: {} vs {}", pr.distance, d.abs());
        prop_assert!((pr.uv - uv0).abs().max_element() <= 1e-7 * size.max_element(), "hint: uv {} vs {}", pr.uv, uv0);
        let pr = project_to_surface(&s, target, None, &opts);
        prop_assert!(pr.distance <= d.abs() + 1e-9 * (1.0 + d.abs()), "no hint: {} > {}", pr.distance, d.abs());
        prop_assert!((pr.point.distance(target) - pr.distance).abs() <= 1e-12 * 100.0);
    }

    /// With creases (C0 knot lines) the distance has a basin on each side of
    /// a crease: S(u,v) is still found exactly without a hint, and an offset
    /// point is never reported farther than its offset.
    #[test]
    fn surface_projection_with_creases(
        g in graph_gen(false), fu in 0.0f64..=1.0, fv in 0.0f64..=1.0, fd in -1.0f64..1.0,
    ) {
        let s = g.build();
        let [lo, hi] = s.domain();
        let size = hi - lo;
        let uv0 = lo + size * DVec2::new(fu, fv);
        let opts = ProjectionOptions::default();
        let p0 = s.point(uv0);
        let pr = project_to_surface(&s, p0, None, &opts);
        prop_assert!(pr.distance <= 1e-10, "distance {}", pr.distance);
        prop_assert!((pr.uv - uv0).abs().max_element() <= 1e-8 * size.max_element(), "uv {} vs {}", pr.uv, uv0);
        // Offsets within the focal distance at uv0 (farther ones make two
        // basins across every knot line where the curvature jumps).
        let d = fd * (0.3 / max_curvature(&s, uv0).max(1e-9)).min(2.0);
        let target = p0 + s.normal(uv0) * d;
        for hint in [None, Some(uv0)] {
            let pr = project_to_surface(&s, target, hint, &opts);
            prop_assert!(pr.distance <= d.abs() + 1e-9 * (1.0 + d.abs()), "{:?}: {} > {}", hint, pr.distance, d.abs());
            prop_assert!((pr.point.distance(target) - pr.distance).abs() <= 1e-12 * 100.0);
        }
    }

    /// Projection onto the exact sphere and torus finds the analytic distance
    /// for points anywhere around them, poles and seams included.
    #[test]
    fn projection_onto_sphere_and_torus_is_exact(
        dir in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), radius in 2.0f64..30.0,
        theta in 0.0f64..std::f64::consts::TAU, phi in 0.0f64..std::f64::consts::TAU, off in -4.0f64..4.0,
    ) {
        let opts = ProjectionOptions::default();
        let sphere = shapes::sphere_surface(shapes::SPHERE_RADIUS);
        let dir = DVec3::new(dir.0, dir.1, dir.2);
        prop_assume!(dir.length() > 0.1);
        let p = dir.normalize() * radius;
        let pr = project_to_surface(&sphere, p, None, &opts);
        let exact = shapes::sphere_distance(p);
        prop_assert!((pr.distance - exact).abs() <= 1e-9, "sphere at {}: {} vs {}", p, pr.distance, exact);
        prop_assert!((pr.point.length() - shapes::SPHERE_RADIUS).abs() <= 1e-12 * 10.0);

        let torus = shapes::torus_surface(shapes::TORUS_MAJOR, shapes::TORUS_MINOR);
        let tube = shapes::TORUS_MINOR + off;
        let rho = shapes::TORUS_MAJOR + tube * phi.cos();
        let q = DVec3::new(rho * theta.cos(), rho * theta.sin(), tube * phi.sin());
        let pr = project_to_surface(&torus, q, None, &opts);
        let exact = shapes::torus_distance(q);
        prop_assert!((exact - off.abs()).abs() <= 1e-12 * 30.0);
        prop_assert!((pr.distance - exact).abs() <= 1e-9, "torus at {}: {} vs {}", q, pr.distance, exact);
    }

    /// Curve projection: C(t) projects back to t; an offset perpendicular to
    /// the curve is never reported farther than the offset; a circle gives
    /// the analytic distance.
    #[test]
    fn curve_projection_round_trip(
        c in curve_gen(4), f in 0.02f64..0.98, fd in -1.0f64..1.0, side in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        q in (-8.0f64..8.0, -8.0f64..8.0, -3.0f64..3.0),
    ) {
        let (a, b) = c.domain();
        let t0 = lerp(a, b, f);
        let d0 = c.derivs(t0);
        prop_assume!(d0.d1.length() > 1e-6);
        let surfmesh::CurveProjection { t, point, distance: dist } = c.project(d0.point);
        prop_assert!(dist <= 1e-10 * 30.0, "distance {}", dist);
        prop_assert!(point.distance(c.point(t)) <= 1e-12 * 30.0);
        prop_assert!((t - t0).abs() <= 1e-7 * (b - a) || c.point(t).distance(d0.point) <= 1e-10 * 30.0);

        let side = DVec3::new(side.0, side.1, side.2);
        let normal = side - d0.d1 * (side.dot(d0.d1) / d0.d1.length_squared());
        prop_assume!(normal.length() > 1e-3);
        let kappa = d0.d1.cross(d0.d2).length() / d0.d1.length().powi(3);
        let d = fd * (0.3 / kappa.max(1e-9)).min(2.0);
        let target = d0.point + normal.normalize() * d;
        let dist = c.project(target).distance;
        prop_assert!(dist <= d.abs() + 1e-9 * (1.0 + d.abs()), "{} > {}", dist, d.abs());

        // Exact circle of radius 5 in the plane z = 0.
        let circle = shapes::uv_circle(DVec2::ZERO, 5.0).build();
        let q = DVec3::new(q.0, q.1, q.2);
        prop_assume!(q.truncate().length() > 0.5);
        let surfmesh::CurveProjection { point, distance: dist, .. } = circle.project(q);
        let exact = (q.truncate().length() - 5.0).hypot(q.z);
        prop_assert!((dist - exact).abs() <= 1e-9, "circle at {}: {} vs {}", q, dist, exact);
        prop_assert!((point.truncate().length() - 5.0).abs() <= 1e-12 * 5.0);
    }
}

/// Targets on and near the sphere's axis project to (or next to) a pole,
/// where the surface is degenerate, with the analytic distance.
#[test]
fn projection_near_sphere_poles() {
    let s = shapes::sphere_surface(shapes::SPHERE_RADIUS);
    let opts = ProjectionOptions::default();
    for z in [-25.0, -12.0, -10.0, -9.0, -3.0, 3.0, 9.0, 10.0, 12.0, 25.0] {
        for off in [0.0, 1e-6, 1e-3, 0.05, 0.5] {
            for az in [0.0, 0.7, 1.6, 2.5, 3.3, 4.4, 5.9] {
                let p = DVec3::new(off * f64::cos(az), off * f64::sin(az), z);
                let exact = shapes::sphere_distance(p);
                for hint in [None, Some(DVec2::new(0.3, if z > 0.0 { 0.97 } else { 0.03 }))] {
                    let pr = project_to_surface(&s, p, hint, &opts);
                    assert!(
                        (pr.distance - exact).abs() <= 1e-9,
                        "{p} (hint {hint:?}): {} vs {exact}, at {}",
                        pr.distance,
                        pr.uv
                    );
                }
            }
        }
    }
}

/// A hint on the wrong side of a seam still reaches the closest point: the
/// search continues across the seam of a closed surface.
#[test]
fn projection_crosses_seams() {
    let opts = ProjectionOptions::default();
    let torus = shapes::torus_surface(shapes::TORUS_MAJOR, shapes::TORUS_MINOR);
    let cylinder = shapes::first_surface(&shapes::cylinder()).clone();
    for (theta, phi) in [(-0.05, 0.3), (0.05, -0.3), (-0.2, -0.2), (0.01, 0.01)] {
        let tube = shapes::TORUS_MINOR + 0.5;
        let rho = shapes::TORUS_MAJOR + tube * f64::cos(phi);
        let p = DVec3::new(rho * f64::cos(theta), rho * f64::sin(theta), tube * f64::sin(phi));
        for hint in [None, Some(DVec2::new(0.0, 0.0)), Some(DVec2::new(1.0, 1.0)), Some(DVec2::new(0.02, 0.98))] {
            let pr = project_to_surface(&torus, p, hint, &opts);
            assert!((pr.distance - 0.5).abs() <= 1e-9, "torus {p} hint {hint:?}: {}", pr.distance);
        }
        let q = DVec3::new(12.0 * f64::cos(theta), 12.0 * f64::sin(theta), 15.0 + 100.0 * phi);
        for hint in [None, Some(DVec2::new(0.0, 0.5)), Some(DVec2::new(1.0, 0.5))] {
            let pr = project_to_surface(&cylinder, q, hint, &opts);
            let exact = shapes::cylinder_distance(q);
            assert!((pr.distance - exact).abs() <= 1e-9, "cylinder {q} hint {hint:?}: {} vs {exact}", pr.distance);
        }
    }
    // An open surface is not wrapped: the freeform's closest point to a
    // target beyond its u = 0 edge stays on that edge.
    let free = shapes::freeform();
    let s = shapes::first_surface(&free);
    let edge = s.point(DVec2::new(0.0, 0.5));
    let pr = project_to_surface(s, edge - DVec3::X * 5.0, Some(DVec2::new(0.01, 0.5)), &opts);
    assert!(pr.uv.x == 0.0 && pr.distance <= 5.0 + 1e-9, "{pr:?}");
    // A non-finite hint falls back to the search.
    let pr = project_to_surface(&torus, DVec3::new(25.0, 0.0, 0.0), Some(DVec2::NAN), &opts);
    assert!(pr.distance <= 1e-9, "{pr:?}");
}

// ---------------------------------------------------------------------------
// Normals
// ---------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(128))]

    /// The normal is unit length and along Su × Sv wherever that is not tiny.
    #[test]
    fn normal_is_unit_and_along_su_cross_sv(g in surf_gen(4, 0.3..3.0), fu in 0.0f64..=1.0, fv in 0.0f64..=1.0) {
        let s = g.build();
        let [lo, hi] = s.domain();
        let uv = lo + (hi - lo) * DVec2::new(fu, fv);
        let n = s.normal(uv);
        prop_assert!(n.is_finite() && (n.length() - 1.0).abs() <= 1e-12, "|n| = {}", n.length());
        let d = s.derivs(uv);
        let c = d.su.cross(d.sv);
        if c.length() > 1e-6 * d.su.length() * d.sv.length() {
            prop_assert!(n.dot(c.normalize()) >= 1.0 - 1e-12, "n {} vs su x sv {}", n, c);
        }
    }
}

/// On the exact sphere the normal is the outward radius everywhere: poles
/// (collapsed edges), seam, and the lines next to them.
#[test]
fn sphere_normal_is_radial_including_poles() {
    let r = shapes::SPHERE_RADIUS;
    let s = shapes::sphere_surface(r);
    // At the poles exactly: -z at the south (v = 0), +z at the north.
    for k in 0..=16 {
        let u = k as f64 / 16.0;
        let south = s.normal(DVec2::new(u, 0.0));
        let north = s.normal(DVec2::new(u, 1.0));
        assert!(south.distance(DVec3::NEG_Z) < 1e-5, "south pole normal {south} at u = {u}");
        assert!(north.distance(DVec3::Z) < 1e-5, "north pole normal {north} at u = {u}");
    }
    let vs = [1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0 - 1e-6, 1.0 - 1e-9, 1.0 - 1e-12];
    for k in 0..=16 {
        let u = k as f64 / 16.0;
        for &v in &vs {
            let uv = DVec2::new(u, v);
            let n = s.normal(uv);
            let radial = s.point(uv) / r;
            assert!((n.length() - 1.0).abs() < 1e-12, "|n| = {} at {uv}", n.length());
            assert!(n.distance(radial) < 1e-5, "normal {n} vs radial {radial} at {uv}");
        }
    }
}

/// The torus, cylinder and pole shapes: unit normals, outward on the torus and
/// cylinder; at the pole's apex the normal is vertical and agrees with its
/// neighbours.
#[test]
fn normals_of_test_shapes() {
    let torus = shapes::torus_surface(shapes::TORUS_MAJOR, shapes::TORUS_MINOR);
    let cylinder = shapes::first_surface(&shapes::cylinder()).clone();
    for i in 0..=12 {
        for j in 0..=12 {
            let uv = DVec2::new(i as f64 / 12.0, j as f64 / 12.0);
            let p = torus.point(uv);
            let axis = p.truncate().normalize() * shapes::TORUS_MAJOR;
            let outward = (p - axis.extend(0.0)).normalize();
            assert!(torus.normal(uv).distance(outward) < 1e-9, "torus at {uv}");
            let p = cylinder.point(uv);
            assert!(cylinder.normal(uv).distance(p.truncate().normalize().extend(0.0)) < 1e-9, "cylinder at {uv}");
        }
    }
    let pole = shapes::pole();
    let s = shapes::first_surface(&pole);
    for k in 0..=20 {
        let u = k as f64 / 20.0;
        let n = s.normal(DVec2::new(u, 0.0));
        assert!((n.length() - 1.0).abs() < 1e-12);
        assert!(n.z.abs() > 1.0 - 1e-6, "apex normal {n} at u = {u}");
        let nearby = s.normal(DVec2::new(u, 0.01));
        assert!(n.dot(nearby) > 0.99, "apex normal {n} vs nearby {nearby} at u = {u}");
    }
}

// ---------------------------------------------------------------------------
// Bounding boxes
// ---------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(128))]

    /// Boxes contain every sampled point of the curve or surface.
    #[test]
    fn bbox_contains_samples(g in surf_gen(4, 0.3..3.0), c in curve_gen(5)) {
        let s = g.build();
        let b = s.bounding_box();
        prop_assert_eq!(b, s.bbox());
        let [lo, hi] = s.domain();
        for i in 0..=20 {
            for j in 0..=20 {
                let p = s.point(lo + (hi - lo) * DVec2::new(i as f64 / 20.0, j as f64 / 20.0));
                prop_assert!(b.contains(p, 1e-12 * 20.0), "{} outside {:?}", p, b);
            }
        }
        let b = c.bbox();
        let (t0, t1) = c.domain();
        for k in 0..=200 {
            let p = c.point(lerp(t0, t1, k as f64 / 200.0));
            prop_assert!(b.contains(p, 1e-12 * 20.0), "{} outside {:?}", p, b);
        }
        prop_assert!(b.diagonal() > 0.0 && !b.is_empty());
    }
}

/// Clamping an unclamped (periodic) knot vector keeps the surface and its
/// domain, and puts the first and last control rows on its edges, which a
/// seam move needs.
#[test]
fn surface_clamping_keeps_shape_and_clamps_the_ends() {
    let (nu, nv) = (9, 3);
    let knots_u: Vec<f64> = (0..nu + 4).map(|i| (i as f64 - 3.0) * 0.25).collect();
    let knots_v = vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    let points: Vec<Vec<DVec3>> = (0..nu)
        .map(|i| (0..nv).map(|j| DVec3::new(i as f64, (i * i % 5) as f64 + j as f64, (j * i) as f64 * 0.3)).collect())
        .collect();
    let weights: Vec<Vec<f64>> =
        (0..nu).map(|i| (0..nv).map(|j| 1.0 + 0.1 * ((i + 2 * j) % 4) as f64).collect()).collect();
    let s = NurbsSurface::try_new([3, 2], knots_u, knots_v, &points, Some(&weights)).unwrap();
    let c = s.clamped(true);
    assert_eq!(c.domain(), s.domain());
    let ku = c.knots_u().knots();
    let [lo, hi] = s.domain();
    assert!(ku[..4].iter().all(|&k| k == lo.x) && ku[ku.len() - 4..].iter().all(|&k| k == hi.x), "{ku:?}");
    assert_eq!(c.knots_v(), s.knots_v());
    let mut worst = 0.0f64;
    for i in 0..=40 {
        for j in 0..=10 {
            let uv = lo + (hi - lo) * DVec2::new(i as f64 / 40.0, j as f64 / 10.0);
            worst = worst.max(s.point(uv).distance(c.point(uv)));
        }
    }
    assert!(worst <= 1e-12 * 30.0, "shape moved by {worst}");
    // Clamped ends interpolate the corners.
    let [cu, cv] = c.counts();
    for (i, u) in [(0, lo.x), (cu - 1, hi.x)] {
        for (j, v) in [(0, lo.y), (cv - 1, hi.y)] {
            let h = c.homogeneous(i, j);
            let gap = (h.truncate() / h.w).distance(s.point(DVec2::new(u, v)));
            assert!(gap < 1e-12 * 30.0, "control point ({i}, {j}) is {gap} off the corner");
        }
    }
    // Already clamped: unchanged.
    assert_eq!(c.clamped(true), c);
}
