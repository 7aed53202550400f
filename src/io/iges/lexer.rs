//! IGES records and free-format fields: the file split into its sections
//! (column 73 names the section), and the parameter tokenizer shared by the
//! Global and Parameter sections (delimiters, Hollerith strings, Fortran
//! `D` exponents).

use alloc::string::String;
use alloc::vec::Vec;

use super::{iges_error, Section};
use crate::warning::{Warning, WarningKind};
use crate::Error;

/// One 80-column record.
#[derive(Debug, Clone, Copy)]
pub(super) struct Record<'a> {
    /// 1-based line of the file.
    pub line: usize,
    /// Columns 1–72 (fewer when the line was short).
    pub data: &'a [u8],
    /// Whether the section letter sat in column 73 (fixed columns intact).
    pub fixed: bool,
}

/// The records of each section, in file order.
#[derive(Debug, Default)]
pub(super) struct Sections<'a> {
    pub global: Vec<Record<'a>>,
    pub directory: Vec<Record<'a>>,
    pub parameter: Vec<Record<'a>>,
    pub terminate: Vec<Record<'a>>,
    /// Line of a last record cut short (no section letter): the file was
    /// truncated there, and the record was dropped.
    pub truncated: Option<usize>,
    /// What was forgiven in the record layout, one warning each.
    pub notes: Vec<Warning>,
}

/// Splits `bytes` into records. Accepts LF or CRLF line ends, a missing
/// final newline, blank lines, and lines shorter than 80 columns (trailing
/// blanks dropped); the section letter is column 73, or, on a line shorter
/// than that, the letter before the trailing sequence number. Forgiven with
/// a note: records without line breaks between them (one long line of
/// 80-column records, numbered as if broken), blanks before a record that
/// push it past 80 columns, and section letters in lower case.
///
/// # Errors
/// A line with no section letter, a compressed or binary file, or sections
/// out of order.
pub(super) fn split_sections(bytes: &[u8]) -> Result<Sections<'_>, Error> {
    let mut sp = Splitter { out: Sections::default(), last: 0, lowercase: None, shifted: None };
    // The last line with content: cut short there, it is a truncated record.
    let last_line = bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .filter(|(_, l)| !l.iter().all(|b| b.is_ascii_whitespace()))
        .map(|(i, _)| i + 1)
        .last()
        .unwrap_or(0);
    let mut offset = 0; // records numbered past the physical lines, once one line held several
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = i + 1 + offset;
        let text = raw.strip_suffix(b"\r").unwrap_or(raw);
        if text.iter().all(|b| b.is_ascii_whitespace()) {
            continue;
        }
        if let Some(n) = unbroken(text) {
            sp.out.notes.push(Warning::new(WarningKind::UnbrokenRecords { line: i + 1, records: n, first: line }));
            for (k, chunk) in text.chunks(80).enumerate() {
                if !chunk.iter().all(|b| b.is_ascii_whitespace()) && !sp.record(line + k, chunk, false)? {
                    break;
                }
            }
            offset += n - 1;
            continue;
        }
        if !sp.record(line, text, i + 1 == last_line)? {
            break;
        }
    }
    if let Some((line, n)) = sp.shifted {
        sp.out.notes.push(Warning { more: n - 1, ..Warning::new(WarningKind::ShiftedRecord { line }) });
    }
    if let Some((line, n)) = sp.lowercase {
        sp.out.notes.push(Warning { more: n - 1, ..Warning::new(WarningKind::LowerCaseSection { line }) });
    }
    Ok(sp.out)
}

/// How many 80-column records a line longer than 80 columns holds when it
/// is several records without line breaks: each full 80 columns end in a
/// section letter and a sequence number.
fn unbroken(text: &[u8]) -> Option<usize> {
    if text.len() < 160 {
        return None;
    }
    let full = text.len() / 80;
    let ok = text.chunks(80).take(full).all(|c| {
        matches!(c[72].to_ascii_uppercase(), b'S' | b'G' | b'D' | b'P' | b'T')
            && c[73..80].iter().all(|b| b.is_ascii_digit() || *b == b' ')
            && c[79].is_ascii_digit()
    });
    let rest = text.len() - 80 * full;
    (ok && (rest == 0 || text[80 * full..].iter().all(|b| b.is_ascii_whitespace()) || rest >= 73))
        .then_some(full + usize::from(rest >= 73))
}

