//! The command-line program's tests, one module per file beside this one
//! (`tools/tests/input_cli.rs` is `input_cli::…`), built as one test binary:
//! one link instead of one per file, and tests from every file run side by
//! side. Run one file's tests with `cargo test -p vkhair-tools --test suite input_cli::`.

#[path = "authored_cli.rs"]
mod authored_cli;
#[path = "bench_cli.rs"]
mod bench_cli;
mod common;
#[path = "config_cli.rs"]
mod config_cli;
#[path = "hostile_cli.rs"]
mod hostile_cli;
#[path = "input_cli.rs"]
mod input_cli;
#[path = "output_cli.rs"]
mod output_cli;
#[path = "profile_cli.rs"]
mod profile_cli;
#[path = "simulate_cli.rs"]
mod simulate_cli;
#[path = "sizes_cli.rs"]
mod sizes_cli;
