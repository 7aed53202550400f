//! Point-cloud readers: `.xyz` (numbers separated by blanks), `.csv` (by
//! commas or semicolons, optional header) and `.ply` (ASCII or binary
//! little-endian, the `vertex` element's `x y z`). Errors name the line (or,
//! in binary PLY, the vertex and its byte offset).

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use glam::DVec3;

use crate::Error;

/// Point file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum PointFormat {
    /// One point per line: `x y z` and optionally more columns (ignored),
    /// separated by spaces or tabs; `#` starts a comment.
    Xyz,
    /// Comma- (or semicolon-) separated `x,y,z[,…]`; a first line that is not
    /// numbers is a header, and its `x`, `y`, `z` columns are used when it names them.
    Csv,
    /// Stanford PLY, `format ascii 1.0` or `format binary_little_endian 1.0`.
    Ply,
}

/// Most points a file may hold: bounds memory before any geometry is built.
pub const MAX_FILE_POINTS: usize = 10_000_000;

impl PointFormat {
    /// Format from a name or extension (`"xyz"`, `".csv"`, `"ply"`, also `"txt"` and `"pts"` as xyz).
    ///
    /// # Errors
    /// [`Error::Format`] for an unknown name.
    pub fn from_name(name: &str) -> Result<Self, Error> {
        let n = name.trim_start_matches('.').to_ascii_lowercase();
        match n.as_str() {
            "xyz" | "txt" | "pts" => Ok(Self::Xyz),
            "csv" => Ok(Self::Csv),
            "ply" => Ok(Self::Ply),
            _ => Err(Error::Format(format!("unknown point format '{name}' (expected xyz, csv or ply)"))),
        }
    }

    /// Guesses the format from the first bytes: `ply` on the first line is
    /// PLY; a first data line with a comma or semicolon is CSV; else xyz.
    pub fn detect(bytes: &[u8]) -> Self {
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
            return Self::Ply;
        }
        let first = bytes
            .split(|&b| b == b'\n')
            .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
            .find(|l| l.iter().any(|c| !c.is_ascii_whitespace()) && !l.trim_ascii_start().starts_with(b"#"));
        match first {
            Some(l) if l.contains(&b',') || l.contains(&b';') => Self::Csv,
            _ => Self::Xyz,
        }
    }
}

/// Reads the points of a file in `format`.
///
/// # Errors
/// [`Error::Points`] naming the line (or PLY vertex) and what is wrong: too
/// few columns, text that is not a number, a value that is not finite, a bad
/// PLY header or a truncated binary body; [`Error::Limit`] past
/// [`MAX_FILE_POINTS`].
pub fn read_points(bytes: &[u8], format: PointFormat) -> Result<Vec<DVec3>, Error> {
    match format {
        PointFormat::Xyz => read_text(bytes, false),
        PointFormat::Csv => read_text(bytes, true),
        PointFormat::Ply => read_ply(bytes),
    }
}

fn err(line: usize, message: String) -> Error {
    Error::Points { line, message }
}

/// Lines of `bytes` with their 1-based numbers, without line ends.
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    bytes.split(|&b| b == b'\n').map(|l| l.strip_suffix(b"\r").unwrap_or(l)).enumerate().map(|(i, l)| (i + 1, l))
}

fn parse_number(field: &str, line: usize, column: usize) -> Result<f64, Error> {
    let v: f64 = field
        .trim()
        .parse()
        .map_err(|_| err(line, format!("column {column}: '{}' is not a number", short(field.trim()))))?;
    if !v.is_finite() {
        return Err(err(line, format!("column {column}: {v} is not a finite coordinate")));
    }
    Ok(v)
}

/// At most 40 characters of `s`, for messages.
fn short(s: &str) -> String {
    let mut out: String = s.chars().take(40).collect();
    if s.chars().count() > 40 {
        out.push('…');
    }
    out
}

