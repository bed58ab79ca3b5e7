//! vkhair's part of the viewer: the scene the command line names, the
//! simulation at a fixed 60 Hz through `FixedStepDriver`, the renderer drawing
//! between the last two states by the driver's alpha, the GPU profiler, and the
//! run-time controls the keys and the overlay change.

use std::path::Path;

use ash::vk;
use glam::{Mat4, Vec3};
use vkhair::character::{Character, HairRig};
use vkhair::config::Config;
use vkhair::groom::binding::RootBinding;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes;
use vkhair::groom::tfx::TfxFile;
use vkhair::groom::Groom;
use vkhair::render::{Camera, Light, RenderTarget, Renderer, ShadingMode, ShadowParams, Transparency};
use vkhair::sim::{motion, Collider, FixedStepDriver, HairSim, KeyHairs, RigidTransform, SimState};
use vkhair::{ash, GpuContext, GpuProfiler, ProfileReport};

use crate::crowd::CrowdScene;
use crate::host::BoxError;
use crate::skin::{GpuSkin, MAX_STEPS, SKINNED_STRIDE};
use crate::Args;

/// Frames the host keeps in flight (vkhair's `RenderParams::frames_in_flight`
/// is set to match).
pub const FRAMES_IN_FLIGHT: u32 = 2;

/// The groom, what it collides with and the head the host draws.
pub struct Scene {
    pub groom: Groom,
    /// The head the host draws and, with `mesh_collider`, the strands collide
    /// with (a `--gltf` character's: its head's region, in its head's frame).
    pub head: TriMesh,
    /// Whether the strands collide with `head` (an --obj mesh).
    pub mesh_collider: bool,
    /// Sphere and capsule colliders (the thesis scene's).
    pub colliders: Vec<Collider>,
    pub center: Vec3,
    pub radius: f32,
    /// Height of the floor the host draws.
    pub floor_y: f32,
    /// The `--gltf` character, skinned by the host and carrying the hair.
    pub rig: Option<HairRig>,
    /// `--crowd`: members in the crowd (the thesis head, and the character
    /// when there is one, instead of `groom` alone).
    pub crowd: Option<usize>,
}

impl Scene {
    /// The thesis scene, or `--input` (`.hair` or `.tfx`, repaired when it has
    /// defects) with `--obj` scaled by `--scale`.
    pub fn load(args: &Args) -> Result<Scene, BoxError> {
        if let Some(path) = &args.gltf {
            return Scene::character(path, args);
        }
        let (groom, head, mesh_collider, colliders) = match &args.input {
            None => {
                let head = TriMesh::uv_sphere(scenes::THESIS_HEAD_CENTER, scenes::THESIS_HEAD_RADIUS * 0.97, 24, 32)?;
                (scenes::thesis()?, head, false, motion::thesis_colliders())
            }
            Some(path) => {
                let groom = read_groom(path)?.scaled(args.scale)?.resampled(16)?;
                let head = match &args.obj {
                    Some(obj) => {
                        let m = TriMesh::load_obj(obj)?;
                        TriMesh::new(m.positions.iter().map(|p| *p * args.scale).collect(), m.triangles)?
                    }
                    None => {
                        let (lo, hi) = groom.bounds();
                        TriMesh::uv_sphere(0.5 * (lo + hi), 0.25 * (hi - lo).max_element(), 16, 24)?
                    }
                };
                (groom, head, args.obj.is_some(), Vec::new())
            }
        };
        let bounds = vkhair::groom::bounding_box(groom.positions().iter().chain(&head.positions).copied());
        let (center, radius) = vkhair::groom::bounding_sphere(bounds);
        let lo = bounds.0;
        if !(center.is_finite() && radius.is_finite() && radius > 0.0) {
            return Err(format!("the groom and mesh span no finite volume (radius {radius})").into());
        }
        let floor_y = lo.y - 0.2 * radius;
        Ok(Scene {
            groom,
            head,
            mesh_collider,
            colliders,
            center,
            radius,
            floor_y,
            rig: None,
            crowd: args.crowd.map(|n| n as usize),
        })
    }

