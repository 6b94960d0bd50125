//! The frame graph of a chain of passes: each pass declares the textures it reads and writes by
//! name, the graph checks that every read has a writer before it, and gives each transient
//! texture (one that lives within the frame) a slot of a pool, shared with other transients of
//! the same format whose lives do not overlap. Only histories (a [`super::PingPong`], declared
//! with [`FrameGraph::history`]) outlive a frame, as NRD's `AddTextureToTransientPool` and
//! kajiya's `rg.create` temporaries do it.
//!
//! A texture's life runs from the first pass that writes it to the last pass that reads or
//! writes it, or to the end of the frame for what the frame reads after the chain ([`FrameGraph::output`]:
//! the composite's and TAA's inputs, a debug view, a test's readback). The graph is declared
//! for every pass the chain may record: a pass a setting skips only shortens lives, so a plan
//! holds for every setting of the chain.
//!
//! Written here rather than taken from a crate: the render graphs of the ecosystem (kajiya-rg,
//! Bevy's) own their device and resources; this one only plans, and the chain makes its
//! textures from the plan with the frame's labelled memory.

use super::{GpuMemory, Tex};
use std::collections::HashMap;

/// What a texture of the graph is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Lives within the frame; shares a pool slot with textures whose lives do not overlap.
    Transient,
    /// Outlives the frame: read before it is written (last frame's), never pooled.
    History,
    /// Made by someone else (the frame's G-buffer and trace): always there to read.
    External,
}

/// A plan-time error of a graph: what was wrong and which passes and textures it concerns.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GraphError {
    #[error("pass {pass:?} reads {texture:?}, which no pass before it writes{}", later(.written_by))]
    ReadBeforeWrite { pass: String, texture: String, written_by: Option<String> },
    #[error("pass {pass:?} binds {texture:?}, which the graph does not declare")]
    Undeclared { pass: String, texture: String },
    #[error("{texture:?} is declared twice")]
    Duplicate { texture: String },
}

fn later(w: &Option<String>) -> String {
    w.as_ref().map(|w| format!(" (pass {w:?} writes it after)")).unwrap_or_default()
}

struct Texture {
    name: String,
    format: wgpu::TextureFormat,
    kind: Kind,
}

struct Pass {
    name: String,
    reads: Vec<String>,
    writes: Vec<String>,
}

/// A chain's passes in the order it records them, and the textures they bind.
#[derive(Default)]
pub struct FrameGraph {
    textures: Vec<Texture>,
    passes: Vec<Pass>,
    outputs: Vec<String>,
}

/// Where a transient texture lives: its pool slot and the passes it lives over (first, last).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Placement {
    pub slot: usize,
    pub life: (usize, usize),
}

/// A graph's plan: a slot for every transient texture, and each slot's format.
#[derive(Clone, Debug, Default)]
pub struct GraphPlan {
    pub placements: HashMap<String, Placement>,
    pub slots: Vec<wgpu::TextureFormat>,
    /// The passes by name, in order (what each life's indices count).
    pub passes: Vec<String>,
}

impl FrameGraph {
    fn declare(&mut self, name: &str, format: wgpu::TextureFormat, kind: Kind) -> &mut Self {
        self.textures.push(Texture { name: name.to_string(), format, kind });
        self
    }

    /// A texture that lives within the frame, from its first writer to its last reader.
    pub fn transient(&mut self, name: &str, format: wgpu::TextureFormat) -> &mut Self {
        self.declare(name, format, Kind::Transient)
    }

    /// A texture that outlives the frame (one slot of a history's pair).
    pub fn history(&mut self, name: &str, format: wgpu::TextureFormat) -> &mut Self {
        self.declare(name, format, Kind::History)
    }

    /// A texture someone else made and wrote before the chain runs (the frame's I/O).
    pub fn external(&mut self, name: &str) -> &mut Self {
        self.declare(name, wgpu::TextureFormat::R8Unorm, Kind::External)
    }

    /// The next pass the chain records: what it reads and what it writes.
    pub fn pass(&mut self, name: &str, reads: &[&str], writes: &[&str]) -> &mut Self {
        let own = |v: &[&str]| v.iter().map(|s| s.to_string()).collect();
        self.passes.push(Pass { name: name.to_string(), reads: own(reads), writes: own(writes) });
        self
    }

