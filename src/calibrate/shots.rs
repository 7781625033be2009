//! The experiments file of a calibration: one row per experiment (shot),
//! each column a parameter of the scene (the shot's settings) or an
//! observable (its measurement), in the project's own vocabulary.
//!
//! Reserved columns: `shot` (a label), `sigma_NAME` (the uncertainty of the
//! measurement `NAME`, in its unit), `outline` (a measured outline of the
//! rod: a CSV file of `z_m,r_m` as `run --profile` writes it, relative to
//! the experiments file's folder) and `sigma_outline` (m). Lines that start
//! with `#` are comments. An empty cell of a measurement means "not
//! measured in this shot"; a setting must be given.

use crate::error::{Error, Result};
use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// One measured value.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The observable's name.
    pub name: String,
    /// The measured value, in the observable's unit.
    pub value: f64,
    /// Its uncertainty, if given.
    pub sigma: Option<f64>,
}

/// A measured outline of the rod.
#[derive(Debug, Clone, PartialEq)]
pub struct Outline {
    /// The file it was read from.
    pub path: PathBuf,
    /// Points `(z, r)` (m), from the impact face up.
    pub points: Vec<[f64; 2]>,
    /// Uncertainty of a radius (m), if given.
    pub sigma: Option<f64>,
}

/// One experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct Shot {
    /// Its label (the `shot` column, or its line number).
    pub label: String,
    /// Its line in the experiments file.
    pub line: u64,
    /// The scene's parameters it sets, in column order.
    pub settings: Vec<(String, f64)>,
    /// Its measurements, in column order.
    pub observed: Vec<Measured>,
    /// Its measured outline, if given.
    pub outline: Option<Outline>,
}

impl Shot {
    /// Its measurements (one per measured observable, one per outline
    /// point).
    pub fn measurements(&self) -> usize {
        self.observed.len() + self.outline.as_ref().map_or(0, |o| o.points.len())
    }
}

/// What one column of the file holds.
#[derive(Debug, Clone, PartialEq)]
enum Column {
    Label,
    Setting(String),
    Observed(String),
    Sigma(String),
    Outline,
    OutlineSigma,
}

/// Reads the experiments file at `path` against `scene` (the fixed part of
/// the fit): each setting is checked by building the shot's scene.
pub fn read(path: &Path, scene: &Scene) -> Result<Vec<Shot>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse(&text, path, scene)
}

