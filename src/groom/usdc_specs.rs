//! What a binary USD layer's specs may hold before the USD library composes
//! them, read from the layer the library has parsed: the bounds and refusals
//! [`super::usda_check`] applies to a text layer — how deep and how much its
//! prims nest, and no value clips or relocates.

use openusd::sdf::{AbstractData, Path as SdfPath, SpecType};

use super::usda_check::{CLIPS_REFUSED, CLIP_FIELDS, MAX_USDA_DEPTH, MAX_USDA_DEPTH_WORK, RELOCATES_REFUSED};

/// Checks the prims of a binary layer's specs `typed` (in `data`): each at
/// most [`MAX_USDA_DEPTH`] deep and their depths squared summing to at most
/// [`MAX_USDA_DEPTH_WORK`] (a chain of 2,000 nested prims took the library
/// past 10 s, 500 about 10 s), and none with value clips or relocates.
pub(super) fn check(data: &impl AbstractData, typed: &[(SdfPath, SpecType)]) -> Result<(), String> {
    if matches!(data.try_field(&SdfPath::abs_root(), "layerRelocates"), Ok(Some(_))) {
        return Err(format!("the layer has {RELOCATES_REFUSED}"));
    }
    let mut work = 0u64;
    for (path, _) in typed.iter().filter(|(_, t)| *t == SpecType::Prim) {
        let depth = path.as_str().split('/').filter(|e| !e.is_empty()).count();
        if depth > MAX_USDA_DEPTH {
            return Err(format!("its prim {} nests {depth} deep (at most {MAX_USDA_DEPTH})", shortened(path)));
        }
        work += (depth as u64).pow(2);
        if work > MAX_USDA_DEPTH_WORK {
            return Err(format!(
                "its prims nest too deeply all together: the sum of their depths squared passes \
                 {MAX_USDA_DEPTH_WORK} (at {})",
                shortened(path)
            ));
        }
        let has = |field: &str| matches!(data.try_field(path, field), Ok(Some(_)));
        if let Some(field) = CLIP_FIELDS.iter().find(|f| has(f)) {
            return Err(format!("its prim {} has {CLIPS_REFUSED} (`{field}`)", path.as_str()));
        }
        if has("relocates") {
            return Err(format!("its prim {} has {RELOCATES_REFUSED}", path.as_str()));
        }
    }
    Ok(())
}

/// A prim path as long as its nesting, shown by its two ends.
fn shortened(path: &SdfPath) -> String {
    let p = path.as_str();
    match (p.char_indices().nth(60), p.char_indices().rev().nth(39)) {
        (Some((head, _)), Some((tail, _))) if tail > head => format!("{}…{}", &p[..head], &p[tail..]),
        _ => p.to_owned(),
    }
}
