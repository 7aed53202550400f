//! A small constrained Delaunay triangulation of one triangle with points on
//! its edges, points inside and constraint segments between them (paper 002
//! §4.2 sub-triangulation). Written for the few to few hundred points one
//! intersected triangle carries: points are inserted one by one with
//! brute-force location, constraints are recovered by edge flips (Sloan), and
//! Lawson flips make the result Delaunay away from the constraints. Every
//! orientation test is exact ([`orient2d`]), so the triangulation of the given
//! 2-D points is always valid or the call fails; it never makes a triangle of
//! zero or negative area.

use alloc::vec::Vec;
use core::cmp::Ordering;
use glam::DVec2;

use super::topology::NONE;
use crate::predicates::orient2d;

/// Why a sub-triangulation failed (the 2-D picture after rounding contradicts
/// the exact topology: a point outside, two points on one spot, crossing
/// constraints).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Conflict {
    /// A point could not be placed strictly inside.
    Outside,
    /// Two points coincide.
    Duplicate,
    /// A constraint crosses another, or passes through a point.
    Crossing,
}

/// The triangulation: triangles of local point indices (counter-clockwise),
/// neighbours (`3 * triangle + edge`, [`NONE`] on the outer boundary), and
/// which edges are constraints.
#[derive(Debug, Clone, Default)]
pub(crate) struct Cdt {
    pub tris: Vec<[u32; 3]>,
    pub nbr: Vec<[u32; 3]>,
    pub fixed: Vec<[bool; 3]>,
}

impl Cdt {
    fn link(&mut self, u: u32, v: u32) {
        if u != NONE {
            self.nbr[(u / 3) as usize][(u % 3) as usize] = v;
        }
        if v != NONE {
            self.nbr[(v / 3) as usize][(v % 3) as usize] = u;
        }
    }

    /// Rotates triangle `t` so that its edge `k` becomes edge 0.
    fn rotate(&mut self, t: usize, k: usize) {
        if k == 0 {
            return;
        }
        let (v, n, f) = (self.tris[t], self.nbr[t], self.fixed[t]);
        for i in 0..3 {
            self.tris[t][i] = v[(i + k) % 3];
            self.fixed[t][i] = f[(i + k) % 3];
            let u = n[(i + k) % 3];
            self.nbr[t][i] = u;
            if u != NONE {
                self.nbr[(u / 3) as usize][(u % 3) as usize] = 3 * t as u32 + i as u32;
            }
        }
    }

    /// Splits triangle `t` on its edge 0 (which must be on the outer boundary) at point `p`.
    fn split_boundary(&mut self, t: usize, p: u32, pts: &[DVec2]) -> Result<(), Conflict> {
        let [u, w, x] = self.tris[t];
        if orient2d(pts[u as usize], pts[p as usize], pts[x as usize]) != Ordering::Greater
            || orient2d(pts[p as usize], pts[w as usize], pts[x as usize]) != Ordering::Greater
        {
            return Err(Conflict::Outside);
        }
        let (n1, n2) = (self.nbr[t][1], self.nbr[t][2]);
        let (f1, f2) = (self.fixed[t][1], self.fixed[t][2]);
        let s = self.tris.len();
        self.tris[t] = [u, p, x];
        self.tris.push([p, w, x]);
        self.nbr.push([NONE; 3]);
        self.fixed[t] = [false, false, f2];
        self.fixed.push([false, f1, false]);
        self.nbr[t][0] = NONE;
        self.link(3 * t as u32 + 2, n2);
        self.link(3 * s as u32 + 1, n1);
        self.link(3 * t as u32 + 1, 3 * s as u32 + 2);
        Ok(())
    }

    /// Splits triangle `t` into three at a point strictly inside it.
    fn split_inside(&mut self, t: usize, p: u32) {
        let [a, b, c] = self.tris[t];
        let n = self.nbr[t];
        let f = self.fixed[t];
        let (s1, s2) = (self.tris.len(), self.tris.len() + 1);
        self.tris[t] = [a, b, p];
        self.tris.push([b, c, p]);
        self.tris.push([c, a, p]);
        self.nbr.push([NONE; 3]);
        self.nbr.push([NONE; 3]);
        self.fixed[t] = [f[0], false, false];
        self.fixed.push([f[1], false, false]);
        self.fixed.push([f[2], false, false]);
        let (t3, s13, s23) = (3 * t as u32, 3 * s1 as u32, 3 * s2 as u32);
        self.link(t3, n[0]);
        self.link(s13, n[1]);
        self.link(s23, n[2]);
        self.link(t3 + 1, s13 + 2);
        self.link(s13 + 1, s23 + 2);
        self.link(s23 + 1, t3 + 2);
    }

