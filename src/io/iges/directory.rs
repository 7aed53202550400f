//! Directory entries (two fixed-column records per entity) and each
//! entity's parameter data, with checked accessors: every count read from
//! the file is checked against the data actually present before anything is
//! allocated from it.

use alloc::string::String;
use alloc::vec::Vec;

use super::lexer::{Record, Tokenizer, Value};
use super::{iges_error, Notes, Section, MAX_ENTITIES, MAX_PARAMS};
use crate::warning::{Warning, WarningKind};
use crate::Error;

/// One entity: its directory entry fields and parameters.
#[derive(Debug, Clone)]
pub(super) struct Entity {
    /// Directory entry number (sequence number of its first D record, odd).
    pub de: usize,
    /// Entity type number.
    pub kind: u32,
    /// Form number.
    pub form: i64,
    /// Pointer to the transformation matrix (0: none).
    pub xform: usize,
    /// Subordinate switch of the status number (0 independent, 1 physically,
    /// 2 logically dependent, 3 both).
    pub subordinate: u8,
    /// Blank status of the status number: the entity is hidden (not to be displayed).
    pub blanked: bool,
    /// File line of its first P record.
    pub pline: usize,
    /// Parameters; `params[0]` is the entity type.
    pub params: Vec<Value>,
    /// Why its parameter data could not be read (the entity is then
    /// skipped, and so is whatever needs it): reported once, by the directory.
    pub damage: Option<Error>,
}

/// All entities, indexed by `(de - 1) / 2`.
#[derive(Debug, Default)]
pub(super) struct Directory {
    pub entities: Vec<Entity>,
    /// What was forgiven or skipped, one warning per kind.
    pub notes: Vec<Warning>,
}

impl Directory {
    /// Parses the D and P sections with the file's delimiters.
    ///
    /// # Errors
    /// Odd record counts, shifted columns, non-numeric fields, parameter
    /// data lines that are missing or belong to another entity type.
    pub fn parse(d: &[Record<'_>], p: &[Record<'_>], param: u8, record: u8) -> Result<Self, Error> {
        let mut notes = Notes::default();
        let d = if d.len() % 2 != 0 && d.len() > 1 {
            // The last entry lost its second line (a truncated file): the others stand.
            let line = d.last().map_or(0, |r| r.line);
            notes.note("odd", 0, || {
                let m = "odd number of directory records: the last entry's second line is missing \
                         (file truncated?); that entry is skipped";
                Warning::new(WarningKind::Forgiven(iges_error(Section::Directory, line, d.len(), m)))
            });
            &d[..d.len() - 1]
        } else if d.len() % 2 != 0 {
            let line = d.last().map_or(0, |r| r.line);
            return Err(iges_error(
                Section::Directory,
                line,
                d.len(),
                "odd number of directory records: an entry's second line is missing (file truncated?)",
            ));
        } else {
            d
        };
        if d.len() / 2 > MAX_ENTITIES {
            return Err(iges_error(
                Section::Directory,
                0,
                0,
                alloc::format!("{} entities, more than the limit of {MAX_ENTITIES}", d.len() / 2),
            ));
        }
        let mut entities = Vec::with_capacity(d.len() / 2);
        for (k, pair) in d.chunks_exact(2).enumerate() {
            let de = 2 * k + 1;
            let (a, b) = (&pair[0], &pair[1]);
            for r in [a, b] {
                if !r.fixed {
                    return Err(iges_error(
                        Section::Directory,
                        r.line,
                        de,
                        "record shorter than 73 columns: directory fields are in fixed columns (shifted columns?)",
                    ));
                }
            }
            let field = |r: &Record<'_>, i: usize| -> Result<i64, Error> {
                let raw = r.data.get(8 * i..8 * i + 8).unwrap_or(&[]);
                let s = core::str::from_utf8(raw).unwrap_or("?").trim();
                if s.is_empty() {
                    return Ok(0);
                }
                s.parse::<i64>().map_err(|_| {
                    iges_error(
                        Section::Directory,
                        r.line,
                        de,
                        alloc::format!(
                            "field {} (columns {}-{}): '{s}' is not an integer",
                            i + 1,
                            8 * i + 1,
                            8 * i + 8
                        ),
                    )
                })
            };
            let kind = field(a, 0)?;
            let kind2 = field(b, 0)?;
            if kind != kind2 || kind <= 0 || kind > 10_000 {
                return Err(iges_error(
                    Section::Directory,
                    a.line,
                    de,
                    alloc::format!(
                        "entity type {kind} on the first line and {kind2} on the second (shifted or missing line)"
                    ),
                ));
            }
            let pstart = field(a, 1)?;
            let xform = field(a, 6)?;
            let status = a.data.get(64..72).unwrap_or(&[]);
            let digit = |i: usize| status.get(i).filter(|c| c.is_ascii_digit()).map_or(0, |c| c - b'0');
            let subordinate = digit(2) * 10 + digit(3);
            let blanked = digit(0) * 10 + digit(1) == 1;
            let pcount = field(b, 3)?;
            let form = field(b, 4)?;
            let (pline, params, damage) = match parameters(p, de, kind, pstart, pcount, param, record, &mut notes) {
                Ok((pline, params)) => (pline, params, None),
                Err((damage, err)) => {
                    notes.note(damage.key(), de, || Warning::new(WarningKind::EntityDamaged(err.clone())));
                    (0, alloc::vec![Value::Int(kind)], Some(err))
                }
            };
            entities.push(Entity {
                de,
                kind: kind as u32,
                form,
                xform: usize::try_from(xform.max(0)).unwrap_or(0),
                subordinate,
                blanked,
                pline,
                params,
                damage,
            });
        }
        Ok(Self { entities, notes: notes.warnings() })
    }

    /// The entity with directory entry number `de`, if there is one.
    pub fn get(&self, de: usize) -> Option<&Entity> {
        if de % 2 == 0 {
            return None;
        }
        self.entities.get((de - 1) / 2)
    }
}

