//! The `--gltf` scene: a skinned, animated character with key hairs on its
//! head ([`vkhair::character::HairRig`]): grown there in the head joint's
//! frame, the head's region as the mesh collider (it moves with the head), a
//! capsule per bone near the head as the simulation's body colliders, placed
//! in the world at every frame's pose.

use vkhair::character::{Character, HairRig};

use crate::args::input::InputArgs;
use crate::output::Error;
use crate::say;

/// A loaded `--gltf` character with what the tools need of it.
pub type CharacterScene = HairRig;

/// Reads the `--gltf` character, picks its animation and head, fits its
/// capsules; `None` without `--gltf`.
pub fn load(a: &InputArgs) -> Result<Option<CharacterScene>, Error> {
    let Some(path) = &a.gltf else { return Ok(None) };
    let character = Character::load(path)?;
    let rig = HairRig::new(character, a.animation.as_deref(), a.head_joint.as_deref())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let sk = &rig.character.skeleton;
    say!(
        "character: {} vertices, {} joints, head joint {:?}, animation {:?} ({:.2} s), {} capsules ({})",
        rig.character.positions.len(),
        sk.joints.len(),
        rig.joint_name(rig.head),
        sk.animations[rig.animation].name,
        sk.animations[rig.animation].duration(),
        rig.capsules.len(),
        rig.capsules.iter().map(|c| rig.joint_name(c.joint)).collect::<Vec<_>>().join(", ")
    );
    Ok(Some(rig))
}
