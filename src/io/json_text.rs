//! The JSON text of a model, read by hand into the reader's plain vectors.
//!
//! serde_json's deserializer and the serde-derived visitors of the model's
//! five record types were 63 KB of the viewer's wasm before wasm-opt, and
//! they linked a float printer's 10 KB power table that only its error
//! messages used; the schema is fixed and shallow, so a byte scanner that
//! fills the records directly does the same in a fraction of that. Numbers
//! go through `str::parse::<f64>` (correctly rounded, as the IGES and STEP
//! readers already are); a number beyond f64's range is an error, as before.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

/// A syntax or shape error at byte `at` of the text.
pub(super) struct TextError {
    /// Byte offset of the offending character (the text's length at its end).
    pub at: usize,
    /// What was wrong.
    pub message: String,
}

/// Result of one step of the scan.
pub(super) type Scan<T> = Result<T, TextError>;

/// A cursor over the text.
pub(super) struct Text<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Text<'a> {
    /// A cursor at the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, pos: 0 }
    }

    /// An error at the cursor.
    pub fn error(&self, message: impl Into<String>) -> TextError {
        TextError { at: self.pos, message: message.into() }
    }

    /// 1-based line and column of byte `at`.
    pub fn line_column(&self, at: usize) -> (usize, usize) {
        let before = self.bytes.get(..at).unwrap_or(self.bytes);
        let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
        let start = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        (line, at - start + 1)
    }

    /// The next byte after white space, not consumed.
    fn peek(&mut self) -> Option<u8> {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !matches!(b, b' ' | b'\t' | b'\n' | b'\r') {
                return Some(b);
            }
            self.pos += 1;
        }
        None
    }

    /// Consumes `c` (after white space), or fails naming it.
    fn eat(&mut self, c: u8) -> Scan<()> {
        match self.peek() {
            Some(b) if b == c => {
                self.pos += 1;
                Ok(())
            }
            Some(_) => Err(self.error(format!("expected `{}`", c as char))),
            None => Err(self.error(format!("EOF while parsing: expected `{}`", c as char))),
        }
    }

    /// Checks that only white space is left.
    pub fn end(&mut self) -> Scan<()> {
        match self.peek() {
            None => Ok(()),
            Some(_) => Err(self.error("trailing characters")),
        }
    }

    /// Consumes `null` if it comes next.
    pub fn null(&mut self) -> bool {
        let next = self.peek().map(|_| self.bytes.get(self.pos..self.pos + 4));
        if next == Some(Some(b"null")) {
            self.pos += 4;
            return true;
        }
        false
    }

    /// An object: `field` is called with each key and must read its value.
    /// A key given twice is an error, as serde's derive made it.
    pub fn object(&mut self, field: &mut dyn FnMut(&mut Self, &str) -> Scan<()>) -> Scan<()> {
        if self.peek() != Some(b'{') {
            return Err(self.error("invalid type: expected an object"));
        }
        self.pos += 1;
        let mut seen: Vec<String> = Vec::new();
        if self.peek() == Some(b'}') {
            self.pos += 1;
            return Ok(());
        }
        loop {
            let at = self.peek().map(|_| self.pos);
            let key = self.string()?;
            if seen.contains(&key) {
                return Err(TextError { at: at.unwrap_or(self.pos), message: format!("duplicate field `{key}`") });
            }
            self.eat(b':')?;
            field(self, &key)?;
            seen.push(key);
            if self.next_or_end(b'}', "an object")? {
                return Ok(());
            }
        }
    }

    /// An array: `item` is called for each element and must read it.
    pub fn array(&mut self, item: &mut dyn FnMut(&mut Self) -> Scan<()>) -> Scan<()> {
        if self.peek() != Some(b'[') {
            return Err(self.error("invalid type: expected an array"));
        }
        self.pos += 1;
        if self.peek() == Some(b']') {
            self.pos += 1;
            return Ok(());
        }
        loop {
            item(self)?;
            if self.next_or_end(b']', "a list")? {
                return Ok(());
            }
        }
    }

    /// After an object's field or an array's item: `,` before the next
    /// (false) or `end`, which closes it (true); `what` names it in the
    /// error where the text ends.
    fn next_or_end(&mut self, end: u8, what: &str) -> Scan<bool> {
        match self.peek() {
            Some(b',') => {
                self.pos += 1;
                Ok(false)
            }
            Some(b) if b == end => {
                self.pos += 1;
                Ok(true)
            }
            Some(_) => Err(self.error(format!("expected `,` or `{}`", end as char))),
            None => Err(self.error(format!("EOF while parsing {what}"))),
        }
    }

    /// An array of numbers.
    pub fn numbers(&mut self) -> Scan<Vec<f64>> {
        let mut out = Vec::new();
        self.array(&mut |t| {
            out.push(t.number()?);
            Ok(())
        })?;
        Ok(out)
    }

    /// A number (JSON's grammar), finite.
    pub fn number(&mut self) -> Scan<f64> {
        let (start, _) = self.number_token()?;
        let text = self.bytes.get(start..self.pos).and_then(|s| core::str::from_utf8(s).ok()).unwrap_or("");
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(TextError { at: start, message: "number out of range".into() }),
        }
    }

    /// A non-negative integer that fits a `usize`.
    pub fn count(&mut self) -> Scan<usize> {
        let (start, integer) = self.number_token()?;
        let text = self.bytes.get(start..self.pos).and_then(|s| core::str::from_utf8(s).ok()).unwrap_or("");
        match text.parse::<usize>() {
            Ok(n) if integer => Ok(n),
            _ => Err(TextError {
                at: start,
                message: format!("invalid value: `{text}`, expected a non-negative integer"),
            }),
        }
    }

    /// Scans one number token; its start and whether it has neither a
    /// fraction nor an exponent.
    fn number_token(&mut self) -> Scan<(usize, bool)> {
        match self.peek() {
            Some(b'-' | b'0'..=b'9') => {}
            Some(_) => return Err(self.error("invalid type: expected a number")),
            None => return Err(self.error("EOF while parsing a value")),
        }
        let start = self.pos;
        let digits = |t: &mut Self| {
            let from = t.pos;
            while t.bytes.get(t.pos).is_some_and(u8::is_ascii_digit) {
                t.pos += 1;
            }
            t.pos > from
        };
        if self.bytes.get(self.pos) == Some(&b'-') {
            self.pos += 1;
        }
        let whole = self.pos;
        let leading_zero = self.bytes.get(self.pos) == Some(&b'0');
        // JSON allows no leading zero before other digits ("01").
        let mut ok = digits(self) && !(leading_zero && self.pos - whole > 1);
        let mut integer = true;
        if self.bytes.get(self.pos) == Some(&b'.') {
            self.pos += 1;
            integer = false;
            ok &= digits(self);
        }
        if matches!(self.bytes.get(self.pos), Some(b'e' | b'E')) {
            self.pos += 1;
            integer = false;
            if matches!(self.bytes.get(self.pos), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            ok &= digits(self);
        }
        if !ok {
            return Err(self.error("invalid number"));
        }
        Ok((start, integer))
    }

    /// A string, its escapes decoded.
    pub fn string(&mut self) -> Scan<String> {
        match self.peek() {
            Some(b'"') => self.pos += 1,
            Some(_) => return Err(self.error("invalid type: expected a string")),
            None => return Err(self.error("EOF while parsing a value")),
        }
        let mut out: Vec<u8> = Vec::new();
        loop {
            let Some(&b) = self.bytes.get(self.pos) else {
                return Err(self.error("EOF while parsing a string"));
            };
            self.pos += 1;
            match b {
                b'"' => break,
                b'\\' => self.escape(&mut out)?,
                0..=0x1f => return Err(self.error("control character in a string")),
                _ => out.push(b),
            }
        }
        String::from_utf8(out).map_err(|_| self.error("invalid UTF-8 in a string"))
    }

    /// One escape after its backslash, appended to `out` as UTF-8.
    fn escape(&mut self, out: &mut Vec<u8>) -> Scan<()> {
        let Some(&b) = self.bytes.get(self.pos) else {
            return Err(self.error("EOF while parsing a string"));
        };
        self.pos += 1;
        let c = match b {
            b'"' | b'\\' | b'/' => b as char,
            b'b' => '\u{8}',
            b'f' => '\u{c}',
            b'n' => '\n',
            b'r' => '\r',
            b't' => '\t',
            b'u' => {
                let hi = self.hex4()?;
                let code = if (0xD800..0xDC00).contains(&hi) && self.bytes.get(self.pos..self.pos + 2) == Some(b"\\u") {
                    self.pos += 2;
                    let lo = self.hex4()?;
                    if !(0xDC00..0xE000).contains(&lo) {
                        return Err(self.error("invalid unicode escape"));
                    }
                    0x10000 + ((hi - 0xD800) << 10) + (lo - 0xDC00)
                } else {
                    hi
                };
                char::from_u32(code).ok_or_else(|| self.error("invalid unicode escape"))?
            }
            _ => return Err(self.error("invalid escape")),
        };
        let mut buf = [0u8; 4];
        out.extend_from_slice(c.encode_utf8(&mut buf).as_bytes());
        Ok(())
    }

    /// Four hex digits of a `\u` escape.
    fn hex4(&mut self) -> Scan<u32> {
        let digits = self.bytes.get(self.pos..self.pos + 4).and_then(|s| core::str::from_utf8(s).ok());
        let value =
            digits.and_then(|s| u32::from_str_radix(s, 16).ok().filter(|_| s.bytes().all(|c| c.is_ascii_hexdigit())));
        let value = value.ok_or_else(|| self.error("invalid unicode escape"))?;
        self.pos += 4;
        Ok(value)
    }
}
