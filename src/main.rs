use clap::Parser;

fn main() -> std::process::ExitCode {
    // Usage errors end here, with clap's code 2.
    let cli = zeroset::cli::Cli::parse();
    match zeroset::cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            if let Some(text) = zeroset::cli::exit::error_text(&e) {
                eprintln!("{text}");
            }
            std::process::ExitCode::from(zeroset::cli::exit::exit_code(&e))
        }
    }
}
