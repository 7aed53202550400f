//! The parsed exchange structure: every instance of the DATA section with
//! its parameters, kept flat (one arena of values, lists as ranges into it)
//! so neither parsing nor dropping recurses, and read back through checked
//! accessors whose errors name the instance and the parameter.

use crate::collections::HashMap;
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use super::step_error;
use crate::warning::{Warning, WarningKind};
use crate::Error;

/// One parameter value. Lists and typed values point into [`Graph::values`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Value {
    /// `$`: not given.
    Omitted,
    /// `*`: derived from a supertype's attribute.
    Derived,
    Int(i64),
    Real(f64),
    /// A string: `len` bytes of [`Graph::text`] from `start`.
    Str {
        start: u32,
        len: u32,
    },
    /// `.NAME.`, interned in [`Graph::names`].
    Enum(u32),
    /// `#id`.
    Ref(u64),
    /// `( … )`: `len` values of [`Graph::values`] from `start`.
    List {
        start: u32,
        len: u32,
    },
    /// `NAME(value)`: the value is `values[at]`.
    Typed {
        name: u32,
        at: u32,
    },
    /// `"…"`: binary data (not used by geometry).
    Binary,
}

/// One entity of an instance: its keyword and parameters.
#[derive(Debug, Clone, Copy)]
pub(super) struct Part {
    pub name: u32,
    pub start: u32,
    pub len: u32,
}

/// One instance `#id = …;`: a simple instance has one part, a complex one several.
#[derive(Debug, Clone, Copy)]
pub(super) struct Instance {
    pub id: u64,
    pub first: u32,
    pub count: u32,
    /// 1-based line where the instance starts.
    pub line: u32,
}

/// The whole file, flattened.
#[derive(Debug, Default)]
pub(super) struct Graph {
    pub values: Vec<Value>,
    pub text: String,
    pub names: Vec<String>,
    pub name_ids: HashMap<String, u32>,
    pub parts: Vec<Part>,
    pub instances: Vec<Instance>,
    /// Where each `#id` is in `instances`, built only once the numbers stop
    /// increasing: while they increase (as writers number them) a binary
    /// search of `instances` finds one, and the map's memory is saved.
    index: Option<HashMap<u64, u32>>,
    /// Header entities (`FILE_NAME`, `FILE_SCHEMA`, …), as parts.
    pub header: Vec<Part>,
    /// What the parser forgave (duplicate numbers, bad escapes, a damaged header).
    pub forgiven: Forgiven,
}

/// What a tolerant parser let pass, one entry per kind: the first
/// occurrence's message (naming its line and instance) and how many more of
/// that kind followed, so a file with many of one flaw gets one warning.
#[derive(Debug, Default)]
pub(super) struct Forgiven {
    kinds: Vec<(&'static str, Warning)>,
}

impl Forgiven {
    /// Notes one occurrence of `kind`; `error` (what it would have been
    /// without leniency) is made only for the first.
    pub fn note(&mut self, kind: &'static str, error: impl FnOnce() -> Error) {
        match self.kinds.iter_mut().find(|k| k.0 == kind) {
            Some(k) => k.1.more += 1,
            None => self.kinds.push((kind, Warning::new(WarningKind::Forgiven(error())))),
        }
    }

    /// One warning per kind, in the order the kinds were first met.
    pub fn warnings(&self) -> Vec<Warning> {
        self.kinds.iter().map(|(_, w)| w.clone()).collect()
    }

    /// The warnings' text but for those of kind `skip`, for tests of the text.
    #[cfg(test)]
    pub fn texts_except(&self, skip: &str) -> Vec<String> {
        use alloc::string::ToString;
        self.kinds.iter().filter(|(k, _)| *k != skip).map(|(_, w)| w.to_string()).collect()
    }
}

impl Graph {
    /// Interned id of a keyword.
    pub fn intern(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.name_ids.get(name) {
            return i;
        }
        let i = self.names.len() as u32;
        self.names.push(name.into());
        self.name_ids.insert(name.into(), i);
        i
    }

    /// Adds an instance; `false` (and nothing added) when its `#id` is
    /// already defined.
    pub fn add_instance(&mut self, inst: Instance) -> bool {
        if self.index.is_none() && self.instances.last().is_some_and(|l| l.id >= inst.id) {
            let mut m = HashMap::default();
            m.reserve(self.instances.len() + 1);
            for (i, x) in self.instances.iter().enumerate() {
                m.insert(x.id, i as u32);
            }
            self.index = Some(m);
        }
        if let Some(m) = &mut self.index {
            match m.entry(inst.id) {
                hashbrown::hash_map::Entry::Occupied(_) => return false,
                hashbrown::hash_map::Entry::Vacant(v) => {
                    v.insert(self.instances.len() as u32);
                }
            }
        }
        self.instances.push(inst);
        true
    }

