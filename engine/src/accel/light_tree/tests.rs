use super::*;

/// A deterministic scatter of `n` one-sided triangles in a 10 m box, facing every way, their
/// luminance over two decades (as the many-lamp hall's).
fn scatter(n: usize, seed: u32) -> Vec<Emitter> {
    let mut s = seed.wrapping_mul(0x9e37_79b9) | 1;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s as f32 / u32::MAX as f32
    };
    (0..n)
        .map(|i| {
            let c = Vec3::new(r(), r(), r()) * 10.0 - 5.0;
            let mut e = || Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 0.4;
            let v = [c, c + e(), c + e()];
            Emitter::triangle(v, None, 10f32.powf(2.0 * r()), i as u32 * 3)
        })
        .collect()
}

fn points(n: usize) -> Vec<(Vec3, Vec3)> {
    (0..n)
        .map(|i| {
            let t = i as f32 * 2.399_963;
            let p = Vec3::new(t.sin() * 6.0, (i as f32 * 0.37).sin() * 4.0, t.cos() * 3.0);
            let n =
                if i % 3 == 0 { Vec3::ZERO } else { Vec3::new(t.cos(), 0.6, t.sin()).normalize() };
            (p, n)
        })
        .collect()
}

#[test]
fn every_emitter_is_a_leaf_and_parents_link_back() {
    let e = scatter(300, 1);
    let t = LightTree::build(&e);
    assert_eq!(t.nodes.len(), 2 * e.len() - 1);
    for (i, &leaf) in t.leaf_of.iter().enumerate() {
        let node = &t.nodes[leaf as usize];
        assert_eq!(node.child, LEAF | e[i].slot);
        assert!((node.area - e[i].area).abs() <= 1e-6 * e[i].area);
    }
    for (i, node) in t.nodes.iter().enumerate().skip(1) {
        let p = &t.nodes[node.parent as usize];
        assert!(p.child & LEAF == 0 && (node.parent as usize + 1 == i || p.child as usize == i));
    }
    let total: f32 = e.iter().map(|e| e.area * e.luminance).sum();
    assert!((t.nodes[0].power - total).abs() <= 1e-4 * total);
}

/// The walk down and the walk up agree, and the probabilities of all emitters sum to one, less
/// the walks that end at a node both of whose children face away (no light: unbiased).
#[test]
fn the_probabilities_sum_to_one_and_match_the_samples() {
    let e = scatter(200, 2);
    let t = LightTree::build(&e);
    for (p, n) in points(40) {
        let sum: f64 = (0..e.len()).map(|i| t.pmf(t.leaf_of[i], p, n) as f64).sum();
        assert!(sum <= 1.0 + 1e-4 && sum > 0.5, "sum {sum} at {p} {n}");
        // u stratified over [0, 1): each leaf takes an interval of length pmf.
        const N: usize = 20_000;
        let (mut count, mut none) = (vec![0usize; t.nodes.len()], 0);
        for k in 0..N {
            let Some((leaf, pmf)) = t.sample(p, n, (k as f32 + 0.5) / N as f32) else {
                none += 1;
                continue;
            };
            assert!((pmf - t.pmf(leaf, p, n)).abs() <= 1e-5 + 1e-4 * pmf);
            count[leaf as usize] += 1;
        }
        for &leaf in &t.leaf_of {
            let f = count[leaf as usize] as f32 / N as f32;
            assert!((f - t.pmf(leaf, p, n)).abs() <= 2.0 / N as f32 + 1e-4, "leaf {leaf}: {f}");
        }
        let unlit = none as f64 / N as f64;
        assert!((unlit - (1.0 - sum)).abs() < 1e-3, "{unlit} of the walks end without a light");
    }
}

/// No emitter that faces the point (and so may light it) has probability zero.
#[test]
fn an_emitter_that_faces_the_point_can_be_chosen() {
    let e = scatter(500, 3);
    let t = LightTree::build(&e);
    for (p, n) in points(60) {
        for (i, em) in e.iter().enumerate() {
            if (p - em.vertices[0]).dot(em.normals[0]) > 1e-3 {
                assert!(t.pmf(t.leaf_of[i], p, n) > 0.0, "emitter {i} at {p}");
            }
        }
    }
}

/// Lamps that all face up cannot light a point below them: no sample, no probability.
#[test]
fn lamps_facing_away_are_never_chosen() {
    let e: Vec<Emitter> = (0..64)
        .map(|i| {
            let c = Vec3::new((i % 8) as f32, 0.0, (i / 8) as f32);
            Emitter::triangle([c, c + Vec3::Z * 0.2, c + Vec3::X * 0.2], None, 1.0, i)
        })
        .collect();
    assert!(e[0].normals[0].y > 0.99);
    let t = LightTree::build(&e);
    assert_eq!(t.sample(Vec3::new(3.0, -1.0, 3.0), Vec3::Y, 0.5), None);
    assert!(t.sample(Vec3::new(3.0, 1.0, 3.0), Vec3::Y, 0.5).is_some());
}

#[test]
fn a_row_of_ten_thousand_lamps_makes_a_shallow_tree() {
    let e: Vec<Emitter> = (0..10_000)
        .map(|i| {
            let c = Vec3::new(i as f32 * 0.1, 0.0, 0.0);
            Emitter::triangle([c, c + Vec3::Z * 0.05, c + Vec3::X * 0.05], None, 1.0, i)
        })
        .collect();
    let t = LightTree::build(&e);
    assert!(t.depth() <= 40, "depth {}", t.depth());
    assert_eq!(LightTree::build(&[]).nodes.len(), 0);
    let one = LightTree::build(&e[..1]);
    assert_eq!(one.sample(Vec3::Y, Vec3::ZERO, 0.3), Some((0, 1.0)));
    assert_eq!(one.pmf(0, Vec3::Y, Vec3::ZERO), 1.0);
}

/// The fixed emitters' leaves keep their numbers however the moving ones move.
#[test]
fn a_split_tree_keeps_the_fixed_leaves_where_they_were() {
    let mut e = scatter(100, 4);
    let first = LightTree::build_split(&e, 60);
    for m in e[60..].iter_mut() {
        m.vertices.iter_mut().for_each(|v| *v += Vec3::new(3.0, 1.0, 0.0));
    }
    let moved = LightTree::build_split(&e, 60);
    assert_eq!(first.leaf_of[..60], moved.leaf_of[..60]);
    for (p, n) in points(10) {
        let sum: f64 = (0..e.len()).map(|i| moved.pmf(moved.leaf_of[i], p, n) as f64).sum();
        assert!(sum <= 1.0 + 1e-4 && sum > 0.5);
        for (i, em) in e.iter().enumerate() {
            if (p - em.vertices[0]).dot(em.normals[0]) > 1e-3 {
                assert!(moved.pmf(moved.leaf_of[i], p, n) > 0.0);
            }
        }
    }
}
