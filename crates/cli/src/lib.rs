//! The tubemem application layer: case files, FE runs with their outputs (steps.csv,
//! summary.json, profiles, VTU), the closed-form commands and the figures. The `tubemem` binary
//! (`main.rs`) and the Python bindings (`crates/py`) are thin front ends over it. Errors are
//! `anyhow` chains whose outer context names the stage, step, key or file.

pub mod case;
pub mod figures;
pub mod gps_cmd;
pub mod main_job;
pub mod material_args;
pub mod run_cmd;
