//! `vkhair config`: the default parameters as commented TOML, a starting point
//! for `--config`.

use vkhair::config::Config;

use crate::output::CliResult;
use crate::say;

pub fn config() -> CliResult {
    let text = Config::default().to_commented_toml()?;
    say!("{}", text.trim_end_matches('\n'));
    Ok(())
}
