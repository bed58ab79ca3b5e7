//! Every file in `presets/` is a valid parameter file, and the styled ones turn
//! the shape constraint on.

use std::path::Path;

use vkhair::config::Config;

#[test]
fn every_preset_is_a_valid_parameter_file() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets");
    let mut names = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("presets folder") {
        let path = entry.expect("entry").path();
        let config = Config::default().load_over(&path).unwrap_or_else(|e| panic!("{e}"));
        let name = path.file_stem().and_then(|s| s.to_str()).expect("name").to_owned();
        if name != "thesis" {
            assert!(config.sim.global_shape_stiffness > 0.0, "{name} holds no style");
            assert!(config.sim.sag_free, "{name} sags");
        }
        names.push(name);
    }
    names.sort();
    assert_eq!(names, ["bob", "curly", "long_straight", "mohawk", "thesis"]);
}
