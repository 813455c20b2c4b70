//! What `tubemem fit` writes and prints, for the elastic fit and the history fit alike: the
//! figure's files checked before anything is read, and the parameter lines.

use tubemem_material::fit::FitResult;

/// One line per parameter: its name, value, unit (`unit_name` for a modulus, s for a Prony
/// τ), standard error or why it has none.
pub fn parameter_lines(result: &FitResult, unit_name: &str) -> std::io::Result<()> {
    for p in &result.parameters {
        let se = match (p.fixed, p.std_error) {
            (true, _) => "fixed".to_string(),
            (_, Some(e)) => format!("± {e:.2e}"),
            (_, None) => "± —".to_string(),
        };
        let u = if tubemem_material::fit::is_modulus(&p.name) {
            unit_name
        } else if p.name.ends_with(".tau") {
            "s"
        } else {
            ""
        };
        crate::say!(
            "  {:<20} {:>14.6e} {u:<8} {se}{}",
            p.name,
            p.value,
            match (&p.at_bound, p.determined) {
                (Some(b), _) => format!("   at its {b} bound"),
                (None, false) => format!(
                    "   not determined by the data (rank {} of {})",
                    result.rank, result.free_parameters
                ),
                _ => String::new(),
            }
        )?;
    }
    Ok(())
}

/// The `--plot` files `stem`.svg and .png checked before anything is read: not an input, and an
/// existing file only where it is a figure of this command (an SVG whose text holds `title`;
/// a PNG's writer cannot be told from its bytes: it is ours where the SVG beside it is), or
/// with `overwrite`.
pub fn check_plot(
    stem: &std::path::Path,
    inputs: &[&std::path::Path],
    title: &str,
    overwrite: bool,
) -> anyhow::Result<()> {
    let ours = |t: &str| t.starts_with("<svg") && t.contains(title);
    let svg_ours = std::fs::read_to_string(stem.with_extension("svg")).is_ok_and(|t| ours(&t));
    for ext in ["svg", "png"] {
        let path = stem.with_extension(ext);
        tubemem_app::output_file::check("--plot", &path, inputs, |t| {
            overwrite || ours(t) || (ext == "png" && svg_ours)
        })
        .map_err(|e| anyhow::anyhow!(tubemem_app::error_chain(&e)))?;
    }
    Ok(())
}