    /// Splits the interior edge 0 of `t` (shared with its neighbour) at `p`.
    fn split_edge(&mut self, t: usize, p: u32) {
        let twin = self.nbr[t][0];
        let (t2, k2) = ((twin / 3) as usize, (twin % 3) as usize);
        self.rotate(t2, k2);
        // t = [a, b, c], t2 = [b, a, d].
        let [a, b, c] = self.tris[t];
        let d = self.tris[t2][2];
        let (tn, t2n) = (self.nbr[t], self.nbr[t2]);
        let (tf, t2f) = (self.fixed[t], self.fixed[t2]);
        let (s, s2) = (self.tris.len(), self.tris.len() + 1);
        // t: [a, p, c], s: [p, b, c], t2: [b, p, d], s2: [p, a, d].
        self.tris[t] = [a, p, c];
        self.tris.push([p, b, c]);
        self.tris[t2] = [b, p, d];
        self.tris.push([p, a, d]);
        self.nbr.push([NONE; 3]);
        self.nbr.push([NONE; 3]);
        self.fixed[t] = [tf[0], false, tf[2]];
        self.fixed.push([tf[0], tf[1], false]);
        self.fixed[t2] = [t2f[0], false, t2f[2]];
        self.fixed.push([t2f[0], t2f[1], false]);
        let (t3, s3, u3, s23) = (3 * t as u32, 3 * s as u32, 3 * t2 as u32, 3 * s2 as u32);
        self.link(t3 + 2, tn[2]);
        self.link(s3 + 1, tn[1]);
        self.link(u3 + 2, t2n[2]);
        self.link(s23 + 1, t2n[1]);
        self.link(t3 + 1, s3 + 2);
        self.link(u3 + 1, s23 + 2);
        // a-p (t edge 0) with p-a (s2 edge 0); p-b (s edge 0) with b-p (t2 edge 0).
        self.link(t3, s23);
        self.link(s3, u3);
    }

    /// Flips edge `k` of `t` if the quadrilateral around it is strictly
    /// convex; returns the two triangles, whose shared edge is now edge 2 of both.
    fn flip(&mut self, t: usize, k: usize, pts: &[DVec2]) -> Option<(usize, usize)> {
        let twin = self.nbr[t][k];
        if twin == NONE || self.fixed[t][k] {
            return None;
        }
        self.rotate(t, k);
        let (t2, k2) = (((self.nbr[t][0]) / 3) as usize, (self.nbr[t][0] % 3) as usize);
        self.rotate(t2, k2);
        let [a, b, c] = self.tris[t];
        let d = self.tris[t2][2];
        let p = |i: u32| pts[i as usize];
        if orient2d(p(c), p(a), p(d)) != Ordering::Greater || orient2d(p(d), p(b), p(c)) != Ordering::Greater {
            return None;
        }
        let (n1, n2) = (self.nbr[t][1], self.nbr[t][2]);
        let (m1, m2) = (self.nbr[t2][1], self.nbr[t2][2]);
        let (f1, f2) = (self.fixed[t][1], self.fixed[t][2]);
        let (g1, g2) = (self.fixed[t2][1], self.fixed[t2][2]);
        self.tris[t] = [c, a, d];
        self.tris[t2] = [d, b, c];
        self.fixed[t] = [f2, g1, false];
        self.fixed[t2] = [g2, f1, false];
        let (tt, uu) = (3 * t as u32, 3 * t2 as u32);
        self.link(tt, n2);
        self.link(tt + 1, m1);
        self.link(uu, m2);
        self.link(uu + 1, n1);
        self.link(tt + 2, uu + 2);
        Some((t, t2))
    }

