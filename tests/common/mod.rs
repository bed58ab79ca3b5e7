//! Shared by the integration tests: a validated headless context.

use glam::Vec3;
use vkhair::groom::grow::{grow, GrowParams};
use vkhair::groom::scenes;
use vkhair::sim::{RigidTransform, SimState};
use vkhair::{ContextOptions, GpuContext, Groom, ValidationLog};

/// The camera of the small scenes: the thesis head from the front, `distance`
/// metres away, slightly above and looking a little down, for a `w` × `h` image.
#[allow(dead_code, reason = "not every test file draws the thesis head")]
pub fn front_camera(distance: f32, (w, h): (u32, u32)) -> vkhair::render::Camera {
    let center = scenes::THESIS_HEAD_CENTER;
    vkhair::render::Camera::look_at(
        center + Vec3::new(0.0, -0.05, distance),
        center - Vec3::new(0.0, 0.1, 0.0),
        0.7,
        w as f32 / h as f32,
        0.05,
        10.0,
    )
    .expect("camera")
}

/// Key hairs grown on the `thesis` scalp: `strands` × `points`, 0.35 m long with
/// segments 1.5× longer toward the tip, from `seed`.
#[allow(dead_code, reason = "not every test file grows its own groom")]
pub fn grown_groom(strands: usize, points: usize, seed: u64) -> Groom {
    let p = GrowParams {
        strands,
        points_per_strand: points,
        length: 0.35,
        segment_growth: 1.5,
        seed,
        ..GrowParams::default()
    };
    grow(&scenes::thesis_scalp(), &p).expect("groom")
}

/// The raw bits of every component of a state's positions and velocities: equal
/// bits, not merely equal values (−0 and +0, NaN payloads differ).
#[allow(dead_code, reason = "not every test file compares states")]
pub fn bits(state: &SimState) -> Vec<u32> {
    state.positions.iter().chain(&state.velocities).flat_map(|v| v.to_array().map(f32::to_bits)).collect()
}

/// Whether `ctx` runs on lavapipe, where the README promises that the GPU
/// simulation and its CPU reference agree bit for bit (other drivers may round
/// `sqrt` and division differently).
#[allow(dead_code, reason = "not every test file compares with the reference")]
pub fn on_lavapipe(ctx: &GpuContext) -> bool {
    ctx.info().name.contains("llvmpipe")
}

/// How far one step of the GPU may end from the CPU reference's from the same
/// state on a device other than lavapipe, in |Δx| + dt·|Δv|: 50 µm. Vulkan lets
/// a driver round `sqrt` and division to 2.5–3 ULP where the reference rounds
/// exactly, and a step chains them through every iteration; after a 10 m
/// teleport one ULP of a coordinate is 1 µm. On an H100 (NVIDIA 580.159) most
/// runs stay under 10 µm a step; two exceed this (a level of detail with
/// density friction, 56 µm; after a 10 m cut, 0.24 mm) and are not explained
/// yet.
pub const OTHER_DEVICE_STEP_TOLERANCE_M: f32 = 5e-5;

/// The GPU's state `gpu` against the CPU reference `cpu` after the same step:
/// bit for bit on lavapipe; on another device within one step's
/// [`OTHER_DEVICE_STEP_TOLERANCE_M`], after which the reference continues from
/// the GPU's state, so that every step is compared from the same start: hair
/// in motion grows any difference without bound over many steps (on an H100:
/// millimetres after 20 to 200 steps).
#[allow(dead_code, reason = "not every test file compares with the reference")]
pub fn agree(ctx: &GpuContext, gpu: &SimState, cpu: &mut vkhair::sim::CpuHairSim, dt: f32, what: &str) {
    if on_lavapipe(ctx) {
        assert!(bits(gpu) == bits(cpu.state()), "{what}: GPU and CPU not bit for bit on lavapipe");
        return;
    }
    let apart = gpu.step_difference(cpu.state(), dt);
    assert!(apart <= OTHER_DEVICE_STEP_TOLERANCE_M, "{what}: GPU and CPU one step apart by {apart} m");
    cpu.write_state(gpu).expect("the reference takes the GPU's state");
}

