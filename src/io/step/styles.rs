//! Surface colours from presentation styles: a `STYLED_ITEM` (or an
//! `OVER_RIDING_STYLED_ITEM`) gives its item (a solid, shell or face) the
//! fill colour of its surface style, by the chain `PRESENTATION_STYLE_ASSIGNMENT`
//! → `SURFACE_STYLE_USAGE` → `SURFACE_SIDE_STYLE` → `SURFACE_STYLE_FILL_AREA`
//! → `FILL_AREA_STYLE` → `FILL_AREA_STYLE_COLOUR` → `COLOUR_RGB` or
//! `DRAUGHTING_PRE_DEFINED_COLOUR`. Curve, text and symbol styles colour no
//! surface and are passed over; so is anything malformed (colours are
//! decoration: a bad style never stops the file).

use crate::collections::HashMap;

use super::graph::{Ent, Graph};

/// Red, green and blue in 0..=1.
pub type Rgb = [f32; 3];

/// The surface colour each styled item has, by item `#id`.
pub(super) fn colours(g: &Graph) -> HashMap<u64, Rgb> {
    let mut out = HashMap::default();
    for e in g.all() {
        // Context-dependent over-riding styles colour one assembly instance,
        // not every use of the item: those are left out.
        if !(e.has("STYLED_ITEM") || e.has("OVER_RIDING_STYLED_ITEM")) {
            continue;
        }
        let a = match e.part("STYLED_ITEM") {
            Some(a) if e.is_complex() => a,
            _ => e.attrs(),
        };
        let (Ok(styles), Ok(item)) = (a.refs(1), a.refr(2)) else { continue };
        if let Some(c) = styles.iter().find_map(|&s| g.find(s).and_then(|s| assignment_colour(g, s))) {
            // An over-riding style wins over a plain one for the same item.
            if e.has("OVER_RIDING_STYLED_ITEM") || !out.contains_key(&item) {
                out.insert(item, c);
            }
        }
    }
    out
}

/// The fill colour of a presentation style assignment (or one by context).
fn assignment_colour(g: &Graph, psa: Ent<'_>) -> Option<Rgb> {
    if !(psa.has("PRESENTATION_STYLE_ASSIGNMENT") || psa.has("PRESENTATION_STYLE_BY_CONTEXT")) {
        return None;
    }
    let styles = psa.attrs().refs(0).ok()?;
    styles.iter().find_map(|&s| {
        let usage = g.find(s)?;
        if !usage.has("SURFACE_STYLE_USAGE") {
            return None;
        }
        let side = usage.attrs().ent(1).ok()?;
        if !side.has("SURFACE_SIDE_STYLE") {
            return None;
        }
        side.attrs().refs(1).ok()?.iter().find_map(|&el| {
            let fill = g.find(el)?;
            if !fill.has("SURFACE_STYLE_FILL_AREA") {
                return None;
            }
            let area = fill.attrs().ent(0).ok()?;
            area.attrs().refs(1).ok()?.iter().find_map(|&c| {
                let fasc = g.find(c)?;
                if !fasc.has("FILL_AREA_STYLE_COLOUR") {
                    return None;
                }
                colour(fasc.attrs().ent(1).ok()?)
            })
        })
    })
}

/// An RGB colour, or one of the pre-defined colours by name.
fn colour(c: Ent<'_>) -> Option<Rgb> {
    if let Some(a) = c.part("COLOUR_RGB") {
        let (r, g, b) = (a.real(1).ok()?, a.real(2).ok()?, a.real(3).ok()?);
        let ok = |x: f64| (0.0..=1.0).contains(&x);
        return (ok(r) && ok(g) && ok(b)).then_some([r as f32, g as f32, b as f32]);
    }
    if c.has("DRAUGHTING_PRE_DEFINED_COLOUR") {
        let name = c.attrs().string(0).ok()?;
        return Some(match name.trim().to_ascii_lowercase().as_str() {
            "red" => [1.0, 0.0, 0.0],
            "green" => [0.0, 1.0, 0.0],
            "blue" => [0.0, 0.0, 1.0],
            "yellow" => [1.0, 1.0, 0.0],
            "magenta" => [1.0, 0.0, 1.0],
            "cyan" => [0.0, 1.0, 1.0],
            "black" => [0.0, 0.0, 0.0],
            "white" => [1.0, 1.0, 1.0],
            _ => return None,
        });
    }
    None
}