fn read_text(bytes: &[u8], csv: bool) -> Result<Vec<DVec3>, Error> {
    let mut points = Vec::new();
    let mut columns = [0usize, 1, 2];
    let mut first_data = true;
    for (no, raw) in lines(bytes) {
        let text = core::str::from_utf8(raw).map_err(|_| err(no, "not UTF-8 text".to_string()))?;
        let text = text.split('#').next().unwrap_or("").trim();
        if text.is_empty() {
            continue;
        }
        let fields: Vec<&str> =
            if csv { text.split([',', ';']).map(str::trim).collect() } else { text.split_ascii_whitespace().collect() };
        if csv && first_data && fields.first().is_some_and(|f| f.parse::<f64>().is_err()) {
            // Header line: pick the x, y, z columns when it names them.
            let find = |name: &str| fields.iter().position(|f| f.trim_matches('"').eq_ignore_ascii_case(name));
            if let (Some(x), Some(y), Some(z)) = (find("x"), find("y"), find("z")) {
                columns = [x, y, z];
            }
            first_data = false;
            continue;
        }
        first_data = false;
        let need = columns.iter().max().copied().unwrap_or(2) + 1;
        if fields.len() < need {
            return Err(err(no, format!("expected {need} numbers (x y z), found {}", fields.len())));
        }
        let mut c = [0.0; 3];
        for (k, &col) in columns.iter().enumerate() {
            c[k] = parse_number(fields[col], no, col + 1)?;
        }
        if points.len() >= MAX_FILE_POINTS {
            return Err(Error::Limit(format!("more than {MAX_FILE_POINTS} points")));
        }
        points.push(DVec3::from_array(c));
    }
    Ok(points)
}

/// A scalar PLY property type and its size in bytes.
#[derive(Clone, Copy)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// The little-endian value at the start of `b` (which holds at least `size` bytes).
    fn read(self, b: &[u8]) -> Option<f64> {
        let a = |n: usize| b.get(..n);
        Some(match self {
            Self::I8 => *b.first()? as i8 as f64,
            Self::U8 => *b.first()? as f64,
            Self::I16 => i16::from_le_bytes(a(2)?.try_into().ok()?) as f64,
            Self::U16 => u16::from_le_bytes(a(2)?.try_into().ok()?) as f64,
            Self::I32 => i32::from_le_bytes(a(4)?.try_into().ok()?) as f64,
            Self::U32 => u32::from_le_bytes(a(4)?.try_into().ok()?) as f64,
            Self::F32 => f32::from_le_bytes(a(4)?.try_into().ok()?) as f64,
            Self::F64 => f64::from_le_bytes(a(8)?.try_into().ok()?),
        })
    }
}

/// A PLY property: scalar, or list (count type, item type).
enum Property {
    Scalar(String, Scalar),
    List(Scalar, Scalar),
}

struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

fn read_ply(bytes: &[u8]) -> Result<Vec<DVec3>, Error> {
    // Header: up to "end_header".
    let mut binary = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut body_start = None;
    let mut body_line = 0;
    let mut offset = 0usize;
    for (no, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate().map(|(i, l)| (i + 1, l)) {
        offset += raw.len();
        let text = core::str::from_utf8(raw).map_err(|_| err(no, "PLY header is not text".to_string()))?.trim();
        let mut words = text.split_ascii_whitespace();
        let Some(first) = words.next() else { continue };
        match (no, first) {
            (1, "ply") => {}
            (1, _) => return Err(err(1, "not a PLY file (the first line must be 'ply')".to_string())),
            (_, "comment" | "obj_info") => {}
            (_, "format") => {
                binary = Some(match words.next() {
                    Some("ascii") => false,
                    Some("binary_little_endian") => true,
                    Some("binary_big_endian") => {
                        return Err(err(
                            no,
                            "binary_big_endian PLY is not supported (ascii or binary_little_endian)".into(),
                        ))
                    }
                    _ => return Err(err(no, format!("unknown PLY format '{}'", short(text)))),
                });
            }
            (_, "element") => {
                let name = words.next().unwrap_or("").to_string();
                let count = words
                    .next()
                    .and_then(|c| c.parse::<usize>().ok())
                    .ok_or_else(|| err(no, format!("element '{}' has no count", short(&name))))?;
                elements.push(Element { name, count, props: Vec::new() });
            }
            (_, "property") => {
                let el = elements.last_mut().ok_or_else(|| err(no, "property before any element".to_string()))?;
                let kind = words.next().unwrap_or("");
                if kind == "list" {
                    let c = words.next().and_then(Scalar::parse);
                    let i = words.next().and_then(Scalar::parse);
                    match (c, i) {
                        (Some(c), Some(i)) => el.props.push(Property::List(c, i)),
                        _ => return Err(err(no, format!("bad list property '{}'", short(text)))),
                    }
                } else {
                    let ty = Scalar::parse(kind)
                        .ok_or_else(|| err(no, format!("unknown property type '{}'", short(kind))))?;
                    el.props.push(Property::Scalar(words.next().unwrap_or("").to_string(), ty));
                }
            }
            (_, "end_header") => {
                body_start = Some(offset);
                body_line = no + 1;
                break;
            }
            _ => return Err(err(no, format!("unexpected PLY header line '{}'", short(text)))),
        }
    }
    let body_start = body_start.ok_or_else(|| err(0, "PLY header has no end_header line".to_string()))?;
    let binary = binary.ok_or_else(|| err(0, "PLY header has no format line".to_string()))?;
    let vi = elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| err(0, "PLY header declares no vertex element".to_string()))?;
    let vertex = &elements[vi];
    let col = |name: &str| {
        vertex
            .props
            .iter()
            .position(|p| matches!(p, Property::Scalar(n, _) if n == name))
            .ok_or_else(|| err(0, format!("PLY vertex element has no '{name}' property")))
    };
    let xyz = [col("x")?, col("y")?, col("z")?];
    if vertex.count > MAX_FILE_POINTS {
        return Err(Error::Limit(format!("PLY declares {} vertices; at most {MAX_FILE_POINTS}", vertex.count)));
    }
    let body = &bytes[body_start.min(bytes.len())..];
    if binary {
        read_ply_binary(body, &elements, vi, xyz, body_start)
    } else {
        read_ply_ascii(body, &elements, vi, xyz, body_line)
    }
}