    /// A texture the frame reads after the chain: it lives to the end of the frame.
    pub fn output(&mut self, name: &str) -> &mut Self {
        self.outputs.push(name.to_string());
        self
    }

    /// The histories declared: (name, format).
    pub fn histories(&self) -> impl Iterator<Item = (&str, wgpu::TextureFormat)> {
        self.textures
            .iter()
            .filter(|t| t.kind == Kind::History)
            .map(|t| (t.name.as_str(), t.format))
    }

    /// The transient textures declared.
    pub fn transients(&self) -> impl Iterator<Item = &str> {
        self.textures.iter().filter(|t| t.kind == Kind::Transient).map(|t| t.name.as_str())
    }

    /// Whether `name` is declared.
    pub fn declares(&self, name: &str) -> bool {
        self.textures.iter().any(|t| t.name == name)
    }

    /// Check the graph and place its transient textures: in order of their first writer, each
    /// takes the first slot of its format whose last texture's life ended before its life
    /// begins (a greedy interval colouring: as few slots as the most lives that overlap).
    pub fn plan(&self) -> Result<GraphPlan, GraphError> {
        let mut kinds: HashMap<&str, &Texture> = HashMap::new();
        for t in &self.textures {
            if kinds.insert(&t.name, t).is_some() {
                return Err(GraphError::Duplicate { texture: t.name.clone() });
            }
        }
        let end = self.passes.len();
        let mut lives: HashMap<&str, (usize, usize)> = HashMap::new();
        for (i, p) in self.passes.iter().enumerate() {
            for name in p.reads.iter().chain(&p.writes) {
                if !kinds.contains_key(name.as_str()) {
                    let (pass, texture) = (p.name.clone(), name.clone());
                    return Err(GraphError::Undeclared { pass, texture });
                }
            }
            for r in &p.reads {
                if kinds[r.as_str()].kind != Kind::Transient {
                    continue;
                }
                match lives.get_mut(r.as_str()) {
                    Some(life) => life.1 = life.1.max(i),
                    None => {
                        let written_by = self.passes[i..]
                            .iter()
                            .find(|q| q.writes.contains(r))
                            .map(|q| q.name.clone());
                        let (pass, texture) = (p.name.clone(), r.clone());
                        return Err(GraphError::ReadBeforeWrite { pass, texture, written_by });
                    }
                }
            }
            // A write after the last read still touches the texture's memory.
            for w in &p.writes {
                lives.entry(w.as_str()).or_insert((i, i)).1 = i;
            }
        }
        for o in &self.outputs {
            match (kinds.get(o.as_str()), lives.get_mut(o.as_str())) {
                (None, _) => {
                    return Err(GraphError::Undeclared {
                        pass: "(frame)".into(),
                        texture: o.clone(),
                    });
                }
                (Some(t), None) if t.kind == Kind::Transient => {
                    return Err(GraphError::ReadBeforeWrite {
                        pass: "(frame)".into(),
                        texture: o.clone(),
                        written_by: None,
                    });
                }
                (_, Some(life)) => life.1 = end,
                _ => {}
            }
        }
        let mut order: Vec<(&str, (usize, usize))> = self
            .textures
            .iter()
            .filter(|t| t.kind == Kind::Transient)
            .filter_map(|t| lives.get(t.name.as_str()).map(|l| (t.name.as_str(), *l)))
            .collect();
        order.sort_by_key(|(_, life)| *life);
        let mut plan = GraphPlan {
            passes: self.passes.iter().map(|p| p.name.clone()).collect(),
            ..Default::default()
        };
        // Per slot: the end of the life of the texture placed there last.
        let mut ends: Vec<usize> = vec![];
        for (name, life) in order {
            let format = kinds[name].format;
            let free = (0..plan.slots.len()).find(|&s| plan.slots[s] == format && ends[s] < life.0);
            let slot = free.unwrap_or_else(|| {
                plan.slots.push(format);
                ends.push(0);
                plan.slots.len() - 1
            });
            ends[slot] = life.1;
            plan.placements.insert(name.to_string(), Placement { slot, life });
        }
        Ok(plan)
    }
}

