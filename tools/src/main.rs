//! `vkhair`: the command-line program of the vkhair crate.
//!
//! This file is the dispatcher only. Each command lives in its own folder
//! under `commands/` and imports no other command; what several share lives
//! beside them: the argument groups (`args/`: the groom input, the simulation
//! knobs, the rendered scene), the scene they build (`scene/`), the output
//! (`output.rs`), profiles (`profile.rs`) and charts (`chart.rs`).

mod args;
mod chart;
mod commands;
mod destinations;
mod output;
mod profile;
mod scene;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use commands::{bench, config, convert, devices, grow, inspect, plot, render, simulate};

#[derive(Parser)]
#[command(name = "vkhair", version, about = "Real-time strand hair on Vulkan: devices, grooms, growth")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List Vulkan devices, what vkhair can use of each, and which one it would choose.
    Devices,
    /// Print counts, lengths, bounds and point statistics of a .hair or .tfx file.
    Inspect(inspect::InspectArgs),
    /// Grow strands on a scalp and write them as a .hair file.
    Grow(grow::GrowArgs),
    /// Simulate a groom on the GPU with the shaking-head motion; print per-stage GPU times.
    Simulate(simulate::SimulateArgs),
    /// Simulate and render a head of hair headless: PNG frames, a contact sheet and a
    /// per-pass GPU timing table.
    Render(render::RenderArgs),
    /// Measure every stage on the GPU beside its CPU reference (thesis, Sintel, a
    /// large groom), with recorded work, bandwidth bounds and scaling curves.
    Bench(bench::BenchArgs),
    /// Print the default parameters as commented TOML, a starting point for --config.
    Config,
    /// Chart the render benchmark's CSV (cargo bench --features bench --bench render) as a PNG.
    Plot(plot::PlotArgs),
    /// Resample and/or pick key hairs from a .hair or .tfx file; write a .hair file.
    Convert(convert::ConvertArgs),
}

fn main() -> ExitCode {
    output::restore_sigpipe();
    output::bound_heap_growth();
    output::exit_cleanly_on_signals();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Devices => devices::devices(),
        Command::Inspect(args) => inspect::inspect(&args),
        Command::Grow(args) => grow::grow_groom(&args),
        Command::Simulate(args) => simulate::simulate(&args),
        Command::Render(args) => render::render(&args),
        Command::Config => config::config(),
        Command::Plot(args) => plot::plot(&args),
        Command::Bench(args) => bench::bench(&args),
        Command::Convert(args) => convert::convert(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            say_err!("vkhair: {e}");
            ExitCode::FAILURE
        }
    }
}
