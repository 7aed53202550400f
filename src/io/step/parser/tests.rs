//! The parser on small files: escapes, complex instances, malformed input and its leniencies.

use super::*;
use alloc::string::ToString;

fn file(data: &str) -> String {
    format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n"
    )
}

fn message(bytes: &[u8]) -> String {
    match parse(bytes) {
        Ok(_) => String::from("parsed"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn escapes_crlf_comments_and_raw_utf8() {
    let g = parse(include_bytes!("../../../../tests/data/step_escapes.stp")).unwrap();
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
    let g = parse(include_bytes!("../../../../tests/data/step_latin1.stp")).unwrap();
    assert_eq!(g.get(1, 0).unwrap().attrs().string(0).unwrap(), "caf\u{e9}");
}

#[test]
fn complex_instances_typed_values_and_forward_references() {
    let g = parse(include_bytes!("../../../../tests/data/step_complex.stp")).unwrap();
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
    let m = message(include_bytes!("../../../../tests/data/step_unclosed_string.stp"));
    assert_eq!(m, "STEP line 10, #7: string not closed by a quote");
    assert!(m.contains("#7") && m.contains("line 10") && m.contains("string not closed"), "{m}");
    let m = message(include_bytes!("../../../../tests/data/step_unclosed_comment.stp"));
    assert!(m.contains("line 10") && m.contains("comment not closed"), "{m}");
    let m = message(include_bytes!("../../../../tests/data/step_bad_token.stp"));
    assert!(m.contains("#4") && m.contains("line 10") && m.contains("'@'"), "{m}");
    let m = message(include_bytes!("../../../../tests/data/step_huge_id.stp"));
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
fn instances_numbered_out_of_order_are_found() {
    let g = parse(file("#5 = A(#9);\n#7 = A(2);\n#2 = A(#5);\n#9 = A(3);").as_bytes()).unwrap();
    for id in [2, 5, 7, 9] {
        assert_eq!(g.get(id, 0).unwrap().id(), id);
    }
    assert!(g.find(3).is_none() && g.find(10).is_none());
    assert_eq!(g.get(2, 0).unwrap().attrs().ent(0).unwrap().attrs().ent(0).unwrap().id(), 9);
}

/// The warnings' text, other than the test header's (which lacks FILE_NAME and FILE_SCHEMA).
fn forgiven(g: &Graph) -> Vec<String> {
    g.forgiven.texts_except("header")
}

#[test]
fn a_duplicate_instance_number_keeps_the_first_definition_with_one_warning() {
    let g = parse(include_bytes!("../../../../tests/data/step_duplicate_id.stp")).unwrap();
    assert_eq!(g.get(2, 0).unwrap().attrs().reals(1).unwrap(), [1.0, 0.0, 0.0]);
    assert_eq!(
        g.forgiven.texts_except(""),
        ["STEP line 10, #2: instance number defined twice; the first definition (line 9) is kept"]
    );
    // Out of order, and again after the map is built: each time the first is kept, one warning in all.
    let g = parse(file("#5 = A(1);\n#2 = A(1);\n#5 = A(2);\n#3 = A(1);\n#2 = A(7);").as_bytes()).unwrap();
    assert_eq!(g.get(5, 0).unwrap().attrs().int(0).unwrap(), 1);
    assert_eq!(g.get(2, 0).unwrap().attrs().int(0).unwrap(), 1);
    assert_eq!(g.get(3, 0).unwrap().attrs().int(0).unwrap(), 1);
    let w = forgiven(&g);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("STEP line 8, #5: instance number defined twice") && w[0].ends_with("(and 1 more like it)"),
        "{w:?}"
    );
}

#[test]
fn malformed_escapes_keep_their_raw_text_with_one_warning_each_kind() {
    let s = |g: &Graph, id: u64| g.get(id, 0).unwrap().attrs().string(0).unwrap().to_string();
    // Left open by the string's end: what decoded is kept.
    let g = parse(file("#1 = A('x \\X2\\03B103B2');\n#2 = A('\\X2\\03B1\\X0\\ \\X2\\03B3');").as_bytes()).unwrap();
    assert_eq!(s(&g, 1), "x \u{3b1}\u{3b2}");
    assert_eq!(s(&g, 2), "\u{3b1} \u{3b3}");
    let w = forgiven(&g);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].starts_with("STEP line 6, #1: \\X2\\ or \\X4\\ escape not closed by \\X0\\"), "{w:?}");
    assert!(w[0].ends_with("(and 1 more like it)"), "{w:?}");
    // A bad digit: decoded units kept, the rest raw; nothing decoded: all raw.
    let g = parse(
        file("#1 = A('\\X2\\00C400G4\\X0\\');\n#2 = A('\\X4\\0001F6\\X0\\!');\n#3 = A('\\X\\G1 ok');").as_bytes(),
    )
    .unwrap();
    assert_eq!(s(&g, 1), "\u{c4}00G4\\X0\\");
    assert_eq!(s(&g, 2), "\\X4\\0001F6\\X0\\!");
    assert_eq!(s(&g, 3), "\\X\\G1 ok");
    let w = forgiven(&g);
    assert_eq!(w.len(), 3, "{w:?}");
    assert!(w[0].starts_with("STEP line 6, #1: bad hex digit in a \\X2\\ or \\X4\\ escape; kept as raw text"), "{w:?}");
    assert!(w[1].starts_with("STEP line 7, #2: \\X2\\ or \\X4\\ escape not closed"), "{w:?}");
    assert!(w[2].starts_with("STEP line 8, #3: bad hex digit in a \\X\\ escape"), "{w:?}");
}

#[test]
fn a_lone_apostrophe_stays_in_the_string() {
    let g = parse(file("#1 = A('it's', 'b' , 'c'/* x */);\n#2 = A('end'\n);").as_bytes()).unwrap();
    let a = g.get(1, 0).unwrap().attrs();
    assert_eq!((a.string(0).unwrap(), a.string(1).unwrap(), a.string(2).unwrap()), ("it's", "b", "c"));
    assert_eq!(g.get(2, 0).unwrap().attrs().string(0).unwrap(), "end");
    let w = forgiven(&g);
    assert_eq!(w, ["STEP line 6, #1: a lone apostrophe inside a string (not doubled); kept in the text"]);
    // A string that never ends is still an error.
    let m = message(file("#1 = A('a'b);").as_bytes());
    assert!(m.contains("#1") && m.contains("not closed"), "{m}");
}

#[test]
fn deep_nesting_is_refused_without_recursion() {
    let m = message(include_bytes!("../../../../tests/data/step_deep_nesting.stp"));
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
    let bytes = include_bytes!("../../../../tests/data/step_complex.stp");
    for n in 0..bytes.len() {
        let _ = parse(&bytes[..n]);
    }
    let bytes = include_bytes!("../../../../tests/data/step_escapes.stp");
    for n in 0..bytes.len() {
        let _ = parse(&bytes[..n]);
    }
}

#[test]
fn syntax_errors_name_the_token_as_the_file_spells_it() {
    let m = message(file("#1 = FOO(1.5 2);").as_bytes());
    assert!(m.contains("found the integer `2`"), "{m}");
    let m = message(file("#1 = FOO(1,2)\n#2 = BAR();").as_bytes());
    assert!(m.contains("found the instance name `#2`"), "{m}");
    let m = message(file("#1 FOO(1);").as_bytes());
    assert!(m.contains("found the keyword `FOO`"), "{m}");
}

#[test]
fn keywords_borrow_the_file_and_lower_case_ones_read_the_same() {
    assert!(matches!(ascii_upper(b"B_SPLINE_SURFACE_WITH_KNOTS"), Cow::Borrowed("B_SPLINE_SURFACE_WITH_KNOTS")));
    assert_eq!(ascii_upper(b"Cartesian_point-2"), "CARTESIAN_POINT-2");
    let upper =
        parse(file("#1 = CARTESIAN_POINT('',(1.,2.,3.));\n#2 = FOO(.T.,BAR(#1),!USER(1));").as_bytes()).unwrap();
    let lower =
        parse(file("#1 = cartesian_point('',(1.,2.,3.));\n#2 = Foo(.t.,bar(#1),!user(1));").as_bytes()).unwrap();
    for g in [&upper, &lower] {
        assert_eq!(g.get(1, 0).unwrap().name(), "CARTESIAN_POINT");
        let e = g.get(2, 0).unwrap();
        assert_eq!(e.name(), "FOO");
        let a = e.attrs();
        assert!(a.boolean(0, false).unwrap());
        assert!(matches!(a.value(1).unwrap(), Value::Typed { name, .. } if g.name(name) == "BAR"));
        assert!(matches!(a.value(2).unwrap(), Value::Typed { name, .. } if g.name(name) == "!USER"));
    }
}