    /// `--gltf`: key hairs grown on the character's head, its head's region
    /// as the mesh collider, framed on the hair and the body near the head.
    fn character(path: &Path, args: &Args) -> Result<Scene, BoxError> {
        let character = Character::load(path)?;
        let rig = HairRig::new(character, args.animation.as_deref(), args.head_joint.as_deref())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let (groom, head) = rig.grow(16)?;
        let body = rig.body_at(0.0)?;
        let (center, radius) = rig.framing(&groom, &body);
        if !(center.is_finite() && radius.is_finite() && radius > 0.0) {
            return Err(format!("{}: the hair and head span no finite volume", path.display()).into());
        }
        let floor_y = body.positions.iter().map(|p| p.y).fold(f32::MAX, f32::min);
        let crowd = args.crowd.map(|n| n as usize);
        // In a crowd the host draws the thesis heads' spheres beside the character's body.
        let head = match crowd {
            Some(_) => TriMesh::uv_sphere(scenes::THESIS_HEAD_CENTER, scenes::THESIS_HEAD_RADIUS * 0.97, 24, 32)?,
            None => head,
        };
        let mesh_collider = crowd.is_none();
        Ok(Scene { groom, head, mesh_collider, colliders: Vec::new(), center, radius, floor_y, rig: Some(rig), crowd })
    }
}

fn read_groom(path: &Path) -> Result<Groom, BoxError> {
    let tfx = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("tfx"));
    let (groom, repairs) = if tfx {
        let (f, r) = TfxFile::open_repairing(path)?;
        (f.groom, r)
    } else {
        let (f, r) = HairFile::open_repairing(path)?;
        (f.groom, r)
    };
    if !repairs.is_empty() {
        eprintln!("viewer: warning: {}: {repairs}", path.display());
    }
    Ok(groom)
}

/// The simulation: one groom's, or a crowd's.
enum Sim {
    One(Box<HairSim>),
    /// The crowd and its members' time, seconds.
    Crowd(Box<CrowdScene>, f32),
}

/// The simulation, the renderer and the controls.
pub struct Hair {
    sim: Sim,
    pub renderer: Renderer,
    pub profiler: GpuProfiler,
    pub config: Config,
    pub shadows: ShadowParams,
    pub shadows_on: bool,
    /// Latest per-pass GPU timings.
    pub report: Option<ProfileReport>,
    pub paused: bool,
    /// Steps still to run while paused (the single-step key).
    pub pending_steps: u32,
    /// Whether the head follows the reference motion (else it stays still).
    pub moving: bool,
    pub steps_done: u64,
    driver: FixedStepDriver,
    initial: SimState,
    alpha: f32,
    /// The `--gltf` character the hair rides.
    rig: Option<Riding>,
}

/// A `--gltf` character in the simulation.
struct Riding {
    rig: HairRig,
    /// The animation's time at the latest step, seconds.
    time: f32,
    /// Bytes of one step's slot of the host's skinned vertices.
    slot_bytes: u64,
    /// Each key hair's root on the character's mesh (bind pose).
    bound: Vec<RootBinding>,
}

impl Hair {
    /// With a `--gltf` character, `skin` is the host's skinning pass whose
    /// skinned vertices the key hairs' roots ride.
    pub fn new(ctx: &GpuContext, scene: &Scene, config: Config, skin: Option<&GpuSkin>) -> Result<Hair, BoxError> {
        let mut config = config;
        config.render.frames_in_flight = FRAMES_IN_FLIGHT;
        if let Some(count) = scene.crowd {
            let crowd = CrowdScene::new(ctx, count, scene.rig.as_ref().map(|r| (r, &scene.groom)), &config.sim)?;
            if config.lights.is_empty() {
                config.lights = Light::thesis_rig(crowd.center, crowd.radius).to_vec();
            }
            config.render.hairs_per_key = crowd_hairs_per_key(ctx, &crowd, &config.render);
            let initial = crowd.crowd.sim().read_state()?;
            // Each member's hair is about the thesis head's depth: the maps' layers as for it.
            return Self::with_sim(ctx, Sim::Crowd(Box::new(crowd), 0.0), config, initial, (None, 1.0));
        }
        if config.lights.is_empty() {
            config.lights = Light::thesis_rig(scene.center, scene.radius).to_vec();
        }
        let head = scene.rig.as_ref().map_or(RigidTransform::default(), |r| r.head_at(0.0));
        let mut sim = HairSim::new(ctx, &scene.groom, &config.sim, &head)?;
        sim.set_colliders(&scene.colliders)?;
        match &scene.rig {
            // The character's body near the head, following its bones.
            Some(r) if scene.mesh_collider => {
                let (body, skin) = r.body_region()?;
                sim.set_skinned_mesh(&body, &skin, &r.scalp_bones(0.0), &config.mesh_collider)?;
            }
            _ if scene.mesh_collider => sim.set_mesh(Some(&scene.head), &config.mesh_collider)?,
            _ => {}
        }
        let mut rig = None;
        if let (Some(r), Some(skin)) = (&scene.rig, skin) {
            // The host's skinned vertices: slot k holds step k's of a frame.
            let (buffer, size, slot) = skin.skinned();
            let vertex_count = u32::try_from(r.character.positions.len())?;
            let format = vk::Format::R32G32B32A32_SFLOAT;
            let source = vkhair::sim::scalp::ScalpSource { buffer, size, stride: SKINNED_STRIDE, format, vertex_count };
            let scalp = vkhair::sim::scalp::Scalp { skin: Vec::new(), ..r.scalp()? };
            // SAFETY: the buffer is the host device's, with storage usage and
            // `size` bytes bound to memory; the viewer destroys it after vkhair
            // (`Running::shut_down`); the skinning pass writes it in the same
            // queue before the steps that read it, behind a barrier after the
            // previous frame's steps.
            unsafe { sim.bind_scalp_source(&scalp, &source) }?;
            sim.set_body_colliders(&r.colliders_at(0.0))?;
            let bound = r.bind_roots(&scene.groom, 1e-3)?;
            rig = Some(Riding { rig: r.clone(), time: 0.0, slot_bytes: slot, bound });
        }
        let initial = sim.read_state()?;
        Self::with_sim(ctx, Sim::One(Box::new(sim)), config, initial, (rig, scene.radius / 0.465))
    }

