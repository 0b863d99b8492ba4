//! The `lumiere` command: arguments in, image and statistics out. All rendering lives in the library.

use std::io::Write;
use std::process::ExitCode;

use lumiere_cli::cli::{self, output};

fn main() -> ExitCode {
    let args = match <cli::Cli as clap::Parser>::try_parse() {
        Ok(args) => args,
        Err(e) => return refuse_arguments(e),
    };
    match cli::run(args) {
        Ok(code) => ExitCode::from(code),
        // The reader of stdout went away (`lumiere info x.obj | head -1`): nothing left to say.
        Err(e) if output::is_closed_stdout(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr().lock(), "lumiere: error: {}", lumiere::error::one_line(&e.to_string()));
            ExitCode::from(2)
        }
    }
}

/// Help and version go out as clap writes them; a bad argument is one line, as every other refusal
/// (clap's own message spreads over up to six, with a usage line and a pointer to `--help`): its
/// lines of substance joined, exit code 2.
fn refuse_arguments(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        // As clap's `exit` does, with its exit code, but a stdout that cannot take the text (a
        // full disk) is an error, as it is for `info`; a reader gone away (`| head -1`) is not.
        return match e.print().and_then(|()| std::io::stdout().flush()) {
            Ok(()) => ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2)),
            Err(error) if error.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
            Err(error) => {
                let _ = writeln!(std::io::stderr().lock(), "lumiere: error: <stdout>: {error}");
                ExitCode::from(2)
            }
        };
    }
    let text = e.render().to_string();
    let line = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .map(|l| l.strip_prefix("error: ").unwrap_or(l))
        .fold(String::new(), |line, piece| match line.as_str() {
            "" => piece.to_string(),
            // "...not provided:" goes on with what was not.
            _ if line.ends_with(':') => format!("{line} {piece}"),
            _ => format!("{line}; {piece}"),
        });
    let _ = writeln!(std::io::stderr().lock(), "lumiere: error: {line} (see --help)");
    ExitCode::from(2)
}