    /// The triangle and edge running `u -> v`, if that edge exists.
    fn find_edge(&self, u: u32, v: u32) -> Option<(usize, usize)> {
        self.tris
            .iter()
            .enumerate()
            .find_map(|(t, x)| (0..3).find(|&k| x[k] == u && x[(k + 1) % 3] == v).map(|k| (t, k)))
    }
}

/// Triangulates a triangle whose corners are points 0, 1, 2 (counter-clockwise
/// in `pts`), with `on_edge[k]` the points on edge k (corner k to corner k+1)
/// in order, `inside` points strictly inside, and `constraints` to appear as
/// edges. Points must be distinct.
///
/// # Errors
/// A [`Conflict`] when the rounded 2-D positions cannot carry the topology.
pub(crate) fn triangulate(
    pts: &[DVec2],
    on_edge: &[Vec<u32>; 3],
    inside: &[u32],
    constraints: &[[u32; 2]],
) -> Result<Cdt, Conflict> {
    let mut cdt = Cdt { tris: alloc::vec![[0, 1, 2]], nbr: alloc::vec![[NONE; 3]], fixed: alloc::vec![[false; 3]] };
    if orient2d(pts[0], pts[1], pts[2]) != Ordering::Greater {
        return Err(Conflict::Outside);
    }
    for k in 0..3 {
        let mut prev = k as u32;
        let end = ((k + 1) % 3) as u32;
        for &p in &on_edge[k] {
            let (t, e) = cdt.find_edge(prev, end).ok_or(Conflict::Outside)?;
            if cdt.nbr[t][e] != NONE {
                return Err(Conflict::Outside);
            }
            cdt.rotate(t, e);
            cdt.split_boundary(t, p, pts)?;
            prev = p;
        }
    }
    for &p in inside {
        insert_inside(&mut cdt, pts, p)?;
    }
    for &[u, v] in constraints {
        insert_constraint(&mut cdt, pts, u, v)?;
    }
    make_delaunay(&mut cdt, pts);
    Ok(cdt)
}

fn insert_inside(cdt: &mut Cdt, pts: &[DVec2], p: u32) -> Result<(), Conflict> {
    let q = pts[p as usize];
    for t in 0..cdt.tris.len() {
        let [a, b, c] = cdt.tris[t].map(|i| pts[i as usize]);
        let o = [orient2d(a, b, q), orient2d(b, c, q), orient2d(c, a, q)];
        if o.contains(&Ordering::Less) {
            continue;
        }
        let zeros: Vec<usize> = (0..3).filter(|&k| o[k] == Ordering::Equal).collect();
        match zeros.len() {
            0 => cdt.split_inside(t, p),
            1 => {
                if cdt.nbr[t][zeros[0]] == NONE {
                    return Err(Conflict::Outside);
                }
                if cdt.fixed[t][zeros[0]] {
                    return Err(Conflict::Crossing);
                }
                cdt.rotate(t, zeros[0]);
                cdt.split_edge(t, p);
            }
            _ => return Err(Conflict::Duplicate),
        }
        return Ok(());
    }
    Err(Conflict::Outside)
}

/// Whether the open segments `a b` and `c d` cross at one interior point.
fn crosses(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (o1, o2) = (orient2d(a, b, c), orient2d(a, b, d));
    let (o3, o4) = (orient2d(c, d, a), orient2d(c, d, b));
    o1 != Ordering::Equal
        && o2 != Ordering::Equal
        && o1 != o2
        && o3 != Ordering::Equal
        && o4 != Ordering::Equal
        && o3 != o4
}