    /// The renderer, profiler and controls around `sim`.
    fn with_sim(
        ctx: &GpuContext,
        sim: Sim,
        config: Config,
        initial: SimState,
        (rig, k): (Option<Riding>, f32),
    ) -> Result<Hair, BoxError> {
        let mut renderer = Renderer::new(ctx, key_hairs(&sim), &config.render)?;
        renderer.set_lights(&config.lights)?;
        renderer.set_material(&config.material)?;
        let layers = ShadowParams::default().layers.map(|l| l * k);
        let shadows = ShadowParams { casters: vec![0.into(), 1.into()], layers, ..ShadowParams::default() };
        renderer.set_shadows(key_hairs(&sim), &shadows)?;
        let moving = rig.is_some() || matches!(&sim, Sim::Crowd(c, _) if c.has_character());
        let profiler = GpuProfiler::new(ctx, FRAMES_IN_FLIGHT, 64)?;
        let driver = FixedStepDriver::new(f64::from(config.sim.dt), 2)?;
        Ok(Hair {
            sim,
            renderer,
            profiler,
            config,
            shadows,
            shadows_on: true,
            report: None,
            paused: false,
            pending_steps: 0,
            moving,
            steps_done: 0,
            driver,
            initial,
            alpha: 1.0,
            rig,
        })
    }

    /// Records frame `frame`: the steps due after `frame_time` seconds, the
    /// geometry between the last two states, the shadow maps.
    ///
    /// # Safety
    /// `cmd` records for the context's queue, outside rendering; the frame
    /// `frame − FRAMES_IN_FLIGHT` has completed.
    pub unsafe fn record_simulation(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: u64,
        frame_time: f64,
        camera: &Camera,
        skin: Option<&mut GpuSkin>,
    ) -> Result<(), BoxError> {
        // SAFETY: guaranteed by the caller.
        unsafe {
            if let Some(report) = self.profiler.begin_frame(cmd, frame) {
                self.report = Some(report);
            }
            let steps = if self.paused {
                self.alpha = 1.0;
                let now = self.pending_steps.min(MAX_STEPS);
                self.pending_steps -= now;
                now
            } else {
                let plan = self.driver.advance(frame_time);
                self.alpha = plan.alpha;
                plan.steps
            };
            match (skin, &mut self.sim) {
                (Some(skin), Sim::One(_)) if self.rig.is_some() => {
                    self.record_character_steps(cmd, frame, steps, skin)?
                }
                (skin, Sim::Crowd(crowd, time)) => {
                    let dt = self.config.sim.dt;
                    for _ in 0..steps {
                        self.steps_done += 1;
                        if self.moving {
                            *time += dt;
                        }
                        crowd.crowd.set_poses(&crowd.poses(*time, self.moving))?;
                        crowd.crowd.record_step(cmd, Some(&mut self.profiler))?;
                    }
                    if let (Some(skin), Some(bones)) =
                        (skin, crowd.drawn_bones(*time - dt * (1.0 - self.alpha), self.moving))
                    {
                        // The character's body as shown: one skinning, drawn at every place.
                        let frame_slot = (frame % u64::from(FRAMES_IN_FLIGHT)) as u32;
                        skin.write_bones(frame_slot, &[], &bones)?;
                        skin.record(cmd, frame_slot, 0);
                    }
                }
                (_, Sim::One(sim)) => {
                    for _ in 0..steps {
                        self.steps_done += 1;
                        let t = self.steps_done as f32 * self.config.sim.dt;
                        let head = if self.moving { motion::reference_motion(t) } else { RigidTransform::default() };
                        sim.record_step(cmd, &head, Some(&mut self.profiler))?;
                    }
                }
            }
            let hairs = key_hairs(&self.sim).blended(self.alpha)?;
            self.renderer.record_prepare(cmd, hairs, Some(camera), Some(&mut self.profiler))?;
            self.renderer.record_shadows(cmd, hairs, Some(&mut self.profiler))?;
        }
        Ok(())
    }

