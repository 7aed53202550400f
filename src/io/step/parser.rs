//! ISO 10303-21 exchange structure: bytes to a [`Graph`].
//!
//! One forward pass over the bytes, no token buffer and no recursion:
//! nested lists are parsed with an explicit stack whose depth is capped,
//! every value lands in one flat arena (a closed list becomes a range of
//! it), and the counts of instances, values and string bytes are capped, so
//! the memory used is a small multiple of the input's size whatever it
//! holds. Strings decode `''`, `\\`, `\S\`, `\X\hh`, `\X2\…\X0\` and
//! `\X4\…\X0\`; raw bytes above 127 are taken as UTF-8 (ISO 8859-1 when
//! they are not valid UTF-8); line breaks inside strings are dropped,
//! comments `/* … */` are skipped anywhere between tokens.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use super::graph::{Graph, Instance, Part, Value};
use super::step_error;
use crate::Error;

/// Deepest nesting of lists and typed values inside one instance.
pub(super) const MAX_DEPTH: usize = 32;
/// Most values (of all instances together).
pub(super) const MAX_VALUES: usize = 1 << 26;
/// Most instances.
pub(super) const MAX_INSTANCES: usize = 1 << 24;

/// A token.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Keyword(String),
    Instance(u64),
    Int(i64),
    Real(f64),
    /// Decoded string: `len` bytes at the end of the graph's text.
    Str(u32, u32),
    Enum(String),
    Binary,
    Omitted,
    Derived,
    Open,
    Close,
    Comma,
    Semicolon,
    Equals,
    End,
}

