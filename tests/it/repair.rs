//! Mesh repair (paper 002): offsets of meshed shapes that self-intersect come
//! out as closed, consistently oriented 2-manifolds without self-intersections
//! (checked here by a brute-force test written independently of the library's,
//! and by the library's exact BVH search); bad input gets clear errors.

use std::path::Path;

use glam::DVec3;
use surfmesh::{
    find_self_intersections, mesh_model, offset_mesh, read_iges, read_json, read_mesh, repair_mesh, weld_mesh,
    write_obj, write_stl, Bucketing, Error, Mesh, MeshFormat, MeshOptions, RepairOptions, RepairResult, WarningKind,
};

fn data(name: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)).unwrap()
}

/// A model from `tests/data` meshed at a relative tolerance, welded into one closed mesh.
fn meshed(name: &str, rel: f64) -> Mesh {
    let model = read_json(&data(name)).unwrap();
    let r = mesh_model(&model, &MeshOptions::default().with_relative_tolerance(rel)).unwrap();
    let diag = bbox_diagonal(&r.mesh);
    let mut m = weld_mesh(&r.mesh, 1e-9 * diag);
    drop_collapsed(&mut m);
    m
}

fn drop_collapsed(m: &mut Mesh) {
    let keep: Vec<u32> =
        m.indices.chunks(3).filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0]).flatten().copied().collect();
    m.indices = keep;
}

fn bbox_diagonal(m: &Mesh) -> f64 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in &m.positions {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (hi - lo).length()
}

fn scaled(mut m: Mesh, s: DVec3) -> Mesh {
    for p in &mut m.positions {
        *p *= s;
    }
    m
}

// ------------------------------------------------------------ independent checks

/// Edge census by vertex index: (free, non-manifold, same-direction pairs).
fn census(m: &Mesh) -> (usize, usize, usize) {
    let mut uses: std::collections::HashMap<(u32, u32), (u32, u32)> = std::collections::HashMap::new();
    for t in m.indices.chunks(3) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = uses.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                e.0 += 1
            } else {
                e.1 += 1
            }
        }
    }
    let free = uses.values().filter(|(f, r)| f + r == 1).count();
    let nonmanifold = uses.values().filter(|(f, r)| f + r > 2).count();
    let flipped = uses.values().filter(|(f, r)| f + r == 2 && *f != 1).count();
    (free, nonmanifold, flipped)
}

fn volume(m: &Mesh) -> f64 {
    m.indices
        .chunks(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let c3 = |p: DVec3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Exact 2-D orientation of points given as (x, y).
fn orient2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let c2 = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
    robust::orient2d(c2(a), c2(b), c2(c))
}

/// Whether segment `p q` crosses the interior of triangle `t` at one point
/// strictly inside both (exact signs from the `robust` crate: an independent
/// implementation of the predicates, not the library's).
fn segment_crosses_triangle(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let (sp, sq) = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
    if !(sp > 0.0 && sq < 0.0 || sp < 0.0 && sq > 0.0) {
        return false;
    }
    let s = [orient(p, q, t[0], t[1]), orient(p, q, t[1], t[2]), orient(p, q, t[2], t[0])];
    s.iter().all(|&x| x > 0.0) || s.iter().all(|&x| x < 0.0)
}

/// The triangle's corners with the coordinate along its normal's largest
/// component dropped (exact: no arithmetic on the coordinates).
fn drop_axis(t: [DVec3; 3], p: &[DVec3]) -> Vec<[f64; 2]> {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).abs();
    let keep = if n.x >= n.y && n.x >= n.z {
        [1, 2]
    } else if n.y >= n.z {
        [2, 0]
    } else {
        [0, 1]
    };
    p.iter().map(|q| [q[keep[0]], q[keep[1]]]).collect()
}

/// Whether 2-D point `p` is strictly inside triangle `t` (either orientation).
fn strictly_inside2(p: [f64; 2], t: &[[f64; 2]]) -> bool {
    let s = [orient2(t[0], t[1], p), orient2(t[1], t[2], p), orient2(t[2], t[0], p)];
    s.iter().all(|&x| x > 0.0) || s.iter().all(|&x| x < 0.0)
}

