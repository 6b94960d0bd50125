//! Numerical extremes and unusable input: no NaN/Inf, no panic, a clear error where the input
//! cannot be rendered.

use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::{ReferenceTracer, TraceView};
use hush_engine::scene::{Scene, load_gltf};
use hush_tests::gltf_writer::{GltfWriter, Prim, write_json};
use hush_tests::render;
use serde_json::json;

fn quad(y: f32, s: f32, up: bool) -> ([[f32; 3]; 4], [u32; 6]) {
    let p = [[-s, y, -s], [s, y, -s], [s, y, s], [-s, y, s]];
    // Counter-clockwise seen from +Y when `up`.
    if up { (p, [0, 2, 1, 0, 3, 2]) } else { (p, [0, 1, 2, 0, 2, 3]) }
}

/// A floor, a 1e6-radiance emitter, a mirror (roughness 0, F0 = 1), a roughness-1 metal, a
/// mesh without normals, zero-area and degenerate triangles and a NaN vertex.
fn extreme_scene(camera: Option<([f32; 3], [f32; 3])>) -> Scene {
    let mut g = GltfWriter::default();
    let floor_m = g.lambert([0.8, 0.8, 0.8]);
    let light_m = g.emitter(1e6);
    let mirror_m = g.metal([1.0, 1.0, 1.0], 0.0);
    let rough_m = g.metal([1.0, 1.0, 1.0], 1.0);
    let (fp, fi) = quad(0.0, 2.0, true);
    let floor = g.mesh(Prim {
        positions: &fp,
        normals: Some(&[[0.0, 1.0, 0.0]; 4]),
        indices: Some(&fi),
        material: floor_m,
    });
    let (lp, li) = quad(1.5, 0.05, false);
    let light =
        g.mesh(Prim { positions: &lp, normals: None, indices: Some(&li), material: light_m });
    // A mirror tilted 45 degrees and a rough metal panel, both without indices.
    let mirror = g.mesh(Prim {
        positions: &[
            [-1.0, 0.0, -1.0],
            [0.0, 0.0, -1.0],
            [0.0, 1.0, -1.5],
            [-1.0, 0.0, -1.0],
            [0.0, 1.0, -1.5],
            [-1.0, 1.0, -1.5],
        ],
        normals: None,
        indices: None,
        material: mirror_m,
    });
    let rough = g.mesh(Prim {
        positions: &[[0.2, 0.0, -1.0], [1.2, 0.0, -1.0], [1.2, 1.0, -1.0], [0.2, 1.0, -1.0]],
        normals: Some(&[[0.0, 0.0, 1.0]; 4]),
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material: rough_m,
    });
    // Degenerate triangles (a repeated vertex, collinear vertices) and one with a NaN vertex.
    let junk = g.mesh(Prim {
        positions: &[
            [0.0, 0.5, 0.0],
            [0.0, 0.5, 0.0],
            [0.1, 0.6, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
            [2.0, 2.0, 2.0],
            [f32::NAN, 0.0, 0.0],
            [0.3, 0.3, 0.3],
            [0.3, 0.4, 0.3],
        ],
        normals: None,
        indices: None,
        material: floor_m,
    });
    for m in [floor, light, mirror, rough, junk] {
        g.node(json!({"mesh": m}));
    }
    if let Some((eye, target)) = camera {
        g.camera(eye, target, 0.9);
    } else {
        g.camera([0.0, 1.0, 3.0], [0.0, 0.3, 0.0], 0.9);
    }
    // serde_json writes NaN as null, which a glTF float accessor cannot carry: the NaN travels
    // in the binary buffer instead (see GltfWriter::vec3_accessor).
    // Tests run on parallel threads of one process: each scene gets a folder of its own, or
    // one test reads the file while another rewrites it.
    static SCENES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = SCENES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    load_gltf(&g.write(&format!("extreme-{n}"))).unwrap()
}

#[test]
fn extreme_values_render_without_nan() {
    let scene = extreme_scene(None);
    let prepared = PreparedScene::new(&scene, hush_engine::accel::BvhKind::DEFAULT).unwrap();
    assert_eq!(
        prepared.dropped_triangles, 3,
        "the zero-area, collinear and NaN triangles are dropped"
    );
    for (w, h) in [(17, 9), (1, 1), (3, 64)] {
        let acc = render(&scene, w, h, 16, 1).unwrap();
        assert_eq!(acc.nonfinite_samples, 0, "{w}x{h}: NaN/Inf samples");
        assert_eq!(acc.mean.nonfinite_pixels(), 0);
        assert!(acc.mean.mean().max_element() > 0.0, "{w}x{h}: the 1e6 emitter lights the scene");
    }
}

#[test]
fn grazing_cameras_render_without_nan() {
    for (eye, target) in [
        ([0.0, 0.0, 3.0], [0.0, 0.0, -1.0]), // exactly in the floor's plane
        ([0.0, 1e-6, 3.0], [0.0, 1e-6, -1.0]), // a hair above it
        ([0.0, 1.5, 0.0], [0.0, 1.5, -1.0]), // in the emitter's plane
        ([0.0, 3.0, 0.0], [0.0, -1.0, 0.0001]), // straight down
    ] {
        let scene = extreme_scene(Some((eye, target)));
        let acc = render(&scene, 16, 16, 8, 2).unwrap();
        assert_eq!(acc.nonfinite_samples, 0, "camera {eye:?}");
        assert_eq!(acc.mean.nonfinite_pixels(), 0);
    }
}

#[test]
fn empty_scenes_render_the_sky() {
    for (name, doc) in [
        ("no_nodes", json!({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0})),
        ("no_scene_nodes", json!({"asset": {"version": "2.0"}, "scenes": [{}]})),
    ] {
        let mut scene = load_gltf(&write_json(name, &doc)).unwrap();
        assert_eq!(scene.triangle_count(), 0);
        scene.add_sun_and_sky_if_unlit();
        let acc = render(&scene, 8, 8, 4, 0).unwrap();
        assert_eq!(acc.nonfinite_samples, 0);
        assert!(acc.mean.mean().min_element() > 0.0, "{name}: the sky preset is visible");
    }
}

fn load_err(name: &str, doc: serde_json::Value) -> String {
    format!("{:#}", load_gltf(&write_json(name, &doc)).unwrap_err())
}

#[test]
fn unusable_input_is_a_clear_error() {
    let e = load_err(
        "req",
        json!({"asset": {"version": "2.0"}, "extensionsRequired": ["KHR_draco_mesh_compression"], "extensionsUsed": ["KHR_draco_mesh_compression"], "scenes": [{}]}),
    );
    assert!(e.contains("KHR_draco_mesh_compression") && e.contains("does not support"), "{e}");
    let e = load_err(
        "abs",
        json!({"asset": {"version": "2.0"}, "scenes": [{}], "buffers": [{"byteLength": 4, "uri": "/etc/passwd"}]}),
    );
    assert!(e.contains("refusing"), "{e}");
    let e = load_err(
        "escape",
        json!({"asset": {"version": "2.0"}, "scenes": [{}], "buffers": [{"byteLength": 4, "uri": "../../x.bin"}]}),
    );
    assert!(e.contains("leaves the scene's folder"), "{e}");
    let e = load_err(
        "res",
        json!({"asset": {"version": "2.0"}, "scenes": [{"extras": {"resolution": [0, 10]}}]}),
    );
    assert!(e.contains("resolution"), "{e}");
    // A thin lens needs both numbers, each finite and positive.
    for (name, extras, needle) in [
        ("lens_neg", json!({"aperture_radius": -0.1, "focus_distance": 3.0}), "aperture radius"),
        ("lens_half", json!({"aperture_radius": 0.1}), "both"),
        ("lens_str", json!({"aperture_radius": 0.1, "focus_distance": "far"}), "focus_distance"),
    ] {
        let doc = json!({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"camera": 0}],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.01}, "extras": extras}]});
        let e = load_err(name, doc);
        assert!(e.contains("cameras[0].extras") && e.contains(needle), "{e}");
    }
    let e = format!("{:#}", load_gltf(std::path::Path::new("/nonexistent/x.gltf")).unwrap_err());
    assert!(e.contains("/nonexistent/x.gltf"), "{e}");
    std::fs::write(hush_tests::gltf_writer::temp_dir("garbage").join("g.gltf"), b"{not json")
        .unwrap();
    assert!(load_gltf(&hush_tests::gltf_writer::temp_dir("garbage").join("g.gltf")).is_err());

    // An index past the end of the vertex list.
    let mut g = GltfWriter::default();
    let m = g.lambert([0.5; 3]);
    let mesh = g.mesh(Prim {
        positions: &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        normals: None,
        indices: Some(&[0, 1, 7]),
        material: m,
    });
    g.node(json!({"mesh": mesh}));
    let e = format!("{:#}", load_gltf(&g.write("badindex")).unwrap_err());
    assert!(e.contains("out of range"), "{e}");

    // Image sizes the tracer cannot make.
    let scene = extreme_scene(None);
    let prepared = PreparedScene::new(&scene, hush_engine::accel::BvhKind::DEFAULT).unwrap();
    let gpu = Gpu::headless(&prepared.requirements(0, 0)).unwrap();
    let gs = prepared.upload(&gpu);
    for (w, h) in [(0, 10), (10, 0), (20000, 10)] {
        let view = TraceView::new(scene.camera_or_default(), (w, h), 6, 0);
        let e = ReferenceTracer::new(&gpu, &prepared, &gs, &view)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("out of range"), "{w}x{h}: {e}");
    }
}