struct Lexer<'a> {
    b: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lexer<'a> {
    fn error(&self, id: u64, message: impl Into<String>) -> Error {
        step_error(id, self.line, message)
    }

    /// Skips white space and comments.
    fn skip(&mut self, id: u64) -> Result<(), Error> {
        loop {
            match self.b.get(self.pos) {
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                }
                Some(&c) if c <= b' ' => self.pos += 1,
                Some(b'/') if self.b.get(self.pos + 1) == Some(&b'*') => {
                    let start = self.line;
                    self.pos += 2;
                    loop {
                        match self.b.get(self.pos) {
                            None => return Err(step_error(id, start, "comment not closed by */")),
                            Some(b'*') if self.b.get(self.pos + 1) == Some(&b'/') => {
                                self.pos += 2;
                                break;
                            }
                            Some(b'\n') => {
                                self.line += 1;
                                self.pos += 1;
                            }
                            Some(_) => self.pos += 1,
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn next(&mut self, g: &mut Graph, id: u64) -> Result<Tok, Error> {
        self.skip(id)?;
        let Some(&c) = self.b.get(self.pos) else { return Ok(Tok::End) };
        let tok = match c {
            b'(' => {
                self.pos += 1;
                Tok::Open
            }
            b')' => {
                self.pos += 1;
                Tok::Close
            }
            b',' => {
                self.pos += 1;
                Tok::Comma
            }
            b';' => {
                self.pos += 1;
                Tok::Semicolon
            }
            b'=' => {
                self.pos += 1;
                Tok::Equals
            }
            b'$' => {
                self.pos += 1;
                Tok::Omitted
            }
            b'*' => {
                self.pos += 1;
                Tok::Derived
            }
            b'#' => {
                self.pos += 1;
                let digits = self.take(|c| c.is_ascii_digit());
                if digits.is_empty() {
                    return Err(
                        self.error(id, "'#' not followed by an instance number (constant names are not supported)")
                    );
                }
                Tok::Instance(parse_u64(digits).ok_or_else(|| self.error(id, "instance number too large"))?)
            }
            b'\'' => self.string(g, id)?,
            b'"' => {
                self.pos += 1;
                self.take(|c| c.is_ascii_hexdigit());
                if self.b.get(self.pos) != Some(&b'"') {
                    return Err(self.error(id, "binary value not closed by '\"'"));
                }
                self.pos += 1;
                Tok::Binary
            }
            b'.' if self.b.get(self.pos + 1).is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_') => {
                self.pos += 1;
                let name = self.take(|c| c.is_ascii_alphanumeric() || c == b'_');
                if self.b.get(self.pos) != Some(&b'.') {
                    return Err(self.error(id, "enumeration not closed by '.'"));
                }
                self.pos += 1;
                Tok::Enum(ascii_upper(name))
            }
            b'0'..=b'9' | b'+' | b'-' | b'.' => self.number(id)?,
            b'!' | b'A'..=b'Z' | b'a'..=b'z' | b'_' => {
                let user = c == b'!';
                if user {
                    self.pos += 1;
                }
                let name = self.take(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'-');
                let mut k = ascii_upper(name);
                if user {
                    k.insert(0, '!');
                }
                Tok::Keyword(k)
            }
            other => {
                let shown = if other.is_ascii_graphic() {
                    format!("'{}'", other as char)
                } else {
                    format!("byte 0x{other:02x}")
                };
                return Err(self.error(id, format!("unexpected {shown}")));
            }
        };
        Ok(tok)
    }

    fn take(&mut self, f: impl Fn(u8) -> bool) -> &'a [u8] {
        let start = self.pos;
        while self.b.get(self.pos).is_some_and(|&c| f(c)) {
            self.pos += 1;
        }
        &self.b[start..self.pos]
    }

    fn number(&mut self, id: u64) -> Result<Tok, Error> {
        let start = self.pos;
        if matches!(self.b.get(self.pos), Some(b'+' | b'-')) {
            self.pos += 1;
        }
        self.take(|c| c.is_ascii_digit());
        let mut real = false;
        if self.b.get(self.pos) == Some(&b'.') {
            real = true;
            self.pos += 1;
            self.take(|c| c.is_ascii_digit());
        }
        if matches!(self.b.get(self.pos), Some(b'E' | b'e')) {
            real = true;
            self.pos += 1;
            if matches!(self.b.get(self.pos), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            self.take(|c| c.is_ascii_digit());
        }
        let text = core::str::from_utf8(&self.b[start..self.pos]).unwrap_or("");
        if !text.bytes().any(|c| c.is_ascii_digit()) {
            return Err(self.error(id, format!("'{text}' is not a number")));
        }
        if !real {
            if let Ok(n) = text.parse::<i64>() {
                return Ok(Tok::Int(n));
            }
        }
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Tok::Real(x)),
            _ => Err(self.error(id, format!("'{text}' is not a finite number"))),
        }
    }

    /// A string token; its decoded text is appended to `g.text`.
    fn string(&mut self, g: &mut Graph, id: u64) -> Result<Tok, Error> {
        let start_line = self.line;
        self.pos += 1;
        let mut out: Vec<u8> = Vec::new();
        loop {
            let Some(&c) = self.b.get(self.pos) else {
                return Err(step_error(id, start_line, "string not closed by a quote"));
            };
            self.pos += 1;
            match c {
                b'\'' => {
                    if self.b.get(self.pos) == Some(&b'\'') {
                        self.pos += 1;
                        out.push(b'\'');
                    } else {
                        break;
                    }
                }
                b'\n' => self.line += 1,
                b'\r' => {}
                b'\\' => self.directive(&mut out, id)?,
                _ => out.push(c),
            }
        }
        // Raw bytes above 127 are UTF-8 where they decode as such, else ISO 8859-1 (the standard's default).
        let text: String = match core::str::from_utf8(&out) {
            Ok(t) => t.into(),
            Err(_) => out.iter().map(|&b| char::from(b)).collect(),
        };
        let start = g.text.len();
        if start + text.len() > u32::MAX as usize / 2 {
            return Err(self.error(id, "more than 2 GB of strings"));
        }
        g.text.push_str(&text);
        Ok(Tok::Str(start as u32, text.len() as u32))
    }

    /// After a backslash in a string: `\\`, `\S\c`, `\P?\`, `\X\hh`,
    /// `\X2\…\X0\`, `\X4\…\X0\`, `\N\`; anything else is kept literally.
    fn directive(&mut self, out: &mut Vec<u8>, id: u64) -> Result<(), Error> {
        let rest = &self.b[self.pos..];
        let push = |out: &mut Vec<u8>, ch: char| {
            let mut buf = [0u8; 4];
            out.extend_from_slice(ch.encode_utf8(&mut buf).as_bytes());
        };
        match rest {
            [b'\\', ..] => {
                self.pos += 1;
                out.push(b'\\');
            }
            [b'S', b'\\', c, ..] => {
                self.pos += 3;
                push(out, char::from(c.wrapping_add(128)));
            }
            [b'P', _, b'\\', ..] => self.pos += 3,
            [b'N', b'\\', ..] => self.pos += 2,
            [b'X', b'\\', h, l, ..] => {
                let v = hex(*h).zip(hex(*l)).ok_or_else(|| self.error(id, "bad \\X\\ escape in a string"))?;
                self.pos += 4;
                push(out, char::from(v.0 * 16 + v.1));
            }
            [b'X', w @ (b'2' | b'4'), b'\\', ..] => {
                let width = if *w == b'2' { 4 } else { 8 };
                self.pos += 3;
                let mut units: Vec<u32> = Vec::new();
                loop {
                    if self.b.get(self.pos..self.pos + 4) == Some(b"\\X0\\") {
                        self.pos += 4;
                        break;
                    }
                    let Some(chunk) = self.b.get(self.pos..self.pos + width) else {
                        return Err(self.error(id, "\\X2\\ or \\X4\\ escape not closed by \\X0\\"));
                    };
                    let mut v = 0u32;
                    for &h in chunk {
                        let d = hex(h).ok_or_else(|| self.error(id, "bad hex digit in a \\X2\\ or \\X4\\ escape"))?;
                        v = (v << 4) | u32::from(d);
                    }
                    units.push(v);
                    self.pos += width;
                }
                if width == 4 {
                    let u16s: Vec<u16> = units.iter().map(|&u| u as u16).collect();
                    for ch in char::decode_utf16(u16s) {
                        push(out, ch.unwrap_or(char::REPLACEMENT_CHARACTER));
                    }
                } else {
                    for u in units {
                        push(out, char::from_u32(u).unwrap_or(char::REPLACEMENT_CHARACTER));
                    }
                }
            }
            _ => out.push(b'\\'),
        }
        Ok(())
    }
}

fn hex(c: u8) -> Option<u8> {
    match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'A'..=b'F' => Some(c - b'A' + 10),
        b'a'..=b'f' => Some(c - b'a' + 10),
        _ => None,
    }
}

