// Raster G-buffer: the primary surfaces, drawn from the same triangle buffers the tracer reads
// (vertex pulling: vertex i is corner i % 3 of triangle slot i / 3), so raster and trace agree on
// every triangle. Both faces are drawn: the back of a single-sided surface is a black absorber
// (as in the tracer) and must still hide what is behind it. A mesh stored once is drawn
// instanced, each instance its object (draw_instance; common/instances.wgsl).

struct VsOut {
    @builtin(position) clip: vec4f,
    @location(0) bary: vec2f,
    @location(1) @interpolate(flat) slot: u32,
    @location(4) @interpolate(flat) inst: u32,
    // The G-buffer's object id: the instance's, or the world-space triangle's own.
    @location(5) @interpolate(flat) object: u32,
    // Unjittered current and previous clip positions, for motion vectors.
    @location(2) cur: vec4f,
    @location(3) prev: vec4f,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> VsOut {
    let slot = vi / 3u;
    let corner = vi % 3u;
    let inst = draw_instance(ii);
    let p = inst_point(inst, tris[slot * 3u + corner].xyz);
    let object = select(bitcast<u32>(shading_at(slot * 4u + 3u).w), inst, inst != NO_INSTANCE);
    var o: VsOut;
    o.inst = inst;
    o.object = object;
    o.clip = frame.view_proj * vec4f(p, 1.0);
    o.bary = select(vec2f(0.0), select(vec2f(0.0, 1.0), vec2f(1.0, 0.0), corner == 1u), corner > 0u);
    o.slot = slot;
    o.cur = frame.unjittered_view_proj * vec4f(p, 1.0);
    o.prev = frame.prev_view_proj * vec4f(previous_vertex(slot, o.bary, object, p), 1.0);
    return o;
}

struct GBufferOut {
    // Octahedral shading normal (world), facing the camera.
    @location(0) normal: vec2f,
    // Pixels from this pixel to where its surface was in the previous frame.
    @location(1) motion: vec2f,
    // rgb: base colour; a: metallic.
    @location(2) base_color: vec4f,
    // rgb: specular F0; a: roughness.
    @location(3) specular: vec4f,
    // rgb: emitted radiance; a: Fresnel at grazing (f90).
    @location(4) emission: vec4f,
    // x: object index; y: triangle slot.
    @location(5) ids: vec2u,
}

@fragment
fn fs_main(v: VsOut, @builtin(front_facing) facing: bool) -> GBufferOut {
    // A mirroring instance's triangles reach the raster wound the other way (a flattened one's
    // winding is swapped instead).
    let front = facing != inst_mirrored(v.inst);
    let slot = v.slot;
    let b = v.bary;
    // Blended surfaces draw per pixel and frame (the jittered frames then average them).
    if !alpha_accept(slot, b, alpha_raster(vec2u(v.clip.xy), frame.index)) {
        discard;
    }
    let m = material(tri_material(slot));
    let tc = tri_tex_coords(slot, b);
    let v0 = tris[slot * 3u].xyz;
    var ng = normalize(cross(tris[slot * 3u + 1u].xyz - v0, tris[slot * 3u + 2u].xyz - v0));
    var ns = tri_normal(slot, b);
    let len = length(ns);
    ns = select(ng, ns / len, len > 1e-12 && len < 1e30);
    if !front {
        ns = -ns;
    }
    // An instance's normals are in its mesh's space (as in surface_at, common/scene.wgsl).
    ns = inst_shading_normal(v.inst, apply_normal_map(slot, b, ns, tc, m));
    let ms = material_at(m, tc);
    let bsdf = with_glass(material_bsdf(m, ms), m, ms, front);
    var o: GBufferOut;
    o.normal = oct_encode(ns);
    o.motion = to_pixels(v.prev) - to_pixels(v.cur);
    o.ids = vec2u(v.object, slot);
    if !front && (m.flags & MAT_DOUBLE_SIDED) == 0u {
        // The tracer's black absorber: no material, no light.
        o.base_color = vec4f(0.0);
        o.specular = vec4f(0.0, 0.0, 0.0, 1.0);
        o.emission = vec4f(0.0);
        return o;
    }
    o.base_color = vec4f(clamp(ms.base.rgb, vec3f(0.0), vec3f(1.0)), clamp(ms.metallic, 0.0, 1.0));
    o.specular = vec4f(clamp(bsdf.f0, vec3f(0.0), vec3f(1.0)), clamp(ms.roughness, 0.0, 1.0));
    // Emitters emit from the front face only.
    let e = select(vec3f(0.0), ms.emission, front);
    o.emission = vec4f(half_safe(e), clamp(max3(bsdf.f90), 0.0, 1.0));
    if bsdf.transmission > 0.0 {
        // Glass: the trace puts all its light in the glossy signal (realtime/trace.wgsl,
        // shade_glass); F = 1 and no matte base composite it unchanged.
        o.base_color = vec4f(0.0);
        o.specular = vec4f(1.0, 1.0, 1.0, clamp(ms.roughness, 0.0, 1.0));
        o.emission.w = 1.0;
    }
    // 8-bit targets: unbiased over the frames (realtime/gbuffer_dither.wgsl).
    let stored = dither_material(o.base_color, o.specular, vec2u(v.clip.xy), frame.index);
    o.base_color = stored[0];
    o.specular = stored[1];
    return o;
}
