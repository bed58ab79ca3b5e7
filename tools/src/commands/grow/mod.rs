//! `vkhair grow`: strands grown on a scalp, written as a .hair file.

use std::path::PathBuf;

use clap::ValueEnum;
use glam::Vec3;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::grow::{grow, GrowParams, Scalp};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes;

use crate::destinations::{self, Kind, Output};
use crate::output::CliResult;
use crate::say;

#[derive(Clone, Copy, ValueEnum)]
pub enum ScalpKind {
    /// The `thesis` reference scene (1750 × 6 on a head sphere); other options ignored.
    Thesis,
    /// A sphere cap around +Y, face (+Z) left free.
    Sphere,
    /// An ellipsoid cap around +Y, face (+Z) left free.
    Ellipsoid,
    /// Upward-facing triangles in the top part of an OBJ mesh (--obj).
    Obj,
    /// The head of a skinned glTF character (--gltf; the joint that dominates
    /// the top of the mesh, or --head-joint), the face left free, combed back;
    /// written in the character's bind pose (meters), its roots on the mesh,
    /// for `render`/`simulate --gltf FILE --input OUT`.
    Gltf,
}

#[derive(clap::Args)]
pub struct GrowArgs {
    /// Scalp shape.
    #[arg(long, value_enum, default_value = "thesis")]
    scalp: ScalpKind,
    /// OBJ mesh for --scalp obj.
    #[arg(long)]
    obj: Option<PathBuf>,
    /// glTF character (.glb or .gltf) for --scalp gltf.
    #[arg(long)]
    gltf: Option<PathBuf>,
    /// --scalp gltf: the joint the hair grows on, by name [default: found by weights].
    #[arg(long)]
    head_joint: Option<String>,
    /// Sphere radius / ellipsoid semi-axes "x,y,z" (scalp units).
    #[arg(long, default_value = "0.1")]
    radius: String,
    /// Centre of the sphere/ellipsoid "x,y,z".
    #[arg(long, default_value = "0,0,0")]
    center: String,
    /// Roots within this angle of +Y, degrees (sphere/ellipsoid).
    #[arg(long, default_value_t = 110.0)]
    max_angle: f32,
    /// OBJ: only triangles above this fraction of the mesh height.
    #[arg(long, default_value_t = 0.8)]
    min_height: f32,
    /// OBJ: only triangles whose normal·up is at least this.
    #[arg(long, default_value_t = 0.2)]
    min_up_dot: f32,
    /// Number of strands.
    #[arg(long, default_value_t = 1000)]
    strands: usize,
    /// Points per strand.
    #[arg(long, default_value_t = 16)]
    points: usize,
    /// Strand length (scalp units); default 0.3, 35 % of the mesh height for
    /// OBJ, 0.28 m for glTF.
    #[arg(long)]
    length: Option<f32>,
    /// Bend toward gravity, radians over the strand.
    #[arg(long, default_value_t = 2.5)]
    droop: f32,
    /// Sphere, ellipsoid and OBJ: the direction the face looks, "x,y,z", or
    /// "0" for none. Hair frames it: combed back from it, parted at the middle
    /// and, in front, turned to its side (glTF: the character's own forward).
    #[arg(long, default_value = "0,0,1")]
    face: String,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output .hair file.
    #[arg(long)]
    out: PathBuf,
}

fn parse_vec3(name: &str, s: &str) -> Result<Vec3, String> {
    let parts: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("--{name} {s:?}: {e}"))?;
    match parts.as_slice() {
        [v] => Ok(Vec3::splat(*v)),
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!("--{name} {s:?}: give one value or three separated by commas")),
    }
}