fn parse_u64(d: &[u8]) -> Option<u64> {
    let mut v: u64 = 0;
    for &c in d {
        v = v.checked_mul(10)?.checked_add(u64::from(c - b'0'))?;
    }
    Some(v)
}

fn ascii_upper(b: &[u8]) -> String {
    b.iter().map(|c| char::from(c.to_ascii_uppercase())).collect()
}

/// Parses a whole exchange structure.
///
/// # Errors
/// A malformed file (the line and, inside the DATA section, the instance
/// named), a duplicate instance number, or a size limit.
pub(super) fn parse(bytes: &[u8]) -> Result<Graph, Error> {
    let mut g = Graph::default();
    let mut lx = Lexer { b: bytes, pos: 0, line: 1 };
    // Magic.
    match lx.next(&mut g, 0)? {
        Tok::Keyword(k) if k == "ISO-10303-21" => {}
        _ => return Err(step_error(0, lx.line, "not a STEP file: it does not start with ISO-10303-21;")),
    }
    expect(&mut lx, &mut g, 0, &Tok::Semicolon, "';' after ISO-10303-21")?;
    presize(&mut g, bytes);
    let mut scratch: Vec<Value> = Vec::new();
    let mut seen_data = false;
    loop {
        let line = lx.line;
        match lx.next(&mut g, 0)? {
            Tok::Keyword(k) if k == "HEADER" => {
                expect(&mut lx, &mut g, 0, &Tok::Semicolon, "';' after HEADER")?;
                header(&mut lx, &mut g, &mut scratch)?;
            }
            Tok::Keyword(k) if k == "DATA" => {
                // Edition 3: DATA(name, (schemas));
                let mut t = lx.next(&mut g, 0)?;
                if t == Tok::Open {
                    parse_params(&mut lx, &mut g, &mut scratch, 0)?;
                    t = lx.next(&mut g, 0)?;
                }
                if t != Tok::Semicolon {
                    return Err(step_error(0, lx.line, "';' expected after DATA"));
                }
                data(&mut lx, &mut g, &mut scratch)?;
                seen_data = true;
            }
            Tok::Keyword(k) if k == "END-ISO-10303-21" => break,
            Tok::Keyword(k) if k == "ANCHOR" || k == "REFERENCE" || k == "SIGNATURE" => {
                // Edition 3 sections this reader does not use: skip to ENDSEC.
                skip_section(&mut lx, &mut g)?;
            }
            Tok::End => {
                if seen_data {
                    break; // a missing END-ISO-10303-21 is forgiven
                }
                return Err(step_error(0, line, "the file ends before a DATA section"));
            }
            other => {
                return Err(step_error(0, line, format!("expected HEADER, DATA or END-ISO-10303-21, found {other:?}")))
            }
        }
    }
    if !seen_data {
        return Err(step_error(0, lx.line, "no DATA section"));
    }
    g.shrink();
    Ok(g)
}