/// The state of [`split_sections`] between records.
struct Splitter<'a> {
    out: Sections<'a>,
    /// Rank of the last section seen: S < G < D < P < T.
    last: u8,
    /// First line whose section letter was in lower case, and how many.
    lowercase: Option<(usize, usize)>,
    /// First record pushed past column 80 by leading blanks, and how many.
    shifted: Option<(usize, usize)>,
}

impl<'a> Splitter<'a> {
    /// Files one record; `false` when it was the truncated last one.
    fn record(&mut self, line: usize, text: &'a [u8], last_line: bool) -> Result<bool, Error> {
        let rank = |c: u8| match c {
            b'S' => 1,
            b'G' => 2,
            b'D' => 3,
            b'P' => 4,
            b'T' => 5,
            _ => 0,
        };
        let mut text = text;
        // Blanks before a record that push its section letter past column 73.
        if text.len() > 80 && rank(text[72].to_ascii_uppercase()) == 0 {
            let lead = text.iter().take_while(|&&b| b == b' ').count();
            let k = text.len() - 80;
            if k <= lead && rank(text[72 + k].to_ascii_uppercase()) > 0 {
                text = &text[k..];
                let n = self.shifted.map_or(0, |s| s.1);
                self.shifted = Some((self.shifted.map_or(line, |s| s.0), n + 1));
            }
        }
        let (letter, data, fixed) = if text.len() >= 73 {
            (text[72], &text[..72], true)
        } else {
            match short_record(text) {
                Some((letter, cut)) => (letter, &text[..cut], false),
                None if last_line && self.last >= 3 => {
                    self.out.truncated = Some(line);
                    return Ok(false);
                }
                None => {
                    return Err(iges_error(
                        Section::Unknown,
                        line,
                        0,
                        "no section letter (S, G, D, P or T) in column 73: not an 80-column IGES record",
                    ))
                }
            }
        };
        let letter = if rank(letter) == 0 && rank(letter.to_ascii_uppercase()) > 0 {
            let n = self.lowercase.map_or(0, |s| s.1);
            self.lowercase = Some((self.lowercase.map_or(line, |s| s.0), n + 1));
            letter.to_ascii_uppercase()
        } else {
            letter
        };
        let r = rank(letter);
        if r == 0 {
            let message = match letter {
                b'C' => "compressed IGES (section letter C) is not supported".into(),
                b'B' => "binary IGES (section letter B) is not supported".into(),
                other => alloc::format!("unknown section letter '{}' in column 73", char::from(other).escape_default()),
            };
            return Err(iges_error(Section::Unknown, line, 0, message));
        }
        if r < self.last {
            return Err(iges_error(
                Section::from_letter(letter),
                line,
                0,
                "section out of order (expected Start, Global, Directory, Parameter, Terminate)",
            ));
        }
        self.last = r;
        let rec = Record { line, data, fixed };
        match letter {
            b'G' => self.out.global.push(rec),
            b'D' => self.out.directory.push(rec),
            b'P' => self.out.parameter.push(rec),
            b'T' => self.out.terminate.push(rec),
            _ => {}
        }
        Ok(true)
    }
}

/// On a line shorter than 73 columns: the section letter followed by
/// blanks and digits at its end. Returns the letter and where the data ends.
fn short_record(text: &[u8]) -> Option<(u8, usize)> {
    let mut end = text.len();
    while end > 0 && text[end - 1].is_ascii_whitespace() {
        end -= 1;
    }
    let digits_end = end;
    while end > 0 && text[end - 1].is_ascii_digit() {
        end -= 1;
    }
    if end == digits_end {
        return None;
    }
    while end > 0 && text[end - 1] == b' ' {
        end -= 1;
    }
    let letter = *text.get(end.checked_sub(1)?)?;
    matches!(letter.to_ascii_uppercase(), b'S' | b'G' | b'D' | b'P' | b'T' | b'C' | b'B').then_some((letter, end - 1))
}

