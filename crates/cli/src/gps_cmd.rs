//! `tubemem gps …` and the default job.
use crate::material_args::{add_si, Hyp, MaterialArgs, UnitArgs};
use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use serde::Serialize;
use std::path::PathBuf;
use tubemem_app::curves::{
    flattening_values, inflation_values, FLATTENING_HEADER, INFLATION_HEADER,
};
use tubemem_gps::limits::{limit_points, Limits};
use tubemem_gps::{flatten, flattening_curve, inflate, inflation_curve, Hypothesis};

fn write_csv(
    path: &std::path::Path,
    header: &str,
    rows: impl Iterator<Item = Vec<f64>>,
) -> Result<()> {
    tubemem_app::curves::write_csv(path, header, rows).map_err(|e| anyhow::anyhow!(e.chain()))
}

/// The output policy for a file a `gps` command writes (`key` its option): not an input (the
/// `--law` file, `--ring`), and an existing file only where it is one of this command's own
/// (its first line `header`), or with `--overwrite`.
fn may_write(
    key: &'static str,
    path: &std::path::Path,
    inputs: &[&std::path::Path],
    header: &str,
    overwrite: bool,
) -> Result<()> {
    tubemem_app::output_file::check(key, path, inputs, |text| {
        overwrite || text.starts_with(header)
    })
    .map_err(|e| anyhow::anyhow!(e.chain()))
}

/// Whether `text` begins as a figure tubemem wrote (an SVG of plotters' with its title) or a
/// PNG (whose writer cannot be told: replaced only with `--overwrite`).
fn figure_title(title: &'static str) -> impl Fn(&str) -> bool {
    move |text: &str| text.starts_with("<svg") && text.contains(title)
}

/// The `--law` argument's file, when it names one (an input no output may replace).
fn law_file(law: &Option<String>) -> Option<PathBuf> {
    law.as_ref().map(PathBuf::from).filter(|p| p.is_file())
}

/// The first columns of `gps confine --csv` (each wall's contact and force follow).
const CONFINE_HEADER: &str = "scale,w,lambda_s,lambda_z,n_s,n_z,r,area,regime";

/// The title of `gps confine --figure`.
const SECTION_TITLE: &str = "Confined cross-section (GPS closed form, eqs. 55–60)";

#[derive(Subcommand, Debug)]
pub enum GpsCommand {
    /// Free inflation (eqs. 66 and 70): one state at --stretch, or a curve --from/--to/--points into --csv.
    Inflate(InflateArgs),
    /// Flattening between two plates (eqs. 76–79): the gas closed in (--control gas, the
    /// default) or its pressure regulated (--control pressure: held at the inflated value, or
    /// --pressure; plates closer than R inflated from zero pressure without --initial-stretch),
    /// one state at --rho, or a curve --to/--points into --csv.
    Flatten(FlattenArgs),
    /// Pressure maximum and minimum of the inflation curve and the Maxwell pressure.
    Limits(LimitsArgs),
    /// Confinement by any convex set of planes parallel to the axis (eqs. 55–60): the gas
    /// closed in at --initial-stretch and the walls moved in from first contact, or a given
    /// --pressure. One state (--json), a path into --csv, a figure of the section (--figure).
    Confine(ConfineArgs),
    /// Free inflation in time with a viscoelastic law (a QLV Prony series on the base law):
    /// the pressure, the hoop stretch or the enclosed volume ramped to --to over --ramp, then
    /// held for --hold (creep at constant pressure, relaxation at fixed volume); time steps
    /// doubled until their estimated error is below --tolerance.
    History(crate::gps_history::HistoryArgs),
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct ConfineArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[command(flatten)]
    units: UnitArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: Hyp,
    /// A wall {x : n·x = d} as nx,ny,d, the membrane on the side n·x ≤ d (n need not be unit
    /// length; the axis must be inside: d > 0); d per R, or in m with --radius and
    /// --thickness. Repeat for each wall.
    #[arg(
        long = "plane",
        value_name = "NX,NY,D",
        required = true,
        allow_hyphen_values = true
    )]
    planes: Vec<String>,
    /// The inflated hoop stretch λs* at which the gas is closed in (the walls then move in
    /// from first contact to their offsets d; `--target-stretch` is an alias).
    #[arg(long, conflicts_with = "pressure", visible_alias = "target-stretch")]
    initial_stretch: Option<f64>,
    /// A given pressure instead (no gas law): the reduced pressure ϖ, or in Pa with --radius
    /// and --thickness.
    #[arg(long)]
    pressure: Option<f64>,
    /// With --initial-stretch: the path's number of states (≥ 2), written to --csv.
    #[arg(long, requires = "csv")]
    points: Option<usize>,
    /// Write the path (the walls' offsets scaled from first contact to d) to this CSV file.
    #[arg(long, requires = "initial_stretch")]
    csv: Option<PathBuf>,
    /// Draw the final section and the walls to this figure (.png or .svg).
    #[arg(long)]
    figure: Option<PathBuf>,
    /// Replace an existing --csv or --figure file that this command did not write.
    #[arg(long)]
    overwrite: bool,
    /// With --figure: also draw these FE mid-span ring points (x,y CSV, e.g. a run's
    /// profiles/stage2_midspan_ring.csv).
    #[arg(long, requires = "figure")]
    ring: Option<PathBuf>,
    #[arg(long)]
    json: bool,
}