pub fn grow_groom(a: &GrowArgs) -> CliResult {
    if !(a.max_angle.is_finite() && a.max_angle > 0.0 && a.max_angle <= 180.0) {
        return Err(format!("--max-angle must be within (0, 180] degrees (got {})", a.max_angle).into());
    }
    let inputs: Vec<&std::path::Path> = a.obj.iter().chain(&a.gltf).map(|p| p.as_path()).collect();
    let _made = destinations::check(&inputs, &[Output { flag: "--out", path: &a.out, kind: Kind::File(&["hair"]) }])?;
    let groom = match a.scalp {
        ScalpKind::Thesis => {
            if a.strands != 1000 || a.points != 16 || a.length.is_some() {
                crate::say_err!(
                    "vkhair: warning: --scalp thesis (the default) is the reference scene, 1750 strands of 6 points: \
                     --strands, --points and --length are ignored (give --scalp sphere, ellipsoid, obj or gltf to \
                     grow your own)"
                );
            }
            scenes::thesis()?
        }
        ScalpKind::Gltf => {
            let path = a.gltf.as_ref().ok_or("--scalp gltf needs --gltf FILE.glb")?;
            let character = vkhair::character::Character::load(path)?;
            // The rig's animation is not used: the groom is grown in the bind pose.
            let rig = vkhair::character::HairRig::new(character, None, a.head_joint.as_deref())
                .map_err(|e| format!("{}: {e}", path.display()))?;
            let params = GrowParams {
                strands: a.strands,
                points_per_strand: a.points,
                length: a.length.unwrap_or(vkhair::character::RIG_HAIR_LENGTH),
                droop: a.droop,
                seed: a.seed,
                ..GrowParams::default()
            };
            let (groom, _) = rig.grow_with(&params).map_err(crate::args::flag_error)?;
            say!("grown on joint {:?} of {}", rig.joint_name(rig.head), path.display());
            groom.rigidly_moved(&rig.bind_frame())?
        }
        kind => {
            let mut length = a.length.unwrap_or(0.3);
            let scalp = match kind {
                ScalpKind::Obj => {
                    let path = a.obj.as_ref().ok_or("--scalp obj needs --obj FILE.obj")?;
                    let mesh = TriMesh::load_obj(path)?;
                    let (lo, hi) = mesh.bounds();
                    if a.length.is_none() {
                        length = 0.35 * (hi.y - lo.y);
                    }
                    Scalp::Mesh { mesh, up: Vec3::Y, min_height: a.min_height, min_up_dot: a.min_up_dot }
                }
                _ => {
                    let radii = parse_vec3("radius", &a.radius)?;
                    if !(radii.is_finite() && radii.min_element() > 0.0 && radii.max_element() <= 1e6) {
                        return Err(format!("--radius {:?}: each semi-axis within (0, 1e6]", a.radius).into());
                    }
                    let center = parse_vec3("center", &a.center)?;
                    if !(center.is_finite() && center.abs().max_element() <= 1e6) {
                        return Err(format!("--center {:?}: each component within ±1e6", a.center).into());
                    }
                    let mut scalp = Scalp::sphere_cap(center, radii.x, a.max_angle.to_radians());
                    if let Scalp::Ellipsoid { radii: r, .. } = &mut scalp {
                        *r = radii;
                    }
                    scalp
                }
            };
            let face = parse_vec3("face", &a.face)?;
            if face.abs().max_element() > 1e6 {
                return Err(format!("--face {:?}: each component within ±1e6", a.face).into());
            }
            let params = GrowParams {
                strands: a.strands,
                points_per_strand: a.points,
                length,
                droop: a.droop,
                seed: a.seed,
                face,
                // Back from the face, a little up: the crown's hair lies over the head.
                comb: match face.try_normalize() {
                    Some(f) => 0.2 * Vec3::Y - 0.8 * f,
                    None => Vec3::ZERO,
                },
                ..GrowParams::default()
            };
            grow(&scalp, &params).map_err(|e| -> crate::output::Error {
                match e {
                    // The scalp's place and the strands' length are the flags'.
                    vkhair::Error::GroomFarAway { distance, median } => {
                        let place = match kind {
                            ScalpKind::Obj => "the OBJ's scalp",
                            _ => "--radius and --center",
                        };
                        let most = vkhair::groom::MAX_DISTANCE_IN_STRANDS;
                        // The strands' length as the user set it, or the default's value.
                        let given = match a.length {
                            Some(l) => format!("--length {l}"),
                            None => format!("length {length}, the default"),
                        };
                        format!(
                            "{place} put the hair {distance:.3e} from the origin, over {most} times the size of its \
                         strands ({median:.3e} across, {given}): vkhair keeps a groom within that \
                         (grow a smaller scalp nearer the origin, or longer strands)"
                        )
                        .into()
                    }
                    e => crate::args::flag_error(e).into(),
                }
            })?
        }
    };
    let s = groom.stats();
    HairFile::new(groom, "grown by vkhair").save(&a.out)?;
    say!("wrote {}: {} strands, {} points, mean length {:.4}", a.out.display(), s.strands, s.points, s.strand_length.1);
    Ok(())
}
