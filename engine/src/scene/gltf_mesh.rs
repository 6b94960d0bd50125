//! glTF mesh primitives, read through the checked accessors of `accessor`.

use super::accessor::{self, Data, Expect};
use super::gltf_importer::Importer;
use super::{Mesh, MorphTarget};
use anyhow::{Result, bail};
use glam::{Vec2, Vec3, Vec4};

/// Read one primitive as a triangle mesh, or None (with a warning) for points and lines.
pub(super) fn primitive(
    imp: &mut Importer,
    prim: &gltf::Primitive,
    data: &Data,
    default_material: u32,
    here: &str,
) -> Result<Option<Mesh>> {
    use gltf::mesh::Mode;
    let mode = prim.mode();
    if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
        imp.warn(format!("{here}: {mode:?} primitives are not rendered"));
        return Ok(None);
    }
    let attribute = |s: gltf::Semantic| prim.get(&s).map(|a| a.index());
    // KHR_mesh_quantization widens the component types of the geometry attributes.
    let quantized = data.root.extensions_used.iter().any(|e| e == "KHR_mesh_quantization");
    let q = |plain: Expect, widened: Expect| if quantized { widened } else { plain };
    let Some(pos) = attribute(gltf::Semantic::Positions) else {
        imp.warn(format!("{here} has no POSITION; skipped"));
        return Ok(None);
    };
    let positions: Vec<Vec3> = vec3s(accessor::read_f32(
        data,
        pos,
        q(accessor::POSITION, accessor::Q_POSITION),
        &mut imp.budget,
        &format!("{here}.attributes.POSITION"),
    )?);
    let n = positions.len();
    let raw: Vec<u32> = match prim.indices() {
        Some(a) => {
            accessor::read_indices(data, a.index(), &mut imp.budget, &format!("{here}.indices"))?
        }
        None => (0..n as u32).collect(),
    };
    if let Some(bad) = raw.iter().find(|&&i| i as usize >= n) {
        bail!("{here}: index {bad} is out of range for {n} vertices");
    }
    // Counted against the triangles budget before any per-triangle work (triangulation,
    // flattening, tangents), as if the mesh were placed once more.
    let triangles = match mode {
        Mode::Triangles => raw.len() / 3,
        _ => raw.len().saturating_sub(2),
    } as u64;
    imp.triangles_fit(triangles, format_args!("{here}"))?;
    let indices = triangulate(mode, &raw);
    drop(raw);
    // glTF 2.0 §3.7.2.1: all attributes of a primitive have the same count.
    let same_count = |name: &str,
                      s: gltf::Semantic,
                      expect: Expect,
                      imp: &mut Importer|
     -> Result<Option<Vec<f32>>> {
        let Some(i) = attribute(s) else { return Ok(None) };
        let what = format!("{here}.attributes.{name}");
        let v = accessor::read_f32(data, i, expect, &mut imp.budget, &what)?;
        let count = v.len() / expect.ty.multiplicity();
        if count != n {
            bail!(
                "{what} has {count} elements and POSITION {n}; a primitive's attributes have one count"
            );
        }
        Ok(Some(v))
    };
    let normals = same_count(
        "NORMAL",
        gltf::Semantic::Normals,
        q(accessor::NORMAL, accessor::Q_NORMAL),
        imp,
    )?
    .map(vec3s);
    let uvs: Vec<Vec2> = match same_count(
        "TEXCOORD_0",
        gltf::Semantic::TexCoords(0),
        q(accessor::TEXCOORD, accessor::Q_TEXCOORD),
        imp,
    )? {
        Some(t) => t.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect(),
        None => vec![Vec2::ZERO; n],
    };
    let (reads_uv1, normal_uv1) = super::gltf_material::texcoord1_uses(&prim.material());
    let uvs1: Vec<Vec2> = match reads_uv1 {
        false => vec![],
        true => {
            match same_count(
                "TEXCOORD_1",
                gltf::Semantic::TexCoords(1),
                q(accessor::TEXCOORD, accessor::Q_TEXCOORD),
                imp,
            )? {
                Some(t) => t.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect(),
                None => {
                    imp.warn(format!("{here}: its material reads TEXCOORD_1, which it lacks; TEXCOORD_0 is read instead"));
                    uvs.clone()
                }
            }
        }
    };
    let colors: Vec<Vec4> = match attribute(gltf::Semantic::Colors(0)) {
        None => vec![],
        Some(i) => {
            let rgba = data.root.accessors.get(i).is_some_and(|a| {
                a.type_ == gltf::json::validation::Checked::Valid(gltf::json::accessor::Type::Vec4)
            });
            let expect = if rgba { accessor::COLOR_RGBA } else { accessor::COLOR_RGB };
            let c =
                same_count("COLOR_0", gltf::Semantic::Colors(0), expect, imp)?.unwrap_or_default();
            let clean = |x: f32| if x.is_finite() { x.clamp(0.0, 1.0) } else { 1.0 };
            if rgba {
                c.chunks_exact(4)
                    .map(|c| Vec4::from_slice(c).to_array().map(clean).into())
                    .collect()
            } else {
                c.chunks_exact(3)
                    .map(|c| Vec4::new(clean(c[0]), clean(c[1]), clean(c[2]), 1.0))
                    .collect()
            }
        }
    };
    let tangents: Option<Vec<Vec4>> = same_count(
        "TANGENT",
        gltf::Semantic::Tangents,
        q(accessor::TANGENT, accessor::Q_TANGENT),
        imp,
    )?
    .map(|t| t.chunks_exact(4).map(|c| Vec4::new(c[0], c[1], c[2], c[3])).collect());
    let material = prim.material().index().map(|i| i as u32).unwrap_or(default_material);
    let mut m = Mesh {
        positions,
        normals: normals.unwrap_or_default(),
        uvs,
        uvs1,
        colors,
        tangents: vec![],
        indices,
        material,
        ..Default::default()
    };
    super::gltf_deform::read_influences(imp, prim, data, here, &mut m)?;
    super::gltf_deform::read_targets(imp, prim, data, here, quantized, &mut m)?;
    if m.normals.len() != n {
        // glTF: without NORMAL, clients compute flat normals.
        flatten_with_face_normals(&mut m);
    }
    if prim.material().normal_texture().is_some() {
        match tangents {
            Some(t) if t.len() == m.positions.len() => m.tangents = t,
            _ => generate_tangents(&mut m, normal_uv1),
        }
    }
    Ok(Some(m))
}

