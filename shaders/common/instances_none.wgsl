// A scene whose meshes are stored where they stand: every hit is in world space already.
fn inst_point(inst: u32, p: vec3f) -> vec3f {
    return p;
}

fn inst_vector(inst: u32, v: vec3f) -> vec3f {
    return v;
}

fn inst_normal(inst: u32, n: vec3f) -> vec3f {
    return n;
}

fn inst_shading_normal(inst: u32, n: vec3f) -> vec3f {
    return n;
}

fn inst_close_point(inst: u32, p: vec3f) -> vec3f {
    return p;
}

fn inst_mirrored(inst: u32) -> bool {
    return false;
}

fn instance_of_object(object: u32) -> u32 {
    return NO_INSTANCE;
}

fn draw_instance(i: u32) -> u32 {
    return NO_INSTANCE;
}