fn parse_plane(text: &str) -> Result<tubemem_gps::confine::Wall> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| anyhow::anyhow!("--plane {text:?}: expected three numbers nx,ny,d"))?;
    let [nx, ny, d] = v[..] else {
        bail!(
            "--plane {text:?}: expected three numbers nx,ny,d, got {}",
            v.len()
        );
    };
    Ok(tubemem_gps::confine::Wall::new(nx, ny, d)?)
}

fn confine_json(s: &tubemem_gps::confine::ConfineState) -> Result<serde_json::Value> {
    let mut nums = vec![s.w, s.lambda_s, s.lambda_z, s.n_s, s.n_z, s.r, s.area];
    nums.extend(s.walls.iter().flat_map(|w| [w.contact_length, w.force]));
    ensure_finite(&nums)?;
    Ok(serde_json::to_value(s)?)
}

fn run_confine(a: ConfineArgs) -> Result<()> {
    use tubemem_app::units::Dimension;
    use tubemem_gps::confine::{confine_at_pressure, confine_path, section_outline};
    let law = a.material.build()?;
    let units = a.units.units(law.as_ref())?;
    let hyp: Hypothesis = a.hypothesis.into();
    // with SI units the offsets are lengths in m: the closed form takes them per R
    let walls = a
        .planes
        .iter()
        .map(|p| {
            let w = parse_plane(p)?;
            Ok(tubemem_gps::confine::Wall::new(
                w.normal[0],
                w.normal[1],
                units.to_core(Dimension::Length, w.offset),
            )?)
        })
        .collect::<Result<Vec<_>>>()?;
    // every output checked against every input and existing file before anything is read
    // or written: the --ring file may not be the --csv or the --figure
    let law_path = law_file(&a.material.law);
    let inputs: Vec<&std::path::Path> = law_path
        .iter()
        .map(|p| p.as_path())
        .chain(a.ring.as_deref())
        .collect();
    if let Some(csv) = &a.csv {
        may_write("--csv", csv, &inputs, CONFINE_HEADER, a.overwrite)?;
    }
    if let Some(fig) = &a.figure {
        let title = figure_title(SECTION_TITLE);
        tubemem_app::output_file::check("--figure", fig, &inputs, |t| a.overwrite || title(t))
            .map_err(|e| anyhow::anyhow!(e.chain()))?;
    }
    if let (Some(c), Some(f)) = (&a.csv, &a.figure) {
        if c == f {
            bail!(
                "--csv and --figure name the same file {}: give two",
                c.display()
            );
        }
    }
    let path = match (a.initial_stretch, a.pressure) {
        (Some(ls0), None) => confine_path(law.as_ref(), hyp, &walls, ls0, a.points.unwrap_or(2))?,
        (None, Some(p)) => vec![confine_at_pressure(
            law.as_ref(),
            hyp,
            &walls,
            units.to_core(Dimension::Pressure, p),
        )?],
        _ => bail!("give --initial-stretch λs* (the gas closed in) or --pressure ϖ"),
    };
    let Some(last) = path.last() else {
        bail!("internal error: an empty confinement path; please report this input");
    };
    if let Some(csv) = &a.csv {
        let mut header = CONFINE_HEADER.to_string();
        for k in 0..walls.len() {
            header.push_str(&format!(",contact_{k},force_{k}"));
        }
        let mut text = header + "\n";
        for s in &path {
            confine_json(s)?;
            let mut row = [
                s.scale, s.w, s.lambda_s, s.lambda_z, s.n_s, s.n_z, s.r, s.area,
            ]
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>();
            row.push(format!("{:?}", s.regime).to_lowercase());
            for w in &s.walls {
                row.push(w.contact_length.to_string());
                row.push(w.force.to_string());
            }
            text.push_str(&row.join(","));
            text.push('\n');
        }
        tubemem_mesh::file::write_whole(csv, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: {e}", csv.display()))?;
        crate::say!("wrote {} states to {}", path.len(), csv.display())?;
    }
    if let Some(fig) = &a.figure {
        let ring = match &a.ring {
            None => vec![],
            Some(p) => {
                let text =
                    tubemem_mesh::io::read_text_limited(p, tubemem_mesh::io::MAX_TEXT_INPUT_BYTES)
                        .map_err(|e| anyhow::anyhow!("--ring {}: {e}", p.display()))?;
                text.lines()
                    .skip(1)
                    .enumerate()
                    .map(|(k, l)| {
                        let v: Vec<f64> =
                            l.split(',').filter_map(|t| t.trim().parse().ok()).collect();
                        match v[..] {
                            [x, y] if x.is_finite() && y.is_finite() => Ok((x, y)),
                            _ => Err(anyhow::anyhow!(
                                "--ring {} line {}: expected x,y",
                                p.display(),
                                k + 2
                            )),
                        }
                    })
                    .collect::<Result<Vec<_>>>()?
            }
        };
        draw_section(
            fig,
            &walls,
            last,
            &section_outline(&walls, last, 720),
            &ring,
        )?;
        crate::say!("wrote {}", fig.display())?;
    }
    let mut v = confine_json(last)?;
    add_si(&mut v, &units);
    if a.json {
        crate::say!("{v}")?;
    } else if a.csv.is_none() {
        print_state(last, false, &units)?;
    }
    Ok(())
}

/// The section (closed outline) and the walls (segments across the picture).
fn draw_section(
    path: &std::path::Path,
    walls: &[tubemem_gps::confine::Wall],
    state: &tubemem_gps::confine::ConfineState,
    outline: &[[f64; 2]],
    ring: &[(f64, f64)],
) -> Result<()> {
    use tubemem_app::figures::{Figure, FigureOptions, Markers, Series, Stroke};
    let extent = outline
        .iter()
        .fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()))
        * 1.3;
    let mut series = vec![Series {
        label: format!(
            "section: ϖ = {:.4}, λs = {:.4}, λz = {:.4}, r = {:.4}",
            state.w, state.lambda_s, state.lambda_z, state.r
        ),
        points: outline
            .iter()
            .chain(outline.first())
            .map(|p| (p[0], p[1]))
            .collect(),
        color: plotters::style::RGBColor(31, 90, 180),
        stroke: Stroke::Solid,
        width: 3,
    }];
    for (k, w) in walls.iter().enumerate() {
        let d = w.offset * state.scale;
        let (n, t) = (w.normal, [-w.normal[1], w.normal[0]]);
        let p0 = [n[0] * d, n[1] * d];
        series.push(Series {
            label: format!(
                "wall {}: contact {:.4} R, force {:.4}",
                k + 1,
                state.walls[k].contact_length,
                state.walls[k].force
            ),
            points: vec![
                (p0[0] - extent * t[0], p0[1] - extent * t[1]),
                (p0[0] + extent * t[0], p0[1] + extent * t[1]),
            ],
            color: plotters::style::RGBColor(90, 90, 90),
            stroke: Stroke::Dashed,
            width: 2,
        });
    }
    let fig = Figure {
        markers: if ring.is_empty() {
            vec![]
        } else {
            vec![Markers {
                label: "FE mid-span ring (nodes)".into(),
                points: ring.to_vec(),
                color: plotters::style::RGBColor(20, 140, 60),
                hollow: true,
            }]
        },
        equal_aspect: true,
        y_from_zero: false,
        ..Figure::new(SECTION_TITLE, "x/R", "y/R", series)
    };
    let stem = path.with_extension("");
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("png");
    let opts = FigureOptions {
        png: ext == "png",
        svg: ext == "svg",
        ..FigureOptions::default()
    };
    tubemem_app::figures::save(&fig, &stem, &opts).map_err(|e| anyhow::anyhow!(e.chain()))?;
    Ok(())
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct InflateArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[command(flatten)]
    units: UnitArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: Hyp,
    /// Hoop stretch λs (≥ 1) for a single state.
    #[arg(long)]
    stretch: Option<f64>,
    /// First λs of a curve.
    #[arg(long)]
    from: Option<f64>,
    /// Last λs of a curve.
    #[arg(long)]
    to: Option<f64>,
    /// Number of points of a curve (≥ 2).
    #[arg(long)]
    points: Option<usize>,
    /// Write the curve to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Replace an existing --csv file that this command did not write.
    #[arg(long)]
    overwrite: bool,
    /// Print one JSON object (a single state) instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct FlattenArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[command(flatten)]
    units: UnitArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: Hyp,
    /// The inflated hoop stretch λs* at which the plates start (the case file's
    /// `target_stretch` of the inflation; `--target-stretch` is an alias). Required with the
    /// gas closed in.
    #[arg(long, visible_alias = "target-stretch")]
    initial_stretch: Option<f64>,
    /// How the gas is supplied while the plates close: "gas" (closed in at λs*, Boyle) or
    /// "pressure" (regulated; the case file's `control`).
    #[arg(long, value_enum, default_value = "gas")]
    control: GasSupply,
    /// --control pressure: the pressure the plates end at (ramped from the inflated one; held
    /// when absent), the reduced pressure ϖ, or in Pa with --radius and --thickness. Without
    /// --initial-stretch: plates at --rho < 1 hold the stress-free tube, inflated to it.
    #[arg(long)]
    pressure: Option<f64>,
    /// Half-gap ρ = r/R (0 < ρ < λs*) for a single state (the case file's `target_rho`;
    /// `--target-rho` is an alias).
    #[arg(long, visible_alias = "target-rho")]
    rho: Option<f64>,
    /// Last ρ of a curve that starts at ρ = λs*.
    #[arg(long)]
    to: Option<f64>,
    /// Number of points of a curve (≥ 2).
    #[arg(long)]
    points: Option<usize>,
    /// Write the curve to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Replace an existing --csv file that this command did not write.
    #[arg(long)]
    overwrite: bool,
    #[arg(long)]
    json: bool,
}

