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
