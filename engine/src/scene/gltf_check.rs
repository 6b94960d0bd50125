//! Checks on a glTF document's structure that the `gltf` crate's validation leaves out and its
//! accessors assume (it panics where they fail), and the node hierarchy's shape: glTF nodes form
//! disjoint trees (§3.5.1), which is what makes walking them finite; a file whose nodes form a
//! cycle or share a child could otherwise loop forever or fan out exponentially.

use crate::limits::{Limits, over_budget};
use anyhow::{Result, bail};
use gltf::json::validation::Checked;

/// Everything below, each failure naming the JSON path. Runs before the `gltf` crate's own
/// validation, which indexes the accessor a primitive's POSITION names without checking it.
pub fn check(root: &gltf::json::Root, limits: &Limits) -> Result<()> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let position =
                prim.attributes.get(&Checked::Valid(gltf::json::mesh::Semantic::Positions));
            if let Some(i) = position.map(|i| i.value()).filter(|&i| i >= root.accessors.len()) {
                bail!(
                    "meshes[{m}].primitives[{p}].attributes.POSITION names accessors[{i}], which does not exist"
                );
            }
        }
    }
    // The gltf crate validates an animation's samplers but not its channels' targets.
    for (a, anim) in root.animations.iter().enumerate() {
        for (c, ch) in anim.channels.iter().enumerate() {
            if ch.target.node.value() >= root.nodes.len() {
                bail!(
                    "animations[{a}].channels[{c}].target.node names nodes[{}], which does not exist",
                    ch.target.node.value()
                );
            }
            if matches!(ch.target.path, Checked::Invalid) {
                bail!(
                    "animations[{a}].channels[{c}].target.path must be translation, rotation, scale or weights"
                );
            }
        }
    }
    check_cameras(root)?;
    check_images(root)?;
    check_lights(root)?;
    check_nodes(root, limits)
}

fn check_cameras(root: &gltf::json::Root) -> Result<()> {
    use gltf::json::camera::Type;
    for (i, c) in root.cameras.iter().enumerate() {
        match (&c.type_, &c.perspective, &c.orthographic) {
            (Checked::Valid(Type::Perspective), Some(p), _) => {
                if !(p.yfov > 0.0 && p.yfov < std::f32::consts::PI) {
                    bail!(
                        "cameras[{i}].perspective.yfov must be in (0, pi) radians, got {}",
                        p.yfov
                    );
                }
            }
            (Checked::Valid(Type::Orthographic), _, Some(o)) => {
                let finite = [o.xmag, o.ymag, o.znear, o.zfar].iter().all(|x| x.is_finite());
                if !finite || o.xmag == 0.0 || o.ymag == 0.0 {
                    bail!(
                        "cameras[{i}].orthographic: xmag and ymag must be finite and non-zero, got {} and {}",
                        o.xmag,
                        o.ymag
                    );
                }
            }
            (Checked::Valid(Type::Perspective), None, _) => {
                bail!("cameras[{i}] is of type perspective but has no `perspective`")
            }
            (Checked::Valid(Type::Orthographic), _, None) => {
                bail!("cameras[{i}] is of type orthographic but has no `orthographic`")
            }
            (Checked::Invalid, ..) => {
                bail!("cameras[{i}].type must be perspective or orthographic")
            }
        }
    }
    Ok(())
}

fn check_images(root: &gltf::json::Root) -> Result<()> {
    for (i, img) in root.images.iter().enumerate() {
        match (&img.uri, &img.buffer_view) {
            (Some(_), Some(_)) => {
                bail!("images[{i}] has both `uri` and `bufferView`; glTF allows one")
            }
            (None, None) => bail!("images[{i}] has neither `uri` nor `bufferView`"),
            (None, Some(_)) if img.mime_type.is_none() => {
                bail!("images[{i}] is stored in a bufferView but has no `mimeType`")
            }
            _ => {}
        }
    }
    Ok(())
}