fn read_ply_ascii(
    body: &[u8],
    elements: &[Element],
    vi: usize,
    xyz: [usize; 3],
    first_line: usize,
) -> Result<Vec<DVec3>, Error> {
    let skip: usize = elements[..vi].iter().map(|e| e.count).sum();
    let count = elements[vi].count;
    let mut points = Vec::with_capacity(count.min(1 << 20));
    let mut seen = 0usize;
    for (no, raw) in lines(body) {
        let no = no + first_line - 1;
        let text = core::str::from_utf8(raw).map_err(|_| err(no, "not UTF-8 text".to_string()))?.trim();
        if text.is_empty() {
            continue;
        }
        seen += 1;
        if seen <= skip {
            continue;
        }
        if points.len() == count {
            break;
        }
        // Scalar properties before any list take one field each.
        let fields: Vec<&str> = text.split_ascii_whitespace().collect();
        let need = xyz.iter().max().copied().unwrap_or(2) + 1;
        if fields.len() < need {
            return Err(err(
                no,
                format!("vertex {}: expected at least {need} values, found {}", points.len(), fields.len()),
            ));
        }
        let mut c = [0.0; 3];
        for k in 0..3 {
            c[k] = parse_number(fields[xyz[k]], no, xyz[k] + 1)?;
        }
        points.push(DVec3::from_array(c));
    }
    if points.len() < count {
        return Err(err(0, format!("PLY body ends after {} of {count} vertices", points.len())));
    }
    Ok(points)
}