/// Whether triangles `a` and `b` (vertex indices) of `m` meet anywhere but
/// along what they share. Triangles sharing an edge are taken as neighbours.
/// Counted: an edge of one through the interior of the other; a vertex of one
/// on the other's plane strictly inside it (touching); coplanar triangles
/// whose edges cross or that hold a vertex of the other strictly inside.
/// Exact signs throughout; nothing here comes from the library.
fn triangles_meet(m: &Mesh, a: [u32; 3], b: [u32; 3]) -> bool {
    let shared: Vec<u32> = a.iter().copied().filter(|v| b.contains(v)).collect();
    if shared.len() >= 2 {
        return false;
    }
    let pos = |i: u32| m.positions[i as usize];
    let (pa, pb) = (a.map(pos), b.map(pos));
    let free_edge = |t: [u32; 3], k: usize| !shared.contains(&t[k]) && !shared.contains(&t[(k + 1) % 3]);
    let sb = pb.map(|q| orient(pa[0], pa[1], pa[2], q));
    let sa = pa.map(|q| orient(pb[0], pb[1], pb[2], q));
    if sb.iter().all(|&x| x == 0.0) {
        // Coplanar: in the plane, by dropping one coordinate.
        if (pa[1] - pa[0]).cross(pa[2] - pa[0]) == DVec3::ZERO {
            return false;
        }
        let (fa, fb) = (drop_axis(pa, &pa), drop_axis(pa, &pb));
        for i in 0..3 {
            for j in 0..3 {
                if !free_edge(a, i) || !free_edge(b, j) {
                    continue;
                }
                let (p, q, r, s) = (fa[i], fa[(i + 1) % 3], fb[j], fb[(j + 1) % 3]);
                let (o1, o2) = (orient2(p, q, r), orient2(p, q, s));
                let (o3, o4) = (orient2(r, s, p), orient2(r, s, q));
                if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
                    return true;
                }
            }
        }
        let inside_a = (0..3).any(|k| !shared.contains(&b[k]) && strictly_inside2(fb[k], &fa));
        let inside_b = (0..3).any(|k| !shared.contains(&a[k]) && strictly_inside2(fa[k], &fb));
        return inside_a || inside_b;
    }
    let crossing = (0..3).any(|k| free_edge(a, k) && segment_crosses_triangle(pa[k], pa[(k + 1) % 3], pb))
        || (0..3).any(|k| free_edge(b, k) && segment_crosses_triangle(pb[k], pb[(k + 1) % 3], pa));
    // A vertex on the other's plane strictly inside it (not a shared one).
    let touch = |t: [u32; 3], pt: [DVec3; 3], u: [u32; 3], pu: [DVec3; 3], s: [f64; 3]| {
        (0..3).any(|k| {
            s[k] == 0.0
                && !t.contains(&u[k])
                && (pt[1] - pt[0]).cross(pt[2] - pt[0]) != DVec3::ZERO
                && strictly_inside2(drop_axis(pt, &[pu[k]])[0], &drop_axis(pt, &pt))
        })
    };
    // An edge of one lying in the other's plane and crossing one of its edges.
    let in_plane = |t: [u32; 3], pt: [DVec3; 3], u: [u32; 3], pu: [DVec3; 3], s: [f64; 3]| {
        if (pt[1] - pt[0]).cross(pt[2] - pt[0]) == DVec3::ZERO {
            return false;
        }
        let (ft, fu) = (drop_axis(pt, &pt), drop_axis(pt, &pu));
        (0..3).any(|j| {
            s[j] == 0.0
                && s[(j + 1) % 3] == 0.0
                && free_edge(u, j)
                && (0..3).any(|i| {
                    let (p, q, r, w) = (ft[i], ft[(i + 1) % 3], fu[j], fu[(j + 1) % 3]);
                    free_edge(t, i)
                        && orient2(p, q, r) * orient2(p, q, w) < 0.0
                        && orient2(r, w, p) * orient2(r, w, q) < 0.0
                })
        })
    };
    crossing
        || touch(a, pa, b, pb, sb)
        || touch(b, pb, a, pa, sa)
        || in_plane(a, pa, b, pb, sb)
        || in_plane(b, pb, a, pa, sa)
}

fn boxes(m: &Mesh) -> Vec<(DVec3, DVec3)> {
    m.indices
        .chunks(3)
        .map(|t| {
            let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
        })
        .collect()
}

fn tri(m: &Mesh, i: usize) -> [u32; 3] {
    [m.indices[3 * i], m.indices[3 * i + 1], m.indices[3 * i + 2]]
}

fn overlap(a: &(DVec3, DVec3), b: &(DVec3, DVec3)) -> bool {
    !(a.0.cmpgt(b.1).any() || b.0.cmpgt(a.1).any())
}

/// Brute force over all pairs (boxes apart are skipped: a filter, not a
/// search structure). O(n²): for small meshes.
fn brute_force_intersections(m: &Mesh) -> usize {
    let bx = boxes(m);
    let mut count = 0;
    for i in 0..bx.len() {
        for j in i + 1..bx.len() {
            if overlap(&bx[i], &bx[j]) && triangles_meet(m, tri(m, i), tri(m, j)) {
                count += 1;
            }
        }
    }
    count
}