/// `--control` of `gps flatten`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum GasSupply {
    /// the gas closed in at λs* (Boyle, eq. 77₂)
    Gas,
    /// a regulated pressure (eqs. 76 at a given pressure)
    Pressure,
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct LimitsArgs {
    #[command(flatten)]
    material: MaterialArgs,
    #[command(flatten)]
    units: UnitArgs,
    #[arg(long, value_enum, default_value = "gps")]
    hypothesis: Hyp,
    #[arg(long)]
    json: bool,
}

/// Refuse to print a non-finite number: it would be a silent wrong answer.
fn ensure_finite(values: &[f64]) -> Result<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        bail!("internal error: a non-finite value was computed ({values:?}); please report this input")
    }
}

fn print_state<T: Serialize>(
    state: &T,
    json: bool,
    units: &tubemem_app::units::Units,
) -> Result<()> {
    let mut v = serde_json::to_value(state)?;
    add_si(&mut v, units);
    if json {
        crate::say!("{v}")?;
    } else if let Some(map) = v.as_object() {
        for (k, x) in map {
            crate::say!("{k:>13} = {x}")?;
        }
    }
    Ok(())
}

/// An error of the closed form names its parameter as the library calls it (`lambda_s`);
/// the user gave a flag: name the flag, with the parameter after it.
fn flagged(e: anyhow::Error, names: &[(&str, &str)]) -> anyhow::Error {
    let mut msg = format!("{e:#}");
    for (name, flag) in names {
        msg = msg.replace(&format!("`{name}`"), &format!("{flag} (`{name}`)"));
    }
    anyhow::anyhow!(msg)
}

