//! The `tubemem` command-line front end: argument parsing, the progress display and the console
//! lines, over the application layer `tubemem_app` (which owns cases, runs, outputs and
//! figures). Errors are `anyhow` chains whose outer context names the stage, step, key or file.

pub mod console;
pub mod gps_cmd;
pub mod material_args;