/// Room for the arenas from a count of separators (every value ends at a
/// `,` or `)`, every instance at a `;`), so they are not grown by doubling:
/// in the wasm heap a grown arena held its old and new copies at once. Only
/// room that can be had, at most a value per 4 bytes of input (the densest
/// real lists, of references, take 5 or more; a file of bare commas would
/// fail at its first one), and [`Graph::shrink`] gives back what strings'
/// separators over-counted.
fn presize(g: &mut Graph, bytes: &[u8]) {
    let (mut ends, mut semis) = (0usize, 0usize);
    for &c in bytes {
        match c {
            b',' | b')' => ends += 1,
            b';' => semis += 1,
            _ => {}
        }
    }
    let _ = g.values.try_reserve_exact(ends.min(bytes.len() / 4).min(MAX_VALUES));
    let _ = g.instances.try_reserve_exact(semis);
    let _ = g.parts.try_reserve_exact(semis);
}

fn expect(lx: &mut Lexer<'_>, g: &mut Graph, id: u64, want: &Tok, what: &str) -> Result<(), Error> {
    let t = lx.next(g, id)?;
    if &t == want {
        Ok(())
    } else {
        Err(lx.error(id, format!("expected {what}, found {t:?}")))
    }
}

fn skip_section(lx: &mut Lexer<'_>, g: &mut Graph) -> Result<(), Error> {
    loop {
        match lx.next(g, 0)? {
            Tok::Keyword(k) if k == "ENDSEC" => return expect(lx, g, 0, &Tok::Semicolon, "';' after ENDSEC"),
            Tok::End => return Err(lx.error(0, "section not closed by ENDSEC")),
            _ => {}
        }
    }
}

fn header(lx: &mut Lexer<'_>, g: &mut Graph, scratch: &mut Vec<Value>) -> Result<(), Error> {
    loop {
        match lx.next(g, 0)? {
            Tok::Keyword(k) if k == "ENDSEC" => return expect(lx, g, 0, &Tok::Semicolon, "';' after ENDSEC"),
            Tok::Keyword(k) => {
                let name = g.intern(&k);
                expect(lx, g, 0, &Tok::Open, "'(' after a header entity name")?;
                let (start, len) = parse_params(lx, g, scratch, 0)?;
                g.header.push(Part { name, start, len });
                expect(lx, g, 0, &Tok::Semicolon, "';' after a header entity")?;
            }
            other => {
                return Err(lx.error(0, format!("in the HEADER section: expected an entity or ENDSEC, found {other:?}")))
            }
        }
    }
}

fn data(lx: &mut Lexer<'_>, g: &mut Graph, scratch: &mut Vec<Value>) -> Result<(), Error> {
    loop {
        let line = lx.line;
        match lx.next(g, 0)? {
            Tok::Keyword(k) if k == "ENDSEC" => return expect(lx, g, 0, &Tok::Semicolon, "';' after ENDSEC"),
            Tok::Instance(id) => {
                let line = lx.line.max(line);
                expect(lx, g, id, &Tok::Equals, "'=' after the instance number")?;
                instance(lx, g, scratch, id, line)?;
            }
            Tok::End => return Err(lx.error(0, "the DATA section is not closed by ENDSEC")),
            other => {
                return Err(lx.error(0, format!("in the DATA section: expected '#number =' or ENDSEC, found {other:?}")))
            }
        }
    }
}