pub fn run(cmd: GpsCommand) -> Result<()> {
    let names: &[(&str, &str)] = match &cmd {
        GpsCommand::Inflate(a) if a.stretch.is_some() => &[("lambda_s", "--stretch")],
        GpsCommand::Inflate(_) => &[("lambda_s", "--from/--to"), ("points", "--points")],
        GpsCommand::Flatten(_) => &[
            ("initial_stretch", "--initial-stretch"),
            ("rho", "--rho"),
            ("w", "--pressure"),
            ("points", "--points"),
        ],
        GpsCommand::Confine(_) => &[
            ("initial_stretch", "--initial-stretch"),
            ("pressure", "--pressure"),
            ("points", "--points"),
        ],
        GpsCommand::History(_) => &[
            ("ramp", "--ramp"),
            ("hold", "--hold"),
            ("squeeze_time", "--squeeze-time"),
            ("plates_hold", "--plates-hold"),
            ("target", "--to"),
            ("steps", "--steps"),
            ("tolerance", "--tolerance"),
        ],
        GpsCommand::Limits(_) => &[],
    };
    run_command(cmd).map_err(|e| flagged(e, names))
}

fn run_command(cmd: GpsCommand) -> Result<()> {
    match cmd {
        GpsCommand::History(a) => crate::gps_history::run(a),
        GpsCommand::Inflate(a) => {
            let law = a.material.build()?;
            let hyp = a.hypothesis.into();
            match (a.stretch, a.to, a.points, &a.csv) {
                (Some(ls), None, None, None) if a.from.is_none() => {
                    let s = inflate(law.as_ref(), hyp, ls)?;
                    ensure_finite(&inflation_values(&s))?;
                    print_state(&s, a.json, &a.units.units(law.as_ref())?)
                }
                (None, Some(to), Some(points), Some(csv)) => {
                    let law_file = law_file(&a.material.law);
                    let inputs: Vec<&std::path::Path> = law_file.iter().map(|p| p.as_path()).collect();
                    may_write("--csv", csv, &inputs, INFLATION_HEADER, a.overwrite)?;
                    let from = a.from.unwrap_or(1.0);
                    let c = inflation_curve(law.as_ref(), hyp, from, to, points)?;
                    write_csv(csv, INFLATION_HEADER, c.iter().map(inflation_values))?;
                    crate::say!("wrote {} {} inflation states (λs {from} → {to}) to {}", c.len(), hyp.label(), csv.display())?;
                    Ok(())
                }
                _ => bail!("give either --stretch λs (one state) or --to, --points and --csv (a curve, with optional --from)"),
            }
        }
        GpsCommand::Flatten(a) if a.control == GasSupply::Pressure => run_regulated(a),
        GpsCommand::Flatten(a) => {
            let law = a.material.build()?;
            let hyp = a.hypothesis.into();
            if a.pressure.is_some() {
                bail!("--pressure belongs to --control pressure (a regulated supply); with the gas closed in the pressure follows from Boyle's law");
            }
            let Some(initial_stretch) = a.initial_stretch else {
                bail!("give --initial-stretch λs*: the gas is closed in the tube inflated to it");
            };
            match (a.rho, a.to, a.points, &a.csv) {
                (Some(rho), None, None, None) => {
                    let s = flatten(law.as_ref(), hyp, initial_stretch, rho)?;
                    ensure_finite(&flattening_values(&s))?;
                    print_state(&s, a.json, &a.units.units(law.as_ref())?)
                }
                (None, Some(to), Some(points), Some(csv)) => {
                    let law_file = law_file(&a.material.law);
                    let inputs: Vec<&std::path::Path> =
                        law_file.iter().map(|p| p.as_path()).collect();
                    may_write("--csv", csv, &inputs, FLATTENING_HEADER, a.overwrite)?;
                    let c = flattening_curve(law.as_ref(), hyp, initial_stretch, to, points)?;
                    write_csv(csv, FLATTENING_HEADER, c.iter().map(flattening_values))?;
                    crate::say!(
                        "wrote {} {} flattening states (ρ {} → {to}) to {}",
                        c.len(),
                        hyp.label(),
                        initial_stretch,
                        csv.display()
                    )?;
                    Ok(())
                }
                _ => bail!("give either --rho ρ (one state) or --to, --points and --csv (a curve)"),
            }
        }
        GpsCommand::Confine(a) => run_confine(a),
        GpsCommand::Limits(a) => {
            let law = a.material.build()?;
            let l = limit_points(law.as_ref(), a.hypothesis.into())?;
            print_limits(&l, a.json, &a.units.units(law.as_ref())?)
        }
    }
}

