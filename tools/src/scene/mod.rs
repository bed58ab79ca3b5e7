//! The scene `render` draws and `bench` measures: the groom (the `thesis`
//! scene, or the user's `--input` with its `--obj` mesh), its bounds, the
//! camera that frames it, and ([`mod@parameters`]) the parameters and renderer
//! of the flags.

mod character;
mod parameters;

use std::path::PathBuf;

use glam::Vec3;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes::{self, THESIS_BOUNDING_RADIUS, THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS};
use vkhair::groom::Groom;
use vkhair::render::Camera;
use vkhair::sim::{motion, Collider};

pub use character::{load as load_character, CharacterScene};
pub use parameters::{bind_followers, make_renderer, parameters};

use crate::args::input::{Dense, InputArgs, Scaled};
use crate::args::scene::SceneArgs;
use crate::output::Error;

/// A loaded scene.
pub struct Scene {
    /// The key hairs simulated (a dense groom's guides).
    pub groom: Groom,
    /// A dense groom drawn as followers of the key hairs.
    pub dense: Option<Dense>,
    pub colliders: Vec<Collider>,
    pub head_mesh: TriMesh,
    pub center: Vec3,
    /// Radius of the sphere around the groom and the mesh (their units).
    pub radius: f32,
    /// Root and tip thickness the groom file gives (its units after --scale).
    pub thickness: Option<(f32, f32)>,
    /// Where the head turns about.
    pub pivot: Vec3,
    /// The credit line a picture of it must carry.
    pub credit: Option<&'static str>,
    /// The `--gltf` character, whose head joint moves the head (the groom,
    /// colliders and head mesh above are in its frame).
    pub character: Option<CharacterScene>,
    /// The head at the start.
    pub start_head: vkhair::sim::RigidTransform,
    /// Where the camera looks from, seen from the centre (+Z, or where the
    /// character faces).
    pub view_dir: Vec3,
}

/// The credit line of the shared character.
const MANNEQUIN_CREDIT: &str = "\"Mannequiny\" by Luciano Muñoz / GDQuest and contributors (CC BY 4.0)";

/// The smallest bounding radius of a scene the tool draws, in the groom's
/// units after `--scale` (a hair's width is a thousandth of a head's size: a
/// smaller scene puts it below f32's reach in the derived widths and
/// distances).
const MIN_SCENE_RADIUS: f32 = 1e-4;
/// The largest bounding radius of a scene the tool draws (1e4 units: a head of
/// hair in millimetres is 300).
const MAX_SCENE_RADIUS: f32 = 1e4;

/// The scene of `a`'s flags.
pub fn load(a: &SceneArgs) -> Result<Scene, Error> {
    if let Some(ch) = character::load(&a.input)? {
        return character_scene(ch, a);
    }
    let sintel =
        |p: &Option<PathBuf>| p.as_ref().is_some_and(|p| p.to_string_lossy().to_lowercase().contains("sintel"));
    let mut dense = None;
    let (groom, thickness, colliders, head_mesh, pivot, credit) = match &a.input.input {
        None => {
            let head = TriMesh::uv_sphere(THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS * 0.97, 24, 32)?;
            (scenes::thesis()?, None, motion::thesis_colliders(), head, Some(motion::NECK_PIVOT), None)
        }
        Some(path) => {
            let scale = a.input.scale();
            let (Scaled { groom, thickness }, followers) = a.input.groom_and_guides(path)?;
            dense = followers;
            let head_mesh = match &a.input.obj {
                Some(obj) => {
                    let m = TriMesh::load_obj(obj)?;
                    TriMesh::new(m.positions.iter().map(|p| *p * scale).collect(), m.triangles)?
                }
                None => {
                    // A stand-in head under the roots, sized by the groom's largest
                    // extent (a flat groom has no extent along one axis).
                    let (lo, hi) = dense.as_ref().map_or(&groom, |d| &d.groom).bounds();
                    let r = 0.25 * (hi - lo).max_element();
                    TriMesh::uv_sphere(0.5 * (lo + hi), r, 16, 24)?
                }
            };
            let credit = (sintel(&a.input.input) || sintel(&a.input.obj))
                .then_some("Sintel © Blender Foundation | durian.blender.org (CC BY 3.0)");
            (groom, thickness, Vec::new(), head_mesh, None, credit)
        }
    };
    let drawn = dense.as_ref().map_or(&groom, |d| &d.groom);
    let (center, radius) = vkhair::groom::bounding_sphere(vkhair::groom::bounding_box(
        drawn.positions().iter().chain(&head_mesh.positions).copied(),
    ));
    if !(center.is_finite() && radius.is_finite() && radius > 0.0) {
        return Err(format!("the groom and mesh span no finite volume (bounding radius {radius})").into());
    }
    if !(MIN_SCENE_RADIUS..=MAX_SCENE_RADIUS).contains(&radius) {
        let files: Vec<String> =
            [&a.input.input, &a.input.obj].into_iter().flatten().map(|p| p.display().to_string()).collect();
        return Err(format!(
            "{}: the groom{} spans {radius:e} units from its centre (after --scale {}); vkhair draws scenes of \
             {MIN_SCENE_RADIUS:e} to {MAX_SCENE_RADIUS:e} (a head of hair in meters: about 0.3): give --scale to \
             bring it there",
            files.join(" and "),
            if a.input.obj.is_some() { " and mesh" } else { "" },
            a.input.scale()
        )
        .into());
    }
    let (lo, _) = drawn.bounds();
    let pivot = pivot.unwrap_or(Vec3::new(center.x, lo.y, center.z));
    let start_head = vkhair::sim::RigidTransform::default();
    let view_dir = Vec3::Z;
    Ok(Scene {
        groom,
        dense,
        colliders,
        head_mesh,
        center,
        radius,
        thickness,
        pivot,
        credit,
        character: None,
        start_head,
        view_dir,
    })
}

