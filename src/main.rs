//! The `tendril` command line.
fn main() -> std::process::ExitCode {
    tendril::cli::main()
}