/// What is wrong with an entity's parameter data, so each kind is one warning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Damage {
    /// The pointer to its data is outside the Parameter section.
    Pointer,
    /// Its data names another entity type than its directory entry.
    Type,
    /// Its data ends without the record delimiter.
    Unended,
    /// A field that cannot be read.
    Syntax,
}

impl Damage {
    /// The key its warnings are gathered under.
    fn key(self) -> &'static str {
        match self {
            Self::Pointer => "pointer",
            Self::Type => "type",
            Self::Unended => "unended",
            Self::Syntax => "syntax",
        }
    }
}

/// The parameters of entity `de`: P records from `pstart`, `pcount` of
/// them, and on past the count while the records still point back to `de`
/// and its data has not ended (a count too small); columns 1–64 joined and
/// split into fields up to the record delimiter. A count that runs past the
/// Parameter section is forgiven with a note when the data ends (`;`) before
/// the section does.
#[allow(clippy::too_many_arguments)]
fn parameters(
    p: &[Record<'_>],
    de: usize,
    kind: i64,
    pstart: i64,
    pcount: i64,
    param: u8,
    record: u8,
    notes: &mut Notes,
) -> Result<(usize, Vec<Value>), (Damage, Error)> {
    let bad = |message: String| (Damage::Pointer, iges_error(Section::Directory, 0, de, message));
    let first = usize::try_from(pstart).ok().filter(|&s| s >= 1 && s <= p.len()).ok_or_else(|| {
        bad(alloc::format!(
            "parameter data pointer {pstart} is outside the Parameter section's {} lines (file truncated?)",
            p.len()
        ))
    })?;
    let count = if pcount > 0 {
        usize::try_from(pcount).unwrap_or(usize::MAX)
    } else {
        p[first - 1..].iter().take_while(|r| back_pointer(r) == Some(de)).count().max(1)
    };
    let by_count = first.saturating_add(count - 1);
    let mut last = by_count.min(p.len());
    let pline = p[first - 1].line;
    let read = |last: usize| {
        let mut text: Vec<u8> = Vec::with_capacity((last + 1 - first) * 64);
        for r in &p[first - 1..last] {
            text.extend_from_slice(content(r));
        }
        let mut tok = Tokenizer::new(&text, param, record);
        let params =
            tok.fields(MAX_PARAMS).map_err(|m| (Damage::Syntax, iges_error(Section::Parameter, pline, de, m)))?;
        Ok::<_, (Damage, Error)>((params, tok.ended))
    };
    let (mut params, mut ended) = read(last)?;
    if !ended {
        // A count too small: the lines after it that still point back here.
        let more = p[last..].iter().take_while(|r| back_pointer(r) == Some(de)).count();
        if more > 0 {
            last += more;
            (params, ended) = read(last)?;
        }
    }
    if !ended {
        return Err((
            Damage::Unended,
            iges_error(
                Section::Parameter,
                pline,
                de,
                alloc::format!(
                    "parameter data on lines {first}..{last} end without the record delimiter ';' (file truncated?)"
                ),
            ),
        ));
    }
    if by_count > p.len() {
        notes.note("overrun", de, || {
            let m = alloc::format!(
                "parameter data lines {first}..{by_count} run past the Parameter section's {} lines; \
                 read up to the entity's ';'",
                p.len()
            );
            Warning::new(WarningKind::Forgiven(iges_error(Section::Directory, 0, de, m)))
        });
    }
    // Every entity's parameters are held until the faces are built: no
    // room left over from growing (a quarter of the list on average).
    params.shrink_to_fit();
    match params.first() {
        Some(Value::Int(k)) if *k == kind => Ok((pline, params)),
        other => Err((
            Damage::Type,
            iges_error(
                Section::Parameter,
                pline,
                de,
                alloc::format!(
                    "parameter data start with {} but the directory entry says type {kind} (bad pointer?)",
                    match other {
                        Some(Value::Int(k)) => alloc::format!("type {k}"),
                        _ => "no entity type".into(),
                    }
                ),
            ),
        )),
    }
}

/// Columns 1–64 of a P record (its data; 65–72 hold the back pointer).
fn content<'a>(r: &Record<'a>) -> &'a [u8] {
    if r.fixed {
        return &r.data[..r.data.len().min(64)];
    }
    // A short line: drop a trailing back pointer (blanks then digits).
    let d = r.data;
    let mut end = d.len();
    while end > 0 && d[end - 1] == b' ' {
        end -= 1;
    }
    let digits_end = end;
    while end > 0 && d[end - 1].is_ascii_digit() {
        end -= 1;
    }
    if end < digits_end && end > 0 && d[end - 1] == b' ' {
        &d[..end]
    } else {
        &d[..d.len().min(64)]
    }
}