/// Parses the text of an experiments file named `path` (for the messages
/// and the outlines' folder).
pub fn parse(text: &str, path: &Path, scene: &Scene) -> Result<Vec<Shot>> {
    let file = path.display().to_string();
    let fail = |line: u64, col: Option<usize>, what: String| {
        Error::ShotsFile(match col {
            Some(c) => format!("{file}, line {line}, column {}: {what}", c + 1),
            None => format!("{file}, line {line}: {what}"),
        })
    };
    let mut rdr = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header = rdr
        .headers()
        .map_err(|e| fail(csv_line(&e).unwrap_or(1), None, e.to_string()))?
        .clone();
    let header_line = header_line(text);
    let observables: Vec<&str> = scene
        .kind()
        .observable_specs()
        .iter()
        .map(|s| s.name)
        .collect();
    let params: Vec<&str> = scene.param_specs().iter().map(|s| s.name).collect();
    let mut columns = Vec::new();
    for (c, name) in header.iter().enumerate() {
        let column = if name == "shot" {
            Column::Label
        } else if name == "outline" {
            Column::Outline
        } else if name == "sigma_outline" {
            Column::OutlineSigma
        } else if let Some(of) = name.strip_prefix("sigma_") {
            if !observables.contains(&of) {
                return Err(fail(
                    header_line,
                    Some(c),
                    format!(
                        "`{name}` is the uncertainty of `{of}`, which is not an observable of scene `{}`; observables: {}",
                        scene.kind().name(),
                        observables.join(", ")
                    ),
                ));
            }
            Column::Sigma(of.to_string())
        } else if observables.contains(&name) {
            Column::Observed(name.to_string())
        } else if params.contains(&name) {
            Column::Setting(name.to_string())
        } else {
            return Err(fail(
                header_line,
                Some(c),
                format!(
                    "`{name}` is neither a parameter nor an observable of scene `{}` (nor shot, outline or sigma_NAME); \
                     parameters: {}; observables: {}",
                    scene.kind().name(),
                    params.join(", "),
                    observables.join(", ")
                ),
            ));
        };
        if columns.contains(&column) {
            return Err(fail(
                header_line,
                Some(c),
                format!("`{name}` appears twice"),
            ));
        }
        columns.push(column);
    }
    if !columns
        .iter()
        .any(|c| matches!(c, Column::Observed(_) | Column::Outline))
    {
        return Err(fail(
            header_line,
            None,
            format!(
                "no column is a measurement: name at least one observable of scene `{}` ({})",
                scene.kind().name(),
                observables.join(", ")
            ),
        ));
    }
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut shots = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| fail(csv_line(&e).unwrap_or(0), None, e.to_string()))?;
        let line = rec.position().map_or(0, |p| p.line());
        let number = |c: usize, cell: &str| -> Result<f64> {
            let v: f64 = cell
                .parse()
                .map_err(|_| fail(line, Some(c), format!("`{cell}` is not a number")))?;
            if !v.is_finite() {
                return Err(fail(
                    line,
                    Some(c),
                    format!("{cell} is not a finite number"),
                ));
            }
            Ok(v)
        };
        // An uncertainty: a finite positive number.
        let sigma = |c: usize, cell: &str, column: &str| -> Result<f64> {
            let s = number(c, cell)?;
            if s <= 0.0 {
                return Err(fail(
                    line,
                    Some(c),
                    format!("{column} = {cell}: an uncertainty must be positive"),
                ));
            }
            Ok(s)
        };
        let mut shot = Shot {
            label: format!("line {line}"),
            line,
            settings: Vec::new(),
            observed: Vec::new(),
            outline: None,
        };
        let mut sigmas = Vec::new();
        let mut outline_sigma = None;
        let mut shot_scene = scene.clone();
        for (c, column) in columns.iter().enumerate() {
            let cell = rec.get(c).unwrap_or("");
            match column {
                Column::Label => {
                    if !cell.is_empty() {
                        shot.label = cell.to_string();
                    }
                }
                Column::Setting(name) => {
                    if cell.is_empty() {
                        return Err(fail(
                            line,
                            Some(c),
                            format!("the setting `{name}` is empty"),
                        ));
                    }
                    let v = scene
                        .spec(name)?
                        .parse(cell)
                        .map_err(|e| fail(line, Some(c), e.to_string()))?;
                    shot_scene
                        .set(name, v)
                        .map_err(|e| fail(line, Some(c), e.to_string()))?;
                    shot.settings.push((name.clone(), v));
                }
                Column::Observed(name) => {
                    if !cell.is_empty() {
                        shot.observed.push(Measured {
                            name: name.clone(),
                            value: number(c, cell)?,
                            sigma: None,
                        });
                    }
                }
                Column::Sigma(name) => {
                    if !cell.is_empty() {
                        let s = sigma(c, cell, &format!("sigma_{name}"))?;
                        sigmas.push((c, name.clone(), s));
                    }
                }
                Column::Outline => {
                    if !cell.is_empty() {
                        let p = folder.join(cell);
                        let points = read_outline(&p).map_err(|e| fail(line, Some(c), e))?;
                        shot.outline = Some(Outline {
                            path: p,
                            points,
                            sigma: None,
                        });
                    }
                }
                Column::OutlineSigma => {
                    if !cell.is_empty() {
                        outline_sigma = Some(sigma(c, cell, "sigma_outline")?);
                    }
                }
            }
        }
        for (c, name, s) in sigmas {
            match shot.observed.iter_mut().find(|m| m.name == name) {
                Some(m) => m.sigma = Some(s),
                None => {
                    return Err(fail(
                        line,
                        Some(c),
                        format!("sigma_{name} is given but `{name}` is not measured in this shot"),
                    ));
                }
            }
        }
        if let Some(s) = outline_sigma {
            match &mut shot.outline {
                Some(o) => o.sigma = Some(s),
                None => {
                    return Err(fail(
                        line,
                        None,
                        "sigma_outline is given but no outline".into(),
                    ));
                }
            }
        }
        for m in &shot.observed {
            if m.value == 0.0 && m.sigma.is_none() {
                let c = columns
                    .iter()
                    .position(|x| *x == Column::Observed(m.name.clone()))
                    .unwrap_or(0);
                return Err(fail(
                    line,
                    Some(c),
                    format!(
                        "{} = 0 has no relative error; give sigma_{} (its uncertainty)",
                        m.name, m.name
                    ),
                ));
            }
        }
        if shot.measurements() == 0 {
            return Err(fail(line, None, "the shot has no measurement".into()));
        }
        shot_scene
            .validate()
            .map_err(|e| fail(line, None, e.to_string()))?;
        shots.push(shot);
    }
    if shots.is_empty() {
        return Err(Error::ShotsFile(format!("{file}: no experiments (rows)")));
    }
    Ok(shots)
}

/// The line of the header: the first that is not a comment.
fn header_line(text: &str) -> u64 {
    text.lines()
        .position(|l| !l.trim_start().starts_with('#'))
        .map_or(1, |k| k as u64 + 1)
}

/// The line of a CSV error, where the parser knows it.
fn csv_line(e: &csv::Error) -> Option<u64> {
    e.position().map(|p| p.line())
}

/// Reads a measured outline: `z_m,r_m` rows (as `run --profile` writes),
/// finite, with z increasing.
fn read_outline(path: &Path) -> std::result::Result<Vec<[f64; 2]>, String> {
    let text =
        std::fs::read_to_string(path).map_err(|e| format!("outline {}: {e}", path.display()))?;
    let mut rdr = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let bad = |line: u64, what: String| format!("outline {}, line {line}: {what}", path.display());
    let header = rdr.headers().map_err(|e| bad(1, e.to_string()))?.clone();
    if header.len() != 2 || &header[0] != "z_m" || &header[1] != "r_m" {
        return Err(bad(
            1,
            "expected the header `z_m,r_m` (as run --profile writes)".into(),
        ));
    }
    let mut points: Vec<[f64; 2]> = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| bad(csv_line(&e).unwrap_or(0), e.to_string()))?;
        let line = rec.position().map_or(0, |p| p.line());
        let v = |k: usize| -> std::result::Result<f64, String> {
            let cell = rec.get(k).unwrap_or("");
            cell.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad(line, format!("`{cell}` is not a finite number")))
        };
        let (z, r) = (v(0)?, v(1)?);
        if r <= 0.0 {
            return Err(bad(line, format!("radius {r} must be positive")));
        }
        if points.last().is_some_and(|p| z < p[0]) {
            return Err(bad(
                line,
                format!("z = {z} decreases (the outline runs from the impact face up)"),
            ));
        }
        points.push([z, r]);
    }
    if points.len() < 2 {
        return Err(bad(1, "an outline needs at least two points".into()));
    }
    Ok(points)
}