    /// The steps of [`Hair::record_simulation`] with a character: the host's
    /// skinning pass for each step's pose and the frame's shown pose, then the
    /// steps, each reading its slot of skinned vertices, with the character's
    /// capsules as body colliders and its head joint as the head; the
    /// animation plays while `moving`.
    ///
    /// # Safety
    /// As for [`Hair::record_simulation`].
    unsafe fn record_character_steps(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: u64,
        steps: u32,
        skin: &mut GpuSkin,
    ) -> Result<(), BoxError> {
        let (Some(Riding { rig, time, slot_bytes, .. }), Sim::One(sim)) = (&mut self.rig, &mut self.sim) else {
            return Ok(());
        };
        let dt = if self.moving { self.config.sim.dt } else { 0.0 };
        let times: Vec<f32> = (1..=steps).map(|k| *time + dt * k as f32).collect();
        *time += dt * steps as f32;
        let shown = *time - dt * (1.0 - self.alpha);
        let bones: Vec<Vec<glam::Mat4>> = times.iter().map(|&t| rig.pose(t).skin).collect();
        let frame_slot = (frame % u64::from(FRAMES_IN_FLIGHT)) as u32;
        skin.write_bones(frame_slot, &bones, &rig.pose(shown).skin)?;
        // SAFETY: guaranteed by the caller.
        unsafe {
            skin.record(cmd, frame_slot, steps);
            for (k, &t) in times.iter().enumerate() {
                self.steps_done += 1;
                sim.set_scalp_offset(k as u64 * *slot_bytes)?;
                sim.set_body_colliders(&rig.colliders_at(t))?;
                sim.set_mesh_bones(&rig.scalp_bones(t))?;
                sim.record_step(cmd, &rig.head_at(t), Some(&mut self.profiler))?;
            }
        }
        Ok(())
    }

    /// With a crowd: where the host draws the thesis heads' spheres and the
    /// character's bodies as shown this frame.
    pub fn crowd_drawn(&self) -> Option<(Vec<Mat4>, Vec<Mat4>)> {
        let Sim::Crowd(crowd, time) = &self.sim else { return None };
        Some(crowd.drawn(*time - self.config.sim.dt * (1.0 - self.alpha), self.moving))
    }

    /// Members and the sphere (centre, radius) they stand in, with a crowd.
    pub fn crowd_framing(&self) -> Option<(usize, Vec3, f32)> {
        let Sim::Crowd(crowd, _) = &self.sim else { return None };
        Some((crowd.members(), crowd.center, crowd.radius))
    }

    /// Records the hair into the host's `target`.
    ///
    /// # Safety
    /// As for [`Hair::record_simulation`], recorded after it.
    pub unsafe fn record_draw(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: u64,
        target: &RenderTarget,
        camera: &Camera,
    ) -> Result<(), BoxError> {
        // SAFETY: guaranteed by the caller.
        unsafe { self.renderer.record_draw(cmd, frame, target, camera, Some(&mut self.profiler)) }?;
        Ok(())
    }

    /// Back to the first state (the device must be idle: the state is uploaded).
    pub fn reset(&mut self) -> Result<(), BoxError> {
        match (&mut self.rig, &mut self.sim) {
            (_, Sim::Crowd(crowd, time)) => {
                // Every member back to its first pose, its hair at rest there.
                *time = 0.0;
                crowd.crowd.set_poses(&crowd.poses(0.0, false))?;
                crowd.crowd.reset();
            }
            (Some(Riding { rig, time, .. }), Sim::One(sim)) => {
                // The rest pose where the animation starts again: the hair and its
                // skinned roots start there together (no sweep from the old pose).
                *time = 0.0;
                sim.teleport(&rig.head_at(0.0))?;
                sim.set_body_colliders(&rig.colliders_at(0.0))?;
                sim.set_mesh_bones(&rig.scalp_bones(0.0))?;
                sim.reset();
            }
            (None, Sim::One(sim)) => sim.write_state(&self.initial)?,
        }
        self.driver = FixedStepDriver::new(f64::from(self.config.sim.dt), 2)?;
        self.steps_done = 0;
        // The hair jumps back: no motion across the jump.
        self.renderer.reset_motion();
        Ok(())
    }