fn read_ply_binary(
    body: &[u8],
    elements: &[Element],
    vi: usize,
    xyz: [usize; 3],
    body_offset: usize,
) -> Result<Vec<DVec3>, Error> {
    let mut pos = 0usize;
    let truncated = |what: String| err(0, format!("PLY body ends inside {what}"));
    // Skip the elements before the vertices.
    for el in &elements[..vi] {
        for item in 0..el.count {
            for p in &el.props {
                match p {
                    Property::Scalar(_, t) => pos += t.size(),
                    Property::List(ct, it) => {
                        let n = body
                            .get(pos..)
                            .and_then(|b| ct.read(b))
                            .ok_or_else(|| truncated(format!("{} {item}", el.name)))?;
                        if !(0.0..=1e6).contains(&n) {
                            return Err(err(0, format!("{} {item}: list of {n} items", el.name)));
                        }
                        pos += ct.size() + n as usize * it.size();
                    }
                }
            }
            if pos > body.len() {
                return Err(truncated(format!("{} {item}", el.name)));
            }
        }
    }
    let vertex = &elements[vi];
    let mut points = Vec::with_capacity(vertex.count.min(1 << 20));
    for v in 0..vertex.count {
        let start = pos;
        let mut c = [0.0; 3];
        for (k, p) in vertex.props.iter().enumerate() {
            match p {
                Property::Scalar(_, t) => {
                    if let Some(slot) = xyz.iter().position(|&x| x == k) {
                        c[slot] = body
                            .get(pos..)
                            .and_then(|b| t.read(b))
                            .ok_or_else(|| truncated(format!("vertex {v} (byte {})", body_offset + start)))?;
                    }
                    pos += t.size();
                }
                Property::List(ct, it) => {
                    let n = body
                        .get(pos..)
                        .and_then(|b| ct.read(b))
                        .ok_or_else(|| truncated(format!("vertex {v} (byte {})", body_offset + start)))?;
                    if !(0.0..=1e6).contains(&n) {
                        return Err(err(0, format!("vertex {v}: list of {n} items")));
                    }
                    pos += ct.size() + n as usize * it.size();
                }
            }
        }
        if pos > body.len() {
            return Err(truncated(format!("vertex {v} (byte {})", body_offset + start)));
        }
        if let Some(k) = c.iter().position(|x| !x.is_finite()) {
            return Err(err(
                0,
                format!("vertex {v} (byte {}): {} is not finite", body_offset + start, ["x", "y", "z"][k]),
            ));
        }
        points.push(DVec3::from_array(c));
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    #[test]
    fn xyz_with_comments_extra_columns_and_crlf() {
        let text = b"# scan\r\n1 2 3 255 0 0\r\n\r\n4\t5\t6 # tail\r\n-1e-3 0 7";
        let p = read_points(text, PointFormat::Xyz).unwrap();
        assert_eq!(p, vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0), DVec3::new(-1e-3, 0.0, 7.0)]);
        assert_eq!(PointFormat::detect(text), PointFormat::Xyz);
    }

    #[test]
    fn text_errors_name_the_line() {
        let e = read_points(b"1 2 3\n4 5\n", PointFormat::Xyz).unwrap_err();
        assert_eq!(e.to_string(), "points line 2: expected 3 numbers (x y z), found 2");
        let e = read_points(b"1 2 3\n4 five 6\n", PointFormat::Xyz).unwrap_err();
        assert_eq!(e.to_string(), "points line 2: column 2: 'five' is not a number");
        let e = read_points(b"1 2 3\n4 NaN 6\n", PointFormat::Xyz).unwrap_err();
        assert_eq!(e.to_string(), "points line 2: column 2: NaN is not a finite coordinate");
    }

    #[test]
    fn csv_with_a_header_naming_columns() {
        let text = b"id,z,y,x\n0,3,2,1\n1;6;5;4\n";
        assert_eq!(PointFormat::detect(text), PointFormat::Csv);
        let p = read_points(text, PointFormat::Csv).unwrap();
        assert_eq!(p, vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0)]);
        let e = read_points(b"x,y,z\n1,2,3\n1,2,inf\n", PointFormat::Csv).unwrap_err();
        assert_eq!(e.to_string(), "points line 3: column 3: inf is not a finite coordinate");
    }

    #[test]
    fn ply_ascii_skips_other_elements() {
        let text = b"ply\nformat ascii 1.0\ncomment made by hand\nelement camera 1\nproperty float f\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n9\n1 2 3 200\n4 5 6 100\n";
        assert_eq!(PointFormat::detect(text), PointFormat::Ply);
        let p = read_points(text, PointFormat::Ply).unwrap();
        assert_eq!(p, vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0)]);
        let e = read_points(b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5\n", PointFormat::Ply).unwrap_err();
        assert_eq!(e.to_string(), "points line 9: vertex 1: expected at least 3 values, found 2");
    }

    #[test]
    fn ply_binary_little_endian_with_lists_and_doubles() {
        let mut b = b"ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 2\nproperty double x\nproperty uchar tag\nproperty double y\nproperty double z\nend_header\n".to_vec();
        b.push(3);
        for i in [0i32, 1, 2] {
            b.extend_from_slice(&i.to_le_bytes());
        }
        for v in [[1.0f64, 2.0, 3.0], [4.0, 5.0, 6.0]] {
            b.extend_from_slice(&v[0].to_le_bytes());
            b.push(7);
            b.extend_from_slice(&v[1].to_le_bytes());
            b.extend_from_slice(&v[2].to_le_bytes());
        }
        let p = read_points(&b, PointFormat::Ply).unwrap();
        assert_eq!(p, vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0)]);
        let cut = &b[..b.len() - 4];
        let e = read_points(cut, PointFormat::Ply).unwrap_err();
        assert!(e.to_string().contains("PLY body ends inside vertex 1"), "{e}");
        let e = read_points(b"ply\nformat binary_big_endian 1.0\nend_header\n", PointFormat::Ply).unwrap_err();
        assert_eq!(
            e.to_string(),
            "points line 2: binary_big_endian PLY is not supported (ascii or binary_little_endian)"
        );
    }
}
