//! Hostile input, end to end through `hush-cli`: one test per class of defect that hand-made bad
//! files once found (panics, hangs, runaway memory, reads outside the scene's folder, silently
//! wrong output, late or misleading errors). Each case asserts the exact outcome: the exit code
//! and the error's words, no output written, and for the memory class the child's peak memory.
//! Scenes render at 8x8 with one sample, so the suite costs seconds.

mod support;

use serde_json::json;
use std::path::Path;
use support::*;

#[test]
fn files_that_panicked_are_clear_errors() {
    let png = png_bomb(4, 4);
    for (name, scene, needle) in [
        (
            "float indices",
            case("float_indices", |d| d["accessors"][3]["componentType"] = json!(5126)),
            "indices (accessors[3]) is SCALAR of FLOAT",
        ),
        (
            "camera type without its data",
            case(
                "camera_type",
                |d| d["cameras"][0] = json!({"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "zfar": 10, "znear": 0.1}}),
            ),
            "cameras[0] is of type perspective but has no `perspective`",
        ),
        (
            "image with uri and bufferView",
            write_case(
                "image_both",
                &textured(
                    quad_doc(),
                    json!({"uri": "t.png", "bufferView": 0, "mimeType": "image/png"}),
                ),
                &[("t.png", &png)],
            ),
            "images[0] has both `uri` and `bufferView`",
        ),
        (
            "image with neither",
            write_case("image_neither", &textured(quad_doc(), json!({"name": "x"})), &[]),
            "images[0] has neither `uri` nor `bufferView`",
        ),
        (
            "image in a view without mimeType",
            write_case("image_mime", &textured(quad_doc(), json!({"bufferView": 0})), &[]),
            "images[0] is stored in a bufferView but has no `mimeType`",
        ),
        (
            "normal map with short TEXCOORD_0",
            case("short_uv", |d| {
                d["materials"][0]["normalTexture"] = json!({"index": 0});
                d["textures"] = json!([{"source": 0}]);
                d["images"] = json!([{"uri": "t.png"}]);
                d["accessors"][2]["count"] = json!(2);
            }),
            "TEXCOORD_0 has 2 elements and POSITION 4",
        ),
        (
            "POSITION naming a missing accessor",
            case("position_index", |d| {
                d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(9)
            }),
            "POSITION names accessors[9], which does not exist",
        ),
        (
            "animation of an unknown property",
            case("anim_path", |d| {
                d["accessors"].as_array_mut().unwrap().push(
                    json!({"bufferView": 3, "componentType": 5126, "count": 6, "type": "SCALAR"}),
                );
                d["animations"] = json!([{"channels": [{"sampler": 0, "target": {"node": 0, "path": "colour"}}], "samplers": [{"input": 4, "output": 0}]}]);
            }),
            "target.path must be translation, rotation, scale or weights",
        ),
        (
            "spot light without spot",
            case("spot", |d| {
                d["extensionsUsed"] = json!(["KHR_lights_punctual"]);
                d["extensions"] =
                    json!({"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 5}]}});
                d["nodes"][0]["extensions"] = json!({"KHR_lights_punctual": {"light": 0}});
            }),
            "extensions.KHR_lights_punctual.lights[0] is a spot light without `spot`",
        ),
    ] {
        assert_refused(name, &scene, &[], needle);
    }
    // A GLB whose header's length is shorter than the header (the gltf crate subtracted unchecked).
    let glb = support::dir("glb_length").join("scene.glb");
    std::fs::write(
        &glb,
        [&b"glTF"[..], &2u32.to_le_bytes(), &4u32.to_le_bytes(), &[0u8; 8]].concat(),
    )
    .unwrap();
    assert_refused("GLB length under its header", &glb, &[], "shorter than its 12-byte header");

    // Files that are fine but panicked in a dependency: a normal-mapped mesh whose triangles are
    // all degenerate (mikktspace), and 2,000 copies of one triangle (obvhs's BVH depth check).
    let degenerate = case("degenerate_normal_map", |d| {
        d["materials"][0]["normalTexture"] = json!({"index": 0});
        d["textures"] = json!([{"source": 0}]);
        d["images"] = json!([{"uri": "t.png"}]);
        d["bufferViews"][0]["byteLength"] = json!(12);
        d["bufferViews"][0]["byteStride"] = json!(12);
        d["accessors"][0]["count"] = json!(1);
        d["accessors"][3]["count"] = json!(3);
        d["bufferViews"][3]["byteLength"] = json!(12);
        d["accessors"][1]["count"] = json!(1);
        d["accessors"][2]["count"] = json!(1);
        d["bufferViews"][3]["byteOffset"] = json!(128);
    });
    std::fs::write(degenerate.with_file_name("t.png"), &png).unwrap();
    // Indices 0, 2, 1 of a one-vertex mesh are out of range; point them all at vertex 0.
    let mut bin = support::quad_bin();
    bin[128..140].fill(0);
    std::fs::write(degenerate.with_file_name("scene.bin"), bin).unwrap();
    assert_renders("all-degenerate normal-mapped mesh", &degenerate, &[], "");
    let stacked = case("stacked", |d| {
        let cam = d["nodes"][1].clone();
        let mut nodes: Vec<_> = (0..1000).map(|_| json!({"mesh": 0})).collect();
        nodes.push(cam);
        d["nodes"] = json!(nodes);
        d["scenes"][0]["nodes"] = json!((0..1001).collect::<Vec<_>>());
    });
    assert_renders("1,000 stacked copies", &stacked, &[], "built by median splits");
}

#[test]
fn inputs_that_hung_end_quickly() {
    assert_refused(
        "node that is its own child",
        &case("own_child", |d| d["nodes"][0]["children"] = json!([0])),
        &[],
        "nodes[0] is its own child",
    );
    assert_refused(
        "camera node that is its own child",
        &case("camera_child", |d| d["nodes"][1]["children"] = json!([1])),
        &[],
        "nodes[1] is its own child",
    );
    assert_refused(
        "cycle out of the scene's reach",
        &case("cycle", |d| {
            d["nodes"]
                .as_array_mut()
                .unwrap()
                .extend([json!({"children": [3]}), json!({"children": [2], "mesh": 0})]);
        }),
        &[],
        "cycle of children",
    );
    let buffer = case("buffer_fifo", |_| {});
    fifo(&buffer.with_file_name("scene.bin"));
    assert_refused(
        "buffer that is a FIFO",
        &buffer,
        &[],
        "scene.bin is a named pipe, not a regular file; refused",
    );
    let texture = write_case("texture_fifo", &textured(quad_doc(), json!({"uri": "t.png"})), &[]);
    fifo(&texture.with_file_name("t.png"));
    assert_renders(
        "texture that is a FIFO",
        &texture,
        &[],
        "t.png is a named pipe, not a regular file; refused; rendering without it",
    );
    let env =
        case("env_fifo", |d| d["scenes"][0]["extras"] = json!({"environment": {"map": "sky.exr"}}));
    fifo(&env.with_file_name("sky.exr"));
    assert_refused("environment map that is a FIFO", &env, &[], "sky.exr is a named pipe");
    let ok = case("ok", |_| {});
    let path = ok.with_file_name("path.json");
    fifo(&path);
    assert_refused(
        "camera path that is a FIFO",
        &ok,
        &["--mode", "realtime", "--camera-path", path.to_str().unwrap()],
        "path.json is a named pipe",
    );
    fifo(&ok.with_file_name("p.toml"));
    assert_refused(
        "preset that is a FIFO",
        &ok,
        &["--mode", "realtime", "--preset", ok.with_file_name("p.toml").to_str().unwrap()],
        "p.toml is a named pipe",
    );

    // Copies of a quad that obvhs's PLOC merged one pair per pass: 20,000 stacked ones ran past
    // 60 s, nested ones too, and a row of evenly spaced ones took 15 s.
    for (name, place) in [
        (
            "stacked",
            Box::new(|_: usize| json!({"mesh": 0})) as Box<dyn Fn(usize) -> serde_json::Value>,
        ),
        (
            "nested",
            Box::new(
                |i| json!({"mesh": 0, "scale": [1.0 + i as f64 * 1e-3, 1, 1.0 + i as f64 * 1e-3]}),
            ),
        ),
        ("row", Box::new(|i| json!({"mesh": 0, "translation": [i as f64 * 2.0, 0, 0]}))),
    ] {
        let scene = case(&format!("instances_{name}"), |d| {
            let cam = d["nodes"][1].clone();
            let mut nodes: Vec<_> = (0..20_000).map(&place).collect();
            nodes.push(cam);
            d["nodes"] = json!(nodes);
            d["scenes"][0]["nodes"] = json!((0..20_001).collect::<Vec<_>>());
        });
        let o = assert_renders(&format!("20,000 {name} copies"), &scene, &[], "");
        assert!(o.secs < 20.0, "20,000 {name} copies took {:.1} s", o.secs);
    }
}

#[test]
fn nothing_outside_the_scene_folder_is_read() {
    let secret = support::dir("secret").join("secret.bin");
    std::fs::write(&secret, b"SECRET-CONTENT").unwrap();
    let buffer = case("buffer_link", |_| {});
    symlink(&secret, &buffer.with_file_name("scene.bin"));
    let o =
        assert_refused("buffer linked outside", &buffer, &[], "leads outside the scene's folder");
    assert!(!o.stderr.contains("SECRET"));
    let texture = write_case("texture_link", &textured(quad_doc(), json!({"uri": "t.png"})), &[]);
    symlink(&secret, &texture.with_file_name("t.png"));
    assert_renders(
        "texture linked outside",
        &texture,
        &[],
        "t.png leads outside the scene's folder",
    );
    let env =
        case("env_link", |d| d["scenes"][0]["extras"] = json!({"environment": {"map": "sky.exr"}}));
    symlink(&secret, &env.with_file_name("sky.exr"));
    assert_refused("environment map linked outside", &env, &[], "leads outside the scene's folder");
    let folder = case("folder_link", |d| d["buffers"][0]["uri"] = json!("sub/scene.bin"));
    let other = support::dir("other");
    std::fs::write(other.join("scene.bin"), support::quad_bin()).unwrap();
    symlink(&other, &folder.with_file_name("sub"));
    assert_refused(
        "folder linked outside",
        &folder,
        &[],
        "sub/scene.bin leads outside the scene's folder",
    );
    for (name, uri, needle) in [
        ("parent", "../secret/secret.bin", "it leaves the scene's folder"),
        ("percent-encoded parent", "%2e%2e/secret/secret.bin", "it leaves the scene's folder"),
        ("absolute", "/etc/passwd", "only paths relative to the scene's folder are allowed"),
        ("file URL", "file:///etc/passwd", "only paths relative to the scene's folder are allowed"),
    ] {
        assert_refused(
            name,
            &case(&format!("uri_{}", name.replace(' ', "_")), |d| {
                d["buffers"][0]["uri"] = json!(uri)
            }),
            &[],
            needle,
        );
    }
}

/// The mean of an EXR render at 8x8, 4 spp.
fn mean(scene: &Path, name: &str) -> glam::Vec3 {
    let out = scene.with_file_name(format!("{name}.exr"));
    let o = run(
        &[
            "render",
            scene.to_str().unwrap(),
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "4",
            "--out",
            out.to_str().unwrap(),
        ],
        LIMIT,
    );
    assert_eq!(o.code, Some(0), "{name}: {}", tail(&o.stderr));
    hush_engine::quality::Image::load(&out).unwrap().mean()
}

#[test]
fn output_that_was_silently_wrong_is_right_or_refused() {
    let clean = mean(&case("clean", |_| {}), "clean");
    assert!(clean.min_element() > 0.05, "the quad is lit: {clean}");
    // A stray triangle with one +Inf vertex (its finite ones inside the quad's bounds): it is
    // dropped, and the quad renders as without it (the infinite bounds had dropped everything).
    let stray = case("inf_vertex", |d| {
        d["buffers"][0]["byteLength"] = json!(152 + 36);
        d["bufferViews"]
            .as_array_mut()
            .unwrap()
            .push(json!({"buffer": 0, "byteOffset": 152, "byteLength": 36}));
        d["accessors"].as_array_mut().unwrap().push(json!({"bufferView": 4, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [0.5, 0, 0.5]}));
        d["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .push(json!({"attributes": {"POSITION": 4}, "material": 0}));
    });
    let mut bin = support::quad_bin();
    for v in [[f32::INFINITY, 0.0, 0.0], [0.0, 0.0, 0.0], [0.5, 0.0, 0.5]] {
        v.iter().for_each(|x| bin.extend_from_slice(&x.to_le_bytes()));
    }
    std::fs::write(stray.with_file_name("scene.bin"), bin).unwrap();
    let with_inf = mean(&stray, "inf");
    assert!(
        (with_inf - clean).abs().max_element() < 1e-4 * clean.max_element(),
        "+Inf vertex: {with_inf} against {clean}"
    );
    // A camera node scaled to zero keeps its pose.
    let zero_scale = mean(
        &case("camera_zero_scale", |d| d["nodes"][1]["scale"] = json!([0, 0, 0])),
        "zero_scale",
    );
    assert!(
        (zero_scale - clean).abs().max_element() < 1e-3 * clean.max_element(),
        "zero-scale camera: {zero_scale} against {clean}"
    );

    for (name, mutate, needle) in [
        (
            "indices past their buffer",
            Box::new(|d: &mut serde_json::Value| d["bufferViews"][3]["byteOffset"] = json!(140))
                as Box<dyn Fn(&mut serde_json::Value)>,
            "indices (accessors[3]): bufferViews[3] (bytes 140..164) runs past its buffer of 152 bytes",
        ),
        (
            "yfov 0",
            Box::new(|d| d["cameras"][0]["perspective"]["yfov"] = json!(0)),
            "cameras[0].perspective.yfov must be in (0, pi) radians, got 0",
        ),
        (
            "negative yfov",
            Box::new(|d| d["cameras"][0]["perspective"]["yfov"] = json!(-0.5)),
            "yfov must be in (0, pi) radians, got -0.5",
        ),
        (
            "yfov of pi",
            Box::new(|d| d["cameras"][0]["perspective"]["yfov"] = json!(std::f32::consts::PI)),
            "yfov must be in (0, pi) radians",
        ),
        (
            "POSITION of unsigned bytes",
            Box::new(|d| d["accessors"][0]["componentType"] = json!(5121)),
            "POSITION (accessors[0]) is VEC3 of UNSIGNED_BYTE; Hush reads it as VEC3 of FLOAT",
        ),
        (
            "POSITION of VEC2",
            Box::new(|d| d["accessors"][0]["type"] = json!("VEC2")),
            "POSITION (accessors[0]) is VEC2 of FLOAT; Hush reads it as VEC3 of FLOAT",
        ),
        (
            "environment intensity \"bright\"",
            Box::new(|d| {
                d["scenes"][0]["extras"] =
                    json!({"environment": {"map": "sky.exr", "intensity": "bright"}})
            }),
            "scenes[0].extras.environment.intensity must be a number >= 0, got \"bright\"",
        ),
    ] {
        assert_refused(name, &case(&name.replace([' ', '"'], "_"), |d| mutate(d)), &[], needle);
    }
    let ok = case("flags", |_| {});
    let (o, out) = render(&ok, &["--max-depth", "-2"]);
    assert!(
        o.code == Some(2) && o.stderr.contains("-2 is not in -1..=65536") && !out.exists(),
        "{}",
        tail(&o.stderr)
    );
    let preset = ok.with_file_name("p.toml");
    std::fs::write(&preset, "denoiser = \"Mara\"\n").unwrap();
    assert_refused(
        "--preset in reference mode",
        &ok,
        &["--preset", preset.to_str().unwrap()],
        "--preset only applies to --mode realtime",
    );
    // An orthographic camera renders through a perspective one, and says so.
    let ortho = case(
        "ortho",
        |d| d["cameras"][0] = json!({"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.01, "zfar": 10}}),
    );
    assert_renders(
        "orthographic camera",
        &ortho,
        &[],
        "cameras[0] is orthographic; Hush renders it as a perspective camera",
    );
    assert_renders(
        "orthographic camera in real time",
        &ortho,
        &["--mode", "realtime"],
        "cameras[0] is orthographic",
    );
}

#[test]
fn errors_come_before_the_work_and_say_what_is_wrong() {
    // Output checks come before the scene is even read: the scene here does not exist.
    let missing = Path::new("/nonexistent/scene.gltf");
    let o = run(&["render", "/nonexistent/scene.gltf", "--out", "x.jpg"], LIMIT);
    assert!(
        o.refused("--out x.jpg: the file must end in .exr or .png")
            && !o.stderr.contains("nonexistent"),
        "{}",
        tail(&o.stderr)
    );
    let o =
        run(&["render", missing.to_str().unwrap(), "--out", "/nonexistent/folder/x.png"], LIMIT);
    assert!(o.refused("the folder /nonexistent/folder does not exist"), "{}", tail(&o.stderr));
    let o = run(
        &[
            "render",
            missing.to_str().unwrap(),
            "--width",
            "65536",
            "--height",
            "65537",
            "--out",
            "x.png",
        ],
        LIMIT,
    );
    assert!(
        o.refused("--width 65536: reference mode renders at most 16384 pixels a side"),
        "{}",
        tail(&o.stderr)
    );
    let o = run(
        &[
            "render",
            missing.to_str().unwrap(),
            "--mode",
            "realtime",
            "--width",
            "9000",
            "--out",
            "x.png",
        ],
        LIMIT,
    );
    assert!(
        o.refused("--width 9000: real-time mode renders at most 8192 pixels a side"),
        "{}",
        tail(&o.stderr)
    );
    // The other commands' outputs too, before any rendering.
    let file = support::dir("outputs").join("a-file");
    std::fs::write(&file, b"").unwrap();
    let under_file = file.join("out");
    for (args, needle) in [
        (
            vec!["quality", "level", "--out-dir", under_file.to_str().unwrap()],
            "a-file is not a folder",
        ),
        (
            vec!["sweep", "level", "--out-dir", under_file.to_str().unwrap()],
            "a-file is not a folder",
        ),
        (
            vec!["bench", "level", "--mode", "realtime", "--profile", "/nonexistent/x.puffin"],
            "the folder /nonexistent does not exist",
        ),
    ] {
        let o = run(&args, LIMIT);
        assert!(o.refused(needle) && o.peak_mib < REFUSED_MIB, "{args:?}: {}", tail(&o.stderr));
    }
    // An accessor past its view names it (it had said 'a primitive has no POSITION').
    assert_refused(
        "accessor past its view",
        &case("past_view", |d| d["accessors"][0]["byteOffset"] = json!(40)),
        &[],
        "POSITION (accessors[0]): 4 elements of 12 bytes (stride 12) from byte 40 run past bufferViews[0] of 48 bytes",
    );
    // A 21 MB data URI that is not base64: the error quotes its first 64 characters.
    let big = format!("data:application/octet-stream;base64,{}", "!".repeat(21 << 20));
    let o = assert_refused(
        "21 MB of bad base64",
        &case("base64", |d| d["buffers"][0]["uri"] = json!(big)),
        &[],
        "invalid base64",
    );
    assert!(o.stderr.len() < 2000, "the error is {} bytes long", o.stderr.len());
    // compare reads images within the same budgets.
    let exr = support::dir("compare").join("big.exr");
    std::fs::write(&exr, exr_header(100_000, 50_000)).unwrap();
    let o = run(&["compare", exr.to_str().unwrap(), exr.to_str().unwrap()], LIMIT);
    assert!(
        o.refused("against the image-pixels budget") && o.peak_mib < REFUSED_MIB,
        "{}",
        tail(&o.stderr)
    );
}