/// The `--gltf` scene: framed on the hair and the body around the head.
fn character_scene(ch: CharacterScene, a: &SceneArgs) -> Result<Scene, Error> {
    let (Scaled { groom, thickness }, dense, head_mesh) = character_groom(&ch, &a.input)?;
    let start_head = ch.head_at(0.0);
    let head = start_head.matrix().transform_point3(Vec3::ZERO);
    let (center, radius) = ch.framing(&groom, &ch.body_at(0.0)?);
    let credit =
        a.input.gltf.as_ref().is_some_and(|p| p.to_string_lossy().contains("mannequiny")).then_some(MANNEQUIN_CREDIT);
    let colliders = Vec::new();
    let view_dir = ch.character.forward();
    Ok(Scene {
        groom,
        dense,
        colliders,
        head_mesh,
        center,
        radius,
        thickness,
        pivot: head,
        credit,
        character: Some(ch),
        start_head,
        view_dir,
    })
}

/// The key hairs on a `--gltf` character, in its head's frame (grown on the
/// head, or the --input groom moved there from the character's bind pose),
/// a dense --input groom's followers likewise, and the head's region (the mesh
/// collider).
pub fn character_groom(ch: &CharacterScene, a: &InputArgs) -> Result<(Scaled, Option<Dense>, TriMesh), Error> {
    let Some(path) = &a.input else {
        let (groom, head_mesh) = ch.grow(a.points.unwrap_or(16))?;
        return Ok((Scaled { groom, thickness: None }, None, head_mesh));
    };
    let to_head = ch.bind_frame().inverse();
    let (Scaled { groom, thickness }, dense) = a.groom_and_guides(path)?;
    let groom = groom.rigidly_moved(&to_head)?;
    let dense = dense.map(|d| d.groom.rigidly_moved(&to_head).map(|groom| Dense { groom, ..d })).transpose()?;
    Ok((Scaled { groom, thickness }, dense, ch.head_region()?))
}

/// How much wider than given the render's lengths are drawn for a scene of
/// bounding radius `radius`: 1 for anything a head of hair in meters could be
/// (5 cm to 1.5 m), else the factor that gives the thesis head's proportions.
pub fn drawing_scale(radius: f32) -> f32 {
    if (0.05..=1.5).contains(&radius) {
        1.0
    } else {
        radius / THESIS_BOUNDING_RADIUS
    }
}

/// Vertical field of view of the tool's camera, radians.
const FOV_Y: f32 = 0.698_131_7; // 40°

/// The camera looking at the scene from the front (`view_dir`): at `distance` when
/// given, else far enough that the bounding sphere fits the image's shorter side.
pub fn framing(s: &Scene, distance: Option<f32>, aspect: f32) -> Result<Camera, vkhair::Error> {
    let half = 0.5 * FOV_Y;
    let half_narrow = if aspect >= 1.0 { half } else { (half.tan() * aspect).atan() };
    let d = distance.unwrap_or(s.radius / half_narrow.sin());
    let r = s.radius;
    let eye = s.center + Vec3::new(0.0, 0.1 * r, 0.0) + s.view_dir * d;
    let near = (d - 1.5 * r).max(0.002 * d);
    let far = d + 1.5 * r;
    Camera::look_at(eye, s.center, FOV_Y, aspect, near, far)
}
