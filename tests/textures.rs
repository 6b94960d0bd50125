//! Texture addressing on the GPU: a quad whose u runs from -1 to 2 shows three tiles of one
//! texture (as emission, seen directly by camera rays), and each wrap mode must tile, mirror or
//! hold the edge as glTF's samplers do (repeat, mirrored repeat, clamp to edge).

use glam::{DMat4, DVec3, Vec2, Vec3};
use hush_engine::quality::{Image, srgb_to_linear};
use hush_engine::scene::{
    Camera, Environment, Material, Object, Scene, Texture, TextureRef, Wrap, quad,
};

const W: u32 = 96;
const H: u32 = 32;
const TILE: u32 = W / 3;

fn scene(wrap_s: Wrap) -> Scene {
    // 4 x 2 texels, every one a different colour.
    let rgba8 = hush_tests::TILE_COLOURS.iter().flat_map(|c| [c[0], c[1], c[2], 255]).collect();
    let texture = Texture {
        name: "tiles".into(),
        width: 4,
        height: 2,
        rgba8,
        srgb: false,
        wrap_s,
        wrap_t: Wrap::Clamp,
        nearest: false,
    };
    // A 6 x 2 quad facing +Z that the camera sees edge to edge; u from -1 (left) to 2.
    let mut mesh = quad(Vec3::ZERO, Vec3::new(3.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 0);
    mesh.uvs =
        vec![Vec2::new(-1.0, 1.0), Vec2::new(2.0, 1.0), Vec2::new(2.0, 0.0), Vec2::new(-1.0, 0.0)];
    let material = Material {
        emission: Vec3::ONE,
        emissive_texture: Some(TextureRef::new(0)),
        base_color: Vec3::ZERO.extend(1.0),
        metallic: 0.0,
        specular_factor: 0.0,
        ..Default::default()
    };
    let yfov = 2.0 * 0.5f64.atan().to_degrees();
    Scene {
        name: "texture tiles".into(),
        meshes: vec![mesh],
        objects: vec![Object {
            name: "quad".into(),
            mesh: 0,
            transform: DMat4::IDENTITY,
            animation: None,
            deform: None,
        }],
        materials: vec![material],
        textures: vec![texture],
        lights: vec![],
        camera: Some(Camera::look_at(DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, yfov as f32)),
        environment: Environment::None,
        resolution: Some((W, H)),
        // Camera rays see emission only.
        max_depth: 1,
        warnings: vec![],
        procedural_sky: false,
        animations: vec![],
    }
}

/// Pixels a and b agree within 5 standard errors of their difference (plus float slack).
fn same(img: &Image, var: &Image, a: (u32, u32), b: (u32, u32)) -> bool {
    let d = (img.at(a.0, a.1) - img.at(b.0, b.1)).abs();
    let tol = ((var.at(a.0, a.1) + var.at(b.0, b.1)).map(|v| v.max(0.0).sqrt()) * 5.0)
        + Vec3::splat(1e-3);
    d.cmple(tol).all()
}

#[test]
fn wrap_modes_tile_mirror_and_clamp() {
    for wrap in [Wrap::Repeat, Wrap::Mirror, Wrap::Clamp] {
        let acc = hush_tests::render(&scene(wrap), W, H, 256, 1).unwrap();
        let (img, var) = (&acc.mean, &acc.variance_of_mean);
        let mut bad = vec![];
        for y in 0..H {
            for x in 0..TILE {
                let ok = match wrap {
                    // Tiles 0 and 2 repeat tile 1 (u in [0, 1]).
                    Wrap::Repeat => {
                        same(img, var, (x, y), (x + TILE, y))
                            && same(img, var, (x + 2 * TILE, y), (x + TILE, y))
                    }
                    // u in [-1, 0] shows [0, 1] flipped, and so does [1, 2].
                    Wrap::Mirror => {
                        same(img, var, (x, y), (2 * TILE - 1 - x, y))
                            && same(img, var, (2 * TILE + x, y), (2 * TILE - 1 - x, y))
                    }
                    // Left of u = 0 the left edge texel column, right of u = 1 the right one.
                    Wrap::Clamp => {
                        same(img, var, (x, y), (0, y))
                            && same(img, var, (2 * TILE + x, y), (W - 1, y))
                    }
                };
                if !ok {
                    bad.push((x, y));
                }
            }
        }
        assert!(
            bad.is_empty(),
            "{wrap:?}: {} pixels disagree, first {:?}",
            bad.len(),
            &bad[..bad.len().min(5)]
        );
        // The middle tile is the texture, not a flat colour: the checks above compare something.
        let spread = (0..TILE)
            .map(|x| (img.at(TILE + x, H / 4) - img.at(TILE, H / 4)).abs().max_element())
            .fold(0.0f32, f32::max);
        assert!(spread > 0.3, "{wrap:?}: the middle tile varies by only {spread}");
        // The edges of the clamped tile are the edge texels' colours (column 0 of the top row
        // is red; column 3 is yellow).
        // At u just above 0 the filter reaches left of the texture: repeat blends in the last
        // column (yellow: green 1), the other modes the first (red: green 0).
        let g = img.at(TILE, 0).y;
        assert!(
            if wrap == Wrap::Repeat { g > 0.3 } else { g < 0.1 },
            "{wrap:?}: green {g} at u = 0+"
        );
        if wrap == Wrap::Clamp {
            let (l, r) = (img.at(0, 0), img.at(W - 1, 0));
            assert!(
                l.x > 0.7 && l.y < 0.3 && r.x > 0.7 && r.y > 0.7 && r.z < 0.3,
                "clamp edges {l} {r}"
            );
        }
    }
}

/// A sampler whose magFilter is NEAREST reads whole texels: away from texel borders every pixel
/// is one texel's colour; the same texture filtered bilinearly blends neighbours there. The
/// scene goes through Hush's glTF export and import, so the sampler's filter is what the file
/// says.
#[test]
fn nearest_samplers_read_whole_texels() {
    let (w, h) = (W, H);
    let mut fractions = vec![];
    for nearest in [true, false] {
        let mut s = scene(Wrap::Repeat);
        s.textures[0].nearest = nearest;
        // u from 0 to 1 across the width: four texel columns of 24 pixels, two rows of 16.
        s.meshes[0].uvs = vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ];
        let dir =
            std::env::temp_dir().join(format!("hush-nearest-{}-{nearest}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("tiles.gltf");
        hush_engine::scene::save_gltf(&s, &path).unwrap();
        let loaded = hush_engine::scene::load_gltf(&path).unwrap();
        assert_eq!(loaded.textures[0].nearest, nearest);
        let acc = hush_tests::render(&loaded, w, h, 64, 2).unwrap();
        let texel_colours: Vec<Vec3> = (0..8)
            .map(|i| {
                // An emissive texture is sRGB in glTF: the loaded one decodes its texels.
                assert!(loaded.textures[0].srgb);
                let c = hush_tests::TILE_COLOURS[i].map(|b| srgb_to_linear(b as f32 / 255.0));
                Vec3::from_array(c)
            })
            .collect();
        // Pixels whose footprint lies inside one texel: 2 pixels and more from texel borders.
        let (mut whole, mut count) = (0, 0);
        for y in 0..h {
            for x in 0..w {
                let (cx, cy) = (x % 24, y % 16);
                if !(2..22).contains(&cx) || !(2..14).contains(&cy) {
                    continue;
                }
                count += 1;
                let c = acc.mean.at(x, y);
                if texel_colours.iter().any(|t| (*t - c).abs().max_element() < 0.01) {
                    whole += 1;
                }
            }
        }
        fractions.push(whole as f64 / count as f64);
    }
    println!(
        "pixels showing one texel's colour: nearest {:.3}, bilinear {:.3}",
        fractions[0], fractions[1]
    );
    assert_eq!(fractions[0], 1.0, "nearest");
    assert!(fractions[1] < 0.5, "bilinear");
}
