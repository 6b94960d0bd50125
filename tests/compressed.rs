//! Compressed geometry: a mesh stored with KHR_mesh_quantization's integer attributes, and one
//! stored in EXT_meshopt_compression's compressed buffer views (vertex and index codecs, the
//! octahedral and exponential filters), load as the float mesh they encode, within the
//! precision of the encoding; a damaged stream is refused with an error that names it.

use base64::Engine;
use glam::{DVec3, Vec2, Vec3};
use hush_engine::scene::{Scene, load_gltf};
use hush_tests::gltf_writer::write_json;
use serde_json::{Value, json};

/// A 5 x 5 grid over a paraboloid cap: positions, unit normals, UVs and triangle indices.
struct Grid {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
}

fn grid() -> Grid {
    let n = 5;
    let mut g = Grid { positions: vec![], normals: vec![], uvs: vec![], indices: vec![] };
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f32 / 2.0 - 1.0, j as f32 / 2.0 - 1.0);
            g.positions.push([x, y, 0.2 * (x * x + y * y)]);
            g.normals.push(Vec3::new(-0.4 * x, -0.4 * y, 1.0).normalize().to_array());
            g.uvs.push([(x + 1.0) / 2.0, (1.0 - y) / 2.0]);
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = (j * n + i) as u32;
            g.indices.extend([a, a + 1, a + n as u32 + 1, a, a + n as u32 + 1, a + n as u32]);
        }
    }
    g
}

/// Buffers, views and accessors of a hand-written file.
#[derive(Clone, Default)]
struct File {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    /// The primitive's topology (glTF's mode; triangles when `None`).
    mode: Option<u32>,
}

impl File {
    fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(s) = stride {
            v["byteStride"] = json!(s);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    fn accessor(
        &mut self,
        view: usize,
        component: u32,
        normalized: bool,
        count: usize,
        ty: &str,
    ) -> usize {
        self.accessors.push(json!({"bufferView": view, "componentType": component, "normalized": normalized, "count": count, "type": ty}));
        self.accessors.len() - 1
    }

    /// The file: one node (with `node` merged in) holding one primitive of `attributes`.
    fn scene(
        self,
        name: &str,
        attributes: Value,
        indices: usize,
        node: Value,
        extensions: &[&str],
        extra_buffers: Vec<Value>,
    ) -> Result<Scene, String> {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        );
        let mut n = json!({"mesh": 0});
        for (k, v) in node.as_object().unwrap() {
            n[k] = v.clone();
        }
        let mut buffers = vec![json!({"byteLength": self.bin.len(), "uri": uri})];
        buffers.extend(extra_buffers);
        let mut primitive = json!({"attributes": attributes, "indices": indices});
        if let Some(m) = self.mode {
            primitive["mode"] = json!(m);
        }
        let j = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [n],
            "meshes": [{"primitives": [primitive]}],
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": buffers,
            "extensionsUsed": extensions,
            "extensionsRequired": extensions,
        });
        load_gltf(&write_json(name, &j)).map_err(|e| format!("{e:#}"))
    }
}

fn floats(v: &[impl AsRef<[f32]>]) -> Vec<u8> {
    v.iter()
        .flat_map(|x| x.as_ref().iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<_>>())
        .collect()
}

/// The grid as one triangle strip (rows joined by degenerate triangles), glTF mode 5.
const STRIP: u32 = 5;
fn strip() -> Vec<u32> {
    let n = 5u32;
    let mut s: Vec<u32> = vec![];
    for j in 0..n - 1 {
        if j > 0 {
            s.extend([*s.last().unwrap(), (j + 1) * n]);
        }
        for i in 0..n {
            s.extend([(j + 1) * n + i, j * n + i]);
        }
    }
    s
}

/// meshoptimizer 0.22's `meshopt_encodeIndexSequence` of `strip()` (the crate binds the
/// encoder only as an unsafe call, so the stream is stored here).
const STRIP_ENCODED: [u8; 51] = [
    209, 20, 18, 24, 18, 24, 18, 24, 18, 24, 18, 0, 24, 0, 18, 24, 18, 24, 18, 24, 18, 24, 18, 0,
    24, 0, 18, 24, 18, 24, 18, 24, 18, 24, 18, 0, 24, 0, 18, 24, 18, 24, 18, 24, 18, 24, 18, 0, 0,
    0, 0,
];

fn float_file(g: &Grid, name: &str) -> Scene {
    float_file_with(g, name, &g.indices, None)
}

