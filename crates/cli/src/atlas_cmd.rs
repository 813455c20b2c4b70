//! `tubemem atlas`: run an atlas file (one FE run per λs* and L/R, in parallel, resumable),
//! fit the end-effect laws and write atlas.csv, runs.csv, atlas.json and the maps; `tubemem
//! atlas predict` reads an atlas's folder and prints the laws' prediction at a point.
//! Exit codes: 0 written, 1 some member runs failed (kept as errors; the others fitted), 2 a
//! usage or setup error, 130 interrupted (the finished runs are kept; a rerun does the rest).

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use tubemem_app::atlas::{self, Atlas, Progress};

#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct AtlasArgs {
    #[command(subcommand)]
    pub command: Option<AtlasCommand>,
    /// The atlas file (TOML: a case template without stages, and an `[atlas]` table).
    pub file: Option<PathBuf>,
    /// Output folder: `runs/<member>/` (each with its case.toml), atlas.csv, runs.csv,
    /// atlas.json, ps_map.csv, figures/. A folder holding the same atlas is resumed.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Member runs at once (default: the number of cores).
    #[arg(long, default_value_t = 0)]
    pub workers: usize,
}

#[derive(clap::Subcommand, Debug)]
pub enum AtlasCommand {
    /// The fitted laws' FE/GPS − 1 at a point, and the minimum L/R per ε.
    Predict {
        /// The atlas's output folder (with its atlas.json).
        dir: PathBuf,
        #[arg(long)]
        lambda_s_star: f64,
        #[arg(long)]
        rho: f64,
        #[arg(long)]
        length_ratio: f64,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn setup(message: impl std::fmt::Display) -> u8 {
    let message = tubemem_material::tidy_numbers(&message.to_string());
    let _ = writeln!(std::io::stderr(), "error: {message}");
    2
}

pub fn run(a: AtlasArgs) -> u8 {
    if let Some(AtlasCommand::Predict {
        dir,
        lambda_s_star,
        rho,
        length_ratio,
        json,
    }) = a.command
    {
        return predict(&dir, lambda_s_star, rho, length_ratio, json);
    }
    let (Some(file), Some(out)) = (a.file, a.out) else {
        return setup("usage: tubemem atlas ATLAS.toml --out DIR (or tubemem atlas predict DIR …)");
    };
    let text =
        match tubemem_mesh::io::read_text_limited(&file, tubemem_app::case::MAX_CASE_FILE_BYTES) {
            Ok(t) => t,
            Err(e) => return setup(format!("cannot read {}: {e}", file.display())),
        };
    let base = file.parent().map(PathBuf::from).unwrap_or_default();
    let atlas = match Atlas::parse(&text, &base) {
        Ok(a) => a,
        Err(e) => {
            return setup(format!(
                "{}: {}",
                file.display(),
                tubemem_app::error_chain(&e)
            ))
        }
    };
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let f = flag.clone();
    if ctrlc::set_handler(move || f.store(true, std::sync::atomic::Ordering::Relaxed)).is_ok() {
        atlas::set_interrupt(flag.clone());
    }
    let workers = if a.workers == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        a.workers
    };
    let n = atlas.members.len();
    let _ = writeln!(
        std::io::stderr(),
        "tubemem atlas: {} — {n} runs ({} λs* × {} L/R) on {workers} worker{}, {} ρ levels, {} quantities",
        file.display(),
        atlas.spec.stretches.len(),
        atlas.spec.lengths.len(),
        if workers == 1 { "" } else { "s" },
        atlas.spec.rho.len(),
        atlas.spec.quantities.len()
    );
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(n as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "runs [{bar:30}] {pos}/{len} {elapsed_precise} (ETA {eta}) {msg}",
            )
            .expect("a valid progress template")
            .progress_chars("=> "),
        );
        b
    });
    // the estimate, from the first run this process finishes (the longest tubes run first,
    // so it is an upper bound per run)
    let estimated = std::sync::atomic::AtomicBool::new(false);
    let progress = |p: Progress| {
        let r = p.result;
        if !p.resumed
            && r.error.is_none()
            && !estimated.swap(true, std::sync::atomic::Ordering::SeqCst)
        {
            let left = p.total - p.done;
            let secs = r.seconds * left as f64 / workers.min(left.max(1)) as f64;
            let line = format!(
                "estimate: the first run took {:.1} s; the {left} left on {workers} worker{} take at most about {}",
                r.seconds,
                if workers == 1 { "" } else { "s" },
                tubemem_app::atlas::duration_words(secs)
            );
            match &bar {
                Some(b) => b.println(line),
                None => {
                    let _ = writeln!(std::io::stderr(), "{line}");
                }
            }
        }
        let what = match (&r.error, p.resumed) {
            (_, true) => "kept from the earlier run".to_string(),
            (Some(e), _) => format!("FAILED: {e}"),
            (None, _) => format!("{:.1} s", r.seconds),
        };
        let line = format!("[{}/{}] {} {what}", p.done, p.total, r.name);
        match &bar {
            Some(b) => {
                b.set_position(p.done as u64);
                if r.error.is_some() {
                    b.println(line);
                } else {
                    b.set_message(format!("{} {what}", r.name));
                }
            }
            None => {
                let _ = writeln!(std::io::stderr(), "{line}");
            }
        }
    };
    let outcome = atlas::run(&atlas, &text, &out, workers, &progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let outcome = match outcome {
        Ok(o) => o,
        Err(e) => return setup(tubemem_app::error_chain(&e)),
    };
    if !outcome.missing.is_empty() {
        let _ = writeln!(
            std::io::stderr(),
            "interrupted: {} of {n} runs are done and kept; run the same command again to do the {} missing ({})",
            n - outcome.missing.len(),
            outcome.missing.len(),
            atlas::missing_summary(&outcome.missing)
        );
        return 130;
    }
    let mut o = std::io::stdout().lock();
    let failed: Vec<&str> = outcome
        .results
        .iter()
        .filter(|r| r.error.is_some())
        .map(|r| r.name.as_str())
        .collect();
    let flagged = outcome.points.iter().filter(|p| p.flag.is_some()).count();
    let _ = writeln!(
        o,
        "{} points (λs*, ρ, quantity): {} with a law, {flagged} flagged (atlas.csv says why); {} runs resumed",
        outcome.points.len(),
        outcome.points.len() - flagged,
        outcome.resumed
    );
    for p in &outcome.written {
        let _ = writeln!(o, "wrote {}", p.display());
    }
    if failed.is_empty() {
        0
    } else {
        let _ = writeln!(
            std::io::stderr(),
            "{} member runs failed (kept as errors in runs.csv; their points are flagged): {}",
            failed.len(),
            failed.join(", ")
        );
        1
    }
}

