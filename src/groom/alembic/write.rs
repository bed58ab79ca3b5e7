//! Writing grooms as Alembic (Ogawa) files: one `AbcGeom_Curve_v2` object per
//! [`CurvesObject`], under an `AbcGeom_Xform_v3` object when it has a
//! transform. Linear, non-periodic curves; `P`, `nVertices`,
//! `curveBasisAndType`, `width` (per point, when the groom has thickness) and,
//! in `.arbGeomParams`, `groom_color` (per point), `groom_guide` and
//! `groom_root_uv` (per curve) in Unreal's convention. One sample each, the
//! layout [`super`] reads.

use glam::{DMat4, Vec2};

use crate::error::{Error, Result};
use crate::groom::Groom;

/// One curves object to write.
#[derive(Debug, Clone)]
pub struct CurvesObject<'a> {
    /// Its name (one path element: no `/`).
    pub name: &'a str,
    /// Its strands, in the object's own space.
    pub groom: &'a Groom,
    /// Per-strand guide marks (`groom_guide`).
    pub guides: Option<&'a [bool]>,
    /// Per-strand root UVs (`groom_root_uv`).
    pub root_uvs: Option<&'a [Vec2]>,
    /// A parent Xform object's matrix (column vectors), written as one matrix op.
    pub transform: Option<DMat4>,
}

const DATA_BIT: u64 = 1 << 63;
/// Alembic's POD codes used here.
const BOOL: u32 = 0;
const U8: u32 = 1;
const I32: u32 = 6;
const F32: u32 = 10;
const F64: u32 = 11;

/// A child of a group being written.
#[derive(Clone, Copy)]
enum Node {
    Group(u64),
    Data(u64),
}

struct Writer {
    out: Vec<u8>,
}

impl Writer {
    /// An Ogawa header with its root position to be filled in.
    fn new() -> Self {
        let mut out = b"Ogawa\xff\x00\x01".to_vec();
        out.extend_from_slice(&[0u8; 8]);
        Writer { out }
    }

    fn data(&mut self, bytes: &[u8]) -> Node {
        if bytes.is_empty() {
            return Node::Data(0);
        }
        let at = self.out.len() as u64;
        self.out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
        self.out.extend_from_slice(bytes);
        Node::Data(at)
    }

    fn group(&mut self, children: &[Node]) -> Node {
        if children.is_empty() {
            return Node::Group(0);
        }
        let at = self.out.len() as u64;
        self.out.extend_from_slice(&(children.len() as u64).to_le_bytes());
        for c in children {
            let v = match *c {
                Node::Group(p) => p,
                Node::Data(p) => p | DATA_BIT,
            };
            self.out.extend_from_slice(&v.to_le_bytes());
        }
        Node::Group(at)
    }

    /// A property's one sample: a 16-byte key, then the values.
    fn sample(&mut self, values: &[u8]) -> Node {
        let mut b = vec![0u8; 16];
        b.extend_from_slice(values);
        self.data(&b)
    }
}

/// A property written: its header bytes and its group.
struct Property {
    header: Vec<u8>,
    node: Node,
}

fn header(kind: u32, pod: u32, extent: u32, name: &str, metadata: &str) -> Vec<u8> {
    // Numbers as 4 bytes (size hint 2), metadata inline (index 0xff), one
    // sample the same throughout (0x800).
    let mut info = kind | (2 << 2) | (0xff << 20);
    if kind != 0 {
        info |= (pod << 4) | 0x800 | ((extent & 0xff) << 12);
    }
    let mut h = info.to_le_bytes().to_vec();
    if kind != 0 {
        h.extend_from_slice(&1u32.to_le_bytes());
    }
    h.extend_from_slice(&(name.len() as u32).to_le_bytes());
    h.extend_from_slice(name.as_bytes());
    h.extend_from_slice(&(metadata.len() as u32).to_le_bytes());
    h.extend_from_slice(metadata.as_bytes());
    h
}

fn array(w: &mut Writer, name: &str, pod: u32, extent: u32, metadata: &str, values: &[u8]) -> Property {
    let data = w.sample(values);
    let node = w.group(&[data, Node::Data(0)]);
    Property { header: header(2, pod, extent, name, metadata), node }
}

