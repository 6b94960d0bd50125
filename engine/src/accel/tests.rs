use super::*;

/// A degenerate PLOC tree (coincident triangles chain up) is replaced by one the GPU can
/// traverse; an ordinary scene keeps its PLOC tree.
#[test]
fn degenerate_layouts_build_fast_shallow_trees() {
    let t = Triangle {
        v0: glam::Vec3A::new(-1.0, 0.0, -1.0),
        v1: glam::Vec3A::new(1.0, 0.0, 1.0),
        v2: glam::Vec3A::new(1.0, 0.0, -1.0),
    };
    let stacked = vec![t; 5000];
    let grid: Vec<Triangle> = (0..5000)
        .map(|i| {
            let o = glam::Vec3A::new((i % 71) as f32, (i / 71) as f32, (i % 13) as f32 * 0.1);
            Triangle { v0: t.v0 + o, v1: t.v1 + o, v2: t.v2 + o }
        })
        .collect();
    for kind in [BvhKind::Bvh2, BvhKind::Cwbvh] {
        let a = build(&stacked, kind);
        assert!(a.median_fallback, "{kind:?}");
        let mut order = a.order.clone();
        order.sort();
        assert_eq!(order, (0..5000).collect::<Vec<u32>>(), "{kind:?}: every triangle once");
        assert!(!build(&grid, kind).median_fallback, "{kind:?}");
    }
    // Evenly spaced copies in a row (PLOC's ties) and nested copies (one centroid) build in
    // well under a second, where obvhs's PLOC alone took 4.9 s and 54 s.
    let row: Vec<Triangle> = (0..20000)
        .map(|i| {
            let o = glam::Vec3A::new(i as f32 * 2.0, 0.0, 0.0);
            Triangle { v0: t.v0 + o, v1: t.v1 + o, v2: t.v2 + o }
        })
        .collect();
    let nested: Vec<Triangle> = (0..20000)
        .map(|i| {
            let k = 1.0 + i as f32 * 1e-3;
            Triangle { v0: t.v0 * k, v1: t.v1 * k, v2: t.v2 * k }
        })
        .collect();
    assert!(Survey::of(&row).tied > TIE_LIMIT && Survey::of(&grid).tied <= TIE_LIMIT);
    for (name, tris, fallback) in [("row", &row, false), ("nested", &nested, true)] {
        let a = build(tris, BvhKind::Cwbvh);
        assert!(
            a.build_time.as_secs_f64() < 1.0 && a.median_fallback == fallback,
            "{name}: {:?}, fallback {}",
            a.build_time,
            a.median_fallback
        );
    }
    let median = median_bvh2(&stacked, 1);
    assert_eq!(bvh2_depth(&median.nodes), 14, "ceil(log2(5000)) + 1");
}

/// The stack a scene's programs get holds its tree, and an animated scene's stack holds any
/// tree a rebuild within it can return (the median tree where the SAH tree is too deep).
#[test]
fn traversal_stacks_hold_the_trees_built_within_them() {
    let t = Triangle {
        v0: glam::Vec3A::new(-1.0, 0.0, -1.0),
        v1: glam::Vec3A::new(1.0, 0.0, 1.0),
        v2: glam::Vec3A::new(1.0, 0.0, -1.0),
    };
    // A row of triangles shrinking geometrically: PLOC chains them into a deep tree.
    let chain: Vec<Triangle> = (0..3000)
        .map(|i| {
            let k = 0.99f32.powi(i);
            let o = glam::Vec3A::new(k * 100.0, 0.0, 0.0);
            Triangle { v0: t.v0 * k + o, v1: t.v1 * k + o, v2: t.v2 * k + o }
        })
        .collect();
    for kind in [BvhKind::Bvh2, BvhKind::Cwbvh] {
        let a = build(&chain, kind);
        let stack = traversal_stack(kind, a.depth, chain.len(), false) as usize;
        assert!(
            stack >= a.depth && stack.is_multiple_of(4) && stack < a.depth + 4,
            "{kind:?}: depth {} stack {stack}",
            a.depth
        );
        let animated = traversal_stack(kind, a.depth, chain.len(), true) as usize;
        assert!(animated >= median_depth_bound(chain.len()) && animated >= a.depth + 4, "{kind:?}");
        // A limit below the SAH tree's depth gets the median tree, which fits the animated
        // scene's stack.
        let limited = build_within(&chain, kind, a.depth - 1);
        assert!(
            limited.median_fallback && limited.depth <= animated,
            "{kind:?}: depth {} limit {}",
            limited.depth,
            a.depth - 1
        );
        assert!(
            limited.depth <= median_depth_bound(chain.len()),
            "{kind:?}: median depth {}",
            limited.depth
        );
    }
    assert_eq!(median_depth_bound(5000), 14);
    assert_eq!(median_depth_bound(1), 1);
}