fn vec3s(v: Vec<f32>) -> Vec<Vec3> {
    v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
}

fn triangulate(mode: gltf::mesh::Mode, idx: &[u32]) -> Vec<u32> {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => idx[..idx.len() / 3 * 3].to_vec(),
        Mode::TriangleStrip => (2..idx.len())
            .flat_map(|i| {
                if i % 2 == 0 {
                    [idx[i - 2], idx[i - 1], idx[i]]
                } else {
                    [idx[i - 1], idx[i - 2], idx[i]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..idx.len()).flat_map(|i| [idx[0], idx[i - 1], idx[i]]).collect(),
        _ => vec![],
    }
}

/// Give every triangle its own three vertices with the face normal.
fn flatten_with_face_normals(m: &mut Mesh) {
    let mut out = Mesh { material: m.material, ..Default::default() };
    for t in m.indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for k in 0..3 {
            out.indices.push(out.positions.len() as u32);
            out.positions.push(p[k]);
            out.normals.push(n);
            out.uvs.push(m.uvs.get(t[k] as usize).copied().unwrap_or_default());
            if let Some(uv) = m.uvs1.get(t[k] as usize) {
                out.uvs1.push(*uv);
            }
            if let Some(c) = m.colors.get(t[k] as usize) {
                out.colors.push(*c);
            }
            if let (Some(j), Some(w)) = (m.joints.get(t[k] as usize), m.weights.get(t[k] as usize))
            {
                out.joints.push(*j);
                out.weights.push(*w);
            }
        }
    }
    // Morph displacements follow their vertices (the flat normals do not morph).
    out.targets = m
        .targets
        .iter()
        .map(|target| {
            let corners = |v: &[Vec3]| -> Vec<Vec3> {
                if v.is_empty() {
                    return vec![];
                }
                m.indices.chunks_exact(3).flatten().map(|&i| v[i as usize]).collect()
            };
            MorphTarget {
                positions: corners(&target.positions),
                normals: vec![],
                tangents: corners(&target.tangents),
            }
        })
        .collect();
    *m = out;
}

/// MikkTSpace tangents (the glTF reference) for a mesh with a normal map but no TANGENT, along
/// the coordinates the normal map is read at (TEXCOORD_1 where `uv1`).
fn generate_tangents(m: &mut Mesh, uv1: bool) {
    struct Geo<'a>(&'a mut Mesh, bool);
    impl Geo<'_> {
        fn vertex(&self, f: usize, v: usize) -> usize {
            self.0.indices[f * 3 + v] as usize
        }
    }
    impl mikktspace::Geometry for Geo<'_> {
        fn num_faces(&self) -> usize {
            self.0.indices.len() / 3
        }
        fn num_vertices_of_face(&self, _: usize) -> usize {
            3
        }
        // mikktspace bins vertices into a grid between the smallest and largest position and
        // indexes past its table where a non-finite one leaves the last cell empty: such values
        // reach it as zeros (their triangles are dropped before rendering anyway).
        fn position(&self, f: usize, v: usize) -> [f32; 3] {
            finite3(self.0.positions[self.vertex(f, v)]).into()
        }
        fn normal(&self, f: usize, v: usize) -> [f32; 3] {
            finite3(self.0.normals.get(self.vertex(f, v)).copied().unwrap_or(Vec3::Z)).into()
        }
        fn tex_coord(&self, f: usize, v: usize) -> [f32; 2] {
            let uvs = if self.1 { &self.0.uvs1 } else { &self.0.uvs };
            let uv = uvs.get(self.vertex(f, v)).copied().unwrap_or_default();
            if uv.is_finite() { uv.into() } else { [0.0; 2] }
        }
        fn set_tangent_encoded(&mut self, t: [f32; 4], f: usize, v: usize) {
            let i = self.vertex(f, v);
            self.0.tangents[i] = Vec4::from(t);
        }
    }
    fn finite3(v: Vec3) -> Vec3 {
        if v.is_finite() { v } else { Vec3::ZERO }
    }
    m.tangents = vec![Vec4::new(1.0, 0.0, 0.0, 1.0); m.positions.len()];
    // The grid spans the largest extent of the positions it is given; where that extent is zero
    // or overflows f32 every vertex lands in the first cell and the same indexing fails. Such a
    // mesh has no area to map (or no finite one) and keeps the default tangents.
    // It also counts down from its non-degenerate triangles (no two positions equal) unchecked.
    let (lo, hi) = m
        .indices
        .iter()
        .map(|&i| finite3(m.positions[i as usize]))
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let extent = (hi - lo).max_element();
    let any_triangle = m.indices.chunks_exact(3).any(|t| {
        let [a, b, c] = [0, 1, 2].map(|k| finite3(m.positions[t[k] as usize]));
        a != b && a != c && b != c
    });
    if !(extent.is_finite() && extent > 0.0 && any_triangle) {
        return;
    }
    // MikkTSpace writes per face-vertex; shared vertices get the last write, which matches for
    // the usual case of vertices split along UV seams.
    let _ = mikktspace::generate_tangents(&mut Geo(m, uv1));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// mikktspace indexes past its vertex grid when the positions have no finite, non-zero
    /// extent, and underflows when every triangle is degenerate; such meshes keep default
    /// tangents instead of panicking.
    #[test]
    fn tangents_of_degenerate_meshes_do_not_panic() {
        for p in [
            [Vec3::ONE; 3],
            [Vec3::splat(-3e38), Vec3::splat(3e38), Vec3::ZERO],
            [Vec3::NAN, Vec3::X, Vec3::INFINITY],
        ] {
            let mut m = Mesh {
                positions: p.to_vec(),
                normals: vec![Vec3::Y; 3],
                uvs: vec![Vec2::ZERO, Vec2::X, Vec2::Y],
                indices: vec![0, 1, 2],
                ..Default::default()
            };
            generate_tangents(&mut m, false);
            assert_eq!(m.tangents.len(), 3);
        }
        let mut m = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
            normals: vec![Vec3::Y; 3],
            uvs: vec![Vec2::ZERO, Vec2::X, Vec2::Y],
            indices: vec![0, 2, 1],
            ..Default::default()
        };
        generate_tangents(&mut m, false);
        assert!((m.tangents[0].truncate() - Vec3::X).length() < 1e-5, "{:?}", m.tangents);
    }
}