fn insert_constraint(cdt: &mut Cdt, pts: &[DVec2], u: u32, v: u32) -> Result<(), Conflict> {
    let (pu, pv) = (pts[u as usize], pts[v as usize]);
    // A point on the open segment would split it: not ours to decide.
    for (i, &p) in pts.iter().enumerate() {
        let i = i as u32;
        if i != u
            && i != v
            && orient2d(pu, pv, p) == Ordering::Equal
            && (p - pu).dot(pv - pu) > 0.0
            && (p - pv).dot(pu - pv) > 0.0
        {
            return Err(Conflict::Crossing);
        }
    }
    // Sloan (1993): a queue of the edges crossing u-v; a crossed edge whose
    // quadrilateral is convex is flipped, and goes back in the queue if the new
    // edge still crosses; one that is not convex waits its turn again.
    let mut queue: alloc::collections::VecDeque<(u32, u32)> = alloc::collections::VecDeque::new();
    for t in 0..cdt.tris.len() {
        for k in 0..3 {
            let (a, b) = (cdt.tris[t][k], cdt.tris[t][(k + 1) % 3]);
            if a < b && crosses(pu, pv, pts[a as usize], pts[b as usize]) {
                if cdt.fixed[t][k] || cdt.nbr[t][k] == NONE {
                    return Err(Conflict::Crossing);
                }
                queue.push_back((a, b));
            }
        }
    }
    let mut budget = 64 + 4 * queue.len() * queue.len();
    let mut waited = 0usize;
    while let Some((a, b)) = queue.pop_front() {
        if budget == 0 || waited > queue.len() + 1 {
            return Err(Conflict::Crossing);
        }
        budget -= 1;
        let Some((t, k)) = cdt.find_edge(a, b) else { return Err(Conflict::Crossing) };
        match cdt.flip(t, k, pts) {
            None => {
                waited += 1;
                queue.push_back((a, b));
            }
            Some((t, _)) => {
                waited = 0;
                // The new edge is edge 2 of `t`.
                let (c, d) = (cdt.tris[t][2], cdt.tris[t][0]);
                if crosses(pu, pv, pts[c as usize], pts[d as usize]) {
                    queue.push_back((c, d));
                }
            }
        }
    }
    match cdt.find_edge(u, v).or_else(|| cdt.find_edge(v, u)) {
        Some((t, k)) => {
            cdt.fixed[t][k] = true;
            let twin = cdt.nbr[t][k];
            if twin != NONE {
                cdt.fixed[(twin / 3) as usize][(twin % 3) as usize] = true;
            }
            Ok(())
        }
        None => Err(Conflict::Crossing),
    }
}

/// Float in-circle test with a relative margin, so that nearly co-circular
/// quadrilaterals are left alone (no flip cycles).
fn in_circle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let (al, bl, cl) = (ad.length_squared(), bd.length_squared(), cd.length_squared());
    let det = al * (bd.x * cd.y - cd.x * bd.y) + bl * (cd.x * ad.y - ad.x * cd.y) + cl * (ad.x * bd.y - bd.x * ad.y);
    let scale = al * (bd.x * cd.y).abs().max((cd.x * bd.y).abs())
        + bl * (cd.x * ad.y).abs().max((ad.x * cd.y).abs())
        + cl * (ad.x * bd.y).abs().max((bd.x * ad.y).abs());
    det > 1e-12 * scale
}

