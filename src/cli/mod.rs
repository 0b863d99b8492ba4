//! Command-line interface: argument definitions and the subcommands.

mod args;
mod bench_bvh;
mod export;
mod info;
mod render;

use lumiere::Result;

pub use args::Cli;
use args::Command;

pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Info(args) => info::run(&args),
        Command::BenchBvh(args) => bench_bvh::run(&args),
    }
}