fn check_lights(root: &gltf::json::Root) -> Result<()> {
    use gltf::json::extensions::scene::khr_lights_punctual::Type;
    let Some(lights) = root.extensions.as_ref().and_then(|e| e.khr_lights_punctual.as_ref()) else {
        return Ok(());
    };
    for (i, l) in lights.lights.iter().enumerate() {
        let here = format!("extensions.KHR_lights_punctual.lights[{i}]");
        match (&l.type_, &l.spot) {
            (Checked::Invalid, _) => bail!("{here}.type must be directional, point or spot"),
            (Checked::Valid(Type::Spot), None) => bail!("{here} is a spot light without `spot`"),
            (Checked::Valid(Type::Spot), Some(s)) => {
                let (inner, outer) = (s.inner_cone_angle, s.outer_cone_angle);
                if !(inner >= 0.0 && inner < outer && outer <= std::f32::consts::FRAC_PI_2) {
                    bail!(
                        "{here}.spot: cone angles must satisfy 0 <= inner < outer <= pi/2, got {inner} and {outer}"
                    );
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Every node has at most one parent, no scene lists a node that has one (or lists a node
/// twice), the file holds at most `limits.nodes` nodes and no tree is deeper than
/// `limits.hierarchy_depth`.
fn check_nodes(root: &gltf::json::Root, limits: &Limits) -> Result<()> {
    let n = root.nodes.len();
    if n as u64 > limits.nodes {
        return Err(over_budget("nodes", "the file's node list", n as u64, limits.nodes));
    }
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (i, node) in root.nodes.iter().enumerate() {
        for c in node.children.iter().flatten() {
            let c = c.value();
            if c >= n {
                bail!("nodes[{i}].children names nodes[{c}], which does not exist");
            }
            if c == i {
                bail!("nodes[{i}] is its own child; glTF nodes form trees");
            }
            if let Some(p) = parent[c] {
                bail!(
                    "nodes[{c}] is a child of both nodes[{p}] and nodes[{i}]; glTF nodes form trees (one parent each)"
                );
            }
            parent[c] = Some(i);
        }
    }
    for (s, scene) in root.scenes.iter().enumerate() {
        let mut listed = std::collections::HashSet::new();
        for r in &scene.nodes {
            let r = r.value();
            if let Some(p) = parent.get(r).copied().flatten() {
                bail!(
                    "scenes[{s}].nodes lists nodes[{r}], which is a child of nodes[{p}]; a scene lists root nodes"
                );
            }
            if !listed.insert(r) {
                bail!("scenes[{s}].nodes lists nodes[{r}] twice");
            }
        }
    }
    // With one parent each, following parents either reaches a root or loops. A loop is never
    // reachable from a scene's roots, but it breaks the rule all the same; every depth is
    // measured so that a chain deeper than the budget is refused by name. Each node is walked
    // once: a walk stops at the first node whose depth is known.
    let mut depth: Vec<u64> = vec![0; n];
    for start in 0..n {
        if depth[start] != 0 {
            continue;
        }
        let mut chain = vec![start];
        let base = loop {
            match parent[*chain.last().unwrap_or(&start)] {
                None => break 0,
                Some(p) if depth[p] != 0 => break depth[p],
                Some(_) if chain.len() > n => {
                    bail!("nodes[{start}] descends from a cycle of children; glTF nodes form trees")
                }
                Some(p) => chain.push(p),
            }
        };
        for (k, &c) in chain.iter().rev().enumerate() {
            depth[c] = base + k as u64 + 1;
        }
        if depth[start] > limits.hierarchy_depth {
            return Err(over_budget(
                "hierarchy-depth",
                format_args!("nodes[{start}]"),
                depth[start],
                limits.hierarchy_depth,
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root(nodes: serde_json::Value, scenes: serde_json::Value) -> gltf::json::Root {
        serde_json::from_value(
            serde_json::json!({"asset": {"version": "2.0"}, "nodes": nodes, "scenes": scenes}),
        )
        .unwrap()
    }

    #[test]
    fn node_hierarchies_must_be_trees_within_budget() {
        let ok = root(
            serde_json::json!([{"children": [1, 2]}, {"children": [3]}, {}, {}]),
            serde_json::json!([{"nodes": [0]}]),
        );
        check(&ok, &Limits::default()).unwrap();
        let e = check(&ok, &Limits { hierarchy_depth: 2, ..Limits::default() })
            .unwrap_err()
            .to_string();
        assert!(e.contains("hierarchy-depth") && e.contains("needs 3"), "{e}");
        let e = check(&ok, &Limits { nodes: 3, ..Limits::default() }).unwrap_err().to_string();
        assert!(e.contains("--limit nodes=4"), "{e}");
        for (nodes, scenes, needle) in [
            (
                serde_json::json!([{"children": [0]}]),
                serde_json::json!([{"nodes": [0]}]),
                "its own child",
            ),
            (
                serde_json::json!([{"children": [1]}, {"children": [0]}]),
                serde_json::json!([{"nodes": []}]),
                "cycle",
            ),
            (
                serde_json::json!([{"children": [2]}, {"children": [2]}, {}]),
                serde_json::json!([{"nodes": [0, 1]}]),
                "child of both",
            ),
            (
                serde_json::json!([{"children": [1]}, {}]),
                serde_json::json!([{"nodes": [0, 1]}]),
                "lists root nodes",
            ),
            (serde_json::json!([{}]), serde_json::json!([{"nodes": [0, 0]}]), "twice"),
        ] {
            let e = check(&root(nodes, scenes), &Limits::default()).unwrap_err().to_string();
            assert!(e.contains(needle), "{needle}: {e}");
        }
    }
}
