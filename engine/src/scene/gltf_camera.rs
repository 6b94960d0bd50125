//! A glTF camera's pose: its node's world transform without the scale glTF cameras do not carry.

use glam::{DMat3, DMat4, DQuat, DVec3};

/// A node's own rotation: its `rotation`, or its matrix's rotation part orthonormalised.
pub(super) fn local_rotation(node: &gltf::Node) -> DQuat {
    match node.transform() {
        gltf::scene::Transform::Decomposed { rotation, .. } => {
            let q = DQuat::from_array(rotation.map(|x| x as f64));
            if q.is_finite() && q.length() > 0.0 { q.normalize() } else { DQuat::IDENTITY }
        }
        gltf::scene::Transform::Matrix { matrix } => {
            let m = DMat4::from_cols_array_2d(&matrix.map(|c| c.map(|x| x as f64)));
            orthonormal(DMat3::from_mat4(m))
                .map(|r| DQuat::from_mat3(&r))
                .unwrap_or(DQuat::IDENTITY)
        }
    }
}

/// The rotation nearest `m`'s axes (Gram-Schmidt from its z and y), or None where they are
/// degenerate.
fn orthonormal(m: DMat3) -> Option<DMat3> {
    let z = m.z_axis.normalize_or_zero();
    let x = m.y_axis.cross(m.z_axis).normalize_or_zero();
    if z == DVec3::ZERO || x == DVec3::ZERO || !x.is_finite() || !z.is_finite() {
        return None;
    }
    Some(DMat3::from_cols(x, z.cross(x), z))
}

/// A camera's pose from its node's world transform. glTF cameras carry no scale, so the axes are
/// orthonormalised; where the transform has none to give (a zero scale), the chain of the nodes'
/// rotations stands in. None where neither gives a pose.
pub(super) fn camera_pose(world: DMat4, rotation: DQuat) -> Option<DMat4> {
    let eye = world.w_axis.truncate();
    let axes = orthonormal(DMat3::from_mat4(world))
        .or_else(|| rotation.is_finite().then(|| DMat3::from_quat(rotation.normalize())))?;
    let m = DMat4::from_cols(
        axes.x_axis.extend(0.0),
        axes.y_axis.extend(0.0),
        axes.z_axis.extend(0.0),
        eye.extend(1.0),
    );
    m.is_finite().then_some(m)
}
