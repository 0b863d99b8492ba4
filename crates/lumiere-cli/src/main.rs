//! The `lumiere` command: arguments in, image and statistics out. All rendering lives in the library.

use std::io::Write;
use std::process::ExitCode;

use lumiere_cli::cli::{self, output};

fn main() -> ExitCode {
    let args = <cli::Cli as clap::Parser>::parse();
    match cli::run(args) {
        Ok(code) => ExitCode::from(code),
        // The reader of stdout went away (`lumiere info x.obj | head -1`): nothing left to say.
        Err(e) if output::is_closed_stdout(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr().lock(), "lumiere: error: {e}");
            ExitCode::from(2)
        }
    }
}
