//! Tests of the work mesh and its refinement.

use super::*;
use crate::nurbs::counted::Counted;

/// The plane z = 0 over [-10, 10]², u = x and v = y.
fn plane() -> crate::nurbs::NurbsSurface {
    crate::nurbs::analytic::xy_plane(10.0)
}

fn at(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// Corner (u,v)s are stored per vertex with a side table for triangles
/// whose corners differ: each reads back exactly what was written, also
/// a seam vertex's second (u,v), -0.0 against 0.0, and a triangle moved
/// into a removed one's slot.
#[test]
fn corner_uvs_read_back_as_written() {
    let mut m = WorkMesh::default();
    for p in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)] {
        m.add_vertex(DVec3::new(p.0, p.1, 0.0), DVec3::Z);
    }
    let a = [at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0)];
    let b = [at(-0.0, 0.0), at(0.0, 1.0), at(-1.0, 0.0)];
    let c = [at(7.0, 0.0), at(0.0, 1.0), at(-1.0, 0.0)];
    m.add_triangle([0, 1, 2], a);
    m.add_triangle([0, 2, 3], b);
    m.add_triangle([0, 2, 3], c);
    let bits = |w: [DVec2; 3]| w.map(|q| (q.x.to_bits(), q.y.to_bits()));
    assert_eq!(bits(m.uv(0)), bits(a));
    assert_eq!(bits(m.uv(1)), bits(b));
    assert_eq!(bits(m.uv(2)), bits(c));
    m.set_uv(1, a.map(|q| q + at(0.0, 0.0)));
    m.set_uv(1, b);
    assert_eq!(bits(m.uv(1)), bits(b));
    #[cfg(feature = "std")]
    {
        m.remove_triangle(0);
        assert_eq!(bits(m.uv(0)), bits(c));
        assert_eq!(bits(m.uv(1)), bits(b));
        m.remove_triangle(1);
        assert_eq!(m.tris.len(), 1);
        assert_eq!(bits(m.uv(0)), bits(c));
    }
}

/// A 4×4 grid of squares on the plane, two triangles each.
fn grid() -> WorkMesh {
    let mut m = WorkMesh::default();
    for j in 0..5 {
        for i in 0..5 {
            m.add_vertex(DVec3::new(i as f64, j as f64, 0.0), DVec3::Z);
        }
    }
    let v = |i: u32, j: u32| 5 * j + i;
    let w = |i: u32, j: u32| at(f64::from(i), f64::from(j));
    for j in 0..4 {
        for i in 0..4 {
            m.add_triangle([v(i, j), v(i + 1, j), v(i + 1, j + 1)], [w(i, j), w(i + 1, j), w(i + 1, j + 1)]);
            m.add_triangle([v(i, j), v(i + 1, j + 1), v(i, j + 1)], [w(i, j), w(i + 1, j + 1), w(i, j + 1)]);
        }
    }
    m
}

/// Each edge with its triangles (lowest first).
fn edge_table(m: &WorkMesh) -> Vec<((u32, u32), [u32; 2])> {
    let mut e: Vec<_> = m.edges.iter().map(|(k, t)| (k, [t[0].min(t[1]), t[0].max(t[1])])).collect();
    e.sort_unstable();
    e
}

/// A face at rest splits border edges (a neighbour's shared split) by
/// its border list alone; woken, it has the triangles, border and edges
/// of the same face split awake, and refines to the same mesh.
#[test]
fn a_face_split_at_rest_wakes_as_if_it_never_slept() {
    let s = plane();
    let (mut awake, mut rested) = (grid(), grid());
    rested.rest();
    assert!(rested.edges.iter().next().is_none());
    assert_eq!(rested.boundary_edges(), awake.boundary_edges());
    let mut out = Vec::new();
    for (a, b, frac) in [(0, 1, 0.5), (4, 9, 0.25), (25, 1, 0.5), (24, 23, 0.7)] {
        let x = awake.split_edge_at(&s, &[], a, b, frac, None, &mut out);
        let y = rested.split_edge_at(&s, &[], a, b, frac, None, &mut out);
        assert_eq!(x, y, "edge {a}-{b}");
        assert_eq!(rested.boundary_edges(), awake.boundary_edges());
    }
    assert!(rested.resting, "border splits leave the face at rest");
    assert_eq!(rested.tris, awake.tris);
    rested.wake();
    assert_eq!(edge_table(&rested), edge_table(&awake));
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 0.3, min_edge: 0.0, steps: 2, lift: Lift::NONE };
    awake.refine(&s, &[], &c, 100_000);
    rested.refine(&s, &[], &c, 100_000);
    assert!(awake.tris.len() > 400);
    assert_eq!(rested.tris, awake.tris);
}