/// One free-format field.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Value {
    /// Nothing between two delimiters: the field's default.
    Empty,
    /// An integer.
    Int(i64),
    /// A real number.
    Real(f64),
    /// A Hollerith string.
    Str(String),
}

/// Splits one record of free-format data (all lines of one entity, or the
/// whole Global section) into fields, up to the record delimiter.
pub(super) struct Tokenizer<'a> {
    text: &'a [u8],
    pos: usize,
    pub param: u8,
    pub record: u8,
    /// Whether [`Tokenizer::fields`] stopped at the record delimiter (not at the end of the text).
    pub ended: bool,
}

impl<'a> Tokenizer<'a> {
    pub fn new(text: &'a [u8], param: u8, record: u8) -> Self {
        Self { text, pos: 0, param, record, ended: false }
    }

    fn skip_blanks(&mut self) {
        while self.pos < self.text.len() && self.text[self.pos] == b' ' {
            self.pos += 1;
        }
    }

    /// The Global section's first two fields: the delimiters, each either
    /// empty (defaults `,` and `;`) or a `1H` string.
    pub fn read_delimiters(&mut self) -> Result<(), LexError> {
        self.skip_blanks();
        if self.text.get(self.pos) == Some(&b',') {
            self.param = b',';
            self.pos += 1;
        } else {
            let c = self.one_char_string(1)?;
            self.param = c;
            self.skip_blanks();
            if self.text.get(self.pos) != Some(&c) {
                return Err(LexError::NoDelimiterAfter(1));
            }
            self.pos += 1;
        }
        self.skip_blanks();
        match self.text.get(self.pos) {
            Some(&c) if c == self.param => {
                self.record = b';';
                self.pos += 1;
            }
            Some(b';') => self.record = b';',
            _ => {
                let c = self.one_char_string(2)?;
                self.record = c;
                self.skip_blanks();
                match self.text.get(self.pos) {
                    Some(&d) if d == self.param => self.pos += 1,
                    Some(&d) if d == self.record => {}
                    _ => return Err(LexError::NoDelimiterAfter(2)),
                }
            }
        }
        if self.param == self.record || self.param == b' ' || self.record == b' ' {
            return Err(LexError::BadDelimiters);
        }
        Ok(())
    }

    /// `1Hc` at the cursor.
    fn one_char_string(&mut self, field: usize) -> Result<u8, LexError> {
        let t = &self.text[self.pos..];
        if t.len() >= 3 && t[0] == b'1' && (t[1] == b'H' || t[1] == b'h') {
            self.pos += 3;
            return Ok(t[2]);
        }
        Err(LexError::DelimiterNotString(field))
    }

    /// All fields up to the record delimiter (or the end of the text).
    /// `max` caps the count (the caller's limit).
    pub fn fields(&mut self, max: usize) -> Result<Vec<Value>, LexError> {
        let mut out = Vec::new();
        let mut after_delim = false;
        loop {
            self.skip_blanks();
            let Some(&c) = self.text.get(self.pos) else {
                if after_delim {
                    out.push(Value::Empty);
                }
                return Ok(out);
            };
            if out.len() >= max {
                return Err(LexError::TooMany(max));
            }
            if c == self.record {
                if after_delim {
                    out.push(Value::Empty);
                }
                self.ended = true;
                return Ok(out);
            }
            if c == self.param {
                out.push(Value::Empty);
                self.pos += 1;
                after_delim = true;
                continue;
            }
            let v = self.field(out.len() + 1)?;
            out.push(v);
            self.skip_blanks();
            match self.text.get(self.pos) {
                None => return Ok(out),
                Some(&d) if d == self.record => {
                    self.ended = true;
                    return Ok(out);
                }
                Some(&d) if d == self.param => {
                    self.pos += 1;
                    after_delim = true;
                }
                Some(&d) => return Err(LexError::AfterValue { index: out.len(), found: char::from(d) }),
            }
        }
    }