    /// Frees the slack the arenas grew with, once the file is read.
    pub fn shrink(&mut self) {
        self.values.shrink_to_fit();
        self.text.shrink_to_fit();
        self.parts.shrink_to_fit();
        self.instances.shrink_to_fit();
    }

    /// Position of instance `#id` in `instances`.
    fn slot(&self, id: u64) -> Option<u32> {
        match &self.index {
            Some(m) => m.get(&id).copied(),
            None => self.instances.binary_search_by_key(&id, |i| i.id).ok().map(|i| i as u32),
        }
    }

    /// The interned keyword `i`.
    pub fn name(&self, i: u32) -> &str {
        self.names.get(i as usize).map_or("", String::as_str)
    }

    /// The instance `#id`; `from` is the instance holding the reference (for the message).
    ///
    /// # Errors
    /// No such instance.
    pub fn get(&self, id: u64, from: u64) -> Result<Ent<'_>, Error> {
        match self.slot(id) {
            Some(idx) => Ok(Ent { g: self, idx }),
            None if from == 0 => Err(step_error(id, 0, "is referenced but not defined")),
            None => Err(step_error(from, self.line_of(from), format!("references #{id}, which is not defined"))),
        }
    }

    /// The instance `#id`, if any.
    pub fn find(&self, id: u64) -> Option<Ent<'_>> {
        self.slot(id).map(|idx| Ent { g: self, idx })
    }

    /// Every instance, in file order.
    pub fn all(&self) -> impl Iterator<Item = Ent<'_>> + '_ {
        (0..self.instances.len() as u32).map(move |idx| Ent { g: self, idx })
    }

    /// 1-based line of instance `#id` (0 when unknown).
    pub fn line_of(&self, id: u64) -> usize {
        self.find(id).map_or(0, |e| e.line())
    }

    fn str_of(&self, start: u32, len: u32) -> &str {
        let (s, e) = (start as usize, start as usize + len as usize);
        self.text.get(s..e).unwrap_or("")
    }

    fn slice(&self, start: u32, len: u32) -> &[Value] {
        let (s, e) = (start as usize, start as usize + len as usize);
        self.values.get(s..e).unwrap_or(&[])
    }

    fn part_values(&self, p: &Part) -> &[Value] {
        self.slice(p.start, p.len)
    }
}

/// A handle on one instance.
#[derive(Clone, Copy)]
pub(super) struct Ent<'g> {
    pub g: &'g Graph,
    idx: u32,
}

impl<'g> Ent<'g> {
    fn inst(&self) -> Instance {
        self.g.instances[self.idx as usize]
    }

    fn parts(&self) -> &'g [Part] {
        let i = self.inst();
        let (s, e) = (i.first as usize, i.first as usize + i.count as usize);
        self.g.parts.get(s..e).unwrap_or(&[])
    }

    /// `#id`.
    pub fn id(&self) -> u64 {
        self.inst().id
    }

    /// 1-based line of the instance.
    pub fn line(&self) -> usize {
        self.inst().line as usize
    }

    /// Whether the instance is complex (several entities).
    pub fn is_complex(&self) -> bool {
        self.inst().count != 1
    }

    /// The entity name of a simple instance; for a complex one the first
    /// part's name (use [`Ent::has`] to test complex instances).
    pub fn name(&self) -> &'g str {
        self.parts().first().map_or("", |p| self.g.name(p.name))
    }

    /// A readable type: the simple name, or `(A B …)` for a complex instance.
    pub fn type_name(&self) -> String {
        if self.is_complex() {
            let names: Vec<&str> = self.parts().iter().map(|p| self.g.name(p.name)).collect();
            format!("({})", names.join(" "))
        } else {
            self.name().into()
        }
    }

    /// Whether the instance is (or, if complex, includes) entity `name`.
    pub fn has(&self, name: &str) -> bool {
        self.parts().iter().any(|p| self.g.name(p.name) == name)
    }

    /// The parameters of part `name` of the instance.
    pub fn part(&self, name: &str) -> Option<Attrs<'g>> {
        let p = self.parts().iter().find(|p| self.g.name(p.name) == name)?;
        Some(Attrs { g: self.g, owner: self.id(), vals: self.g.part_values(p).to_vec() })
    }

    /// The parameters of a simple instance (the first part of a complex one).
    pub fn attrs(&self) -> Attrs<'g> {
        let vals = self.parts().first().map(|p| self.g.part_values(p).to_vec()).unwrap_or_default();
        Attrs { g: self.g, owner: self.id(), vals }
    }

    /// The attributes along an inheritance chain of `(entity, attribute
    /// count)` pairs: a simple instance lists them all in that order; a
    /// complex one holds each entity's own attributes in its part.
    ///
    /// # Errors
    /// Fewer attributes than the chain needs, or a complex instance without
    /// one of the chain's entities that has attributes.
    pub fn chain(&self, chain: &[(&str, usize)]) -> Result<Attrs<'g>, Error> {
        let need: usize = chain.iter().map(|c| c.1).sum();
        if !self.is_complex() {
            let a = self.attrs();
            if a.vals.len() < need {
                return Err(self.error(format!("has {} parameters, {} expected", a.vals.len(), need)));
            }
            return Ok(a);
        }
        let mut vals = Vec::with_capacity(need);
        for &(name, n) in chain {
            match self.part(name) {
                Some(p) if p.vals.len() >= n => vals.extend_from_slice(&p.vals[..n]),
                // Some writers leave the name out: `REPRESENTATION_ITEM()`.
                Some(p) if name == "REPRESENTATION_ITEM" && p.vals.is_empty() => {
                    vals.extend(core::iter::repeat_n(Value::Omitted, n));
                }
                Some(p) => {
                    return Err(self.error(format!("part {name} has {} parameters, {n} expected", p.vals.len())));
                }
                None if n == 0 => {}
                // Some writers leave out the name-only supertype.
                None if name == "REPRESENTATION_ITEM" => vals.extend(core::iter::repeat_n(Value::Omitted, n)),
                None => return Err(self.error(format!("complex instance without {name}"))),
            }
        }
        Ok(Attrs { g: self.g, owner: self.id(), vals })
    }

    /// An error about this instance.
    pub fn error(&self, message: impl core::fmt::Display) -> Error {
        step_error(self.id(), self.line(), format!("{}: {message}", self.type_name()))
    }
}