/// A cached measure reads back no smaller than measured (rounded up to
/// `f32`), and within an `f32` step of it.
#[test]
fn packed_measures_never_understate() {
    for x in [0.0, 1e-300, 0.1, 1.0 / 3.0, 0.249_999_999_9, 7e12, -1e-300, -0.1] {
        let (m, turn) = Packed::pack(TriMeasure { max: x, sum: x }, x).unpack();
        assert!(m.max >= x && turn >= x, "{x}");
        assert!(m.max - x <= x.abs() * 1.2e-7 + 2e-45, "{x}");
    }
    assert!(STALE.max.is_nan());
}

/// Through the splits of refinement every corner's (u,v) stays the
/// surface point of its vertex (on the plane: its x and y).
#[test]
fn refined_corners_keep_their_vertices_uv() {
    let s = plane();
    let mut m = WorkMesh::default();
    for p in [(-8.0, -8.0), (8.0, -8.0), (8.0, 8.0), (-8.0, 8.0)] {
        m.add_vertex(DVec3::new(p.0, p.1, 0.0), DVec3::Z);
    }
    m.add_triangle([0, 1, 2], [at(-8.0, -8.0), at(8.0, -8.0), at(8.0, 8.0)]);
    m.add_triangle([0, 2, 3], [at(-8.0, -8.0), at(8.0, 8.0), at(-8.0, 8.0)]);
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 1.0, min_edge: 0.0, steps: 2, lift: Lift::NONE };
    m.refine(&s, &[], &c, 100_000);
    assert!(m.tris.len() > 500);
    for t in 0..m.tris.len() {
        for (k, &v) in m.tris[t].iter().enumerate() {
            let p = m.pos[v as usize];
            assert!(m.uv(t)[k].distance(at(p.x, p.y)) < 1e-12, "triangle {t} corner {k}");
        }
    }
}

