//! Hostile input that claims memory, end to end through `hush-cli` (the memory class of
//! `hostile.rs`): tiny files that ask for runaway allocations are refused cheaply, and the largest
//! accepted inputs stay within their budgets. Each case measures the child's peak memory.

mod support;

use serde_json::json;
use std::path::Path;
use support::*;

#[test]
fn tiny_files_cannot_claim_runaway_memory() {
    // Each node lists the next one twice: 2^40 paths from 41 nodes.
    let dag = case("dag", |d| {
        let cam = d["nodes"][1].clone();
        let mut nodes: Vec<_> =
            (0..40).map(|i| json!({"children": [i + 1, i + 1], "mesh": 0})).collect();
        nodes.extend([json!({"mesh": 0}), cam]);
        d["nodes"] = json!(nodes);
        d["scenes"][0]["nodes"] = json!([0, 41]);
    });
    assert_refused(
        "nodes fanning out",
        &dag,
        &[],
        "nodes[1] is a child of both nodes[0] and nodes[0]",
    );
    let chain = case("chain", |d| {
        let cam = d["nodes"][1].clone();
        let mut nodes: Vec<_> = (0..2000).map(|i| json!({"children": [i + 1]})).collect();
        nodes.extend([json!({"mesh": 0}), cam]);
        d["nodes"] = json!(nodes);
        d["scenes"][0]["nodes"] = json!([0, 2001]);
    });
    assert_refused(
        "a 2,001-deep hierarchy",
        &chain,
        &[],
        "against the hierarchy-depth budget of 1024; if the file is trusted, raise it with --limit hierarchy-depth=1025",
    );
    let exr = case("exr_header", |d| {
        d["scenes"][0]["extras"] = json!({"environment": {"map": "sky.exr"}})
    });
    std::fs::write(exr.with_file_name("sky.exr"), exr_header(100_000, 50_000)).unwrap();
    assert_refused(
        "EXR declaring 100000x50000",
        &exr,
        &[],
        "(100000x50000) needs 5000000000 against the image-pixels budget of 67108864",
    );
    let bomb = write_case(
        "png_bomb",
        &textured(quad_doc(), json!({"uri": "t.png"})),
        &[("t.png", &png_bomb(16384, 16384))],
    );
    assert!(std::fs::metadata(bomb.with_file_name("t.png")).unwrap().len() < 2 << 20);
    assert_refused(
        "grayscale PNG bomb",
        &bomb,
        &[],
        "(16384x16384) needs 268435456 against the image-pixels budget",
    );
    let zero = case("dev_zero", |_| {});
    symlink(Path::new("/dev/zero"), &zero.with_file_name("scene.bin"));
    assert_refused(
        "buffer linked to /dev/zero",
        &zero,
        &[],
        "leads outside the scene's folder (to /dev/zero)",
    );
    let (o, out) = render(Path::new("/dev/zero"), &[]);
    assert!(
        o.refused("/dev/zero is a device, not a regular file") && !out.exists(),
        "{}",
        tail(&o.stderr)
    );
    let sparse = case("sparse_count", |d| {
        d["accessors"][0] = json!({"componentType": 5126, "count": 1u64 << 31, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1],
            "sparse": {"count": 1, "indices": {"bufferView": 3, "componentType": 5125}, "values": {"bufferView": 0}}});
    });
    assert_refused(
        "sparse accessor of 2^31 zeros",
        &sparse,
        &[],
        "against the decoded-bytes budget",
    );
    // One mesh of a million triangles (12 MB of indices) placed by 20 nodes.
    let mut bin = support::quad_bin();
    bin.extend((0..1_000_000).flat_map(|_| [0u32, 1, 2]).flat_map(u32::to_le_bytes));
    let mut doc = quad_doc();
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": 152, "byteLength": 12_000_000}));
    doc["accessors"].as_array_mut().unwrap().push(
        json!({"bufferView": 4, "componentType": 5125, "count": 3_000_000, "type": "SCALAR"}),
    );
    doc["meshes"][0]["primitives"][0]["indices"] = json!(4);
    let cam = doc["nodes"][1].clone();
    let mut nodes: Vec<_> = (0..20).map(|i| json!({"mesh": 0, "translation": [i, 0, 0]})).collect();
    nodes.push(cam);
    doc["nodes"] = json!(nodes);
    doc["scenes"][0]["nodes"] = json!((0..21).collect::<Vec<_>>());
    let instanced = write_case("instanced", &doc, &[]);
    std::fs::write(instanced.with_file_name("scene.bin"), bin).unwrap();
    assert_refused(
        "20 million instanced triangles",
        &instanced,
        &[],
        "against the triangles budget of 16777215",
    );
    // Budgets can be raised or lowered by name.
    assert_refused(
        "a lowered node budget",
        &case("nodes", |_| {}),
        &["--limit", "nodes=1"],
        "needs 2 against the nodes budget of 1",
    );
    assert_renders("a raised depth budget", &chain, &["--limit", "hierarchy-depth=3000"], "");
}

/// The largest inputs the default budgets accept, and the memory they take: a texture of the
/// full 8192 x 8192 pixels (peak 905 MiB measured: decoding, the RGBA copy and the halving
/// resize's float buffer) and 200,000 instanced quads (536 MiB).
#[test]
fn the_largest_accepted_inputs_stay_within_their_memory() {
    let texture = write_case(
        "png_at_budget",
        &textured(quad_doc(), json!({"uri": "t.png"})),
        &[("t.png", &png_bomb(8192, 8192))],
    );
    let big = assert_renders("an 8192x8192 texture", &texture, &[], "");
    assert!(big.peak_mib < 1200.0, "an 8192x8192 texture took {:.0} MiB", big.peak_mib);
    let many = case("instances_200k", |d| {
        let cam = d["nodes"][1].clone();
        let mut nodes: Vec<_> = (0..200_000)
            .map(|i| json!({"mesh": 0, "translation": [i % 500, 0, i / 500]}))
            .collect();
        nodes.push(cam);
        d["nodes"] = json!(nodes);
        d["scenes"][0]["nodes"] = json!((0..200_001).collect::<Vec<_>>());
    });
    let o = assert_renders("200,000 instances", &many, &[], "");
    assert!(o.peak_mib < 1024.0, "200,000 instances took {:.0} MiB", o.peak_mib);
    println!(
        "peak memory: 8192x8192 texture {:.0} MiB, 200,000 instances {:.0} MiB",
        big.peak_mib, o.peak_mib
    );
}