    /// With a character: the animation's time of the latest step and the
    /// largest distance of a key hair's root from its point on the character's
    /// mesh skinned on the CPU at that time (the device must be idle).
    pub fn root_error(&self) -> Result<Option<(f32, f32)>, BoxError> {
        let (Some(Riding { rig, time, bound, .. }), Sim::One(sim)) = (&self.rig, &self.sim) else { return Ok(None) };
        let skinned = rig.character.skin(&rig.pose(*time));
        Ok(Some((*time, rig.root_error(&sim.read_state()?, bound, &skinned))))
    }

    /// Applies `config.sim`, `config.render` and `config.material` after a change.
    pub fn apply(&mut self) -> Result<(), BoxError> {
        match &mut self.sim {
            Sim::One(sim) => sim.set_params(&self.config.sim)?,
            Sim::Crowd(crowd, _) => crowd.crowd.set_params(&self.config.sim)?,
        }
        self.renderer.set_params(&self.config.render)?;
        self.renderer.set_material(&self.config.material)?;
        Ok(())
    }

    /// Shadows on or off, or a new map resolution (the device must be idle).
    pub fn apply_shadows(&mut self) -> Result<(), BoxError> {
        let params = if self.shadows_on {
            self.shadows.clone()
        } else {
            ShadowParams { casters: Vec::new(), ..self.shadows.clone() }
        };
        self.renderer.set_shadows(key_hairs(&self.sim), &params)?;
        Ok(())
    }

    pub fn toggle_lod(&mut self) -> Result<(), BoxError> {
        self.config.render.lod.enabled = !self.config.render.lod.enabled;
        self.apply()
    }

    pub fn toggle_supersampling(&mut self) -> Result<(), BoxError> {
        self.config.render.supersampling = !self.config.render.supersampling;
        self.apply()
    }

    pub fn next_shading(&mut self) -> Result<(), BoxError> {
        self.config.material.shading = match self.config.material.shading {
            ShadingMode::KajiyaKay => ShadingMode::Marschner,
            _ => ShadingMode::KajiyaKay,
        };
        self.apply()
    }

    pub fn next_transparency(&mut self) -> Result<(), BoxError> {
        self.config.render.transparency = match self.config.render.transparency {
            Transparency::Off => Transparency::Fast,
            Transparency::Fast => Transparency::Exact,
            Transparency::Exact => Transparency::Off,
        };
        self.apply()
    }

    /// A line saying what is on, for the overlay and the log.
    pub fn status(&self) -> String {
        let r = &self.config.render;
        format!(
            "LOD {} · shadows {} · SSAA {} · {:?} · transparency {:?}{}",
            on(r.lod.enabled),
            on(self.shadows_on),
            on(r.supersampling),
            self.config.material.shading,
            r.transparency,
            if self.paused { " · paused" } else { "" }
        )
    }
}

/// The hairs per key hair a crowd is drawn with: the configuration's, or as
/// many as the device's storage range holds for every member (one buffer
/// holds the interpolated hairs of the whole crowd).
fn crowd_hairs_per_key(ctx: &GpuContext, crowd: &CrowdScene, render: &vkhair::render::RenderParams) -> u32 {
    let state = crowd.crowd.sim();
    let (strands, points) = (state.key_hairs().size().0 as u64, state.key_hairs().size().1 as u64);
    let vertices = (points - 1) * u64::from(render.smoothing_level) + 1;
    let fits = u64::from(ctx.info().max_storage_buffer_range) / (strands * vertices * 16).max(1);
    let hairs = render.hairs_per_key.min(u32::try_from(fits).unwrap_or(u32::MAX)).max(1);
    if hairs < render.hairs_per_key {
        println!(
            "viewer: {} hairs per key hair for the crowd's {strands} key hairs ({} configured: past the device's storage range)",
            hairs, render.hairs_per_key
        );
    }
    hairs
}

/// The key hairs the renderer draws: one groom's, or the crowd's with its bounds.
fn key_hairs(sim: &Sim) -> KeyHairs<'_> {
    match sim {
        Sim::One(sim) => sim.key_hairs(),
        Sim::Crowd(crowd, _) => crowd.crowd.key_hairs(),
    }
}

fn on(b: bool) -> &'static str {
    if b {
        "on"
    } else {
        "off"
    }
}