/// The same count through a bounding-volume hierarchy written here (median
/// split on the longest axis of the centroids, leaves of 8), for meshes too
/// large for the brute force. Independent of the library's k-d tree and BVH.
fn bvh_intersections(m: &Mesh) -> usize {
    struct Node {
        lo: DVec3,
        hi: DVec3,
        /// Children, or the range of `order` for a leaf.
        kids: Option<(usize, usize)>,
        range: (usize, usize),
    }
    fn build(bx: &[(DVec3, DVec3)], order: &mut [usize], start: usize, nodes: &mut Vec<Node>) -> usize {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let (mut clo, mut chi) = (lo, hi);
        for &i in order.iter() {
            lo = lo.min(bx[i].0);
            hi = hi.max(bx[i].1);
            let c = (bx[i].0 + bx[i].1) * 0.5;
            clo = clo.min(c);
            chi = chi.max(c);
        }
        let id = nodes.len();
        nodes.push(Node { lo, hi, kids: None, range: (start, start + order.len()) });
        if order.len() > 8 {
            let ext = chi - clo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let key = |i: &usize| (bx[*i].0[axis] + bx[*i].1[axis]) * 0.5;
            order.sort_by(|x, y| key(x).total_cmp(&key(y)));
            let mid = order.len() / 2;
            let (l, r) = order.split_at_mut(mid);
            let left = build(bx, l, start, nodes);
            let right = build(bx, r, start + mid, nodes);
            nodes[id].kids = Some((left, right));
        }
        id
    }
    let bx = boxes(m);
    let mut order: Vec<usize> = (0..bx.len()).collect();
    let mut nodes = Vec::new();
    build(&bx, &mut order, 0, &mut nodes);
    let mut count = 0;
    let mut stack = Vec::new();
    for i in 0..bx.len() {
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &nodes[n];
            if !overlap(&bx[i], &(node.lo, node.hi)) {
                continue;
            }
            match node.kids {
                Some((l, r)) => stack.extend([l, r]),
                None => {
                    for &j in &order[node.range.0..node.range.1] {
                        if j > i && overlap(&bx[i], &bx[j]) && triangles_meet(m, tri(m, i), tri(m, j)) {
                            count += 1;
                        }
                    }
                }
            }
        }
    }
    count
}

/// Everything the acceptance asks of a repaired offset.
fn assert_clean(name: &str, r: &RepairResult, brute: bool) {
    let rep = &r.report;
    eprintln!("{name}: {rep:?}");
    let (free, nonmanifold, flipped) = census(&r.mesh);
    assert!(r.mesh.triangle_count() > 0, "{name}: empty result");
    assert_eq!(free, 0, "{name}: free edges");
    assert_eq!(nonmanifold, 0, "{name}: non-manifold edges");
    assert_eq!(flipped, 0, "{name}: inconsistent orientation");
    assert!(volume(&r.mesh) > 0.0, "{name}: volume {}", volume(&r.mesh));
    // The library's own search, then this file's independent ones.
    let exact = find_self_intersections(&r.mesh).unwrap();
    assert!(exact.is_empty(), "{name}: {} pairs still meet, first {:?}", exact.len(), &exact[..exact.len().min(5)]);
    if brute {
        assert_eq!(brute_force_intersections(&r.mesh), 0, "{name}: brute force finds intersections");
    }
    assert_eq!(bvh_intersections(&r.mesh), 0, "{name}: the test's BVH check finds intersections");
}

// ------------------------------------------------------------ offsets

#[test]
fn repair_ellipsoid_offset_inward_past_the_tip_curvature() {
    // The sphere of radius 10 stretched to semi-axes 25, 15, 10: at the x
    // tips the radii of curvature are 15²/25 = 9 and 10²/25 = 4, so an inward
    // offset of 6 folds them one way: a swallowtail fin along y, which crosses
    // the body. (Equal y and z axes would fold both ways into a pinch point.)
    let m = scaled(meshed("sphere.json", 2e-3), DVec3::new(2.5, 1.5, 1.0));
    let off = offset_mesh(&m, -6.0).unwrap();
    let raw = find_self_intersections(&off).unwrap();
    assert!(raw.len() > 10, "the offset should self-intersect: {}", raw.len());
    let r = repair_mesh(&off, &RepairOptions::default()).unwrap();
    assert!(r.report.segments > 0);
    assert_clean("ellipsoid", &r, true);
    // The tips are cut back: the repaired x extent is below the raw offset's.
    let xmax = |m: &Mesh| m.positions.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max);
    assert!(xmax(&r.mesh) <= xmax(&off) + 1e-9);
}

