//! Surfaces through scattered points (paper 004): the point readers.

use surfmesh::{read_points, PointFormat};

#[test]
fn point_files_read_from_tests_data() {
    let data = |name: &str| {
        std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)).unwrap()
    };
    let xyz = read_points(&data("points_tetra.xyz"), PointFormat::Xyz).unwrap();
    let csv = read_points(&data("points_tetra.csv"), PointFormat::Csv).unwrap();
    let ply = read_points(&data("points_tetra.ply"), PointFormat::Ply).unwrap();
    assert_eq!(xyz.len(), 6);
    assert_eq!(xyz, csv);
    assert_eq!(xyz, ply);
    assert_eq!(PointFormat::detect(&data("points_tetra.ply")), PointFormat::Ply);
    let e = read_points(b"0 0 0\n1 0 0\n0 1\n", PointFormat::Xyz).unwrap_err();
    assert_eq!(e.to_string(), "points line 3: expected 3 numbers (x y z), found 2");
}