/// A flat quad split along its long diagonal (a 5.7° sliver) is re-split
/// along its short one (smallest angle 22°): no triangle more. With the
/// short diagonal's ends two border nodes whose edge another face already
/// has, it stays.
#[test]
fn thin_pair_is_flipped_to_its_better_diagonal() {
    let quad = || {
        let mut m = WorkMesh::default();
        let pts = [(-4.0, 0.0), (1.0, -0.5), (4.0, 0.0), (1.0, 1.5)];
        for p in pts {
            m.add_vertex(DVec3::new(p.0, p.1, 0.0), DVec3::Z);
        }
        let w = |k: usize| at(pts[k].0, pts[k].1);
        m.add_triangle([0, 1, 2], [w(0), w(1), w(2)]);
        m.add_triangle([0, 2, 3], [w(0), w(2), w(3)]);
        m
    };
    let least = |m: &WorkMesh| {
        (0..m.tris.len())
            .map(|t| {
                let p = m.tris[t].map(|v| m.pos[v as usize]);
                (0..3)
                    .map(|k| crate::math::angle_between(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let s = plane();
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 10.0, min_edge: 0.0, steps: 2, lift: Lift::NONE };
    let mut m = quad();
    let before = least(&m);
    let changed = m.improve_angles(&s, &c, &mut crate::collections::HashSet::default());
    assert_eq!(changed, alloc::vec![0, 1]);
    assert_eq!(m.tris.len(), 2);
    assert!(m.tris.iter().all(|t| t.contains(&1) && t.contains(&3)), "{:?}", m.tris);
    assert!(least(&m) > 3.0 * before, "{} against {before}", least(&m));
    // Vertices 1 and 3 as border nodes 7 and 9, already joined elsewhere.
    let mut m = quad();
    m.gid[1] = 7;
    m.gid[3] = 9;
    let mut taken = crate::collections::HashSet::default();
    taken.insert((7, 9));
    assert!(m.improve_angles(&s, &c, &mut taken).is_empty());
    assert_eq!(m.tris[0], [0, 1, 2]);
}

/// Needles fanned from a ring of tiny edges to a far border (as around a
/// pole): the lift refines them by circumcentres and flips until the
/// thinnest triangle is far wider, keeps the border's edges as they were,
/// never folds a triangle, covers the same area, and stops at its budget.
#[cfg(feature = "std")]
#[test]
fn lift_mends_a_fan_of_needles_within_its_budget() {
    let fan = || {
        let mut m = WorkMesh::default();
        let ring = |r: f64, deg: f64| (r * deg.to_radians().cos(), r * deg.to_radians().sin());
        // The centre, 6 ring vertices 0.01 out, 12 border vertices 9 out.
        let mut pts = alloc::vec![(0.0, 0.0)];
        pts.extend((0..6).map(|k| ring(0.01, 60.0 * k as f64)));
        pts.extend((0..12).map(|j| ring(9.0, 30.0 * j as f64)));
        for p in &pts {
            m.add_vertex(DVec3::new(p.0, p.1, 0.0), DVec3::Z);
        }
        let (h, o) = (|k: u32| 1 + k % 6, |j: u32| 7 + j % 12);
        let w = |v: u32| at(pts[v as usize].0, pts[v as usize].1);
        for k in 0..6 {
            for v in [[0, h(k), h(k + 1)], [h(k), o(2 * k), o(2 * k + 1)], [h(k), o(2 * k + 1), h(k + 1)]] {
                m.add_triangle(v, v.map(w));
            }
            let v = [o(2 * k + 1), o(2 * k + 2), h(k + 1)];
            m.add_triangle(v, v.map(w));
        }
        m
    };
    let least = |m: &WorkMesh| (0..m.tris.len() as u32).map(|t| m.least_angle(t)).fold(f64::INFINITY, f64::min);
    let uv_area = |m: &WorkMesh, t: usize| {
        let w = m.uv(t);
        0.5 * (w[1] - w[0]).perp_dot(w[2] - w[0])
    };
    let s = plane();
    let lift = Lift { goal: 25f64.to_radians(), most: 600 };
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 100.0, min_edge: 0.0, steps: 2, lift };
    let mut m = fan();
    let n = m.tris.len();
    let (before, border, area) = (least(&m), m.boundary_edges(), (0..n).map(|t| uv_area(&m, t)).sum::<f64>());
    assert!(before < 0.1f64.to_radians());
    let changed = m.lift_angles(&s, &c);
    assert!(!changed.is_empty());
    assert!(m.tris.len() <= 600, "{}", m.tris.len());
    assert!(least(&m) > 10f64.to_radians(), "{}° from {}°", least(&m).to_degrees(), before.to_degrees());
    assert_eq!(m.boundary_edges(), border);
    assert!((0..m.tris.len()).all(|t| uv_area(&m, t) > 0.0 && !m.inverted(&s, t)));
    let after: f64 = (0..m.tris.len()).map(|t| uv_area(&m, t)).sum();
    assert!((after - area).abs() <= 1e-9 * area, "{after} against {area}");
    // A budget of 4 more triangles is kept.
    let mut m = fan();
    m.lift_angles(&s, &Criteria { lift: Lift { most: n + 4, ..lift }, ..c });
    assert!(m.tris.len() <= n + 4, "{}", m.tris.len());
}

/// An inner vertex whose point lies far from its (u,v) folds the fan
/// around it; collapsing it into a neighbour leaves two triangles fewer,
/// none folded, the tables in step. A border vertex is never collapsed.
#[test]
fn a_folded_fan_collapses_into_a_neighbour() {
    let s = plane();
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 10.0, min_edge: 0.0, steps: 2, lift: Lift::NONE };
    let mut m = grid();
    let x = 12; // (2, 2), inner
    m.pos[x] = DVec3::new(3.6, 2.4, 0.0);
    assert!(!m.folded(&s).is_empty(), "the displaced vertex folds nothing");
    let with = |m: &WorkMesh, v: u32| m.tris.iter().position(|t| t.contains(&v)).unwrap() as u32;
    assert!(m.try_collapse(&s, &c, with(&m, 0), 0).is_none(), "a border vertex was collapsed");
    let kept = m.try_collapse(&s, &c, with(&m, x as u32), x as u32).expect("no neighbour took the vertex");
    let mut changed = kept.clone();
    m.drop_dead(&mut changed);
    assert_eq!(m.tris.len(), 30);
    assert!(m.tris.iter().all(|t| !t.contains(&(x as u32))));
    assert!(m.folded(&s).is_empty(), "still folded: {:?}", m.folded(&s));
    assert!(changed.iter().all(|&t| (t as usize) < m.tris.len()));
    m.check_tables().unwrap();
    for t in 0..m.tris.len() {
        assert!(uv_area(m.uv(t)) > 0.0, "triangle {t} turned clockwise in (u,v)");
    }
}

/// A triangle folded against the surface on a border edge no longer than
/// the shortest edge refinement splits (a side collapsed to a hair, on the
/// far side of its pole) is left whole: splitting its long sides keeps the
/// hair and the fold. The same fold on a longer border edge is split.
#[cfg(feature = "std")]
#[test]
fn a_fold_on_a_hair_of_border_is_not_split() {
    let s = plane();
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: f64::INFINITY, min_edge: 1e-4, steps: 2, lift: Lift::NONE };
    for (edge, split) in [(0.5e-4, false), (1e-2, true)] {
        let mut m = WorkMesh::default();
        // Clockwise in (u,v) and in space: its facet faces -z on the plane.
        let q = [at(0.0, 0.0), at(0.0, edge), at(1.0, 0.5)];
        for p in q {
            m.add_vertex(DVec3::new(p.x, p.y, 0.0), DVec3::Z);
        }
        m.add_triangle([0, 1, 2], q);
        assert!(m.inverted(&s, 0), "the test triangle faces the surface's way");
        m.refine(&s, &[], &c, 1000);
        assert_eq!(m.tris.len() > 1, split, "border edge {edge}: {} triangles", m.tris.len());
    }
}

/// A needle folded against the surface whose two near corners lie within
/// the census's weld is no triangle of the welded mesh and is not counted;
/// the same needle with them farther apart is, and one facing the
/// surface's way never is.
#[test]
fn folds_count_only_triangles_the_weld_keeps() {
    let weld = 1e-3;
    // Corners 1 and 2 `gap` apart, 10 from corner 0; the facet faces -z.
    let needle = |gap: f64| [DVec3::ZERO, DVec3::new(10.0, 0.0, 0.0), DVec3::new(10.0, -gap, 0.0)];
    let up = [DVec3::Z];
    let tri = [[0, 1, 2]];
    assert_eq!(mend::count_folded(&needle(0.5 * weld), &tri, &up, weld, 1e-9), 0);
    assert_eq!(mend::count_folded(&needle(2.0 * weld), &tri, &up, weld, 1e-9), 1);
    assert_eq!(mend::count_folded(&needle(2.0 * weld), &tri, &[-DVec3::Z], weld, 1e-9), 0);
    // Flat within `negligible`: not counted however far apart.
    assert_eq!(mend::count_folded(&needle(2.0 * weld), &tri, &up, weld, 1e-2), 0);
}

/// A flat sheet folded over itself, `S(u,v) = (4v(1 − v), u, 0)`: out along
/// x to v = 1/2 and back, its normal −z before the fold and +z after.
fn pleat() -> crate::nurbs::NurbsSurface {
    let row = |y: f64| alloc::vec![DVec3::new(0.0, y, 0.0), DVec3::new(2.0, y, 0.0), DVec3::new(0.0, y, 0.0)];
    let points = [row(0.0), row(1.0)];
    crate::nurbs::NurbsSurface::try_new(
        [1, 2],
        alloc::vec![0.0, 0.0, 1.0, 1.0],
        alloc::vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        &points,
        None,
    )
    .unwrap()
}

/// A triangle across a fold of the surface lies along one of the sheets it
/// spans and is not counted as turned over, though its facet opposes the
/// normal at its (u,v) centroid; one turned over on one sheet still is.
#[test]
fn a_triangle_across_a_fold_is_judged_by_the_sheet_it_lies_along() {
    let s = pleat();
    let mut m = WorkMesh::default();
    let uvs = [at(0.0, 0.3), at(1.0, 0.3), at(0.5, 0.8), at(0.0, 0.1), at(1.0, 0.1), at(0.5, 0.4)];
    for w in uvs {
        m.add_vertex(s.point(w), s.normal(w));
    }
    m.add_triangle([0, 1, 2], [uvs[0], uvs[1], uvs[2]]);
    m.add_triangle([3, 5, 4], [uvs[3], uvs[5], uvs[4]]);
    let centroid: Vec<DVec3> = (0..2).map(|t| m.centroid_normal(&s, t)).collect();
    let judged: Vec<DVec3> = (0..2).map(|t| m.judged_normal(&s, t)).collect();
    assert_eq!(mend::count_folded(&m.pos, &m.tris, &centroid, 1e-9, 1e-9), 2);
    assert_eq!(mend::count_folded(&m.pos, &m.tris[1..], &judged[1..], 1e-9, 1e-9), 1, "turned over on one sheet");
    assert_eq!(mend::count_folded(&m.pos, &m.tris, &judged, 1e-9, 1e-9), 1);
}

/// A strip 10 long whose cross-section, straight in u, curls by 60°
/// within `r` at its v = 1 edge: a fillet far narrower than the tolerance.
fn curled_strip(r: f64) -> crate::nurbs::NurbsSurface {
    let section = [(0.0, 0.0), (1.0 - r, 0.0), (1.0, 0.0), (1.0 + 0.5 * r, 0.75_f64.sqrt() * r)];
    let row = |x: f64| section.iter().map(|&(y, z)| DVec3::new(x, y, z)).collect::<Vec<_>>();
    let points = [row(0.0), row(10.0)];
    // The curl is the last span, from the middle of the two control points at (1 - r, 0) and (1, 0).
    crate::nurbs::NurbsSurface::try_new(
        [1, 2],
        [0.0, 0.0, 1.0, 1.0].into(),
        [0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0].into(),
        &points,
        None,
    )
    .expect("valid strip")
}

/// A long triangle across a curl narrower than a tenth of the tolerance,
/// its longest edge along the curl, turns past the angle limit however
/// short it is split along it: refinement leaves it as it is (creased),
/// instead of chopping it into slivers a hundred times shorter, whose
/// split points, off the chord by the strip's sag, fold over the next row.
#[test]
fn a_long_triangle_across_a_narrow_curl_is_creased() {
    let uv = [at(0.0, 0.5), at(1.0, 0.5), at(0.5, 1.0)];
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: f64::INFINITY, min_edge: 0.0, steps: 2, lift: Lift::NONE };
    let refined = |r: f64| {
        let s = curled_strip(r);
        let mut m = WorkMesh::default();
        for q in uv {
            m.add_vertex(s.point(q), s.normal(q));
        }
        m.add_triangle([0, 1, 2], uv);
        let out = m.refine(&s, &[], &c, 100_000);
        (m.tris.len(), out)
    };
    let (n, out) = refined(0.005);
    assert!(out.max_turn > 1.0, "the curl turns by {}", out.max_turn);
    assert!(out.max <= c.tol, "deviation {}", out.max);
    assert_eq!(n, 1, "split into {n} triangles");
    assert_eq!((out.creased, out.unproven), (1, 0));
    // A curl as wide as the tolerance is split for its turn as before.
    let (n, _) = refined(0.5);
    assert!(n > 20, "{n} triangles");
}