#[test]
fn repair_flattened_torus_offset_inward_past_the_tube_curvature() {
    // Torus 20 / 5 squashed to a tube of semi-axes 5 (radial) and 2 (z): at
    // its inner and outer equators the tube's radius of curvature is 2²/5 =
    // 0.8, so an inward offset of 1.5 folds both into swallowtail fins that
    // run around the axis.
    let m = scaled(meshed("torus.json", 2e-3), DVec3::new(1.0, 1.0, 0.4));
    let off = offset_mesh(&m, -1.5).unwrap();
    assert!(!find_self_intersections(&off).unwrap().is_empty(), "the offset should self-intersect");
    let r = repair_mesh(&off, &RepairOptions::default()).unwrap();
    assert!(r.report.segments > 0);
    assert_clean("torus", &r, false);
    // Genus 1 survives: V - E + F = 0.
    let edges = r.mesh.indices.len() / 2;
    assert_eq!(r.mesh.positions.len() as i64 - edges as i64 + r.mesh.triangle_count() as i64, 0);
}

#[test]
fn repair_outward_offset_of_a_sphere_is_already_clean_and_kept_whole() {
    let m = meshed("sphere.json", 5e-3);
    let off = offset_mesh(&m, 2.0).unwrap();
    let r = repair_mesh(&off, &RepairOptions::default()).unwrap();
    assert_eq!(r.report.segments, 0);
    assert_eq!(r.mesh.triangle_count(), off.triangle_count());
    assert_clean("sphere", &r, true);
    // Radius 10 + 2: the volume is that of the inscribed polyhedron of radius 12, just below 4/3 π 12³.
    let v = volume(&r.mesh);
    let ball = 4.0 / 3.0 * std::f64::consts::PI * 12f64.powi(3);
    assert!(v < ball && v > 0.97 * ball, "volume {v} vs {ball}");
}

#[test]
fn repair_kd_tree_and_bvh_find_the_same_segments() {
    let m = scaled(meshed("sphere.json", 5e-3), DVec3::new(2.5, 1.5, 1.0));
    let off = offset_mesh(&m, -6.0).unwrap();
    let kd =
        repair_mesh(&off, &RepairOptions::default().with_bucketing(Bucketing::KdTree).with_bucket_capacity(8)).unwrap();
    let bvh = repair_mesh(&off, &RepairOptions::default().with_bucketing(Bucketing::Bvh)).unwrap();
    assert!(kd.report.kd_leaves > 1);
    assert_eq!(kd.report.segments, bvh.report.segments);
    assert_eq!(kd.mesh.triangle_count(), bvh.mesh.triangle_count());
    assert_clean("kd", &kd, false);
}

#[test]
fn repair_inward_offset_of_a_corpus_cube_folds_at_its_edges() {
    // A 10 mm cube from Inventor, meshed finely: vertex normals along the
    // edges point diagonally, so an inward offset larger than the mesh
    // spacing folds the triangles next to every edge over each other.
    let model = read_iges(&crate::corpus_files::corpus_bytes("cube_10x10_inventor.igs")).unwrap();
    let opts = MeshOptions::default().with_max_edge(Some(1.5));
    let r = mesh_model(&model, &opts).unwrap();
    let mut m = weld_mesh(&r.mesh, 1e-6);
    drop_collapsed(&mut m);
    assert_eq!(census(&m), (0, 0, 0), "the meshed cube is closed");
    let off = offset_mesh(&m, -2.0).unwrap();
    assert!(!find_self_intersections(&off).unwrap().is_empty(), "the offset should self-intersect");
    let rep = repair_mesh(&off, &RepairOptions::default()).unwrap();
    assert_clean("cube", &rep, false);
    // About the 6 mm cube that the exact inward offset is.
    let v = volume(&rep.mesh);
    assert!((v - 216.0).abs() < 0.15 * 216.0, "volume {v}");
}