fn float_file_with(g: &Grid, name: &str, indices: &[u32], mode: Option<u32>) -> Scene {
    let mut f = File { mode, ..Default::default() };
    let p = f.view(&floats(&g.positions), None);
    let n = f.view(&floats(&g.normals), None);
    let t = f.view(&floats(&g.uvs), None);
    let i = f.view(&indices.iter().flat_map(|i| i.to_le_bytes()).collect::<Vec<_>>(), None);
    let count = g.positions.len();
    let attrs = json!({
        "POSITION": f.accessor(p, 5126, false, count, "VEC3"),
        "NORMAL": f.accessor(n, 5126, false, count, "VEC3"),
        "TEXCOORD_0": f.accessor(t, 5126, false, count, "VEC2"),
    });
    let idx = f.accessor(i, 5125, false, indices.len(), "SCALAR");
    f.accessors[0]["min"] = json!([-1.0, -1.0, 0.0]);
    f.accessors[0]["max"] = json!([1.0, 1.0, 0.4]);
    f.scene(name, attrs, idx, json!({}), &[], vec![]).unwrap()
}

/// Positions, normals and UVs of a loaded scene's first mesh, positions placed by its node.
fn geometry(s: &Scene) -> (Vec<DVec3>, Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
    let m = &s.meshes[s.objects[0].mesh];
    let t = s.objects[0].transform;
    let p = m.positions.iter().map(|p| t.transform_point3(p.as_dvec3())).collect();
    let n = m.normals.iter().map(|n| n.normalize()).collect();
    (p, n, m.uvs.clone(), m.indices.clone())
}

/// Each triangle turned to start at its smallest index: the index codec may rotate a
/// triangle's vertices (the winding stays).
fn triangles(i: &[u32]) -> Vec<[u32; 3]> {
    i.chunks_exact(3)
        .map(|t| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect()
}

/// Largest differences (positions, normals, UVs) of `test` from `reference`; the same triangles.
fn differences(test: &Scene, reference: &Scene) -> (f64, f32, f32) {
    let (p, n, t, i) = geometry(test);
    let (rp, rn, rt, ri) = geometry(reference);
    assert_eq!(triangles(&i), triangles(&ri), "triangles");
    let dp = p.iter().zip(&rp).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0, f64::max);
    let dn = n.iter().zip(&rn).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0, f32::max);
    let dt = t.iter().zip(&rt).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0, f32::max);
    (dp, dn, dt)
}

#[test]
fn quantized_attributes_load_as_the_floats_they_encode() {
    let g = grid();
    let reference = float_file(&g, "float-grid-q");
    // gltfpack's layout: positions as 16-bit integers with the scale in the node, normals as
    // normalized bytes (padded to 4), UVs as normalized 16-bit.
    let scale = 1024.0;
    let mut f = File::default();
    let pos: Vec<u8> = g
        .positions
        .iter()
        .flat_map(|p| {
            let q = p.map(|x| (x * scale).round() as i16);
            [q[0].to_le_bytes(), q[1].to_le_bytes(), q[2].to_le_bytes(), [0, 0]].concat()
        })
        .collect();
    let nor: Vec<u8> = g
        .normals
        .iter()
        .flat_map(|n| {
            let q = n.map(|x| (x * 127.0).round() as i8 as u8);
            [q[0], q[1], q[2], 0]
        })
        .collect();
    let uv: Vec<u8> = g
        .uvs
        .iter()
        .flat_map(|t| t.map(|x| ((x * 65535.0).round() as u16).to_le_bytes()).concat())
        .collect();
    let p = f.view(&pos, Some(8));
    let n = f.view(&nor, Some(4));
    let t = f.view(&uv, None);
    let i = f.view(
        &g.indices.iter().map(|&i| i as u16).flat_map(u16::to_le_bytes).collect::<Vec<_>>(),
        None,
    );
    let count = g.positions.len();
    let attrs = json!({
        "POSITION": f.accessor(p, 5122, false, count, "VEC3"),
        "NORMAL": f.accessor(n, 5120, true, count, "VEC3"),
        "TEXCOORD_0": f.accessor(t, 5123, true, count, "VEC2"),
    });
    let idx = f.accessor(i, 5123, false, g.indices.len(), "SCALAR");
    f.accessors[0]["min"] = json!([-1024, -1024, 0]);
    f.accessors[0]["max"] = json!([1024, 1024, 410]);
    let node = json!({"scale": [1.0 / scale, 1.0 / scale, 1.0 / scale]});
    let s = f
        .clone()
        .scene(
            "quantized-grid",
            attrs.clone(),
            idx,
            node.clone(),
            &["KHR_mesh_quantization"],
            vec![],
        )
        .unwrap();
    let (dp, dn, dt) = differences(&s, &reference);
    println!("quantized: positions within {dp}, normals {dn}, UVs {dt}");
    // Half a quantization step of each encoding (normals: a step of 1/127 in each component
    // before renormalizing).
    assert!(dp <= 0.5 / scale as f64 + 1e-6, "positions {dp}");
    assert!(dn < 1.5 / 127.0, "normals {dn}");
    assert!(dt <= 0.5 / 65535.0 + 1e-6, "UVs {dt}");
    // Without the extension the same integers are not valid glTF: refused, naming the accessor.
    let e = f.scene("quantized-undeclared", attrs, idx, node, &[], vec![]).unwrap_err();
    assert!(e.contains("POSITION") && e.contains("SHORT"), "{e}");
}