/// `NAME(params);` or `(NAME(params) NAME(params) …);` after `#id =`.
fn instance(lx: &mut Lexer<'_>, g: &mut Graph, scratch: &mut Vec<Value>, id: u64, line: usize) -> Result<(), Error> {
    if g.instances.len() >= MAX_INSTANCES {
        return Err(step_error(id, line, format!("more than {MAX_INSTANCES} instances")));
    }
    let first = g.parts.len() as u32;
    match lx.next(g, id)? {
        Tok::Keyword(k) => {
            let name = g.intern(&k);
            expect(lx, g, id, &Tok::Open, "'(' after the entity name")?;
            let (start, len) = parse_params(lx, g, scratch, id)?;
            g.parts.push(Part { name, start, len });
        }
        Tok::Open => loop {
            match lx.next(g, id)? {
                Tok::Keyword(k) => {
                    let name = g.intern(&k);
                    expect(lx, g, id, &Tok::Open, "'(' after an entity name")?;
                    let (start, len) = parse_params(lx, g, scratch, id)?;
                    g.parts.push(Part { name, start, len });
                }
                Tok::Close => break,
                other => {
                    return Err(
                        lx.error(id, format!("in a complex instance: expected an entity name or ')', found {other:?}"))
                    )
                }
            }
        },
        other => return Err(lx.error(id, format!("expected an entity name, found {other:?}"))),
    }
    let count = g.parts.len() as u32 - first;
    if count == 0 {
        return Err(step_error(id, line, "complex instance without entities"));
    }
    expect(lx, g, id, &Tok::Semicolon, "';' at the end of the instance")?;
    if !g.add_instance(Instance { id, first, count, line: u32::try_from(line).unwrap_or(u32::MAX) }) {
        return Err(step_error(id, line, "instance number defined twice"));
    }
    Ok(())
}

/// What an open frame of the parameter stack is.
#[derive(Clone, Copy)]
enum Frame {
    List,
    Typed(u32),
}

