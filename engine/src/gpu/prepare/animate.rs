//! A prepared scene moved through its animation: objects re-flattened or re-posed, instances
//! placed, the shutter's open, and what the GPU poses this frame.

use super::{PreparedScene, flatten, previous_vertices, rebased};
use crate::scene::Scene;

impl PreparedScene {
    /// Move animated objects to `time` seconds (an instant exposure): re-flatten them, rebuild
    /// the BVH and the per-object motion (`prev_from_current`) that the G-buffer's motion vectors
    /// read. Returns false (and changes nothing) for a static scene.
    pub fn animate(&mut self, scene: &Scene, time: f64) -> bool {
        self.expose(scene, time, None)
    }

    /// [`animate`] to `time`, the shutter's close, with the shutter open since scene time
    /// `open` (None: an instant). Objects whose transform differs between the two move linearly
    /// between them during the exposure (shaders/common/motion_blur.wgsl): the BVH is built over
    /// each triangle's box at both ends and `tris_open` holds the open ends. One rebuild, where
    /// anything changed; returns whether it did.
    ///
    /// [`animate`]: PreparedScene::animate
    pub fn expose(&mut self, scene: &Scene, time: f64, open: Option<f64>) -> bool {
        let on_gpu = self.gpu_posing && !self.rebuild_posing && self.posing_supported();
        let (moved, instances_moved, posed) = self.move_objects(scene, time, on_gpu);
        let swept = self.open_shutter(scene, open, on_gpu);
        // Instances move by their transforms alone: the world-space triangles are rebuilt only
        // where one of them moved or swept.
        let world = moved || (swept && !on_gpu && self.moving.iter().any(|&m| m));
        if world {
            self.assemble();
            if self.split.is_some() {
                self.posing_epoch += 1;
            }
            self.rebuild_posing = false;
        }
        if instances_moved || swept {
            self.place_instances();
        }
        self.geometry_moved = world;
        // The GPU poses again while anything moves, and once more after it stops, so that
        // the previous vertices catch up with the current ones.
        let pose = on_gpu && (posed || self.posed_last || swept);
        self.pose_request = pose.then_some((time, open.filter(|_| self.shutter_moves())));
        self.posed_last = on_gpu && (posed || swept);
        moved || instances_moved || swept || posed
    }

    /// Move every object to `time`: whether world-space triangles moved, whether instances
    /// did, and whether the moving part moved on the GPU (`on_gpu`: it is posed there and
    /// only its transforms are kept here).
    fn move_objects(&mut self, scene: &Scene, time: f64, on_gpu: bool) -> (bool, bool, bool) {
        let mut moved = false;
        let mut instances_moved = false;
        let mut posed = false;
        // The CPU flattening after GPU poses: the last one it made is stale.
        let stale = self.flat_stale && !on_gpu;
        let repose = self.pose_time != Some(time);
        for (i, o) in scene.objects.iter().enumerate().take(self.world.len()) {
            let now = o.transform_at(time);
            let before = self.world[i];
            self.prev_from_current[i] = if o.animation.is_some() {
                rebased(before, self.origin) * rebased(now, self.origin).inverse()
            } else {
                glam::Mat4::IDENTITY
            };
            let deforms = repose && o.deform.as_ref().is_some_and(|d| d.moves());
            if self.proto_of[i].is_some() {
                if now != before {
                    self.world[i] = now;
                    instances_moved = true;
                }
            } else if on_gpu && self.moving[i] {
                posed |= (o.animation.is_some() && now != before) || deforms;
                self.world[i] = now;
            } else if (o.animation.is_some() && now != before)
                || deforms
                || (stale && self.moving[i])
            {
                let mut f = flatten(scene, i, now, self.origin, &self.features, Some(time));
                if stale {
                    let t = self.pose_time.unwrap_or(time);
                    self.flat[i] = flatten(scene, i, before, self.origin, &self.features, Some(t));
                }
                if self.features.deforming {
                    f.prev = previous_vertices(&self.flat[i], &f);
                }
                self.flat[i] = f;
                self.world[i] = now;
                moved = true;
            } else if !self.flat[i].prev.is_empty() {
                // Still since the last call: no motion left to show.
                self.flat[i].prev.clear();
                moved = true;
            }
        }
        self.time = time;
        self.pose_time = Some(time);
        self.flat_stale = if on_gpu { self.flat_stale || posed } else { false };
        (moved, instances_moved, posed)
    }

    /// The per-object transforms from the close to `open` (empty while nothing moves during the
    /// shutter); whether they changed.
    fn open_shutter(&mut self, scene: &Scene, open: Option<f64>, on_gpu: bool) -> bool {
        let mut open_from_close = vec![];
        let mut deformed = false;
        // Deforming meshes posed on the GPU sweep there: every frame while the shutter is
        // open on them.
        let mut swept_on_gpu = false;
        if let Some(t) = open.filter(|_| self.features.animated) {
            let deforms = |o: &crate::scene::Object| o.deform.as_ref().is_some_and(|d| d.moves());
            let moving = scene.objects.iter().enumerate().take(self.world.len()).any(|(i, o)| {
                (o.animation.is_some() && o.transform_at(t) != self.world[i])
                    || (deforms(o) && t != self.time)
            });
            if moving {
                swept_on_gpu = on_gpu;
                open_from_close = scene
                    .objects
                    .iter()
                    .enumerate()
                    .take(self.world.len())
                    .map(|(i, o)| {
                        rebased(o.transform_at(t), self.origin)
                            * rebased(self.world[i], self.origin).inverse()
                    })
                    .collect();
                // A deforming mesh's vertices at the open, triangle by triangle: no transform
                // takes its close to its open.
                for (i, o) in scene.objects.iter().enumerate().take(self.world.len()) {
                    if deforms(o) && !on_gpu {
                        let at_open = flatten(
                            scene,
                            i,
                            o.transform_at(t),
                            self.origin,
                            &self.features,
                            Some(t),
                        );
                        self.flat[i].open = previous_vertices(&at_open, &self.flat[i]);
                        deformed = true;
                    }
                }
            }
        }
        if !deformed {
            for f in &mut self.flat {
                f.open.clear();
            }
        }
        let changed = deformed || swept_on_gpu || open_from_close != self.open_from_close;
        self.open_from_close = open_from_close;
        changed
    }
}