/// `gps flatten --control pressure`: the regulated section at --rho (from the free tube at
/// λs*, or from the stress-free tube held by plates at ρ < 1), with the critical pressure of
/// its plates; or a curve of the regulated squeeze into --csv.
fn run_regulated(a: FlattenArgs) -> Result<()> {
    use tubemem_app::units::Dimension;
    use tubemem_gps::regulated::{
        between_plates, critical_pressure, free_start, plate_stiffness, squeeze_at_pressure,
    };
    let law = a.material.build()?;
    let units = a.units.units(law.as_ref())?;
    let hyp: Hypothesis = a.hypothesis.into();
    let w = a.pressure.map(|p| units.to_core(Dimension::Pressure, p));
    let values = |s: &tubemem_gps::SectionState| {
        [
            s.w, s.lambda_s, s.lambda_z, s.n_s, s.n_z, s.rho, s.chi, s.force,
        ]
    };
    match (a.initial_stretch, a.rho, a.to, a.points, &a.csv) {
        (ls0, Some(rho), None, None, None) => {
            let s = match ls0 {
                Some(ls0) => {
                    let start = free_start(law.as_ref(), hyp, ls0)?;
                    if rho >= ls0 {
                        bail!("--rho {rho} must be below --initial-stretch {ls0}: the plates start at the inflated radius and close");
                    }
                    squeeze_at_pressure(law.as_ref(), hyp, start, rho, w.unwrap_or(start.w))?
                }
                None => {
                    let Some(w) = w else {
                        bail!("give --initial-stretch λs* (the plates close on the inflated tube) or --pressure ϖ (plates at --rho < 1 hold the stress-free tube, inflated to it)");
                    };
                    between_plates(law.as_ref(), hyp, rho, w)?
                }
            };
            ensure_finite(&values(&s))?;
            let mut v = serde_json::to_value(s)?;
            let c = critical_pressure(law.as_ref(), hyp, rho)?;
            let k = plate_stiffness(law.as_ref(), hyp, &s)?;
            if let Some(map) = v.as_object_mut() {
                map.insert("control".into(), "pressure".into());
                map.insert("stiffness".into(), k.into());
                if units.is_si() {
                    map.insert("stiffness_pa".into(), stiffness_si(&units, k).into());
                }
                map.insert("w_critical".into(), c.map(|c| c.w).into());
                if units.is_si() {
                    map.insert(
                        "critical_pressure_pa".into(),
                        c.map(|c| units.from_core(Dimension::Pressure, c.w)).into(),
                    );
                }
                map.insert("lambda_s_critical".into(), c.map(|c| c.lambda_s).into());
            }
            print_state(&v, a.json, &units)
        }
        (Some(ls0), None, Some(to), Some(points), Some(csv)) => {
            let law_file = law_file(&a.material.law);
            let inputs: Vec<&std::path::Path> = law_file.iter().map(|p| p.as_path()).collect();
            may_write("--csv", csv, &inputs, REGULATED_HEADER, a.overwrite)?;
            let rows =
                tubemem_gps::regulated::regulated_curve(law.as_ref(), hyp, ls0, to, points, w)?;
            let rows = rows
                .iter()
                .map(|s| {
                    let mut v = values(s).to_vec();
                    v.push(plate_stiffness(law.as_ref(), hyp, s)?);
                    Ok(v)
                })
                .collect::<Result<Vec<_>, tubemem_gps::GpsError>>()?;
            write_csv(csv, REGULATED_HEADER, rows.iter().cloned())?;
            crate::say!(
                "wrote {} {} regulated flattening states (ρ {ls0} → {to}) to {}",
                rows.len(),
                hyp.label(),
                csv.display()
            )?;
            Ok(())
        }
        _ => bail!(
            "give --rho ρ (one state) or --initial-stretch, --to, --points and --csv (a curve)"
        ),
    }
}