/// A flat sheet whose u-lines are parabolas `y = x²/2` for x in ±0.2 (sag
/// 0.02 over their chord of 0.4) and whose v-lines are straight up `y`,
/// `height` long: a plane parameterized so that its rows bend within it.
fn bent_rows(height: f64) -> crate::nurbs::NurbsSurface {
    let (w, a) = (0.2, 0.5);
    let row = |x: f64, y: f64| alloc::vec![DVec3::new(x, y, 0.0), DVec3::new(x, y + height, 0.0)];
    let points = [row(-w, a * w * w), row(0.0, -a * w * w), row(w, a * w * w)];
    crate::nurbs::NurbsSurface::try_new(
        [2, 1],
        alloc::vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        alloc::vec![0.0, 0.0, 1.0, 1.0],
        &points,
        None,
    )
    .unwrap()
}

/// A column of thin cells, each split on its diagonal for the edge limit:
/// the diagonal's middle lies half a row (0.01) from the cell's lower side,
/// whose chord sags 0.02 sideways, so the triangle between them folds
/// though every corner lies on the surface and it is within all limits.
/// More such folds arise than the ration of fold splits (16 when the
/// first mesh has none); each is split all the same, none is left folded,
/// and the halves of their long sides are enough.
#[test]
fn slivers_folded_by_their_shape_are_split() {
    let rows = 24;
    let s = bent_rows(0.02 * rows as f64);
    let mut m = WorkMesh::default();
    let w = |i: usize, j: usize| at(i as f64, j as f64 / rows as f64);
    for j in 0..=rows {
        for i in 0..2 {
            m.add_vertex(s.point(w(i, j)), s.normal(w(i, j)));
        }
    }
    let v = |i: usize, j: usize| (2 * j + i) as u32;
    for j in 0..rows {
        m.add_triangle([v(0, j), v(1, j), v(1, j + 1)], [w(0, j), w(1, j), w(1, j + 1)]);
        m.add_triangle([v(0, j), v(1, j + 1), v(0, j + 1)], [w(0, j), w(1, j + 1), w(0, j + 1)]);
    }
    assert!(m.folded(&s).is_empty(), "the cells fold before refinement");
    // Between a cell's side (0.4) and its diagonal.
    let side = m.pos[1].distance(m.pos[0]);
    let diagonal = m.pos[3].distance(m.pos[0]);
    let c =
        Criteria { tol: 0.1, angle: 0.5, max_edge: 0.5 * (side + diagonal), min_edge: 0.0, steps: 2, lift: Lift::NONE };
    m.refine(&s, &[], &c, 100_000);
    assert!(m.folded(&s).is_empty(), "{} triangles still folded", m.folded(&s).len());
    assert!(m.tris.len() <= 8 * rows, "{} triangles", m.tris.len());
}

