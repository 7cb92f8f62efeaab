//! 3MF core specification (3MF Consortium, 3D Manufacturing Format core
//! specification 1.3): a zip whose root model part (named by
//! `_rels/.rels`, usually `3D/3dmodel.model`) holds `<resources>` with
//! `<object>`s, each a `<mesh>` (`<vertex x y z>`, `<triangle v1 v2 v3>`) or
//! `<components>` (other objects, each with a `transform`), and a `<build>`
//! whose `<item>`s place objects with their own `transform`. The model's
//! `unit` scales everything to millimetres.
//!
//! Transforms are 12 numbers `m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31
//! m32` applied to row vectors (spec §3.3): `x' = x·m00 + y·m10 + z·m20 +
//! m30`, and so on. A transform with negative determinant mirrors, so its
//! triangles are reversed to stay outward.
//!
//! The zip goes through the `zip` crate and the XML through `quick-xml`
//! (both already in the workspace's tree); errors name the part, line and
//! column.

use std::collections::HashMap;
use std::io::{Cursor, Read};
use std::path::Path;

use glam::{DAffine3, DMat3, DVec3};
use quick_xml::events::{BytesStart, Event};

use super::{MeshError, Soup, coord, excerpt};

/// Largest model part read (uncompressed): refuses zip bombs.
const MAX_PART_BYTES: u64 = 1 << 30;
/// Most triangles a build may expand to through components.
const MAX_TRIANGLES: usize = 100_000_000;
/// Deepest chain of components.
const MAX_DEPTH: usize = 64;
/// Most object instances a build may place (objects that share components
/// multiply: twenty levels of two components are a million instances).
const MAX_INSTANCES: usize = 1_000_000;

pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Soup, MeshError> {
    let bad = |msg: String| MeshError::Invalid {
        path: path.to_path_buf(),
        msg: format!("3MF: {msg}"),
    };
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes))
        .map_err(|e| bad(format!("not a readable zip archive ({e}): truncated?")))?;
    let part = read_part(&mut zip, "_rels/.rels")
        .ok()
        .and_then(|rels| root_part(&rels))
        .unwrap_or_else(|| "3D/3dmodel.model".to_string());
    let xml = read_part(&mut zip, &part).map_err(bad)?;
    let text = std::str::from_utf8(&xml).map_err(|_| bad(format!("`{part}` is not UTF-8 text")))?;
    let model = Model::read(text).map_err(|(at, msg)| {
        let (line, column) = line_column(text, at);
        MeshError::ThreeMf {
            path: path.to_path_buf(),
            part: part.clone(),
            line,
            column,
            msg,
        }
    })?;
    model.build().map_err(bad)
}

fn read_part(zip: &mut zip::ZipArchive<Cursor<&[u8]>>, name: &str) -> Result<Vec<u8>, String> {
    let mut f = zip.by_name(name).map_err(|e| {
        format!("the archive has no readable `{name}` ({e}); a 3MF holds its model there")
    })?;
    let mut out = Vec::with_capacity(f.size().min(MAX_PART_BYTES) as usize);
    (&mut f)
        .take(MAX_PART_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("`{name}` cannot be unpacked: {e}"))?;
    if out.len() as u64 > MAX_PART_BYTES {
        return Err(format!(
            "`{name}` unpacks to more than {MAX_PART_BYTES} bytes"
        ));
    }
    Ok(out)
}

/// The start part named by the package relationships (the relationship
/// whose type ends in `/3dmodel`), without its leading `/`.
fn root_part(rels: &[u8]) -> Option<String> {
    let text = std::str::from_utf8(rels).ok()?;
    let mut r = quick_xml::Reader::from_str(text);
    loop {
        match r.read_event().ok()? {
            Event::Empty(e) | Event::Start(e) if e.local_name().as_ref() == "Relationship" => {
                let ty = attr(&e, "Type").ok().flatten()?;
                if ty.ends_with("/3dmodel") {
                    let t = attr(&e, "Target").ok().flatten()?;
                    return Some(t.trim_start_matches('/').to_string());
                }
            }
            Event::Eof => return None,
            _ => {}
        }
    }
}

