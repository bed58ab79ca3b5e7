//! Reading the groom a user gives: `.hair` or `.tfx`, repaired unless `--strict`
//! (with a warning that counts what was dropped), scaled and resampled.

use std::path::Path;

use glam::Vec3;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::tfx::TfxFile;
use vkhair::groom::{Groom, Repairs};

use crate::output::Error;

/// The groom in `path` and a description of its format. Defects that can be
/// repaired are (with a warning on stderr) unless `strict`; then the file is
/// refused with the defect named.
pub fn load(path: &Path, strict: bool) -> Result<(Groom, String), Error> {
    let tfx = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("tfx"));
    let refused = |e: vkhair::Error| -> Error {
        match e {
            vkhair::Error::Asset { .. } if strict => {
                format!("{e} (--strict: without it, vkhair drops such segments and strands and says so)").into()
            }
            e => e.into(),
        }
    };
    let (groom, kind, repairs) = if tfx {
        let (f, repairs) = if strict {
            (TfxFile::open(path).map_err(refused)?, Repairs::default())
        } else {
            TfxFile::open_repairing(path)?
        };
        let kind = format!("TressFX {} (.tfx)", f.version);
        (f.groom, kind, repairs)
    } else {
        let (f, repairs) = if strict {
            (HairFile::open(path).map_err(refused)?, Repairs::default())
        } else {
            HairFile::open_repairing(path)?
        };
        let info = f.info_str();
        let kind =
            format!("cyHair (.hair){}", if info.is_empty() { String::new() } else { format!(", info \"{info}\"") });
        (f.groom, kind, repairs)
    };
    if !repairs.is_empty() {
        eprintln!(
            "vkhair: warning: {}: {repairs}; {} strands remain (--strict refuses such a file instead)",
            path.display(),
            groom.strand_count()
        );
    }
    Ok((groom, kind))
}

/// The groom in `path` (see [`load`]) with its positions multiplied by `scale`
/// and every strand resampled to `points` points.
pub fn load_scaled(path: &Path, strict: bool, scale: f32, points: usize) -> Result<Groom, Error> {
    let (groom, _) = load(path, strict)?;
    let counts: Vec<u32> = (0..groom.strand_count()).map(|i| groom.strand_len(i) as u32).collect();
    let scaled: Vec<Vec3> = groom.positions().iter().map(|p| *p * scale).collect();
    Ok(Groom::new(scaled, &counts)?.resampled(points)?)
}
