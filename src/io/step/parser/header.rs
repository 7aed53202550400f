//! The HEADER section: read for what it says, forgiven for what it lacks.
//! Nothing in it is needed to read the DATA section, so a syntax error, a
//! missing or malformed `FILE_DESCRIPTION`, `FILE_NAME` or `FILE_SCHEMA`, or
//! an entity the standard does not define costs one warning naming what is
//! wrong, and reading goes on after the section.

use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;

use super::{expect, parse_params, Lexer, Tok};
use crate::io::step::graph::{Graph, Part, Value};
use crate::io::step::step_error;
use crate::Error;

/// The HEADER section, up to and past its `ENDSEC;`. A damaged header (a
/// syntax error, a missing or malformed `FILE_DESCRIPTION`, `FILE_NAME` or
/// `FILE_SCHEMA`, an entity the standard does not define) costs one note
/// naming what is wrong: nothing in it is needed to read the DATA section.
pub(super) fn header(lx: &mut Lexer<'_>, g: &mut Graph, scratch: &mut Vec<Value>) {
    let first_line = lx.line;
    let mut problems: Vec<String> = Vec::new();
    loop {
        let (pos, line) = (lx.pos, lx.line);
        match header_entity(lx, g, scratch) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => {
                problems.push(match e {
                    Error::Step { line, message, .. } => format!("line {line}: {message}"),
                    other => other.to_string(),
                });
                scratch.clear();
                lx.pos = pos;
                lx.line = line;
                resync_after_header(lx);
                break;
            }
        }
    }
    problems.extend(header_problems(g));
    if !problems.is_empty() {
        g.forgiven.note("header", || {
            let m = format!("HEADER section: {}; the DATA section is read anyway", problems.join("; "));
            step_error(0, first_line, m)
        });
    }
}

/// One header entity (`true`), or the closing `ENDSEC;` (`false`).
fn header_entity(lx: &mut Lexer<'_>, g: &mut Graph, scratch: &mut Vec<Value>) -> Result<bool, Error> {
    match lx.next(g, 0)? {
        Tok::Keyword(k) if k == "ENDSEC" => expect(lx, g, 0, &Tok::Semicolon, "';' after ENDSEC").map(|()| false),
        Tok::Keyword(k) => {
            let name = g.intern(&k);
            expect(lx, g, 0, &Tok::Open, "'(' after a header entity name")?;
            let (start, len) = parse_params(lx, g, scratch, 0)?;
            g.header.push(Part { name, start, len });
            expect(lx, g, 0, &Tok::Semicolon, "';' after a header entity")?;
            Ok(true)
        }
        other => Err(lx.error(0, format!("expected an entity or ENDSEC, found {other}"))),
    }
}

/// After a syntax error in the HEADER section: on past the next `ENDSEC;`,
/// or to the `DATA` keyword if that comes first, else to the end (the caller then finds no
/// DATA section). A plain byte scan: the lexer cannot be trusted where the
/// error was.
fn resync_after_header(lx: &mut Lexer<'_>) {
    let b = lx.b;
    let word_at = |i: usize, w: &[u8]| {
        b.get(i..i + w.len()) == Some(w)
            && (i == 0 || !b[i - 1].is_ascii_alphanumeric() && b[i - 1] != b'_' && b[i - 1] != b'-')
    };
    let after_blanks = |mut i: usize| {
        while b.get(i).is_some_and(|c| c.is_ascii_whitespace()) {
            i += 1;
        }
        i
    };
    let mut to = b.len();
    for i in lx.pos..b.len() {
        if word_at(i, b"ENDSEC") {
            let j = after_blanks(i + 6);
            if b.get(j) == Some(&b';') {
                to = j + 1;
                break;
            }
        }
        if word_at(i, b"DATA") && matches!(b.get(after_blanks(i + 4)), Some(b';' | b'(')) {
            to = i;
            break;
        }
    }
    lx.line += b[lx.pos..to].iter().filter(|&&c| c == b'\n').count();
    lx.pos = to;
}

/// What the header lacks or holds that ISO 10303-21 does not define: each
/// of `FILE_DESCRIPTION` (2 parameters), `FILE_NAME` (7) and `FILE_SCHEMA`
/// (1, a list) once, then only the optional entities or user-defined (`!`) ones.
fn header_problems(g: &Graph) -> Vec<String> {
    let mut out = Vec::new();
    for (name, count) in [("FILE_DESCRIPTION", 2u32), ("FILE_NAME", 7), ("FILE_SCHEMA", 1)] {
        match g.header.iter().find(|p| g.name(p.name) == name) {
            None => out.push(format!("no {name}")),
            Some(p) if p.len != count => out.push(format!("{name} has {} parameters, {count} expected", p.len)),
            Some(p) => {
                let first = g.values.get(p.start as usize).copied();
                if name == "FILE_SCHEMA" && !matches!(first, Some(Value::List { .. })) {
                    out.push("FILE_SCHEMA does not give a list of schema names".into());
                }
            }
        }
    }
    const KNOWN: [&str; 6] =
        ["FILE_DESCRIPTION", "FILE_NAME", "FILE_SCHEMA", "FILE_POPULATION", "SECTION_LANGUAGE", "SECTION_CONTEXT"];
    for p in &g.header {
        let name = g.name(p.name);
        if !KNOWN.contains(&name) && !name.starts_with('!') {
            out.push(format!("unknown header entity {name}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::parse;
    use alloc::format;

    #[test]
    fn a_damaged_header_is_one_warning_and_the_data_is_read() {
        let data = "DATA;\n#1 = A(1);\nENDSEC;\nEND-ISO-10303-21;\n";
        let read = |header: &str| {
            let g = parse(format!("ISO-10303-21;\n{header}{data}").as_bytes()).unwrap();
            assert_eq!(g.get(1, 0).unwrap().attrs().int(0).unwrap(), 1);
            g.forgiven.texts_except("")
        };
        let good = "HEADER;\nFILE_DESCRIPTION((''),'2;1');\nFILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('S'));\nENDSEC;\n";
        assert!(read(good).is_empty());
        let w = read(
            "HEADER;\nFILE_DESCRIPTION((''),'2;1');\nX_STAMP(1);\nFILE_NAME('',,'');\nFILE_SCHEMA(('S'));\nENDSEC;\n",
        );
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(
            w[0],
            "STEP line 2: HEADER section: line 5: a value is missing before ','; no FILE_NAME; no FILE_SCHEMA; \
             unknown header entity X_STAMP; the DATA section is read anyway"
        );
        let w = read("HEADER;\nFILE_DESCRIPTION('x');\nFILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA('S');\n!MY_NOTE(1);\nENDSEC;\n");
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].contains("FILE_DESCRIPTION has 1 parameters, 2 expected; FILE_SCHEMA does not give a list"),
            "{w:?}"
        );
        // No ENDSEC: on to DATA. No HEADER at all. A byte the lexer refuses.
        let w = read("HEADER;\nFILE_DESCRIPTION((''),'2;1');\nFILE_NAME('',\n");
        assert!(w[0].contains("no FILE_NAME") && w[0].contains("the DATA section is read anyway"), "{w:?}");
        assert_eq!(read(""), ["STEP: no HEADER section; the DATA section is read anyway"]);
        let w = read("HEADER;\nFILE_DESCRIPTION(@);\nENDSEC;\n");
        assert!(w[0].contains("line 3: unexpected '@'"), "{w:?}");
    }
}