/// Parameters of one instance (or one part of it), with typed, checked reads.
#[derive(Clone)]
pub(super) struct Attrs<'g> {
    pub g: &'g Graph,
    pub owner: u64,
    pub vals: Vec<Value>,
}

/// What a value is, for messages.
fn kind(v: &Value) -> &'static str {
    match v {
        Value::Omitted => "$",
        Value::Derived => "*",
        Value::Int(_) => "an integer",
        Value::Real(_) => "a real",
        Value::Str { .. } => "a string",
        Value::Enum(_) => "an enumeration",
        Value::Ref(_) => "a reference",
        Value::List { .. } => "a list",
        Value::Typed { .. } => "a typed value",
        Value::Binary => "binary data",
    }
}

impl<'g> Attrs<'g> {
    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.vals.len()
    }

    fn err(&self, i: usize, message: String) -> Error {
        let line = self.g.line_of(self.owner);
        let name = self.g.find(self.owner).map(|e| e.type_name()).unwrap_or_default();
        step_error(self.owner, line, format!("{name} parameter {}: {message}", i + 1))
    }

    fn at(&self, i: usize) -> Result<Value, Error> {
        self.vals.get(i).copied().ok_or_else(|| self.err(i, "missing".into()))
    }

    /// Value `i` as is.
    #[cfg(test)]
    pub fn value(&self, i: usize) -> Result<Value, Error> {
        self.at(i)
    }

    /// Value `i` as a number (integers are widened; typed numbers unwrapped).
    pub fn real(&self, i: usize) -> Result<f64, Error> {
        let v = self.at(i)?;
        self.g.number(v).ok_or_else(|| self.err(i, format!("expected a number, found {}", kind(&v))))
    }

    /// Value `i` as a number, or `default` when omitted.
    pub fn real_or(&self, i: usize, default: f64) -> Result<f64, Error> {
        match self.vals.get(i) {
            None | Some(Value::Omitted) | Some(Value::Derived) => Ok(default),
            _ => self.real(i),
        }
    }

    /// Value `i` as an integer.
    pub fn int(&self, i: usize) -> Result<i64, Error> {
        match self.at(i)? {
            Value::Int(n) => Ok(n),
            Value::Real(x) if x == libm::trunc(x) && x.abs() < 9e15 => Ok(x as i64),
            v => Err(self.err(i, format!("expected an integer, found {}", kind(&v)))),
        }
    }

    /// Value `i` as a reference.
    pub fn refr(&self, i: usize) -> Result<u64, Error> {
        match self.at(i)? {
            Value::Ref(r) => Ok(r),
            v => Err(self.err(i, format!("expected a reference, found {}", kind(&v)))),
        }
    }

    /// Value `i` as a reference, `None` when omitted.
    pub fn opt_ref(&self, i: usize) -> Result<Option<u64>, Error> {
        match self.vals.get(i) {
            None | Some(Value::Omitted) | Some(Value::Derived) => Ok(None),
            _ => self.refr(i).map(Some),
        }
    }

    /// The instance referenced by value `i`.
    pub fn ent(&self, i: usize) -> Result<Ent<'g>, Error> {
        self.g.get(self.refr(i)?, self.owner)
    }

    /// Value `i` as a list.
    pub fn list(&self, i: usize) -> Result<&'g [Value], Error> {
        let v = self.at(i)?;
        self.g.list(v).ok_or_else(|| self.err(i, format!("expected a list, found {}", kind(&v))))
    }

    /// Value `i` as a list of references.
    pub fn refs(&self, i: usize) -> Result<Vec<u64>, Error> {
        let l = self.list(i)?;
        let mut out = Vec::with_capacity(l.len());
        for v in l {
            match v {
                Value::Ref(r) => out.push(*r),
                other => return Err(self.err(i, format!("expected a list of references, found {} in it", kind(other)))),
            }
        }
        Ok(out)
    }

    /// Value `i` as a list of numbers.
    pub fn reals(&self, i: usize) -> Result<Vec<f64>, Error> {
        let l = self.list(i)?;
        let mut out = Vec::with_capacity(l.len());
        for v in l {
            match self.g.number(*v) {
                Some(x) => out.push(x),
                None => return Err(self.err(i, format!("expected a list of numbers, found {} in it", kind(v)))),
            }
        }
        Ok(out)
    }

    /// Value `i` as a list of integers.
    pub fn ints(&self, i: usize) -> Result<Vec<i64>, Error> {
        let l = self.list(i)?;
        let mut out = Vec::with_capacity(l.len());
        for v in l {
            match v {
                Value::Int(n) => out.push(*n),
                other => return Err(self.err(i, format!("expected a list of integers, found {} in it", kind(other)))),
            }
        }
        Ok(out)
    }

    /// Value `i` as a string (`""` when omitted).
    pub fn string(&self, i: usize) -> Result<&'g str, Error> {
        match self.at(i)? {
            Value::Str { start, len } => Ok(self.g.str_of(start, len)),
            Value::Omitted | Value::Derived => Ok(""),
            v => Err(self.err(i, format!("expected a string, found {}", kind(&v)))),
        }
    }

    /// Value `i` as an enumeration name (without the dots).
    pub fn enumeration(&self, i: usize) -> Result<&'g str, Error> {
        match self.at(i)? {
            Value::Enum(n) => Ok(self.g.name(n)),
            v => Err(self.err(i, format!("expected an enumeration, found {}", kind(&v)))),
        }
    }

    /// Value `i` as a logical: `.T.` true, `.F.` false, anything else `default`.
    pub fn boolean(&self, i: usize, default: bool) -> Result<bool, Error> {
        match self.at(i)? {
            Value::Enum(n) => Ok(match self.g.name(n) {
                "T" => true,
                "F" => false,
                _ => default,
            }),
            Value::Omitted | Value::Derived => Ok(default),
            v => Err(self.err(i, format!("expected a logical, found {}", kind(&v)))),
        }
    }

    /// An error about parameter `i`.
    pub fn error(&self, i: usize, message: impl Into<String>) -> Error {
        self.err(i, message.into())
    }
}

