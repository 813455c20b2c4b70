//! The `tubemem` command-line front end: argument parsing, the progress display and the console
//! lines, over the application layer `tubemem_app` (which owns cases, runs, outputs and
//! figures). Errors are `anyhow` chains whose outer context names the stage, step, key or file.

pub mod atlas_cmd;
pub mod console;
pub mod fit_cmd;
pub mod fit_history_cmd;
pub mod fit_print;
pub mod gps_cmd;
pub mod gps_history;
pub mod material_args;
pub mod shell_cmd;
pub mod verify_cmd;

/// Write one line to standard output. A closed or full standard output (`> /dev/full`, a pipe
/// whose reader has gone) is an error that the caller reports, never a panic.
pub fn say(line: impl std::fmt::Display) -> std::io::Result<()> {
    use std::io::Write;
    let mut o = std::io::stdout().lock();
    writeln!(o, "{line}")
        .and_then(|()| o.flush())
        .map_err(|e| std::io::Error::new(e.kind(), format!("cannot write to standard output: {e}")))
}

/// `say!(…)`: `println!` that returns the write error instead of panicking.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => { $crate::say(format_args!($($arg)*)) };
}