fn make_delaunay(cdt: &mut Cdt, pts: &[DVec2]) {
    let passes = 8 + cdt.tris.len();
    for _ in 0..passes {
        let mut changed = false;
        for t in 0..cdt.tris.len() {
            for k in 0..3 {
                let twin = cdt.nbr[t][k];
                if twin == NONE || cdt.fixed[t][k] {
                    continue;
                }
                let (t2, k2) = ((twin / 3) as usize, (twin % 3) as usize);
                let [a, b, c] = [cdt.tris[t][k], cdt.tris[t][(k + 1) % 3], cdt.tris[t][(k + 2) % 3]];
                let d = cdt.tris[t2][(k2 + 2) % 3];
                let p = |i: u32| pts[i as usize];
                if in_circle(p(a), p(b), p(c), p(d)) && cdt.flip(t, k, pts).is_some() {
                    changed = true;
                }
            }
        }
        if !changed {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(cdt: &Cdt, pts: &[DVec2], constraints: &[[u32; 2]]) {
        let mut area = 0.0;
        for (t, x) in cdt.tris.iter().enumerate() {
            let [a, b, c] = x.map(|i| pts[i as usize]);
            assert_eq!(orient2d(a, b, c), Ordering::Greater, "triangle {t} {x:?} not counter-clockwise");
            area += (b - a).perp_dot(c - a) * 0.5;
            for k in 0..3 {
                let u = cdt.nbr[t][k];
                if u != NONE {
                    let (t2, k2) = ((u / 3) as usize, (u % 3) as usize);
                    assert_eq!(cdt.nbr[t2][k2], 3 * t as u32 + k as u32);
                    assert_eq!(cdt.tris[t2][k2], x[(k + 1) % 3]);
                    assert_eq!(cdt.tris[t2][(k2 + 1) % 3], x[k]);
                    assert_eq!(cdt.fixed[t2][k2], cdt.fixed[t][k]);
                }
            }
        }
        let whole = (pts[1] - pts[0]).perp_dot(pts[2] - pts[0]) * 0.5;
        assert!((area - whole).abs() < 1e-12 * whole.abs().max(1.0), "area {area} vs {whole}");
        for &[u, v] in constraints {
            assert!(cdt.find_edge(u, v).or_else(|| cdt.find_edge(v, u)).is_some(), "constraint {u}-{v} missing");
        }
        // Every point is used.
        for i in 0..pts.len() as u32 {
            assert!(cdt.tris.iter().any(|x| x.contains(&i)), "point {i} unused");
        }
    }

    #[test]
    fn a_triangle_cut_by_a_chain_keeps_the_chain() {
        let pts = alloc::vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(0.0, 10.0),
            DVec2::new(3.0, 0.0), // 3 on edge 0
            DVec2::new(7.0, 0.0), // 4 on edge 0
            DVec2::new(5.0, 5.0), // 5 on edge 1
            DVec2::new(0.0, 4.0), // 6 on edge 2
            DVec2::new(2.0, 2.0), // 7 inside
            DVec2::new(4.0, 3.0), // 8 inside
        ];
        let on_edge = [alloc::vec![3, 4], alloc::vec![5], alloc::vec![6]];
        let constraints = [[3, 7], [7, 8], [8, 5], [6, 8], [4, 8]];
        let cdt = triangulate(&pts, &on_edge, &[7, 8], &constraints).unwrap();
        check(&cdt, &pts, &constraints);
        // Euler: 2 V - (boundary points) - 2 triangles.
        assert_eq!(cdt.tris.len(), 2 * pts.len() - 7 - 2);
    }

    #[test]
    fn long_constraints_through_many_points_are_recovered_by_flips() {
        // A fan of points inside; a constraint from edge 0 to edge 1 crosses the fan's edges.
        let mut pts = alloc::vec![DVec2::new(0.0, 0.0), DVec2::new(100.0, 0.0), DVec2::new(0.0, 100.0)];
        let mut inside = Vec::new();
        for i in 0..12 {
            for j in 0..12 - i {
                let p = DVec2::new(3.0 + 7.0 * i as f64 + 0.31 * j as f64, 3.0 + 7.0 * j as f64 + 0.17 * i as f64);
                if p.x + p.y < 95.0 {
                    inside.push(pts.len() as u32);
                    pts.push(p);
                }
            }
        }
        let a = pts.len() as u32;
        pts.push(DVec2::new(1.5, 0.0));
        let b = pts.len() as u32;
        pts.push(DVec2::new(49.0, 51.0));
        let on_edge = [alloc::vec![a], alloc::vec![b], Vec::new()];
        let cdt = triangulate(&pts, &on_edge, &inside, &[[a, b]]).unwrap();
        check(&cdt, &pts, &[[a, b]]);
    }

    #[test]
    fn crossing_constraints_and_duplicate_points_are_refused() {
        let pts = alloc::vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(0.0, 10.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(2.0, 4.0),
            DVec2::new(4.0, 2.0),
            DVec2::new(2.0, 2.0),
        ];
        assert_eq!(
            triangulate(&pts[..7], &[Vec::new(), Vec::new(), Vec::new()], &[3, 4, 5, 6], &[[3, 4], [5, 6]])
                .unwrap_err(),
            Conflict::Crossing
        );
        assert_eq!(
            triangulate(&pts, &[Vec::new(), Vec::new(), Vec::new()], &[3, 7], &[]).unwrap_err(),
            Conflict::Duplicate
        );
        // A point on a constraint's open segment.
        let on = [
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(0.0, 10.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(3.0, 3.0),
        ];
        assert_eq!(
            triangulate(&on, &[Vec::new(), Vec::new(), Vec::new()], &[3, 4, 5], &[[3, 5]]).unwrap_err(),
            Conflict::Crossing
        );
    }
}
