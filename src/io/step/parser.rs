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
//!
//! What real writers get wrong and a reader can still make sense of is
//! forgiven with one warning per kind ([`Graph::forgiven`]): a repeated
//! instance number (the first definition is kept), a malformed escape (its
//! raw text is kept), an apostrophe not doubled inside a string (a string
//! ends only at a quote followed by `,` or `)`), a damaged HEADER section
//! ([`header`]). Anything else malformed is an error naming its line.

use alloc::borrow::Cow;
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use super::graph::{Graph, Instance, Part, Value};
use super::step_error;
use crate::Error;

mod header;

/// Deepest nesting of lists and typed values inside one instance.
pub(super) const MAX_DEPTH: usize = 32;
/// Most values (of all instances together).
pub(super) const MAX_VALUES: usize = 1 << 26;
/// Most instances.
pub(super) const MAX_INSTANCES: usize = 1 << 24;

/// A token. Keywords and enumerations are upper case: the file's own text
/// when it is written so (as writers do), else an upper-case copy, so a
/// token costs no allocation.
#[derive(Debug, Clone, PartialEq)]
enum Tok<'a> {
    Keyword(Cow<'a, str>),
    Instance(u64),
    Int(i64),
    Real(f64),
    /// Decoded string: `len` bytes at the end of the graph's text.
    Str(u32, u32),
    Enum(Cow<'a, str>),
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

/// A token as an error message names it ("found `(`", "found the keyword
/// `ENDSEC`"), as the file spells it rather than as the derived `Debug`
/// (`Keyword("ENDSEC")`), which is left to tests: the wasm module no longer
/// carries the derived formatter for these messages.
impl core::fmt::Display for Tok<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Keyword(k) => write!(f, "the keyword `{k}`"),
            Self::Instance(n) => write!(f, "the instance name `#{n}`"),
            Self::Int(n) => write!(f, "the integer `{n}`"),
            Self::Real(x) => write!(f, "the real `{x}`"),
            Self::Str(..) => f.write_str("a string"),
            Self::Enum(e) => write!(f, "the enumeration `.{e}.`"),
            Self::Binary => f.write_str("a binary"),
            Self::Omitted => f.write_str("`$`"),
            Self::Derived => f.write_str("`*`"),
            Self::Open => f.write_str("`(`"),
            Self::Close => f.write_str("`)`"),
            Self::Comma => f.write_str("`,`"),
            Self::Semicolon => f.write_str("`;`"),
            Self::Equals => f.write_str("`=`"),
            Self::End => f.write_str("the end of the file"),
        }
    }
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

    fn next(&mut self, g: &mut Graph, id: u64) -> Result<Tok<'a>, Error> {
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
                    k.to_mut().insert(0, '!');
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

    fn number(&mut self, id: u64) -> Result<Tok<'a>, Error> {
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
    fn string(&mut self, g: &mut Graph, id: u64) -> Result<Tok<'a>, Error> {
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
                    } else if self.ends_string() {
                        break;
                    } else {
                        // A string is a parameter: what follows its closing quote is a
                        // separator. A quote before anything else is one its writer did
                        // not double; it stays in the text.
                        let line = self.line;
                        g.forgiven.note("apostrophe", || {
                            let m = "a lone apostrophe inside a string (not doubled); kept in the text";
                            step_error(id, line, m)
                        });
                        out.push(b'\'');
                    }
                }
                b'\n' => self.line += 1,
                b'\r' => {}
                b'\\' => self.directive(&mut out, g, id),
                _ => out.push(c),
            }
        }
        // Raw bytes above 127 are UTF-8 where they decode as such, else ISO 8859-1 (the standard's default).
        let start = g.text.len();
        let len = match core::str::from_utf8(&out) {
            Ok(t) => t.len(),
            Err(_) => out.iter().map(|&b| char::from(b).len_utf8()).sum(),
        };
        if start + len > u32::MAX as usize / 2 {
            return Err(self.error(id, "more than 2 GB of strings"));
        }
        match core::str::from_utf8(&out) {
            Ok(t) => g.text.push_str(t),
            Err(_) => g.text.extend(out.iter().map(|&b| char::from(b))),
        }
        Ok(Tok::Str(start as u32, len as u32))
    }

    /// After a quote in a string: whether the string ends there, that is
    /// whether a `,` or `)` (or a comment, or the end of the file) follows
    /// past any blanks.
    fn ends_string(&self) -> bool {
        let mut i = self.pos;
        while self.b.get(i).is_some_and(|c| c.is_ascii_whitespace()) {
            i += 1;
        }
        match self.b.get(i) {
            None | Some(b',' | b')') => true,
            Some(b'/') => self.b.get(i + 1) == Some(&b'*'),
            Some(_) => false,
        }
    }

    /// After a backslash in a string: `\\`, `\S\c`, `\P?\`, `\X\hh`,
    /// `\X2\…\X0\`, `\X4\…\X0\`, `\N\`; anything else is kept literally.
    /// A malformed escape (a bad hex digit, a `\X2\` run the string ends
    /// inside) keeps what decoded and leaves the rest as raw text, with a
    /// note naming the line and instance.
    fn directive(&mut self, out: &mut Vec<u8>, g: &mut Graph, id: u64) {
        let rest = &self.b[self.pos..];
        let push = |out: &mut Vec<u8>, ch: char| {
            let mut buf = [0u8; 4];
            out.extend_from_slice(ch.encode_utf8(&mut buf).as_bytes());
        };
        let line = self.line;
        let mut note = |kind: &'static str, message: &str| {
            g.forgiven.note(kind, || step_error(id, line, format!("{message}; kept as raw text")));
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
            [b'X', b'\\', h, l, ..] if hex(*h).is_some() && hex(*l).is_some() => {
                let v = hex(*h).unwrap_or(0) * 16 + hex(*l).unwrap_or(0);
                self.pos += 4;
                push(out, char::from(v));
            }
            [b'X', b'\\', ..] => {
                note("escape-x", "bad hex digit in a \\X\\ escape");
                out.push(b'\\');
            }
            [b'X', w @ (b'2' | b'4'), b'\\', ..] => {
                let width = if *w == b'2' { 4 } else { 8 };
                let start = self.pos;
                self.pos += 3;
                let mut units: Vec<u32> = Vec::new();
                loop {
                    if self.b.get(self.pos..self.pos + 4) == Some(b"\\X0\\") {
                        self.pos += 4;
                        break;
                    }
                    let chunk = self.b.get(self.pos..(self.pos + width).min(self.b.len())).unwrap_or(&[]);
                    match chunk.iter().find(|&&h| hex(h).is_none()) {
                        None if chunk.len() == width => {
                            units.push(chunk.iter().fold(0u32, |v, &h| (v << 4) | u32::from(hex(h).unwrap_or(0))));
                            self.pos += width;
                            continue;
                        }
                        // The string (or the file) ends, or another directive starts, inside the run.
                        None | Some(b'\'' | b'\\') => {
                            note("escape-open", "\\X2\\ or \\X4\\ escape not closed by \\X0\\");
                        }
                        Some(_) => note("escape-hex", "bad hex digit in a \\X2\\ or \\X4\\ escape"),
                    }
                    if units.is_empty() {
                        // Nothing decoded: the escape itself stays as it was written.
                        self.pos = start;
                        out.push(b'\\');
                        return;
                    }
                    break;
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

/// An ASCII word in upper case: borrowed when it already is (`b` holds
/// only ASCII letters, digits, `_` and `-`, as the lexer takes them).
fn ascii_upper(b: &[u8]) -> Cow<'_, str> {
    match core::str::from_utf8(b) {
        Ok(s) if !b.iter().any(u8::is_ascii_lowercase) => Cow::Borrowed(s),
        _ => Cow::Owned(b.iter().map(|c| char::from(c.to_ascii_uppercase())).collect()),
    }
}

/// Parses a whole exchange structure.
///
/// # Errors
/// A malformed file (the line and, inside the DATA section, the instance
/// named) or a size limit.
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
    let mut seen_header = false;
    loop {
        let line = lx.line;
        match lx.next(&mut g, 0)? {
            Tok::Keyword(k) if k == "HEADER" => {
                expect(&mut lx, &mut g, 0, &Tok::Semicolon, "';' after HEADER")?;
                header::header(&mut lx, &mut g, &mut scratch);
                seen_header = true;
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
                return Err(step_error(0, line, format!("expected HEADER, DATA or END-ISO-10303-21, found {other}")))
            }
        }
    }
    if !seen_data {
        return Err(step_error(0, lx.line, "no DATA section"));
    }
    if !seen_header {
        g.forgiven.note("header", || step_error(0, 0, "no HEADER section; the DATA section is read anyway"));
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
    // Branch-free sums, which the compiler vectorizes.
    let (mut ends, mut semis) = (0usize, 0usize);
    for &c in bytes {
        ends += usize::from((c == b',') | (c == b')'));
        semis += usize::from(c == b';');
    }
    let _ = g.values.try_reserve_exact(ends.min(bytes.len() / 4).min(MAX_VALUES));
    let _ = g.instances.try_reserve_exact(semis);
    let _ = g.parts.try_reserve_exact(semis);
}

fn expect(lx: &mut Lexer<'_>, g: &mut Graph, id: u64, want: &Tok<'_>, what: &str) -> Result<(), Error> {
    let t = lx.next(g, id)?;
    if &t == want {
        Ok(())
    } else {
        Err(lx.error(id, format!("expected {what}, found {t}")))
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
                return Err(lx.error(0, format!("in the DATA section: expected '#number =' or ENDSEC, found {other}")))
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
                        lx.error(id, format!("in a complex instance: expected an entity name or ')', found {other}"))
                    )
                }
            }
        },
        other => return Err(lx.error(id, format!("expected an entity name, found {other}"))),
    }
    let count = g.parts.len() as u32 - first;
    if count == 0 {
        return Err(step_error(id, line, "complex instance without entities"));
    }
    expect(lx, g, id, &Tok::Semicolon, "';' at the end of the instance")?;
    if !g.add_instance(Instance { id, first, count, line: u32::try_from(line).unwrap_or(u32::MAX) }) {
        // The first definition is kept: references read before this one
        // already meant it, and writers that repeat a number repeat the same entity.
        g.parts.truncate(first as usize);
        let before = g.line_of(id);
        g.forgiven.note("duplicate", || {
            let m = format!("instance number defined twice; the first definition (line {before}) is kept");
            step_error(id, line, m)
        });
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
    // Each open frame: its kind and where its items start in `scratch`
    // (`frames[..depth]`, on the stack: no allocation per instance).
    let mut frames = [(Frame::List, 0usize); MAX_DEPTH + 1];
    frames[0].1 = scratch.len();
    let mut depth: usize = 1;
    let base = scratch.len();
    let mut expect_value = true; // after '(' or ','
    loop {
        let t = lx.next(g, id)?;
        match t {
            Tok::Close => {
                let Some(&(frame, start)) = depth.checked_sub(1).and_then(|d| frames.get(d)) else {
                    return Err(lx.error(id, "unbalanced ')'"));
                };
                depth -= 1;
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
                if depth == 0 {
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
            return Err(lx.error(id, format!("',' or ')' expected, found {t}")));
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
                let Some(slot) = frames.get_mut(depth).filter(|_| depth < MAX_DEPTH) else {
                    return Err(lx.error(id, format!("lists nested deeper than {MAX_DEPTH}")));
                };
                *slot = (frame, scratch.len());
                depth += 1;
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
            other => return Err(lx.error(id, format!("a value expected, found {other}"))),
        };
        if scratch.len() >= MAX_VALUES {
            return Err(lx.error(id, format!("more than {MAX_VALUES} values in one instance")));
        }
        scratch.push(v);
    }
}

#[cfg(test)]
mod tests;