/// A face whose border curve bulges into it past an inner vertex (one
/// split in on an inner edge between the chord and the curve, outside the
/// face), on a sheet whose rows bend so that the triangle on the chord
/// folds: the chord's split at the curve's middle would fold a child in
/// (u,v), so the vertex moves to the centre of its neighbours first. The
/// chord, longer than the edge limit, is split, and nothing stays folded.
#[test]
fn an_inner_vertex_beyond_its_border_curve_moves_in_for_the_split() {
    let s = bent_rows(0.4);
    // A and B on the border, X beyond its curve, then R, C and L.
    let uv = [at(0.0, 0.0), at(1.0, 0.0), at(0.5, 0.03), at(1.0, 0.5), at(0.5, 1.0), at(0.0, 0.5)];
    let mut m = WorkMesh::default();
    for q in uv {
        m.add_vertex(s.point(q), s.normal(q));
    }
    for t in [[0, 1, 2], [1, 3, 2], [3, 4, 2], [4, 5, 2], [5, 0, 2]] {
        m.add_triangle(t, t.map(|v| uv[v as usize]));
    }
    let curve = |degree: usize, points: &[DVec2]| {
        let knots = [alloc::vec![0.0; degree + 1], alloc::vec![1.0; degree + 1]].concat();
        NurbsCurve::try_new(degree, knots, points.iter().map(|q| q.extend(0.0)).collect(), None).unwrap()
    };
    let mut curves = alloc::vec![curve(2, &[uv[0], at(0.5, 0.2), uv[1]])];
    for (k, (a, b)) in [(1, 3), (3, 4), (4, 5), (5, 0)].into_iter().enumerate() {
        curves.push(curve(1, &[uv[a as usize], uv[b as usize]]));
        m.mark_trim(a, b, k as u32 + 1, 0.0, 1.0);
    }
    m.mark_trim(0, 1, 0, 0.0, 1.0);
    assert_eq!(m.folded(&s), [0], "the triangle on the chord folds");
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 0.3, min_edge: 0.0, steps: 2, lift: Lift::NONE };
    let curves: Vec<&NurbsCurve> = curves.iter().collect();
    let out = m.refine(&s, &curves, &c, 10_000);
    assert_eq!(out.unproven, 0, "edges left over the limit");
    assert!(m.folded(&s).is_empty(), "{} triangles still folded", m.folded(&s).len());
    assert_eq!(m.check_invariants(), Ok(()));
}