/// The extension's octahedral encoding of a unit vector in 8-bit components (X, Y, 1.0 = 127).
fn octahedral8(n: [f32; 3]) -> [u8; 4] {
    let l = n[0].abs() + n[1].abs() + n[2].abs();
    let (mut x, mut y) = (n[0] / l, n[1] / l);
    if n[2] < 0.0 {
        let (ox, oy) = (x, y);
        x = (1.0 - oy.abs()) * ox.signum();
        y = (1.0 - ox.abs()) * oy.signum();
    }
    [(x * 127.0).round() as i8 as u8, (y * 127.0).round() as i8 as u8, 127, 0]
}

/// The meshopt file of `g`; `damage` truncates the compressed positions, `edit` changes the
/// JSON of the first compressed view and of the fallback buffer before writing.
fn meshopt_file(g: &Grid, name: &str, damage: bool) -> Result<Scene, String> {
    meshopt_file_with(g, name, damage, false, |_, _| {})
}

/// `strip`: the grid as `strip()`, its 16-bit indices in an INDICES (index sequence) view,
/// instead of a triangle list in a TRIANGLES view.
fn meshopt_file_with(
    g: &Grid,
    name: &str,
    damage: bool,
    strip: bool,
    edit: impl FnOnce(&mut Value, &mut Value),
) -> Result<Scene, String> {
    let count = g.positions.len();
    let mut f = File { mode: strip.then_some(STRIP), ..Default::default() };
    let positions = meshopt::encode_vertex_buffer(&g.positions).unwrap();
    let normals: Vec<[u8; 4]> = g.normals.iter().map(|&n| octahedral8(n)).collect();
    let normals = meshopt::encode_vertex_buffer(&normals).unwrap();
    // Exponential filter: mantissa x 2^-16 with the exponent in the top byte.
    let uvs: Vec<[i32; 2]> = g
        .uvs
        .iter()
        .map(|t| t.map(|x| (-16i32 << 24) | (((x * 65536.0).round() as i32) & 0xff_ffff)))
        .collect();
    let uvs = meshopt::encode_vertex_buffer(&uvs).unwrap();
    let (indices, index_count, index_stride, index_mode) = if strip {
        (STRIP_ENCODED.to_vec(), self::strip().len(), 2, "INDICES")
    } else {
        (meshopt::encode_index_buffer(&g.indices, count).unwrap(), g.indices.len(), 4, "TRIANGLES")
    };
    // Compressed streams in buffer 0; the views they decode into in buffer 1 (the fallback).
    let mut views = vec![];
    let mut at = 0usize;
    for (data, stride, n, mode, filter) in [
        (&positions, 12, count, "ATTRIBUTES", "NONE"),
        (&normals, 4, count, "ATTRIBUTES", "OCTAHEDRAL"),
        (&uvs, 8, count, "ATTRIBUTES", "EXPONENTIAL"),
        (&indices, index_stride, index_count, index_mode, "NONE"),
    ] {
        let mut data = data.clone();
        if damage && views.is_empty() {
            data.truncate(data.len() / 2);
        }
        let src = f.view(&data, None);
        let source = f.views[src].clone();
        let mut v = json!({"buffer": 1, "byteOffset": at, "byteLength": n * stride, "extensions": {
            "EXT_meshopt_compression": {"buffer": 0, "byteOffset": source["byteOffset"], "byteLength": source["byteLength"],
                "byteStride": stride, "count": n, "mode": mode, "filter": filter}}});
        if mode == "ATTRIBUTES" {
            v["byteStride"] = json!(stride);
        }
        views.push(v);
        at += n * stride;
    }
    let mut fallback =
        json!({"byteLength": at, "extensions": {"EXT_meshopt_compression": {"fallback": true}}});
    edit(&mut views[0], &mut fallback);
    let first = f.views.len();
    f.views.extend(views);
    let attrs = json!({
        "POSITION": f.accessor(first, 5126, false, count, "VEC3"),
        "NORMAL": f.accessor(first + 1, 5120, true, count, "VEC3"),
        "TEXCOORD_0": f.accessor(first + 2, 5126, false, count, "VEC2"),
    });
    let idx = f.accessor(
        first + 3,
        if index_stride == 2 { 5123 } else { 5125 },
        false,
        index_count,
        "SCALAR",
    );
    f.accessors[0]["min"] = json!([-1.0, -1.0, 0.0]);
    f.accessors[0]["max"] = json!([1.0, 1.0, 0.4]);
    f.scene(
        name,
        attrs,
        idx,
        json!({}),
        &["EXT_meshopt_compression", "KHR_mesh_quantization"],
        vec![fallback],
    )
}