impl Graph {
    /// A number, also inside a typed value (`LENGTH_MEASURE(2.5)`).
    pub fn number(&self, v: Value) -> Option<f64> {
        let mut v = v;
        for _ in 0..4 {
            match v {
                Value::Real(x) => return x.is_finite().then_some(x),
                Value::Int(n) => return Some(n as f64),
                Value::Typed { at, .. } => v = *self.values.get(at as usize)?,
                _ => return None,
            }
        }
        None
    }

    /// The items of a list value (also inside a typed value).
    pub fn list(&self, v: Value) -> Option<&[Value]> {
        match v {
            Value::List { start, len } => Some(self.slice(start, len)),
            Value::Typed { at, .. } => match self.values.get(at as usize)? {
                Value::List { start, len } => Some(self.slice(*start, *len)),
                _ => None,
            },
            _ => None,
        }
    }

    /// The text of a string value (also inside a typed value, `IDENTIFIER('…')`).
    pub fn text(&self, v: Value) -> Option<&str> {
        match v {
            Value::Str { start, len } => Some(self.str_of(start, len)),
            Value::Typed { at, .. } => match self.values.get(at as usize)? {
                Value::Str { start, len } => Some(self.str_of(*start, *len)),
                _ => None,
            },
            _ => None,
        }
    }

    /// The keyword of a typed value and its inner value.
    pub fn typed(&self, v: Value) -> Option<(&str, Value)> {
        match v {
            Value::Typed { name, at } => Some((self.name(name), *self.values.get(at as usize)?)),
            _ => None,
        }
    }
}
