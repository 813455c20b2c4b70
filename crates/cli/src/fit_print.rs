//! The parameter lines `tubemem fit` prints, for the elastic fit and the history fit alike.

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