fn scalar(w: &mut Writer, name: &str, pod: u32, extent: u32, values: &[u8]) -> Property {
    let data = w.sample(values);
    let node = w.group(&[data]);
    Property { header: header(1, pod, extent, name, ""), node }
}

fn compound(w: &mut Writer, name: &str, metadata: &str, props: Vec<Property>) -> Property {
    let node = compound_group(w, props);
    Property { header: header(0, 0, 0, name, metadata), node }
}

fn compound_group(w: &mut Writer, props: Vec<Property>) -> Node {
    let mut children: Vec<Node> = props.iter().map(|p| p.node).collect();
    let headers: Vec<u8> = props.into_iter().flat_map(|p| p.header).collect();
    children.push(w.data(&headers));
    w.group(&children)
}

fn f32s(v: impl IntoIterator<Item = f32>) -> Vec<u8> {
    v.into_iter().flat_map(f32::to_le_bytes).collect()
}

/// An object group: its properties, its children, their headers (+ hashes).
fn object(w: &mut Writer, props: Vec<Property>, children: &[(String, String, Node)]) -> Node {
    let top = compound_group(w, props);
    let mut nodes = vec![top];
    let mut headers = Vec::new();
    for (name, metadata, node) in children {
        nodes.push(*node);
        headers.extend_from_slice(&(name.len() as u32).to_le_bytes());
        headers.extend_from_slice(name.as_bytes());
        headers.push(0xff);
        headers.extend_from_slice(&(metadata.len() as u32).to_le_bytes());
        headers.extend_from_slice(metadata.as_bytes());
    }
    headers.extend_from_slice(&[0u8; 32]);
    nodes.push(w.data(&headers));
    w.group(&nodes)
}

fn curves(w: &mut Writer, o: &CurvesObject<'_>) -> Node {
    let g = o.groom;
    let p = f32s(g.positions().iter().flat_map(|p| p.to_array()));
    let counts: Vec<u8> = (0..g.strand_count()).flat_map(|s| (g.strand_len(s) as i32).to_le_bytes()).collect();
    let mut geom = vec![
        array(w, "P", F32, 3, "geoScope=vtx;interpretation=point", &p),
        array(w, "nVertices", I32, 1, "", &counts),
        scalar(w, "curveBasisAndType", U8, 4, &[1, 0, 0, 0]),
    ];
    if let Some(t) = g.thickness() {
        geom.push(array(w, "width", F32, 1, "geoScope=vtx", &f32s(t.iter().copied())));
    }
    let mut arb = Vec::new();
    if let Some(c) = g.colors() {
        let c = f32s(c.iter().flat_map(|c| c.to_array()));
        arb.push(array(w, "groom_color", F32, 3, "geoScope=vtx;interpretation=rgb", &c));
    }
    if let Some(guides) = o.guides {
        let v: Vec<u8> = guides.iter().flat_map(|&b| i32::from(b).to_le_bytes()).collect();
        arb.push(array(w, "groom_guide", I32, 1, "geoScope=uni", &v));
    }
    if let Some(uvs) = o.root_uvs {
        arb.push(array(w, "groom_root_uv", F32, 2, "geoScope=uni", &f32s(uvs.iter().flat_map(|u| u.to_array()))));
    }
    if !arb.is_empty() {
        geom.push(compound(w, ".arbGeomParams", "", arb));
    }
    let geom = compound(w, ".geom", "schema=AbcGeom_Curve_v2", geom);
    object(w, vec![geom], &[])
}

/// An Xform object of one matrix op over `child`.
fn xform(w: &mut Writer, m: DMat4, child: (String, String, Node)) -> Node {
    xform_ops(w, &[3 << 4], &m.to_cols_array(), child)
}

/// An Xform object of encoded `ops` (type << 4) with their channel `vals`.
fn xform_ops(w: &mut Writer, ops: &[u8], vals: &[f64], child: (String, String, Node)) -> Node {
    let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
    let props = vec![
        scalar(w, ".ops", U8, ops.len() as u32, ops),
        scalar(w, ".vals", F64, vals.len() as u32, &bytes),
        scalar(w, ".inherits", BOOL, 1, &[1]),
    ];
    let x = compound(w, ".xform", "schema=AbcGeom_Xform_v3", props);
    object(w, vec![x], &[child])
}

