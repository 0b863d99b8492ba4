//! The `lumiere` command: arguments in, image and statistics out. All rendering lives in the library.

use lumiere_cli::cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    let args = <cli::Cli as clap::Parser>::parse();
    match cli::run(args) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("lumiere: error: {e}");
            ExitCode::from(2)
        }
    }
}
