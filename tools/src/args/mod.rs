//! Argument groups several commands share: the groom a user gives
//! ([`input::InputArgs`]), the simulation knobs ([`sim::SimArgs`]) and the
//! rendered scene ([`scene::SceneArgs`]).

pub mod input;
pub mod scene;
pub mod sim;
pub mod texture;

/// The flags that set a library parameter, by the name the library's errors
/// give it: an out-of-range value a flag gave is named by the flag, not by
/// the parameter (a value from `--config` is refused earlier, with its line).
const FLAG_OF: &[(&str, &str)] = &[
    ("hairs_per_key", "--hairs-per-key"),
    ("smoothing_level", "--level"),
    ("oit.sorted_fragments", "--sorted-fragments"),
    ("oit.fragments_per_pixel", "--fragments-per-pixel"),
    ("volume resolution", "--grid"),
    ("volume max_iterations", "--max-iterations"),
    ("iterations", "--iterations"),
    ("substeps", "--substeps"),
    ("scalp.density", "--density"),
    ("strands", "--strands"),
    ("points_per_strand", "--points"),
    ("length", "--length"),
    ("droop", "--droop"),
    ("min_height", "--min-height"),
    ("min_up_dot", "--min-up-dot"),
    ("face", "--face"),
    ("points per strand", "--points"),
    ("key hair count", "--key-hairs"),
];

/// `e` as the error of the flag that set the parameter it names
/// (`invalid parameter --level: 0 (allowed: 1..=64)`), else as it is.
pub fn flag_error(e: vkhair::Error) -> vkhair::Error {
    match e {
        vkhair::Error::InvalidParameter { name, value, allowed } => {
            let name = FLAG_OF.iter().find(|(n, _)| *n == name).map_or(name, |(_, flag)| flag);
            vkhair::Error::InvalidParameter { name, value, allowed }
        }
        e => e,
    }
}
