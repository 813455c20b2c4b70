"""Independent reference implementations for tubemem, written from the paper's equations and
sharing no code with the Rust crates."""
