use std::process::ExitCode;

fn main() -> ExitCode {
    grainlab_cli::main()
}

#[path = "cli.rs"]
mod grainlab_cli;
