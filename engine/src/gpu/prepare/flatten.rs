//! Objects flattened into rebased world-space triangles with their attributes, and the
//! per-material tables packed beside them.

use super::SceneFeatures;
use crate::scene::Scene;
use glam::{DMat3, DMat4, DVec3, Vec3, Vec4};
use obvhs::triangle::Triangle;

/// One object's triangles in rebased world space, before the BVH orders them.
#[derive(Clone, Default)]
pub(super) struct Flat {
    pub tris: Vec<Triangle>,
    /// Per triangle, its index among the mesh's triangles (degenerate ones are dropped).
    pub src: Vec<u32>,
    /// Per triangle, its vertices at the previous `animate` call; empty: where they are now.
    pub prev: Vec<[Vec3; 3]>,
    /// A deforming mesh's triangles at the shutter's open (`expose`); empty: carried there by
    /// the object's transform.
    pub open: Vec<[Vec3; 3]>,
    pub attrs: Vec<[Vec4; 4]>,
    pub tans: Vec<[Vec4; 3]>,
    pub extras: Vec<[[u32; 4]; 3]>,
    pub mats: Vec<u32>,
    pub dropped: usize,
}

/// `time`: the time a deforming object's mesh is posed at (None: its rest pose).
pub(super) fn flatten(
    scene: &Scene,
    object: usize,
    transform: DMat4,
    origin: DVec3,
    features: &SceneFeatures,
    time: Option<f64>,
) -> Flat {
    let o = &scene.objects[object];
    let mesh = &scene.meshes[o.mesh];
    // A deforming mesh's posed vertices; the rest of it as it is stored.
    let posed = o.deform.as_ref().map(|d| d.pose_vertices(mesh, time));
    let (positions, normals, tangents) = match &posed {
        Some(p) => (&p.positions, &p.normals, &p.tangents),
        None => (&mesh.positions, &mesh.normals, &mesh.tangents),
    };
    let m3 = DMat3::from_mat4(transform);
    let flip = m3.determinant() < 0.0;
    let nmat = m3.inverse().transpose();
    let mat = if (mesh.material as usize) < scene.materials.len() { mesh.material } else { 0 };
    let n = mesh.indices.len() / 3;
    let mut f = Flat {
        tris: Vec::with_capacity(n),
        src: Vec::with_capacity(n),
        attrs: Vec::with_capacity(n),
        mats: Vec::with_capacity(n),
        ..Flat::default()
    };
    for (k, t) in mesh.indices.chunks_exact(3).enumerate() {
        // A mirroring transform reverses the winding; swap to keep the front face CCW.
        let idx = if flip { [t[0], t[2], t[1]] } else { [t[0], t[1], t[2]] };
        let p64 =
            idx.map(|i| transform.transform_point3(positions[i as usize].as_dvec3()) - origin);
        let p = p64.map(|v| v.as_vec3());
        // Degenerate: zero area, or so thin (area below 1e-12 of the longest edge squared)
        // that f32 arithmetic cannot resolve it; such a triangle cannot be hit reliably.
        let area2 = (p64[1] - p64[0]).cross(p64[2] - p64[0]).length();
        let edge2 = (p64[1] - p64[0])
            .length_squared()
            .max((p64[2] - p64[1]).length_squared())
            .max((p64[0] - p64[2]).length_squared());
        let area2_f32 = (p[1] - p[0]).cross(p[2] - p[0]).length();
        if !p.iter().all(|v| v.is_finite())
            || !(area2 > 1e-12 * edge2)
            || !(area2_f32 > 0.0)
            || !area2_f32.is_finite()
        {
            f.dropped += 1;
            continue;
        }
        f.tris.push(Triangle { v0: p[0].into(), v1: p[1].into(), v2: p[2].into() });
        f.src.push(k as u32);
        let n = idx.map(|i| {
            let n = normals.get(i as usize).copied().unwrap_or(Vec3::ZERO);
            let n = (nmat * n.as_dvec3()).normalize_or_zero().as_vec3();
            if n.is_finite() { n } else { Vec3::ZERO }
        });
        let uv = idx.map(|i| {
            let uv = mesh.uvs.get(i as usize).copied().unwrap_or_default();
            if uv.is_finite() { uv } else { glam::Vec2::ZERO }
        });
        // The fourth vec4's w carries the object index (as bits) for motion vectors.
        f.attrs.push([
            n[0].extend(uv[0].x),
            n[1].extend(uv[1].x),
            n[2].extend(uv[2].x),
            Vec4::new(uv[0].y, uv[1].y, uv[2].y, f32::from_bits(object as u32)),
        ]);
        if features.vertex_extras {
            f.extras.push(pack_extras(mesh, idx));
        }
        if features.normal_maps {
            f.tans.push(idx.map(|i| {
                let t = tangents.get(i as usize).copied().unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0));
                let xyz = (m3 * t.truncate().as_dvec3()).normalize_or_zero().as_vec3();
                let w = if flip { -t.w } else { t.w };
                if xyz.is_finite() { xyz.extend(w) } else { Vec4::new(1.0, 0.0, 0.0, 1.0) }
            }));
        }
        f.mats.push(mat);
    }
    f
}