impl FrameGraph {
    /// The graph and its plan as Markdown: each pass with what it reads and writes, then each
    /// pool slot with the textures it holds in turn and their lives (pass numbers), and the
    /// histories. What `docs/architecture.md` shows, drawn from the code.
    pub fn describe(&self, plan: &GraphPlan) -> String {
        let bytes = |f: wgpu::TextureFormat| f.block_copy_size(None).unwrap_or(0);
        let mut s = String::from("| # | pass | reads | writes |\n|---|---|---|---|\n");
        for (i, p) in self.passes.iter().enumerate() {
            let (r, w) = (p.reads.join(", "), p.writes.join(", "));
            s += &format!("| {i} | {} | {r} | {w} |\n", p.name);
        }
        s += "\n| slot | format | bytes/pixel | textures (lives) |\n|---|---|---|---|\n";
        for (slot, f) in plan.slots.iter().enumerate() {
            let mut held: Vec<(&String, &Placement)> =
                plan.placements.iter().filter(|(_, p)| p.slot == slot).collect();
            held.sort_by_key(|(_, p)| p.life);
            let held: Vec<String> =
                held.iter().map(|(n, p)| format!("{n} ({}-{})", p.life.0, p.life.1)).collect();
            s += &format!("| {slot} | {f:?} | {} | {} |\n", bytes(*f), held.join(", "));
        }
        let histories: Vec<String> =
            self.histories().map(|(n, f)| format!("{n} ({f:?}, {} B)", bytes(f))).collect();
        let pooled: u32 = plan.slots.iter().map(|f| bytes(*f)).sum();
        let one_each: u32 = plan.placements.values().map(|p| bytes(plan.slots[p.slot])).sum();
        let kept: u32 = self.histories().map(|(_, f)| bytes(f)).sum();
        s += &format!(
            "\nTransient: {pooled} bytes a pixel in {} slots for {} textures ({one_each} one \
             each). Histories, {kept} bytes a pixel: {}.\n",
            plan.slots.len(),
            plan.placements.len(),
            histories.join(", ")
        );
        s
    }
}

/// The transient textures of one plan at one size: a texture per slot, made in the frame's
/// memory (labelled `prefix pool N`, counted as transient), and each transient's texture by
/// name.
pub struct TransientPool {
    slots: Vec<Tex>,
    plan: GraphPlan,
}

impl TransientPool {
    /// Make `plan`'s slots at `size` in `mem` with `usage`.
    pub fn new(
        device: &wgpu::Device,
        mem: &mut GpuMemory,
        prefix: &str,
        plan: GraphPlan,
        size: (u32, u32),
        usage: wgpu::TextureUsages,
    ) -> TransientPool {
        let slots = plan
            .slots
            .iter()
            .enumerate()
            .map(|(i, f)| {
                mem.transient_texture(device, &format!("{prefix}pool {i}"), size, *f, usage)
            })
            .collect();
        let pool = TransientPool { slots, plan };
        // Readable by name after the frame where no later texture shares its slot (a debug
        // view, a readback): the last texture placed in each slot.
        let placements = &pool.plan.placements;
        for (name, p) in placements {
            if placements.values().all(|q| q.slot != p.slot || q.life.0 <= p.life.0) {
                mem.name_transient(name, &pool.slots[p.slot].0);
            }
        }
        pool
    }

    /// The texture of transient `name` (an error in the graph's declaration if none).
    pub fn tex(&self, name: &str) -> Option<&Tex> {
        self.plan.placements.get(name).map(|p| &self.slots[p.slot])
    }

    pub fn plan(&self) -> &GraphPlan {
        &self.plan
    }
}