fn line_column(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

/// An error at a byte offset of the model part.
type At = (usize, String);

/// One attribute's value (`Ok(None)` when absent).
fn attr(e: &BytesStart, name: &str) -> Result<Option<String>, String> {
    for a in e.attributes() {
        let a = a.map_err(|err| format!("malformed attribute: {err}"))?;
        if a.key.local_name().as_ref() == name {
            return Ok(Some(a.value.into_owned()));
        }
    }
    Ok(None)
}

fn required(e: &BytesStart, name: &str) -> Result<String, String> {
    attr(e, name)?
        .ok_or_else(|| format!("<{}> needs the attribute `{name}`", e.local_name().as_ref()))
}

fn number(e: &BytesStart, name: &str) -> Result<f64, String> {
    let s = required(e, name)?;
    coord(&s).map_err(|m| format!("<{}> attribute `{name}`: {m}", e.local_name().as_ref()))
}

fn index(e: &BytesStart, name: &str) -> Result<u64, String> {
    let s = required(e, name)?;
    s.trim().parse::<u64>().map_err(|_| {
        format!(
            "<{}> attribute `{name}` = `{}` is not a whole number from 0",
            e.local_name().as_ref(),
            excerpt(&s)
        )
    })
}

/// The `transform` attribute (identity when absent).
fn transform(e: &BytesStart) -> Result<DAffine3, String> {
    let Some(s) = attr(e, "transform")? else {
        return Ok(DAffine3::IDENTITY);
    };
    let m: Vec<f64> = s
        .split_whitespace()
        .map(|w| coord(w).map_err(|m| format!("transform: {m}")))
        .collect::<Result<_, _>>()?;
    if m.len() != 12 {
        return Err(format!(
            "transform needs 12 numbers (m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32), found {}",
            m.len()
        ));
    }
    let cols = DMat3::from_cols(
        DVec3::new(m[0], m[1], m[2]),
        DVec3::new(m[3], m[4], m[5]),
        DVec3::new(m[6], m[7], m[8]),
    );
    Ok(DAffine3::from_mat3_translation(
        cols,
        DVec3::new(m[9], m[10], m[11]),
    ))
}

#[derive(Default)]
struct Object {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// Referenced object id, transform, offset of the `<component>`.
    components: Vec<(u64, DAffine3, usize)>,
}

#[derive(Default)]
struct Model {
    /// Millimetres per model unit.
    scale: f64,
    objects: HashMap<u64, Object>,
    /// Object id, transform, offset of the `<item>`.
    items: Vec<(u64, DAffine3, usize)>,
}

impl Model {
    fn read(text: &str) -> Result<Model, At> {
        let mut r = quick_xml::Reader::from_str(text);
        let mut model = Model {
            scale: 1.0,
            ..Model::default()
        };
        let mut current: Option<(u64, Object)> = None;
        loop {
            let at = r.buffer_position() as usize;
            let ev = r
                .read_event()
                .map_err(|e| (r.error_position() as usize, format!("malformed XML: {e}")))?;
            let here = |m: String| (at, m);
            match ev {
                Event::Start(e) | Event::Empty(e) => match e.local_name().as_ref() {
                    "model" => model.scale = unit(&e).map_err(here)?,
                    "object" => {
                        let id = index(&e, "id").map_err(here)?;
                        current = Some((id, Object::default()));
                    }
                    "vertex" => {
                        let o = &mut current
                            .as_mut()
                            .ok_or_else(|| here("<vertex> outside an <object>".into()))?
                            .1;
                        let p = ["x", "y", "z"].map(|n| number(&e, n));
                        let [x, y, z] = p;
                        o.vertices.push(DVec3::new(
                            x.map_err(here)?,
                            y.map_err(here)?,
                            z.map_err(here)?,
                        ));
                    }
                    "triangle" => {
                        let o = &mut current
                            .as_mut()
                            .ok_or_else(|| here("<triangle> outside an <object>".into()))?
                            .1;
                        let n = o.vertices.len() as u64;
                        let mut t = [0u32; 3];
                        for (k, name) in ["v1", "v2", "v3"].iter().enumerate() {
                            let v = index(&e, name).map_err(here)?;
                            if v >= n {
                                return Err(here(format!(
                                    "<triangle> `{name}` = {v}, but the object has {n} vertices before it (0-based: 0..{n})"
                                )));
                            }
                            t[k] = v as u32;
                        }
                        o.triangles.push(t);
                    }
                    "component" => {
                        let o = &mut current
                            .as_mut()
                            .ok_or_else(|| here("<component> outside an <object>".into()))?
                            .1;
                        if attr(&e, "path").map_err(here)?.is_some() {
                            return Err(here("a <component> in another model part (production extension `p:path`) is not read; export the 3MF with all objects in one model".into()));
                        }
                        o.components.push((
                            index(&e, "objectid").map_err(here)?,
                            transform(&e).map_err(here)?,
                            at,
                        ));
                    }
                    "item" => {
                        model.items.push((
                            index(&e, "objectid").map_err(here)?,
                            transform(&e).map_err(here)?,
                            at,
                        ));
                    }
                    _ => {}
                },
                Event::End(e) if e.local_name().as_ref() == "object" => {
                    if let Some((id, o)) = current.take() {
                        model.objects.insert(id, o);
                    }
                }
                Event::Eof => break,
                _ => {}
            }
        }
        if model.items.is_empty() {
            return Err((
                text.len(),
                "the model's <build> has no <item>: nothing to print".into(),
            ));
        }
        for &(id, _, at) in model
            .items
            .iter()
            .chain(model.objects.values().flat_map(|o| &o.components))
        {
            if !model.objects.contains_key(&id) {
                return Err((
                    at,
                    format!("refers to object {id}, which the <resources> do not define"),
                ));
            }
        }
        Ok(model)
    }

    /// Every build item's triangles in millimetres.
    fn build(&self) -> Result<Soup, String> {
        let mut soup = (Vec::new(), Vec::new());
        let scale = DAffine3::from_scale(DVec3::splat(self.scale));
        let mut budget = MAX_INSTANCES;
        for &(id, t, _) in &self.items {
            self.emit(id, scale * t, &mut Vec::new(), &mut budget, &mut soup)?;
        }
        Ok(soup)
    }

    fn emit(
        &self,
        id: u64,
        t: DAffine3,
        stack: &mut Vec<u64>,
        budget: &mut usize,
        out: &mut Soup,
    ) -> Result<(), String> {
        if *budget == 0 {
            return Err(format!(
                "the build places more than {MAX_INSTANCES} object instances through its components"
            ));
        }
        *budget -= 1;
        if stack.contains(&id) {
            return Err(format!(
                "object {id} contains itself through its components"
            ));
        }
        if stack.len() >= MAX_DEPTH {
            return Err(format!("components nest deeper than {MAX_DEPTH} levels"));
        }
        let Some(o) = self.objects.get(&id) else {
            return Err(format!("object {id} is not defined"));
        };
        if out.1.len() + o.triangles.len() > MAX_TRIANGLES {
            return Err(format!(
                "the build expands to more than {MAX_TRIANGLES} triangles through its components"
            ));
        }
        let base = out.0.len() as u32;
        out.0
            .extend(o.vertices.iter().map(|&v| t.transform_point3(v)));
        let mirror = t.matrix3.determinant() < 0.0;
        out.1.extend(o.triangles.iter().map(|&[a, b, c]| {
            if mirror {
                [base + a, base + c, base + b]
            } else {
                [base + a, base + b, base + c]
            }
        }));
        stack.push(id);
        for &(child, ct, _) in &o.components {
            self.emit(child, t * ct, stack, budget, out)?;
        }
        stack.pop();
        Ok(())
    }
}

/// Millimetres per unit of the `<model unit>` attribute (spec §3.2).
fn unit(e: &BytesStart) -> Result<f64, String> {
    Ok(match attr(e, "unit")?.as_deref() {
        None | Some("millimeter") => 1.0,
        Some("micron") => 0.001,
        Some("centimeter") => 10.0,
        Some("inch") => 25.4,
        Some("foot") => 304.8,
        Some("meter") => 1000.0,
        Some(u) => {
            return Err(format!(
                "unknown unit `{u}`; the 3MF core spec allows micron, millimeter, centimeter, inch, foot, meter"
            ));
        }
    })
}