#[test]
fn the_tests_own_intersection_checks_see_crossing_touching_and_coplanar_pairs() {
    // Two triangles and nothing else: does the pair count as meeting?
    let pair = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| {
        let positions = a.iter().chain(&b).map(|p| DVec3::from_array(*p)).collect();
        let m = Mesh { positions, normals: Vec::new(), indices: vec![0, 1, 2, 3, 4, 5], face_ranges: Vec::new() };
        let (brute, bvh) = (brute_force_intersections(&m), bvh_intersections(&m));
        assert_eq!(brute, bvh);
        brute
    };
    let base = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    assert_eq!(pair(base, [[1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [3.0, 3.0, 1.0]]), 1, "crossing");
    assert_eq!(pair(base, [[1.0, 1.0, 0.0], [1.0, 1.0, 1.0], [2.0, 1.0, 1.0]]), 1, "vertex touching the interior");
    assert_eq!(pair(base, [[1.0, 1.0, 0.0], [5.0, 1.0, 0.0], [1.0, 5.0, 0.0]]), 1, "coplanar overlap");
    assert_eq!(pair(base, [[-1.0, 1.0, 0.0], [5.0, 1.0, 0.0], [2.0, 1.0, 3.0]]), 1, "an edge in the plane");
    assert_eq!(pair(base, [[1.0, 1.0, 0.5], [1.0, 1.0, 1.0], [3.0, 3.0, 1.0]]), 0, "above");
    assert_eq!(pair(base, [[5.0, 0.0, 0.0], [9.0, 0.0, 0.0], [5.0, 4.0, 0.0]]), 0, "coplanar apart");
    // On a raw offset that crosses itself, both agree with the library's search on the pairs.
    let m = scaled(meshed("sphere.json", 2e-2), DVec3::new(2.5, 1.5, 1.0));
    let off = offset_mesh(&m, -6.0).unwrap();
    let (brute, bvh) = (brute_force_intersections(&off), bvh_intersections(&off));
    let library = find_self_intersections(&off).unwrap().len();
    eprintln!(
        "raw offset of {} triangles: {brute} pairs by brute force, {bvh} by BVH, {library} by the library",
        off.triangle_count()
    );
    assert!(brute > 10);
    assert_eq!(brute, bvh);
    assert_eq!(brute, library);
}

/// A corpus part meshed with edges up to `max_edge`, welded.
fn corpus_mesh(name: &str, max_edge: f64) -> Mesh {
    let model = read_iges(&crate::corpus_files::corpus_bytes(name)).unwrap();
    let r = mesh_model(&model, &MeshOptions::default().with_max_edge(Some(max_edge))).unwrap();
    let diag = bbox_diagonal(&r.mesh);
    let mut m = weld_mesh(&r.mesh, 1e-9 * diag);
    drop_collapsed(&mut m);
    m
}

#[test]
fn repair_inward_offsets_of_corpus_solids_are_clean() {
    // A CATIA cylinder (diameter 100, height 100) and a capsule whose mesh
    // has slivers and a few crossings where its faces meet: each is repaired into a closed outward solid first, then
    // offset inward by a few percent of its size, and the rims fold over.
    for (name, max_edge, d) in [("OCC8842_cylinder_CATIA.igs", 8.0, -5.0), ("marsCapsule.igs", 1.0, -1.5)] {
        let m = corpus_mesh(name, max_edge);
        let outward = repair_mesh(&m, &RepairOptions::default()).unwrap().mesh;
        assert_eq!(census(&outward), (0, 0, 0), "{name}: the meshed solid is closed");
        assert!(volume(&outward) > 0.0);
        // Turned inside out, a negative offset still goes inward.
        let mut flipped = outward.clone();
        flipped.indices.chunks_mut(3).for_each(|t| t.swap(1, 2));
        let v = volume(&outward);
        assert!(volume(&offset_mesh(&flipped, 0.2 * d).unwrap()).abs() < v, "{name}");
        assert!(volume(&offset_mesh(&outward, 0.2 * d).unwrap()) < v, "{name}");
        let off = offset_mesh(&outward, d).unwrap();
        assert!(!find_self_intersections(&off).unwrap().is_empty(), "{name}: the offset should self-intersect");
        let r = repair_mesh(&off, &RepairOptions::default()).unwrap();
        assert_clean(name, &r, false);
        assert!(volume(&r.mesh) < volume(&outward), "{name}: inward");
    }
}

#[test]
fn repair_of_an_open_corpus_part_keeps_its_border_and_crosses_nothing() {
    // The bearing is an open shell (70 free edges in loops: faces missing in
    // the file). An inward offset by 2% of its size crosses itself; the
    // repair is a best effort: the border stays open, the result crosses
    // nothing, every edge has at most two triangles and they agree.
    let m = corpus_mesh("bearing.iges", 0.004);
    let (free, nonmanifold, _) = census(&m);
    assert!(free > 0 && nonmanifold == 0);
    let off = offset_mesh(&m, -0.0032).unwrap();
    assert!(!find_self_intersections(&off).unwrap().is_empty());
    let r = repair_mesh(&off, &RepairOptions::default()).unwrap();
    eprintln!("bearing: {:?}", r.report);
    assert!(
        r.report.warnings.iter().any(|w| matches!(w.kind, WarningKind::OpenInput { .. })),
        "{:?}",
        r.report.warnings
    );
    let (free_out, nonmanifold_out, flipped) = census(&r.mesh);
    assert!(free_out > 0);
    assert_eq!((nonmanifold_out, flipped), (0, 0));
    assert!(find_self_intersections(&r.mesh).unwrap().is_empty());
    assert_eq!(bvh_intersections(&r.mesh), 0);
    // Deeper, growth leaks around the open border onto both sides of some
    // crossings: the result then has edges of four triangles, and says so.
    let off = offset_mesh(&m, -0.008).unwrap();
    let r = repair_mesh(&off, &RepairOptions::default()).unwrap();
    let nonmanifold = census(&r.mesh).1;
    eprintln!("bearing deeper: {nonmanifold} non-manifold edges, warnings {:?}", r.report.warnings);
    assert_eq!(nonmanifold, r.report.census_out.nonmanifold_edges);
    assert_eq!(nonmanifold > 0, r.report.warnings.iter().any(|w| matches!(w.kind, WarningKind::NotManifold { .. })));
}

// ------------------------------------------------------------ bad input

#[test]
fn repair_refuses_empty_nan_and_non_manifold_input_with_clear_errors() {
    let empty = Mesh::default();
    let e = repair_mesh(&empty, &RepairOptions::default()).unwrap_err().to_string();
    assert!(e.contains("no triangles"), "{e}");

    let mut nan = meshed("sphere.json", 2e-2);
    nan.positions[3].y = f64::NAN;
    let e = repair_mesh(&nan, &RepairOptions::default()).unwrap_err().to_string();
    assert!(e.contains("vertex 3") && e.contains("not a finite number"), "{e}");

    // A fin: a third triangle on an edge of a closed mesh.
    let mut fin = meshed("sphere.json", 2e-2);
    let (a, b) = (fin.indices[0], fin.indices[1]);
    fin.positions.push(DVec3::new(100.0, 0.0, 0.0));
    let c = (fin.positions.len() - 1) as u32;
    fin.indices.extend([a, b, c]);
    let e = repair_mesh(&fin, &RepairOptions::default()).unwrap_err();
    assert!(matches!(e, Error::Repair { .. }), "{e:?}");
    let e = e.to_string();
    assert!(
        e.contains(&format!("edge between vertices {} and {}", a.min(b), a.max(b))) && e.contains("not a 2-manifold"),
        "{e}"
    );

    let mut bad_index = meshed("sphere.json", 2e-2);
    bad_index.indices[5] = 1_000_000;
    let e = repair_mesh(&bad_index, &RepairOptions::default()).unwrap_err().to_string();
    assert!(e.contains("triangle 1") && e.contains("out of range"), "{e}");
}

#[test]
fn repair_keeps_an_open_mesh_open_and_says_so() {
    // A sphere with a few triangles cut out: best effort, the hole stays.
    let mut m = meshed("sphere.json", 1e-2);
    m.indices.truncate(m.indices.len() - 9);
    let r = repair_mesh(&m, &RepairOptions::default()).unwrap();
    assert!(r.report.free_edges_in > 0);
    assert!(
        r.report.warnings.iter().any(|w| matches!(w.kind, WarningKind::OpenInput { .. })),
        "{:?}",
        r.report.warnings
    );
    assert_eq!(r.mesh.triangle_count(), m.triangle_count());
    assert_eq!(census(&r.mesh).0, r.report.free_edges_in);
}

#[test]
fn repair_turns_an_inside_out_mesh_outward() {
    let mut m = meshed("sphere.json", 1e-2);
    for t in m.indices.chunks_mut(3) {
        t.swap(1, 2);
    }
    assert!(volume(&m) < 0.0);
    let r = repair_mesh(&m, &RepairOptions::default()).unwrap();
    assert!(volume(&r.mesh) > 0.0);
    assert!(
        r.report.warnings.iter().any(|w| matches!(w.kind, WarningKind::InsideOut { .. })),
        "{:?}",
        r.report.warnings
    );
}

mod random_input {
    //! Random input never panics: triangle soups on a coarse grid (coplanar,
    //! collinear, coincident and repeated triangles everywhere), and closed
    //! meshes with vertices thrown about until they cross themselves.

    use super::*;
    use proptest::prelude::*;
    use proptest::test_runner::{Config, RngSeed};

    /// Fewer cases unoptimized (CI's `cargo test` is a debug build).
    fn config(cases: u32) -> Config {
        let cases = if cfg!(debug_assertions) { cases / 4 } else { cases };
        Config { cases, rng_seed: RngSeed::Fixed(0x5eed_0008), failure_persistence: None, ..Config::default() }
    }

    /// The sphere all cases throw about, meshed once.
    fn sphere() -> &'static Mesh {
        static SPHERE: std::sync::OnceLock<Mesh> = std::sync::OnceLock::new();
        SPHERE.get_or_init(|| meshed("sphere.json", 5e-2))
    }

    proptest! {
        #![proptest_config(config(96))]

        #[test]
        fn triangle_soups_get_a_result_or_an_error(
            corners in proptest::collection::vec((0u8..3, 0u8..3, 0u8..3), 3..40),
            picks in proptest::collection::vec(0usize..40, 3..60),
        ) {
            let positions: Vec<DVec3> = corners.iter().map(|&(x, y, z)| DVec3::new(x as f64, y as f64, z as f64)).collect();
            let n = positions.len();
            let indices: Vec<u32> = picks[..picks.len() / 3 * 3].iter().map(|&i| (i % n) as u32).collect();
            let m = Mesh { positions, normals: Vec::new(), indices, face_ranges: Vec::new() };
            match repair_mesh(&m, &RepairOptions::default()) {
                Ok(r) => {
                    prop_assert_eq!(r.report.triangles_out, r.mesh.triangle_count());
                    prop_assert!(r.mesh.indices.iter().all(|&i| (i as usize) < r.mesh.positions.len()));
                }
                Err(e) => prop_assert!(!e.to_string().is_empty()),
            }
        }

        #[test]
        fn closed_meshes_thrown_out_of_shape_come_out_clean_or_say_why(
            seed in any::<u64>(), share in 0.05f64..0.5, size in 0.5f64..8.0,
        ) {
            let mut m = sphere().clone();
            let mut rng = seed | 1;
            let mut next = move || {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                (rng >> 11) as f64 / (1u64 << 53) as f64
            };
            for p in &mut m.positions {
                if next() < share {
                    *p += DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 2.0 * size;
                }
            }
            let r = repair_mesh(&m, &RepairOptions::default()).unwrap();
            let (free, nonmanifold, flipped) = census(&r.mesh);
            if r.report.warnings.is_empty() {
                prop_assert_eq!((free, nonmanifold, flipped), (0, 0, 0), "{:?}", r.report);
                prop_assert_eq!(bvh_intersections(&r.mesh), 0, "{:?}", r.report);
                prop_assert!(r.mesh.triangle_count() == 0 || volume(&r.mesh) > 0.0);
            } else {
                prop_assert_eq!(r.report.census_out, surfmesh::mesh_edge_census(&r.mesh).unwrap());
            }
        }
    }
}