#[test]
fn meshopt_compressed_views_load_as_the_mesh_they_encode() {
    let g = grid();
    let reference = float_file(&g, "float-grid-m");
    let s = meshopt_file(&g, "meshopt-grid", false).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let (dp, dn, dt) = differences(&s, &reference);
    println!("meshopt: positions within {dp}, normals {dn}, UVs {dt}");
    // The vertex and index codecs are lossless; the octahedral filter keeps 8 bits a component
    // (about 1/127 of the unit sphere's octant edge), the exponential one a mantissa of 2^-16.
    assert_eq!(dp, 0.0, "positions");
    assert!(dn < 0.03, "normals {dn}");
    assert!(dt <= 0.5 / 65536.0 + 1e-7, "UVs {dt}");
    let e = meshopt_file(&g, "meshopt-damaged", true).unwrap_err();
    assert!(e.contains("EXT_meshopt_compression") && e.contains("does not decode"), "{e}");
}

/// A triangle strip whose indices are an INDICES view (the index-sequence codec, which
/// gltfpack writes for strips, fans, lines and points) loads as the same strip uncompressed.
/// Broken streams are the decoder's unit tests (engine/src/scene/meshopt.rs).
#[test]
fn meshopt_index_sequences_load_as_the_strip_they_encode() {
    let g = grid();
    let reference = float_file_with(&g, "float-strip", &strip(), Some(STRIP));
    let s = meshopt_file_with(&g, "meshopt-strip", false, true, |_, _| {}).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let (dp, _, _) = differences(&s, &reference);
    assert_eq!(dp, 0.0, "positions");
    // The strip's 36 triangles, 8 of them the degenerate joins, reach the mesh.
    assert_eq!(geometry(&s).3.len(), 3 * (strip().len() - 2));
}

/// Hostile compressed views are refused with errors that name what is wrong, before anything
/// large is allocated: a fallback buffer past the decoded-bytes budget, a count whose size
/// overflows, a size that disagrees with the view, a stream outside its buffer, an unknown mode
/// and a stride the filter cannot take.
#[test]
fn hostile_compressed_views_are_refused_by_name() {
    let g = grid();
    let ext = |v: &mut Value| v["extensions"]["EXT_meshopt_compression"].take();
    type Edit = Box<dyn FnOnce(&mut Value, &mut Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        ("huge-fallback", Box::new(|_, b| b["byteLength"] = json!(1u64 << 40)), "decoded-bytes"),
        (
            "overflow",
            Box::new(move |v, _| {
                let mut e = ext(v);
                e["count"] = json!(u64::MAX / 4);
                v["extensions"]["EXT_meshopt_compression"] = e;
            }),
            "overflows",
        ),
        (
            "size",
            Box::new(move |v, _| {
                let mut e = ext(v);
                e["count"] = json!(7);
                v["extensions"]["EXT_meshopt_compression"] = e;
            }),
            "the view holds",
        ),
        (
            "outside",
            Box::new(move |v, _| {
                let mut e = ext(v);
                e["byteOffset"] = json!(1u64 << 33);
                v["extensions"]["EXT_meshopt_compression"] = e;
            }),
            "outside buffers[0]",
        ),
        (
            "mode",
            Box::new(move |v, _| {
                let mut e = ext(v);
                e["mode"] = json!("POINTS");
                v["extensions"]["EXT_meshopt_compression"] = e;
            }),
            "mode",
        ),
        (
            "filter-stride",
            Box::new(move |v, _| {
                let mut e = ext(v);
                e["filter"] = json!("QUATERNION");
                v["extensions"]["EXT_meshopt_compression"] = e;
            }),
            "byteStride 12",
        ),
    ];
    for (name, edit, needle) in cases {
        let e = meshopt_file_with(&g, &format!("meshopt-{name}"), false, false, edit).unwrap_err();
        assert!(e.contains(needle), "{name}: {e}");
    }
}