    /// One non-empty field starting at `pos`.
    fn field(&mut self, index: usize) -> Result<Value, LexError> {
        let t = &self.text[self.pos..];
        let digits = t.iter().take_while(|b| b.is_ascii_digit()).count();
        if digits > 0 && matches!(t.get(digits), Some(b'H' | b'h')) {
            let n: usize = core::str::from_utf8(&t[..digits])
                .ok()
                .and_then(|s| s.parse().ok())
                .ok_or(LexError::BadStringLength(index))?;
            let start = digits + 1;
            let body = t.get(start..start.saturating_add(n)).ok_or(LexError::StringPastEnd { index, length: n })?;
            self.pos += start + n;
            return Ok(Value::Str(body.iter().map(|&b| char::from(b)).collect()));
        }
        let len = t.iter().take_while(|&&b| b != self.param && b != self.record).count();
        self.pos += len;
        let raw = &t[..len];
        parse_number(raw).ok_or_else(|| {
            let shown: String = raw.iter().take(24).map(|&b| char::from(b)).collect();
            LexError::NotANumber { index, shown: shown.trim().into() }
        })
    }
}

/// Why the Global section's delimiters or an entity's parameters could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum LexError {
    /// Field 1 or 2 of the Global section not followed by a delimiter.
    NoDelimiterAfter(usize),
    /// The delimiters are one character or blank.
    BadDelimiters,
    /// A delimiter field that is neither empty nor a `1H` string.
    DelimiterNotString(usize),
    /// More parameters than the limit.
    TooMany(usize),
    /// Something other than a delimiter after parameter `index`.
    AfterValue {
        /// The parameter (1-based).
        index: usize,
        /// What follows it.
        found: char,
    },
    /// A Hollerith string whose length is not a number.
    BadStringLength(usize),
    /// A Hollerith string running past the data.
    StringPastEnd {
        /// The parameter (1-based).
        index: usize,
        /// Its stated length.
        length: usize,
    },
    /// A parameter that is not a number (its first characters).
    NotANumber {
        /// The parameter (1-based).
        index: usize,
        /// Its text, cut at 24 characters.
        shown: String,
    },
}

impl core::fmt::Display for LexError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NoDelimiterAfter(1) => write!(f, "field 1: expected the parameter delimiter after it"),
            Self::NoDelimiterAfter(k) => write!(f, "field {k}: expected a delimiter after it"),
            Self::BadDelimiters => write!(f, "the parameter and record delimiters must differ and not be blank"),
            Self::DelimiterNotString(k) => write!(f, "field {k} (a delimiter) must be empty or a 1H string"),
            Self::TooMany(max) => write!(f, "more than {max} parameters"),
            Self::AfterValue { index, found } => {
                write!(f, "parameter {index}: unexpected '{}' after the value", found.escape_default())
            }
            Self::BadStringLength(index) => write!(f, "parameter {index}: bad string length"),
            Self::StringPastEnd { index, length } => {
                write!(f, "parameter {index}: string of {length} characters runs past the end of the entity's data")
            }
            Self::NotANumber { index, shown } => write!(f, "parameter {index}: '{shown}' is not a number"),
        }
    }
}

/// An integer or real in IGES syntax (blanks ignored; `D` or `E` exponent).
pub(super) fn parse_number(raw: &[u8]) -> Option<Value> {
    let mut s = String::with_capacity(raw.len());
    for &b in raw {
        match b {
            b' ' => {}
            b'D' | b'd' | b'e' => s.push('E'),
            b'0'..=b'9' | b'+' | b'-' | b'.' | b'E' => s.push(char::from(b)),
            _ => return None,
        }
    }
    if s.is_empty() {
        return Some(Value::Empty);
    }
    if !s.contains(['.', 'E']) {
        if let Ok(i) = s.parse::<i64>() {
            return Some(Value::Int(i));
        }
    }
    let x: f64 = s.parse().ok()?;
    x.is_finite().then_some(Value::Real(x))
}