// ------------------------------------------------------------ readers

#[test]
fn stl_and_obj_round_trip_through_the_readers_with_vertices_merged() {
    let m = meshed("sphere.json", 1e-2);
    let stl = read_mesh(&write_stl(&m), MeshFormat::Stl).unwrap();
    // Binary STL stores f32 corners per triangle; identical ones become one vertex again.
    assert_eq!(stl.triangle_count(), m.triangle_count());
    assert_eq!(stl.positions.len(), m.positions.len());
    assert_eq!(census(&stl), (0, 0, 0));
    let obj = read_mesh(&write_obj(&m), MeshFormat::Obj).unwrap();
    assert_eq!(obj.indices, m.indices);
    assert_eq!(obj.positions, m.positions, "OBJ keeps full precision");
    assert_eq!(MeshFormat::detect(&write_stl(&m)), Some(MeshFormat::Stl));
    assert_eq!(MeshFormat::detect(&write_obj(&m)), Some(MeshFormat::Obj));
}

#[test]
fn ascii_stl_reads_with_polygons_and_names_bad_lines() {
    let text = b"solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";
    let m = read_mesh(text, MeshFormat::Stl).unwrap();
    assert_eq!(m.triangle_count(), 2, "a quad facet becomes a fan of two");
    assert_eq!(m.positions.len(), 4);
    let bad = b"solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 zero\n";
    let e = read_mesh(bad, MeshFormat::Stl).unwrap_err().to_string();
    assert_eq!(e, "ASCII STL line 4: 'zero' is not a number");
    let nan = b"solid t\nfacet\nvertex 0 0 nan\nvertex 1 0 0\nvertex 0 1 0\nendfacet\nendsolid\n";
    let e = read_mesh(nan, MeshFormat::Stl).unwrap_err().to_string();
    assert!(e.starts_with("ASCII STL line 3:") && e.contains("not a finite number"), "{e}");
    let truncated = b"solid t\nfacet\nvertex 0 0 0\n";
    let e = read_mesh(truncated, MeshFormat::Stl).unwrap_err().to_string();
    assert!(e.contains("line 2") && e.contains("no 'endfacet'"), "{e}");
    let e = read_mesh(b"", MeshFormat::Stl).unwrap_err().to_string();
    assert!(e.contains("empty"), "{e}");
    // A binary file cut short is neither binary nor ASCII.
    let m = meshed("sphere.json", 5e-2);
    let stl = write_stl(&m);
    let e = read_mesh(&stl[..stl.len() - 7], MeshFormat::Stl).unwrap_err().to_string();
    assert!(e.contains("header says") && e.contains("triangles"), "{e}");
}