/// Every leaf triangle of a packed tree, with the box its parent stores for that leaf (binary:
/// the child box; CWBVH: the dequantized child planes), and every inner child with its box
/// and its own node's boxes.
fn leaf_boxes(a: &Accel) -> Vec<(u32, obvhs::aabb::Aabb)> {
    use obvhs::aabb::Aabb;
    let mut out = vec![];
    match a.kind {
        BvhKind::Bvh2 => {
            let nodes: Vec<Bvh2GpuNode> = bytemuck::pod_collect_to_vec(&a.nodes);
            for n in &nodes {
                for (lo, hi, index, count) in
                    [(n.lmin, n.lmax, n.l_index, n.l_count), (n.rmin, n.rmax, n.r_index, n.r_count)]
                {
                    let b = Aabb::new(lo.into(), hi.into());
                    if count > 0 && lo[0] <= hi[0] {
                        out.extend((index..index + count).map(|s| (s, b)));
                    }
                }
            }
        }
        BvhKind::Cwbvh => {
            let nodes: Vec<obvhs::cwbvh::node::CwBvhNode> = bytemuck::pod_collect_to_vec(&a.nodes);
            for n in &nodes {
                for c in 0..8 {
                    if !n.is_child_empty(c) && n.is_leaf(c) {
                        let (first, count) = n.child_primitives(c);
                        out.extend((first..first + count).map(|s| (s, n.child_aabb(c))));
                    }
                }
            }
        }
    }
    out
}

/// A refit tree's boxes hold every triangle after the triangles moved (bounds within f32
/// rounding of the dequantized planes), in both layouts; a refit that would grow the tree's
/// cost past REFIT_LIMIT is refused (the caller rebuilds).
#[test]
fn refit_bounds_contain_every_triangle() {
    let base: Vec<Triangle> = (0..3000)
        .map(|i| {
            let o = glam::Vec3A::new(
                (i % 50) as f32 * 0.3,
                (i / 50) as f32 * 0.3,
                (i % 7) as f32 * 0.05,
            );
            let s = glam::Vec3A::splat(0.2);
            Triangle { v0: o, v1: o + s * glam::Vec3A::X, v2: o + s * glam::Vec3A::Y }
        })
        .collect();
    // A bend: each triangle moved by a smooth function of where it is.
    let bend = |t: &Triangle, a: f32| {
        let f = |v: glam::Vec3A| v + glam::Vec3A::new(0.0, 0.0, a * (v.x * 0.4).sin());
        Triangle { v0: f(t.v0), v1: f(t.v1), v2: f(t.v2) }
    };
    for kind in [BvhKind::Bvh2, BvhKind::Cwbvh] {
        let (_, tree) = build_refittable(&base, kind, kind.max_depth(), LEAF_TRIANGLES);
        let mut tree = tree.unwrap();
        for a in [0.1f32, 0.3, 0.6] {
            let moved: Vec<Triangle> = base.iter().map(|t| bend(t, a)).collect();
            let accel = refit(&mut tree, &moved).expect("a gentle bend refits");
            let boxes = leaf_boxes(&accel);
            assert_eq!(boxes.len(), moved.len(), "{kind:?}: every triangle in one leaf");
            for (slot, b) in boxes {
                let t = moved[accel.order[slot as usize] as usize].aabb();
                let eps = 1e-5 * (1.0 + t.max.abs().max_element());
                assert!(
                    (t.min - b.min).min_element() >= -eps && (b.max - t.max).min_element() >= -eps,
                    "{kind:?} bend {a}: triangle {slot} {t:?} outside its leaf box {b:?}"
                );
            }
        }
        // Triangles scattered far apart: the old tree's boxes would overlap everywhere.
        let scattered: Vec<Triangle> = base
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let o = glam::Vec3A::splat(((i * 7919) % 3000) as f32 * 0.1);
                Triangle { v0: t.v0 + o, v1: t.v1 + o, v2: t.v2 + o }
            })
            .collect();
        assert!(refit(&mut tree, &scattered).is_none(), "{kind:?}: scattered triangles refit");
        assert_eq!(tree.refits, 3);
    }
}