const CURVE_META: &str = "schema=AbcGeom_Curve_v2;schemaObjTitle=AbcGeom_Curve_v2:.geom";
const XFORM_META: &str = "schema=AbcGeom_Xform_v3;schemaObjTitle=AbcGeom_Xform_v3:.xform";

/// The bytes of an Alembic file holding `objects`. Refused: a name that is
/// empty, has a `/` or is another object's; guide marks or root UVs not one
/// per strand; a transform that is not finite.
pub fn to_bytes(objects: &[CurvesObject<'_>]) -> Result<Vec<u8>> {
    for (i, o) in objects.iter().enumerate() {
        if o.name.is_empty() || o.name.contains('/') || objects[..i].iter().any(|p| p.name == o.name) {
            return Err(Error::param("object name", format!("{:?}", o.name), "a unique name without '/'"));
        }
        let strands = o.groom.strand_count();
        for (what, len) in [("guide marks", o.guides.map(<[bool]>::len)), ("root UVs", o.root_uvs.map(<[Vec2]>::len))] {
            if let Some(len) = len.filter(|&l| l != strands) {
                return Err(Error::AttributeLength { what, expected: strands, actual: len });
            }
        }
        if o.root_uvs.is_some_and(|u| u.iter().any(|uv| !uv.is_finite())) || o.transform.is_some_and(|m| !m.is_finite())
        {
            return Err(Error::param("object", o.name, "finite root UVs and transform"));
        }
    }
    let mut w = Writer::new();
    let mut children = Vec::new();
    for o in objects {
        let node = curves(&mut w, o);
        let child = match o.transform {
            None => (o.name.to_owned(), CURVE_META.to_owned(), node),
            Some(m) => {
                let inner = (o.name.to_owned(), CURVE_META.to_owned(), node);
                (format!("{}_xform", o.name), XFORM_META.to_owned(), xform(&mut w, m, inner))
            }
        };
        children.push(child);
    }
    Ok(finish(w, &children))
}

/// The archive around the top object's `children`: the whole file.
fn finish(mut w: Writer, children: &[(String, String, Node)]) -> Vec<u8> {
    let top = object(&mut w, Vec::new(), children);
    let version = w.data(&1i32.to_le_bytes());
    let library = w.data(&10709i32.to_le_bytes());
    let meta = w.data(b"_ai_Application=vkhair");
    // Time sampling 0: one sample a cycle of 1 s, at 0 (u32 max sample, f64
    // time per cycle, u32 sample count, f64 times).
    let mut sampling = 1u32.to_le_bytes().to_vec();
    sampling.extend_from_slice(&1f64.to_le_bytes());
    sampling.extend_from_slice(&1u32.to_le_bytes());
    sampling.extend_from_slice(&0f64.to_le_bytes());
    let samplings = w.data(&sampling);
    let indexed = w.data(&[]);
    let root = w.out.len() as u64;
    w.group(&[version, library, top, meta, samplings, indexed]);
    w.out[8..16].copy_from_slice(&root.to_le_bytes());
    w.out
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// An animated object: P has two samples (x = 0, then x = 1); the
    /// reader takes the first.
    #[test]
    fn an_animated_object_gives_its_first_sample() {
        let mut w = Writer::new();
        let p = |x: f32| f32s([x, 0.0, 0.0, x, -0.1, 0.0]);
        let (first, second) = (w.sample(&p(0.0)), w.sample(&p(1.0)));
        let node = w.group(&[first, Node::Data(0), second, Node::Data(0)]);
        let mut h = header(2, F32, 3, "P", "geoScope=vtx");
        // Two samples that differ: no "same throughout" bit, a count of 2.
        let info = u32::from_le_bytes([h[0], h[1], h[2], h[3]]) & !0x800;
        h[..4].copy_from_slice(&info.to_le_bytes());
        h[4..8].copy_from_slice(&2u32.to_le_bytes());
        let geom = vec![
            Property { header: h, node },
            array(&mut w, "nVertices", I32, 1, "", &2i32.to_le_bytes()),
            scalar(&mut w, "curveBasisAndType", U8, 4, &[1, 0, 0, 0]),
        ];
        let geom = compound(&mut w, ".geom", CURVE_META, geom);
        let c = object(&mut w, vec![geom], &[]);
        let g = super::super::parse(&finish(w, &[("c".into(), CURVE_META.into(), c)])).expect("file");
        assert_eq!(g.groom.positions(), [Vec3::ZERO, Vec3::new(0.0, -0.1, 0.0)]);
    }

    /// Objects nest up to [`super::super::MAX_DEPTH`] levels: a curves object
    /// that deep (under 255 Xforms) is read, one level deeper is refused
    /// naming it.
    #[test]
    fn objects_nest_as_deep_as_the_limit_and_no_deeper() {
        let groom = Groom::from_strands(&[vec![Vec3::X, Vec3::new(1.0, -1.0, 0.0)]]).expect("groom");
        let nested = |levels: usize| {
            let mut w = Writer::new();
            let o = CurvesObject { name: "c", groom: &groom, guides: None, root_uvs: None, transform: None };
            let mut child = ("c".to_owned(), CURVE_META.to_owned(), curves(&mut w, &o));
            for level in 1..levels {
                child = (format!("x{level}"), XFORM_META.to_owned(), xform(&mut w, DMat4::IDENTITY, child));
            }
            finish(w, &[child])
        };
        let limit = super::super::MAX_DEPTH;
        let g = super::super::parse(&nested(limit)).expect("as deep as the limit");
        assert_eq!(g.groom.strand_count(), 1);
        let err = super::super::parse(&nested(limit + 1)).expect_err("one deeper").to_string();
        assert!(err.contains("/c: objects nest deeper than 256 levels"), "{err}");
    }

    /// An archive reads at most [`super::super::MAX_OBJECTS`] objects: that
    /// many (empty objects beside one curves object) read, one more is
    /// refused naming the bound.
    #[test]
    fn an_archive_holds_as_many_objects_as_the_limit_and_no_more() {
        let groom = Groom::from_strands(&[vec![Vec3::X, Vec3::new(1.0, -1.0, 0.0)]]).expect("groom");
        let archive = |objects: usize| {
            let mut w = Writer::new();
            let o = CurvesObject { name: "c", groom: &groom, guides: None, root_uvs: None, transform: None };
            let mut children = vec![("c".to_owned(), CURVE_META.to_owned(), curves(&mut w, &o))];
            children.extend((1..objects).map(|k| (format!("e{k}"), String::new(), Node::Group(0))));
            finish(w, &children)
        };
        let limit = super::super::MAX_OBJECTS;
        let g = super::super::parse(&archive(limit)).expect("as many objects as the limit");
        assert_eq!(g.groom.strand_count(), 1);
        let err = super::super::parse(&archive(limit + 1)).expect_err("one more").to_string();
        assert!(err.contains("more than 1048576 objects"), "{err}");
    }

    #[test]
    fn xform_ops_compose_with_the_first_outermost() {
        let groom = Groom::from_strands(&[vec![Vec3::X, Vec3::new(1.0, -1.0, 0.0)]]).expect("groom");
        let mut w = Writer::new();
        let o = CurvesObject { name: "c", groom: &groom, guides: None, root_uvs: None, transform: None };
        let node = curves(&mut w, &o);
        // Translate (1, 2, 3), rotate 90° about Y, scale 2.
        let (ops, vals) = ([1 << 4, 5 << 4, 0], [1.0, 2.0, 3.0, 90.0, 2.0, 2.0, 2.0]);
        let x = xform_ops(&mut w, &ops, &vals, ("c".into(), CURVE_META.into(), node));
        let g = super::super::parse(&finish(w, &[("x".into(), XFORM_META.into(), x)])).expect("file");
        // (1, 0, 0) scaled to (2, 0, 0), turned to (0, 0, −2), moved to (1, 2, 1).
        let p = g.groom.strand(0)[0];
        assert!((p - Vec3::new(1.0, 2.0, 1.0)).length() < 1e-5, "{p}");
    }
}