/// Parses parameters after an opening parenthesis up to its matching
/// closing one; returns their range in the arena.
fn parse_params(lx: &mut Lexer<'_>, g: &mut Graph, scratch: &mut Vec<Value>, id: u64) -> Result<(u32, u32), Error> {
    // Each open frame: its kind and where its items start in `scratch`.
    let mut frames: Vec<(Frame, usize)> = alloc::vec![(Frame::List, scratch.len())];
    let base = scratch.len();
    let mut expect_value = true; // after '(' or ','
    loop {
        let t = lx.next(g, id)?;
        match t {
            Tok::Close => {
                let Some((frame, start)) = frames.pop() else {
                    return Err(lx.error(id, "unbalanced ')'"));
                };
                if expect_value && scratch.len() > start {
                    return Err(lx.error(id, "a value is missing before ')'"));
                }
                let items = scratch.len() - start;
                if g.values.len() + items > MAX_VALUES {
                    return Err(lx.error(id, format!("more than {MAX_VALUES} values in the file")));
                }
                let at = g.values.len() as u32;
                g.values.extend_from_slice(&scratch[start..]);
                scratch.truncate(start);
                if frames.is_empty() {
                    debug_assert_eq!(start, base);
                    return Ok((at, items as u32));
                }
                let v = match frame {
                    Frame::List => Value::List { start: at, len: items as u32 },
                    Frame::Typed(name) => {
                        if items != 1 {
                            return Err(
                                lx.error(id, format!("typed value {} holds {items} values, not one", g.name(name)))
                            );
                        }
                        Value::Typed { name, at }
                    }
                };
                scratch.push(v);
                expect_value = false;
                continue;
            }
            Tok::Comma => {
                if expect_value {
                    return Err(lx.error(id, "a value is missing before ','"));
                }
                expect_value = true;
                continue;
            }
            _ => {}
        }
        if !expect_value {
            return Err(lx.error(id, format!("',' or ')' expected, found {t:?}")));
        }
        expect_value = false;
        let v = match t {
            Tok::Open | Tok::Keyword(_) => {
                let frame = match t {
                    Tok::Keyword(k) => {
                        let name = g.intern(&k);
                        expect(lx, g, id, &Tok::Open, "'(' after a typed value's name")?;
                        Frame::Typed(name)
                    }
                    _ => Frame::List,
                };
                if frames.len() >= MAX_DEPTH {
                    return Err(lx.error(id, format!("lists nested deeper than {MAX_DEPTH}")));
                }
                frames.push((frame, scratch.len()));
                expect_value = true;
                continue;
            }
            Tok::Instance(r) => Value::Ref(r),
            Tok::Int(n) => Value::Int(n),
            Tok::Real(x) => Value::Real(x),
            Tok::Str(s, l) => Value::Str { start: s, len: l },
            Tok::Enum(e) => Value::Enum(g.intern(&e)),
            Tok::Binary => Value::Binary,
            Tok::Omitted => Value::Omitted,
            Tok::Derived => Value::Derived,
            Tok::End => return Err(lx.error(id, "the file ends inside an instance's parameters")),
            other => return Err(lx.error(id, format!("a value expected, found {other:?}"))),
        };
        if scratch.len() >= MAX_VALUES {
            return Err(lx.error(id, format!("more than {MAX_VALUES} values in one instance")));
        }
        scratch.push(v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::string::ToString;

    fn file(data: &str) -> String {
        format!("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n")
    }

    fn message(bytes: &[u8]) -> String {
        match parse(bytes) {
            Ok(_) => String::from("parsed"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn escapes_crlf_comments_and_raw_utf8() {
        let g = parse(include_bytes!("../../../tests/data/step_escapes.stp")).unwrap();
        let s = |id: u64, i: usize| g.get(id, 0).unwrap().attrs().string(i).unwrap().to_string();
        assert_eq!(s(1, 0), "\u{c4}\u{d6}-part");
        assert_eq!(s(1, 1), "M\u{fc}ller");
        assert_eq!(s(1, 2), "it's \\ here");
        assert_eq!(s(2, 0), "\u{1f600} \u{c4}");
        assert_eq!(s(3, 0), "Gr\u{fc}\u{df}e \u{6f22}\u{5b57}");
        assert_eq!(s(4, 0), "a string /* not a comment */ ends here");
        assert_eq!(s(5, 0), "split across lines");
        // CRLF line ends count as one line each: #5 starts on line 13.
        assert_eq!(g.line_of(5), 13);
        assert_eq!(g.get(4, 0).unwrap().attrs().refs(2).unwrap(), [2]);
        assert_eq!(g.header.len(), 3);
    }

    #[test]
    fn raw_latin1_bytes() {
        let g = parse(include_bytes!("../../../tests/data/step_latin1.stp")).unwrap();
        assert_eq!(g.get(1, 0).unwrap().attrs().string(0).unwrap(), "caf\u{e9}");
    }

    #[test]
    fn complex_instances_typed_values_and_forward_references() {
        let g = parse(include_bytes!("../../../tests/data/step_complex.stp")).unwrap();
        let u = g.get(11, 0).unwrap();
        assert!(u.is_complex() && u.has("SI_UNIT") && u.has("LENGTH_UNIT") && !u.has("PLANE_ANGLE_UNIT"));
        assert_eq!(u.part("SI_UNIT").unwrap().enumeration(0).unwrap(), "MILLI");
        assert_eq!(u.part("NAMED_UNIT").unwrap().value(0).unwrap(), Value::Derived);
        let inch = g.get(12, 0).unwrap();
        assert_eq!(inch.part("CONVERSION_BASED_UNIT").unwrap().string(0).unwrap(), "INCH");
        let m = g.get(13, 0).unwrap().attrs();
        assert_eq!(m.real(0).unwrap(), 25.4);
        assert_eq!(m.ent(1).unwrap().id(), 11);
        assert_eq!(g.get(15, 0).unwrap().attrs().real(0).unwrap(), 1e-7);
        let n = g.get(16, 0).unwrap().attrs();
        assert_eq!(n.string(0).unwrap(), "n");
        // (((( ((1,2),(3)), ((4)) )))): three single-item lists around a pair.
        let mut l = n.list(1).unwrap();
        for _ in 0..3 {
            assert_eq!(l.len(), 1);
            l = g.list(l[0]).unwrap();
        }
        assert_eq!(l.len(), 2);
        assert_eq!(g.list(g.list(l[0]).unwrap()[0]).unwrap(), [Value::Int(1), Value::Int(2)]);
        assert_eq!(n.opt_ref(2).unwrap(), None);
        assert_eq!(n.value(3).unwrap(), Value::Derived);
        assert!(n.boolean(4, false).unwrap());
        assert_eq!(n.value(5).unwrap(), Value::Binary);
        assert_eq!(n.real(6).unwrap(), -150.0);
        assert_eq!(n.int(7).unwrap(), 7);
        // #17 refers to #18, defined after it.
        let c = g.get(17, 0).unwrap().attrs();
        let pts = c.refs(2).unwrap();
        assert_eq!(pts, [10, 18]);
        assert_eq!(g.get(18, 17).unwrap().attrs().reals(1).unwrap(), [1.0, 2.0, 3.0]);
    }

    #[test]
    fn malformed_files_name_instance_and_line() {
        let m = message(include_bytes!("../../../tests/data/step_unclosed_string.stp"));
        assert_eq!(m, "STEP line 10, #7: string not closed by a quote");
        assert!(m.contains("#7") && m.contains("line 10") && m.contains("string not closed"), "{m}");
        let m = message(include_bytes!("../../../tests/data/step_duplicate_id.stp"));
        assert!(m.contains("#2") && m.contains("line 10") && m.contains("defined twice"), "{m}");
        let m = message(include_bytes!("../../../tests/data/step_unclosed_comment.stp"));
        assert!(m.contains("line 10") && m.contains("comment not closed"), "{m}");
        let m = message(include_bytes!("../../../tests/data/step_bad_token.stp"));
        assert!(m.contains("#4") && m.contains("line 10") && m.contains("'@'"), "{m}");
        let m = message(include_bytes!("../../../tests/data/step_huge_id.stp"));
        assert!(m.contains("line 10") && m.contains("instance number too large"), "{m}");
        let m = message(b"HEADER;\nENDSEC;\n");
        assert!(m.contains("ISO-10303-21"), "{m}");
        let m = message(b"ISO-10303-21;\nHEADER;\nENDSEC;\nEND-ISO-10303-21;\n");
        assert!(m.contains("no DATA section"), "{m}");
        let m = message(file("#1 = A(1);\n#4 = A(1,,2);").as_bytes());
        assert!(m.contains("#4") && m.contains("value is missing"), "{m}");
        let m = message(file("#4 = A(1").as_bytes());
        assert!(m.contains("#4"), "{m}");
    }

    #[test]
    fn instances_numbered_out_of_order_are_found_and_duplicates_refused() {
        let g = parse(file("#5 = A(#9);\n#7 = A(2);\n#2 = A(#5);\n#9 = A(3);").as_bytes()).unwrap();
        for id in [2, 5, 7, 9] {
            assert_eq!(g.get(id, 0).unwrap().id(), id);
        }
        assert!(g.find(3).is_none() && g.find(10).is_none());
        assert_eq!(g.get(2, 0).unwrap().attrs().ent(0).unwrap().attrs().ent(0).unwrap().id(), 9);
        let m = message(file("#5 = A(1);\n#2 = A(1);\n#5 = A(2);").as_bytes());
        assert!(m.contains("#5") && m.contains("defined twice"), "{m}");
        let m = message(file("#1 = A(1);\n#2 = A(1);\n#3 = A(1);\n#2 = A(2);").as_bytes());
        assert!(m.contains("#2") && m.contains("defined twice"), "{m}");
    }

    #[test]
    fn deep_nesting_is_refused_without_recursion() {
        let m = message(include_bytes!("../../../tests/data/step_deep_nesting.stp"));
        assert!(m.contains("#5") && m.contains("nested deeper than"), "{m}");
        let ok = format!("#1 = A({}1{});", "(".repeat(MAX_DEPTH - 2), ")".repeat(MAX_DEPTH - 2));
        assert!(parse(file(&ok).as_bytes()).is_ok());
    }

    #[test]
    fn a_missing_reference_is_named_where_it_is_followed() {
        let g = parse(file("#5 = A(#9);").as_bytes()).unwrap();
        let m = g.get(5, 0).unwrap().attrs().ent(0).err().unwrap().to_string();
        assert!(m.contains("#5") && m.contains("#9") && m.contains("not defined"), "{m}");
    }

    #[test]
    fn every_prefix_of_a_file_parses_or_fails_cleanly() {
        // Truncation anywhere: an error or a graph, never a panic.
        let bytes = include_bytes!("../../../tests/data/step_complex.stp");
        for n in 0..bytes.len() {
            let _ = parse(&bytes[..n]);
        }
        let bytes = include_bytes!("../../../tests/data/step_escapes.stp");
        for n in 0..bytes.len() {
            let _ = parse(&bytes[..n]);
        }
    }
}