#[test]
fn obj_reader_handles_index_forms_and_names_bad_lines() {
    let text = b"# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1 -1\n";
    let m = read_mesh(text, MeshFormat::Obj).unwrap();
    assert_eq!(m.indices, vec![0, 1, 2, 0, 2, 3]);
    let e = read_mesh(b"v 0 0 0\nv 1 0 0\nf 1 2 3\n", MeshFormat::Obj).unwrap_err().to_string();
    assert_eq!(e, "OBJ line 3: vertex index 3 is out of range (1 to 2 so far)");
    let e = read_mesh(b"v 0 0\n", MeshFormat::Obj).unwrap_err().to_string();
    assert_eq!(e, "OBJ line 1: 'v' needs three coordinates");
    let e = read_mesh(b"v 0 0 0\nf 1 1\n", MeshFormat::Obj).unwrap_err().to_string();
    assert_eq!(e, "OBJ line 2: face has 2 vertices, needs at least 3");
}

// ------------------------------------------------------------ command line

#[test]
fn cli_offset_then_repair_writes_a_clean_mesh_and_a_report() {
    let bin = env!("CARGO_BIN_EXE_surfmesh");
    let dir = std::env::temp_dir().join(format!("surfmesh-it-{}-repair-cli", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // A stretched sphere as OBJ, offset inward by the command line.
    let m = scaled(meshed("sphere.json", 5e-3), DVec3::new(2.5, 1.5, 1.0));
    std::fs::write(dir.join("in.obj"), write_obj(&m)).unwrap();
    let run = |args: &[&str]| std::process::Command::new(bin).args(args).current_dir(&dir).output().unwrap();
    let out = run(&["offset", "in.obj", "-d", "-6", "-o", "off.stl"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let off = read_mesh(&std::fs::read(dir.join("off.stl")).unwrap(), MeshFormat::Stl).unwrap();
    assert_eq!(off.triangle_count(), m.triangle_count());
    assert!(!find_self_intersections(&off).unwrap().is_empty());

    let out = run(&["repair", "off.stl", "-o", "fixed.obj", "--report", "r.json", "--verify"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let fixed = read_mesh(&std::fs::read(dir.join("fixed.obj")).unwrap(), MeshFormat::Obj).unwrap();
    assert_eq!(census(&fixed), (0, 0, 0));
    assert!(find_self_intersections(&fixed).unwrap().is_empty());
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    assert_eq!(report["triangles_in"], off.triangle_count());
    assert_eq!(report["triangles_out"], fixed.triangle_count());
    assert_eq!(report["self_intersections_out"], 0);
    assert!(report["segments"].as_u64().unwrap() > 0);
    assert!(report["regions"].as_u64().unwrap() >= 1);
    for stage in ["prepare", "degenerate", "intersect", "regions", "total"] {
        assert!(report["time_ms"][stage].as_f64().unwrap() >= 0.0, "{stage}");
    }

    // Bad input: one line on stderr naming the file and the line, exit 1, nothing written.
    std::fs::write(dir.join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    let out = run(&["repair", "bad.obj", "-o", "never.stl"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim(), "surfmesh: bad.obj: OBJ line 3: vertex index 9 is out of range (1 to 2 so far)");
    assert!(!dir.join("never.stl").exists());
    // Empty files, and a file with a vertex but no triangle.
    std::fs::write(dir.join("empty.stl"), "").unwrap();
    std::fs::write(dir.join("empty.obj"), "").unwrap();
    std::fs::write(dir.join("point.obj"), "v 0 0 0\n").unwrap();
    for (args, message) in [
        (&["repair", "empty.stl", "-o", "never.stl"][..], "surfmesh: empty.stl: STL: the file is empty"),
        (&["repair", "empty.obj", "-o", "never.stl"][..], "surfmesh: empty.obj: repair: mesh: it has no triangles"),
        (&["repair", "point.obj", "-o", "never.stl"][..], "surfmesh: point.obj: repair: mesh: it has no triangles"),
        (
            &["offset", "empty.obj", "-d", "1", "-o", "never.stl"][..],
            "surfmesh: empty.obj: repair: mesh: it has no triangles to offset",
        ),
    ] {
        let out = run(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert_eq!(String::from_utf8_lossy(&out.stderr).trim(), message);
    }
    assert!(!dir.join("never.stl").exists());
    let out = run(&["repair", "off.stl", "--bucketing", "octree"]);
    assert_eq!(out.status.code(), Some(2));
    let out = run(&["offset", "in.obj", "-o", "x.stl"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("-d DIST"));
    let _ = std::fs::remove_dir_all(&dir);
}