/// The columns of a regulated flattening curve: the state, and the plates' stiffness
/// −d(force)/d(2ρ) at the held pressure (`tubemem_gps::regulated::plate_stiffness`).
const REGULATED_HEADER: &str = "w,lambda_s,lambda_z,n_s,n_z,rho,chi,force,stiffness";

/// A plates' stiffness −dF/dgap (the force per length over πμH, the gap in R) in Pa: N/m of
/// force per length per m of gap.
fn stiffness_si(units: &tubemem_app::units::Units, k: f64) -> f64 {
    use tubemem_app::units::Dimension;
    units.from_core(Dimension::ForcePerLength, k) / units.from_core(Dimension::Length, 1.0)
}

fn print_limits(l: &Limits, json: bool, units: &tubemem_app::units::Units) -> Result<()> {
    use tubemem_app::units::Dimension;
    let pa = |w: f64| {
        if units.is_si() {
            format!(" ({:.6e} Pa)", units.from_core(Dimension::Pressure, w))
        } else {
            String::new()
        }
    };
    let mut nums = vec![];
    for p in [l.max, l.min].into_iter().flatten() {
        nums.extend([p.lambda_s, p.lambda_z, p.w]);
    }
    if let Some(m) = l.maxwell {
        nums.extend([m.w, m.lambda_s_lower, m.lambda_s_upper]);
    }
    ensure_finite(&nums)?;
    if json {
        let mut v = serde_json::json!({ "max": l.max, "min": l.min, "maxwell": l.maxwell });
        for k in ["max", "min", "maxwell"] {
            if let Some(p) = v.get_mut(k) {
                add_si(p, units);
            }
        }
        crate::say!("{v}")?;
        return Ok(());
    }
    let point = |name: &str, p: Option<tubemem_gps::limits::LimitPoint>| match p {
        Some(p) => crate::say!(
            "{name:>8}: ϖ = {:.10}{}  at λs = {:.10}, λz = {:.10}",
            p.w,
            pa(p.w),
            p.lambda_s,
            p.lambda_z
        ),
        None => crate::say!("{name:>8}: none"),
    };
    point("maximum", l.max)?;
    point("minimum", l.min)?;
    match l.maxwell {
        Some(m) => crate::say!(
            " Maxwell: ϖ = {:.10}{}  coexisting λs = {:.10} and {:.10}",
            m.w,
            pa(m.w),
            m.lambda_s_lower,
            m.lambda_s_upper
        )?,
        None => crate::say!(" Maxwell: none")?,
    }
    crate::say!(
        "(inflation curve scanned for λs from 1 to {:.3})",
        l.scanned_to
    )?;
    Ok(())
}