fn predict(dir: &std::path::Path, s: f64, rho: f64, l: f64, json: bool) -> u8 {
    let result = atlas::predict::read(dir)
        .and_then(|a| Ok((atlas::predict::predict(&a, s, rho, l)?, a.spec.lengths)));
    let (preds, lengths) = match result {
        Ok(p) => p,
        Err(e) => return setup(tubemem_app::error_chain(&e)),
    };
    let mut o = std::io::stdout().lock();
    if json {
        let v = serde_json::json!({
            "lambda_s_star": s, "rho": rho, "length_ratio": l, "predictions": preds,
        });
        let _ = writeln!(
            o,
            "{}",
            serde_json::to_string_pretty(&v).expect("plain data")
        );
        return 0;
    }
    let _ = writeln!(
        o,
        "λs* = {s}, ρ = {rho}, L/R = {l}: FE/GPS − 1 = c + end effect"
    );
    let longest = lengths.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let shortest = lengths.iter().copied().fold(f64::INFINITY, f64::min);
    if l > longest {
        let _ = writeln!(
            o,
            "note: L/R = {l} is beyond the longest run (L/R = {longest}): the end effect is the fitted law's extrapolation"
        );
    }
    let _ = writeln!(
        o,
        "{:<10} {:>12} {:>12} {:>12}  minimum L/R per ε",
        "quantity", "FE/GPS − 1", "end effect", "c"
    );
    for p in preds {
        let mins: Vec<String> = p
            .min_length_ratio
            .iter()
            .map(|(e, m)| match atlas::fit::extent(*m, &lengths) {
                atlas::fit::Extent::BelowRuns => format!("{e:e}: ≤ {shortest} (below the runs)"),
                atlas::fit::Extent::BeyondRuns => format!("{e:e}: {m:.1} (extrapolated)"),
                atlas::fit::Extent::Within => format!("{e:e}: {m:.1}"),
            })
            .collect();
        let _ = writeln!(
            o,
            "{:<10} {:>12.4e} {:>12.4e} {:>12.4e}  {}",
            p.quantity,
            p.error,
            p.end_effect,
            p.c,
            mins.join(", ")
        );
    }
    0
}