/// Measures a trial mesh took serve the model's mesh of the same face and
/// criteria: refined from the same first mesh, it ends the same, bit for
/// bit, measuring only the triangles the trial did not measure (here
/// none: its evaluations fall to the new vertices and the fold checks), and
/// a carried measure over the limits still fails its triangle.
#[test]
fn carried_measures_stand_in_for_measuring() {
    let p = plane();
    let s = Counted::new(&p);
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 0.6, min_edge: 0.0, steps: 4, lift: Lift::NONE };
    let mut trial = grid();
    trial.log_measures();
    let want = trial.refine(&s, &[], &c, 100_000);
    let (mut fresh, mut carried) = (grid(), grid());
    carried.carried = trial.measured();
    assert!(carried.carried.len() > trial.tris.len(), "the split triangles' measures are carried too");
    let calls = [&mut fresh, &mut carried].map(|m| {
        s.reset();
        let got = m.refine(&s, &[], &c, 100_000);
        assert_eq!(m.tris, trial.tris);
        assert_eq!((got.max.to_bits(), got.sum.to_bits(), got.unproven), (want.max.to_bits(), want.sum.to_bits(), 0));
        s.total()
    });
    // What is left is placing the new vertices and checking for folds.
    assert!(calls[0] > 12 * trial.tris.len(), "{calls:?}");
    assert!(4 * calls[1] < calls[0], "{calls:?}");
    // A triangle whose carried measure is over the tolerance is split as if measured.
    let mut over = grid();
    let big = limits::Packed::pack(TriMeasure { max: 1.0, sum: 1.0 }, 0.0);
    over.carried = (0..over.tris.len()).map(|t| (over.measure_key(t), big)).collect();
    over.refine(&s, &[], &Criteria { max_edge: f64::INFINITY, ..c }, 100_000);
    assert!(over.tris.len() > grid().tris.len(), "{} triangles", over.tris.len());
}

/// A changed triangle turned over in (u,v) fails the mending checks on its
/// orientation alone: nothing is measured against the surface for it (a
/// fuzzed face folded all over spent most of its time measuring such
/// candidates before their orientation ruled them out).
#[test]
fn a_triangle_turned_over_is_ruled_out_before_it_is_measured() {
    let s = plane();
    let counted = Counted::new(&s);
    let m = grid();
    let c = Criteria { tol: 0.1, angle: 0.5, max_edge: 100.0, min_edge: 0.0, steps: 2, lift: Lift::default() };
    // Triangle 0 runs counter-clockwise in (u,v): the opposite sense rules it out.
    assert!(!m.holds(&counted, &c, 0, -1.0));
    assert_eq!(counted.total(), 0, "{} evaluations", counted.total());
    assert!(m.holds(&counted, &c, 0, 1.0), "the right way round it holds");
    assert!(counted.total() > 0, "and is measured");
}