/// A triangle's TEXCOORD_1 and COLOR_0 (shaders/common/attributes.wgsl): the three vertices'
/// TEXCOORD_1 as f32 bits, then their colours as two unorm16x2 words each (RG, BA). A mesh
/// without TEXCOORD_1 stores its TEXCOORD_0 there, one without COLOR_0 white.
pub(super) fn pack_extras(mesh: &crate::scene::Mesh, idx: [u32; 3]) -> [[u32; 4]; 3] {
    let uv = idx.map(|i| {
        let i = i as usize;
        let uv = mesh.uvs1.get(i).or(mesh.uvs.get(i)).copied().unwrap_or_default();
        if uv.is_finite() { uv } else { glam::Vec2::ZERO }
    });
    let unorm16 = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u32;
    let c = idx.map(|i| {
        let c = mesh.colors.get(i as usize).copied().unwrap_or(Vec4::ONE);
        [unorm16(c.x) | unorm16(c.y) << 16, unorm16(c.z) | unorm16(c.w) << 16]
    });
    let b = |x: f32| x.to_bits();
    [
        [b(uv[0].x), b(uv[0].y), b(uv[1].x), b(uv[1].y)],
        [b(uv[2].x), b(uv[2].y), c[0][0], c[0][1]],
        [c[1][0], c[1][1], c[2][0], c[2][1]],
    ]
}

/// Per material and texture slot, the rows of the map from the mesh's coordinates to the
/// texture's (shaders/common/texcoords.wgsl), the first row's w the TEXCOORD set.
pub(super) fn pack_texture_uses(materials: &[crate::scene::Material]) -> Vec<Vec4> {
    let mut v = Vec::with_capacity(materials.len() * 8);
    for m in materials {
        for t in m.texture_refs() {
            let t = t.unwrap_or(crate::scene::TextureRef::new(0));
            let (a, o) = (t.transform.matrix2, t.transform.translation);
            v.push(Vec4::new(a.x_axis.x, a.y_axis.x, o.x, t.set as f32));
            v.push(Vec4::new(a.x_axis.y, a.y_axis.y, o.y, 0.0));
        }
    }
    v
}

/// Per material the two rows of shaders/common/transmission.wgsl's glass table.
pub(super) fn pack_glass(materials: &[crate::scene::Material]) -> Vec<Vec4> {
    let mut v = Vec::with_capacity(materials.len() * 2);
    for m in materials {
        let thin = if m.thickness > 0.0 { 0.0 } else { 1.0 };
        v.push(Vec4::new(m.transmission, m.ior, thin, 0.0));
        let sigma = if m.transmission > 0.0 { m.absorption() } else { Vec3::ZERO };
        v.push(sigma.extend(0.0));
    }
    v
}

/// Each triangle of `now` where it was in `before` (the same object's previous flattening): the
/// same mesh triangle's vertices, or its current ones where `before` had dropped it.
pub(super) fn previous_vertices(before: &Flat, now: &Flat) -> Vec<[Vec3; 3]> {
    // Both lists of mesh triangles ascend: one walk matches them.
    let mut j = 0;
    now.src
        .iter()
        .zip(&now.tris)
        .map(|(&k, t)| {
            while j < before.src.len() && before.src[j] < k {
                j += 1;
            }
            let t = if before.src.get(j) == Some(&k) { &before.tris[j] } else { t };
            [t.v0, t.v1, t.v2].map(Vec3::from)
        })
        .collect()
}

/// f32 matrix of a rebased world transform.
pub(super) fn rebased(m: DMat4, origin: DVec3) -> glam::Mat4 {
    (DMat4::from_translation(-origin) * m).as_mat4()
}