/// `steps` steps of `gpu` and `cpu` with the head at `head(i)`: on lavapipe in
/// one submission, then compared bit for bit; elsewhere step by step, each
/// compared by [`agree`]. Returns the GPU's state.
#[allow(dead_code, reason = "not every test file compares with the reference")]
pub fn run_both(
    ctx: &GpuContext,
    (gpu, cpu): (&mut vkhair::sim::HairSim, &mut vkhair::sim::CpuHairSim),
    steps: std::ops::Range<usize>,
    head: impl Fn(usize) -> vkhair::sim::RigidTransform,
    what: &str,
) -> SimState {
    let dt = gpu.params().dt;
    if on_lavapipe(ctx) {
        let first = steps.start;
        gpu.run(steps.len(), |i| head(first + i), None).expect("gpu run");
        for i in steps {
            cpu.step(&head(i)).expect("cpu step");
        }
        let state = gpu.read_state().expect("readback");
        agree(ctx, &state, cpu, dt, what);
        return state;
    }
    for i in steps {
        gpu.run(1, |_| head(i), None).expect("gpu step");
        cpu.step(&head(i)).expect("cpu step");
        agree(ctx, &gpu.read_state().expect("readback"), cpu, dt, &format!("{what}, step {i}"));
    }
    gpu.read_state().expect("readback")
}

/// A headless context with validation and synchronization validation; dropping it
/// fails the test on any validation message (objects leaked at teardown included).
#[allow(dead_code, reason = "test files with their own contexts use only the helpers")]
pub struct Gpu {
    ctx: Option<GpuContext>,
    log: ValidationLog,
}

#[allow(dead_code, reason = "as above")]
impl Gpu {
    pub fn new() -> Gpu {
        let log = ValidationLog::new();
        let ctx = GpuContext::headless(&ContextOptions::validated(&log)).expect("headless context with validation");
        Gpu { ctx: Some(ctx), log }
    }

    pub fn ctx(&self) -> &GpuContext {
        self.ctx.as_ref().expect("alive")
    }

    /// The context and its log, for a test that drops the context itself and
    /// then checks the log (the helper checks only what happened before).
    pub fn into_parts(mut self) -> (GpuContext, ValidationLog) {
        let ctx = self.ctx.take().expect("alive");
        (ctx, self.log.clone())
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        drop(self.ctx.take());
        if !std::thread::panicking() {
            self.log.assert_clean();
        }
    }
}

/// A mohawk: `strands` straight strands of 10 cm standing out radially from a
/// band of roots over the top of a 10 cm head sphere centred at the origin.
#[allow(dead_code, reason = "not every test file uses every groom")]
pub fn mohawk(strands: usize, points: usize) -> Groom {
    let strands: Vec<Vec<Vec3>> = (0..strands)
        .map(|s| {
            let along = s as f32 / (strands - 1) as f32;
            let angle = (along - 0.5) * 2.0; // ±57° from the top, in the y-z plane
            let side = ((s % 5) as f32 - 2.0) * 0.006;
            let normal = Vec3::new(side * 3.0, angle.cos(), angle.sin()).normalize();
            let root = normal * 0.1;
            (0..points).map(|i| root + normal * (0.1 * i as f32 / (points - 1) as f32)).collect()
        })
        .collect();
    Groom::from_strands(&strands).expect("mohawk")
}

/// Helix curls: `strands` strands of 16 points standing out from the top of the
/// head sphere, each a helix of 1 cm radius and 2.5 cm pitch around its normal,
/// about 10 cm long along the axis.
#[allow(dead_code, reason = "not every test file uses every groom")]
pub fn curls(strands: usize) -> Groom {
    let strands: Vec<Vec<Vec3>> = (0..strands)
        .map(|s| {
            let a = s as f32 * 2.399; // golden-angle spiral over a cap
            let r = 0.6 * ((s as f32 + 0.5) / strands as f32).sqrt();
            let normal = Vec3::new(r * a.cos(), 1.0, r * a.sin()).normalize();
            let (u, v) = normal.any_orthonormal_pair();
            (0..16)
                .map(|i| {
                    let t = i as f32 / 15.0;
                    let turn = std::f32::consts::TAU * 4.0 * t;
                    let radius = 0.01 * t.min(0.1) * 10.0; // grows out of the root
                    normal * (0.1 + 0.1 * t) + (u * turn.cos() + v * turn.sin() - u) * radius
                })
                .collect()
        })
        .collect();
    Groom::from_strands(&strands).expect("curls")
}

