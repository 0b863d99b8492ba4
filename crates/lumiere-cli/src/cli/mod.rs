//! Command-line interface: argument definitions and the subcommands.

mod args;
mod bench_bvh;
mod bench_lab;
mod bench_sampler;
mod export;
mod info;
mod isa;
pub mod output;
mod render;
mod technique_json;

use lumiere::Result;

pub use args::Cli;
use args::Command;

/// Runs a subcommand; returns the process exit code on success.
pub fn run(cli: Cli) -> Result<u8> {
    lumiere::util::threads::start_global_pool()?;
    match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Info(args) => info::run(&args).map(|()| 0),
        Command::BenchBvh(args) => bench_bvh::run(&args).map(|()| 0),
        Command::Bench(args) => bench_lab::run(&args).map(|()| 0),
        Command::BenchSampler(args) => bench_sampler::run(&args).map(|()| 0),
    }
}
