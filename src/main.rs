//! The `macdec` binary: the library's command line ([`macdec::cli`]) over the built-in domains.

fn main() -> std::process::ExitCode {
    macdec::cli::main()
}