/// The directory entry a P record points back to (columns 65–72).
fn back_pointer(r: &Record<'_>) -> Option<usize> {
    let raw = r.data.get(64..72)?;
    core::str::from_utf8(raw).ok()?.trim().parse().ok()
}

impl Entity {
    /// An error about this entity's parameter data.
    pub fn error(&self, message: impl core::fmt::Display) -> Error {
        iges_error(Section::Parameter, self.pline, self.de, message)
    }

    fn value(&self, i: usize) -> &Value {
        self.params.get(i).unwrap_or(&Value::Empty)
    }

    /// Parameter `i` as an integer (blank: 0; a real with an integral value is accepted).
    pub fn int(&self, i: usize) -> Result<i64, Error> {
        match self.value(i) {
            Value::Empty => Ok(0),
            Value::Int(v) => Ok(*v),
            Value::Real(x) if libm::trunc(*x) == *x && x.abs() < 9.0e15 => Ok(*x as i64),
            _ => Err(self.error(alloc::format!("parameter {i} (type {}) should be an integer", self.kind))),
        }
    }

    /// Parameter `i` as a real, `default` when blank.
    pub fn real_or(&self, i: usize, default: f64) -> Result<f64, Error> {
        match self.value(i) {
            Value::Empty => Ok(default),
            Value::Int(v) => Ok(*v as f64),
            Value::Real(x) => Ok(*x),
            Value::Str(_) => Err(self.error(alloc::format!("parameter {i} (type {}) should be a number", self.kind))),
        }
    }

    /// Parameter `i` as a real (blank: 0).
    pub fn real(&self, i: usize) -> Result<f64, Error> {
        self.real_or(i, 0.0)
    }

    /// Three reals from parameter `i` on.
    pub fn vec3(&self, i: usize) -> Result<glam::DVec3, Error> {
        Ok(glam::DVec3::new(self.real(i)?, self.real(i + 1)?, self.real(i + 2)?))
    }

    /// Parameter `i` as a pointer to another entity (`None` for 0 or blank;
    /// a negative pointer is read as its absolute value).
    pub fn ptr(&self, i: usize) -> Result<Option<usize>, Error> {
        let v = self.int(i)?;
        Ok((v != 0).then(|| usize::try_from(v.unsigned_abs()).unwrap_or(usize::MAX)))
    }

    /// Parameter `i` as a string, if it is one.
    pub fn string(&self, i: usize) -> Option<&str> {
        match self.value(i) {
            Value::Str(s) => Some(s),
            _ => None,
        }
    }

    /// A count at parameter `i` of items `per` parameters long that start at
    /// parameter `from`: checked against the parameters present, so a hostile
    /// count cannot make the reader allocate more than the file holds.
    pub fn count(&self, i: usize, per: usize, from: usize) -> Result<usize, Error> {
        let n = self.int(i)?;
        let have = self.params.len().saturating_sub(from);
        let ok = usize::try_from(n).ok().filter(|&n| n.saturating_mul(per) <= have);
        ok.ok_or_else(|| {
            self.error(alloc::format!(
                "count {n} at parameter {i} needs {} parameters after it, only {have} present",
                if n < 0 { "a non-negative count of".into() } else { alloc::format!("{}", (n as u128) * per as u128) }
            ))
        })
    }

    /// Pointers of the property list that follows the entity's own `used`
    /// parameters (after the associativity back pointers).
    pub fn properties(&self, used: usize) -> Vec<usize> {
        let Ok(na) = self.int(used) else { return Vec::new() };
        let Some(np_at) = usize::try_from(na).ok().and_then(|na| na.checked_add(used + 1)) else {
            return Vec::new();
        };
        let Ok(np) = self.int(np_at) else { return Vec::new() };
        let np = usize::try_from(np).unwrap_or(0).min(self.params.len().saturating_sub(np_at + 1));
        (0..np).filter_map(|k| self.ptr(np_at + 1 + k).ok().flatten()).collect()
    }
}