/// Per strand, the largest distance of a tip from where the rest shape carried
/// rigidly by the head puts it, as a fraction of the strand's rest length,
/// sorted.
#[allow(dead_code, reason = "not every test file uses every groom")]
pub fn tip_drift_of(state: &SimState, head: &RigidTransform) -> Vec<f32> {
    let m = head.matrix();
    let mut drift: Vec<f32> = (0..state.strands)
        .map(|s| {
            let tip = s * state.points + state.points - 1;
            let length = state.rest_strand_length(s);
            (state.positions[tip].truncate() - m.transform_point3(state.rest[tip].truncate())).length() / length
        })
        .collect();
    drift.sort_by(f32::total_cmp);
    drift
}

#[allow(dead_code, reason = "not every test file uses every groom")]
pub fn p(drift: &[f32], percent: usize) -> f32 {
    drift[(drift.len() - 1) * percent / 100]
}

/// Frame indices for `Renderer::record_draw`: one per drawn test frame (every
/// test frame is submitted and waited for).
#[allow(dead_code, reason = "not every test file draws")]
pub fn next_frame() -> u64 {
    static FRAME: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    FRAME.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// What the host draws in a test frame around the hair: its clear colour, and
/// green meshes (lit from the camera's side) before and after the hair.
#[allow(dead_code, reason = "not every test file draws")]
pub struct HostFrame<'a> {
    pub clear: Vec3,
    pub before: Option<&'a vkhair::headless::MeshDrawer>,
    pub after: Option<&'a vkhair::headless::MeshDrawer>,
}

/// Records, submits and waits for one frame — the hairs prepared for `camera`,
/// their shadows, the host's clear and `host`'s meshes around the hair's draw
/// into `offscreen` (the meshes with the camera's jittered projection).
#[allow(dead_code, reason = "not every test file draws")]
pub fn record_frame(
    gpu: &Gpu,
    (sim, renderer): (&vkhair::sim::HairSim, &mut vkhair::render::Renderer),
    offscreen: &vkhair::headless::Offscreen,
    camera: &vkhair::render::Camera,
    host: &HostFrame<'_>,
) {
    use vkhair::headless::Submit;
    let view_proj = camera.jittered_projection(offscreen.size()) * camera.view;
    let mesh = |cmd, m: Option<&vkhair::headless::MeshDrawer>| {
        if let Some(m) = m {
            // SAFETY: a recording command buffer of the context's device.
            unsafe {
                m.record(cmd, &offscreen.target(), view_proj, (glam::Quat::IDENTITY, Vec3::ZERO), Vec3::Y, Vec3::NEG_Z)
            };
        }
    };
    let mut result = Ok(());
    gpu.ctx()
        .run_commands("test frame", |cmd| {
            // SAFETY: a recording command buffer of the context's device.
            result = unsafe {
                renderer.record_prepare(cmd, sim, Some(camera), None).and_then(|_| {
                    // Without casters this only marks every light unshadowed.
                    renderer.record_shadows(cmd, sim, None)?;
                    offscreen.record_clear(cmd, host.clear);
                    mesh(cmd, host.before);
                    renderer.record_draw(cmd, next_frame(), &offscreen.target(), camera, None)?;
                    mesh(cmd, host.after);
                    Ok(())
                })
            };
        })
        .expect("submit");
    result.expect("record");
}

/// [`record_frame`], then the target's RGBA8 rows.
#[allow(dead_code, reason = "not every test file draws")]
pub fn draw_frame(
    gpu: &Gpu,
    (sim, renderer): (&vkhair::sim::HairSim, &mut vkhair::render::Renderer),
    offscreen: &vkhair::headless::Offscreen,
    camera: &vkhair::render::Camera,
    host: &HostFrame<'_>,
) -> Vec<u8> {
    record_frame(gpu, (sim, renderer), offscreen, camera, host);
    offscreen.read_rgba8().expect("readback")
}

/// Makes a FIFO at `path` (no process writes it: a reader of it waits forever).
pub fn mkfifo(path: &std::path::Path) {
    let c = std::ffi::CString::new(path.to_str().expect("utf-8")).expect("path");
    // SAFETY: mkfifo with a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo {}", path.display());
}
