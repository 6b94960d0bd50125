//! SVGF's frame graph against its programs (naga only, no GPU): what a pass declares is what
//! its program binds, so the pool cannot give a texture a pass touches to another one.

use super::targets::{Chain, LEVELS, Pass, graph, passes, textures, writes};
use super::{Variant, program};
use crate::gpu::Parity;

/// The frame's own names (passes/io.rs): the G-buffers, the trace's light, the previous
/// G-buffer, the radiance cache's prior and the posed triangles.
fn frame_offers(name: &str) -> bool {
    ["gb_", "tr_", "cache_prior", "tri_"].iter().any(|p| name.starts_with(p))
        || ["prev_depth", "prev_normal", "prev_object"].contains(&name)
}

/// The program of `pass` of `c`: (label, prelude, modules), where it has one.
fn pass_program(c: Chain, pass: Pass, v: Variant) -> Option<(String, Vec<&'static str>)> {
    let glossy = c == Chain::Glossy;
    let motion = crate::gpu::Motion::Static;
    let file = match pass {
        Pass::Temporal if glossy => "svgf/temporal_glossy.wgsl",
        Pass::Temporal => "svgf/temporal_matte.wgsl",
        Pass::Variance => "svgf/variance.wgsl",
        Pass::Atrous(_) => "svgf/atrous.wgsl",
        Pass::Spread(_) => "svgf/spread.wgsl",
        Pass::Regression(_) => "svgf/regression.wgsl",
        Pass::Final => "svgf/final.wgsl",
        Pass::Motion => {
            let prelude =
                crate::denoise::mara::glossy::MotionProgram::of(&Default::default()).prelude();
            return Some((
                prelude,
                crate::denoise::mara::glossy::modules("glossy/motion.wgsl", motion),
            ));
        }
        Pass::Prefilter(_) => {
            return Some((
                String::new(),
                crate::denoise::mara::glossy::modules("glossy/prefilter.wgsl", motion),
            ));
        }
        Pass::HistoryCopy => return None,
    };
    Some((String::new(), program(file, glossy, motion, v)))
}

/// Every texture a pass's program binds is one the pass lists (read, or written where the
/// program writes it) or one the frame offers; nothing it lists goes unbound.
#[test]
fn every_pass_declares_what_its_program_binds() {
    let variants = [Variant::default(), Variant { prior: true, uncertain: true, kernel_5x5: true }];
    for (name, c, list) in passes(true) {
        for pass in list {
            for v in variants {
                let Some((prelude, modules)) = pass_program(c, pass, v) else { continue };
                let p = crate::shader::compose(&name, &prelude, &modules).unwrap();
                let (module, info) = p.validate_with_info().unwrap();
                let slots = crate::shader::reflect(&name, &module, &info).unwrap();
                let declared = textures(c, pass, Parity::default());
                for slot in &slots.slots {
                    let written = match slot.ty {
                        wgpu::BindingType::StorageTexture { .. } => true,
                        wgpu::BindingType::Texture { .. } => false,
                        _ => continue,
                    };
                    match declared.iter().find(|(n, _)| *n == slot.name) {
                        Some((n, _)) => assert_eq!(
                            writes(n),
                            written,
                            "{name}: `{n}` is {} by its program",
                            if written { "written" } else { "read" }
                        ),
                        None => assert!(
                            frame_offers(&slot.name),
                            "{name} binds `{}`, which neither the pass lists nor the frame offers",
                            slot.name
                        ),
                    }
                }
            }
        }
    }
}

/// SVGF's graph plans, and its transients take less memory than one texture each: the glossy
/// signal's passes reuse the matte signal's.
#[test]
fn the_graph_plans_and_the_glossy_signal_reuses_the_matte_signals_memory() {
    let bytes = |f: wgpu::TextureFormat| f.block_copy_size(None).unwrap_or(0) as usize;
    for glossy in [false, true] {
        let g = graph(glossy, &[]);
        let plan = g.plan().unwrap();
        let pooled: usize = plan.slots.iter().map(|f| bytes(*f)).sum();
        let one_each: usize = plan.placements.values().map(|p| bytes(plan.slots[p.slot])).sum();
        assert!(pooled < one_each, "glossy {glossy}: {pooled} B/px pooled, {one_each} one each");
    }
    // The outputs the composite and TAA read live to the end of the frame.
    let plan = graph(true, &[]).plan().unwrap();
    let end = plan.passes.len();
    for out in ["svgf/matte out", "svgf/matte state", "svgf/glossy out"] {
        assert_eq!(plan.placements[out].life.1, end, "{out}");
    }
    assert_eq!(LEVELS, crate::settings::SVGF_MAX_LEVELS as usize);
}

/// A texture the frame keeps (a debug view) lives to the end of the frame and shares its slot
/// with no texture placed after it.
#[test]
fn a_kept_texture_holds_its_texels_after_the_frame() {
    let kept = vec!["svgf/matte variance".to_string()];
    let plan = graph(true, &kept).plan().unwrap();
    let v = &plan.placements["svgf/matte variance"];
    assert_eq!(v.life.1, plan.passes.len());
    assert!(plan.placements.values().all(|p| p.slot != v.slot || p.life.0 <= v.life.0));
}

/// docs/architecture.md draws SVGF's frame graph as this code plans it, so that it cannot
/// drift: `hush-cli graph` prints what belongs between its markers.
#[test]
fn the_architecture_doc_draws_this_codes_frame_graph() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/architecture.md");
    let doc = std::fs::read_to_string(path).unwrap();
    let (begin, end) = ("<!-- hush-cli graph: begin -->\n", "<!-- hush-cli graph: end -->");
    let from = doc.find(begin).expect("the begin marker") + begin.len();
    let to = doc.find(end).expect("the end marker");
    let g = super::frame_graph(true);
    let want = g.describe(&g.plan().unwrap());
    assert!(
        doc[from..to] == want,
        "docs/architecture.md's frame graph is not this code's: put `hush-cli graph`'s output \
         between its markers:\n{want}"
    );
}