/// Whether the frame keeps `label` readable after it: one of `kept` (`Renderer::keep`'s
/// prefixes, and the texture a view shows) starts it.
pub fn is_kept(kept: &[String], label: &str) -> bool {
    kept.iter().any(|k| label.starts_with(k.as_str()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use wgpu::TextureFormat::{Rgba16Float as H, Rgba32Float as F};

    #[test]
    fn a_read_with_no_writer_before_it_names_the_pass_the_texture_and_the_late_writer() {
        let mut g = FrameGraph::default();
        g.transient("a", H).transient("b", H);
        g.pass("first", &["b"], &["a"]).pass("second", &[], &["b"]);
        let e = g.plan().unwrap_err();
        let want = GraphError::ReadBeforeWrite {
            pass: "first".into(),
            texture: "b".into(),
            written_by: Some("second".into()),
        };
        assert_eq!(e, want);
        assert_eq!(
            e.to_string(),
            "pass \"first\" reads \"b\", which no pass before it writes (pass \"second\" writes it after)"
        );
        let mut g = FrameGraph::default();
        g.transient("a", H).pass("only", &["missing"], &["a"]);
        assert!(matches!(g.plan(), Err(GraphError::Undeclared { .. })));
    }

    #[test]
    fn histories_and_external_inputs_are_read_before_any_write() {
        let mut g = FrameGraph::default();
        g.history("h0", F).history("h1", F).external("gb_depth").transient("t", H);
        g.pass("temporal", &["h0", "gb_depth"], &["t", "h1"]).pass("filter", &["t"], &[]);
        let plan = g.plan().unwrap();
        assert_eq!(plan.placements.len(), 1, "only the transient is pooled");
        assert_eq!(plan.slots, vec![H]);
    }

    #[test]
    fn lives_that_do_not_overlap_share_a_slot_of_their_format() {
        let mut g = FrameGraph::default();
        g.transient("a", H).transient("b", H).transient("c", H).transient("d", F);
        g.pass("1", &[], &["a"]).pass("2", &["a"], &["b"]).pass("3", &["b"], &["c", "d"]);
        g.pass("4", &["c", "d"], &[]);
        let p = g.plan().unwrap();
        // a [0,1], b [1,2], c [2,3]: a and c share, b overlaps both; d has a format of its own.
        assert_eq!(p.placements["a"].slot, p.placements["c"].slot);
        assert_ne!(p.placements["a"].slot, p.placements["b"].slot);
        assert_eq!(p.slots.len(), 3);
        assert_eq!(p.slots[p.placements["d"].slot], F);
    }

    #[test]
    fn an_output_lives_to_the_end_of_the_frame() {
        let mut g = FrameGraph::default();
        g.transient("out", H).transient("late", H);
        g.pass("1", &[], &["out"]).pass("2", &[], &["late"]).pass("3", &["late"], &[]);
        assert_eq!(g.plan().unwrap().slots.len(), 1, "out's life ends at pass 1");
        g.output("out");
        let p = g.plan().unwrap();
        assert_eq!(p.slots.len(), 2);
        assert_eq!(p.placements["out"].life, (0, 3));
    }

    /// xorshift: the graphs below are the same on every run.
    fn next(s: &mut u64) -> u64 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        *s
    }

    /// The pool never gives one slot to two textures whose lives overlap (a pass between the
    /// first writer and the last reader of one touches the other's memory), and never mixes
    /// formats, over random chains of passes.
    #[test]
    fn no_slot_holds_two_textures_whose_lives_overlap() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..500 {
            let mut g = FrameGraph::default();
            let n = 2 + next(&mut seed) as usize % 12;
            let names: Vec<String> = (0..n).map(|i| format!("t{i}")).collect();
            for name in &names {
                g.transient(name, if next(&mut seed).is_multiple_of(3) { F } else { H });
            }
            let mut written: Vec<&str> = vec![];
            let passes = 1 + next(&mut seed) as usize % 16;
            for p in 0..passes {
                let reads: Vec<&str> =
                    written.iter().copied().filter(|_| next(&mut seed).is_multiple_of(3)).collect();
                let w = names[next(&mut seed) as usize % n].as_str();
                if !written.contains(&w) {
                    written.push(w);
                }
                g.pass(&format!("p{p}"), &reads, &[w]);
            }
            if let Some(o) = written.first()
                && next(&mut seed).is_multiple_of(2)
            {
                g.output(o);
            }
            let plan = g.plan().unwrap();
            let placed: Vec<(&String, &Placement)> = plan.placements.iter().collect();
            for (i, (a, pa)) in placed.iter().enumerate() {
                for (b, pb) in &placed[i + 1..] {
                    if pa.slot != pb.slot {
                        continue;
                    }
                    let overlap = pa.life.0 <= pb.life.1 && pb.life.0 <= pa.life.1;
                    assert!(
                        !overlap,
                        "{a} {:?} and {b} {:?} share slot {}",
                        pa.life, pb.life, pa.slot
                    );
                }
            }
            for t in &g.textures {
                if let Some(p) = plan.placements.get(&t.name) {
                    assert_eq!(
                        plan.slots[p.slot], t.format,
                        "{} took a slot of another format",
                        t.name
                    );
                }
            }
        }
    }
}
