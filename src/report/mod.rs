//! The verification report (`meshless-impact report --out DIR`): error against
//! run time, sensitivity, Table 1, figures like the paper's, a stability
//! matrix of stiff, extreme and invalid cases, the large-strain
//! benchmarks beside their references, and the seed's ballistic case with
//! its damage zones. It is written as `DIR/index.md`
//! with a CSV file for every table and an SVG file for every figure.
//!
//! The report is a module of the program, not of the library (cargo feature
//! `report`, on by default, with its plotting dependency): it only uses the
//! library's public API ([`Simulation`](meshless_impact::Simulation),
//! [`Scene`](meshless_impact::Scene)), and the physics core knows nothing of
//! it.
//!
//! Wall times: the convergence runs go one at a time, each using every core
//! through the solver's own parallelism, so their wall times are comparable.
//! The sensitivity, Table 1 and stability cases run side by side (rayon) and
//! share the cores, so their wall times are only indicative.

mod benchmarks;
mod convergence;
pub mod digest;
mod figures;
mod penetration;
pub mod plot;
mod profiles;
pub mod runner;
mod sensitivity;
mod stability;

use meshless_impact::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to generate.
#[derive(Debug, Clone)]
pub struct ReportOptions {
    /// Output directory (created if missing).
    pub out: PathBuf,
    /// Coarse resolutions and a reduced stability matrix (for the tests).
    pub quick: bool,
}

/// Resolutions and case lists of one mode.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    pub quick: bool,
    /// Noh particle counts for the convergence study.
    pub noh: Vec<usize>,
    /// Taylor particles across the radius for the convergence study.
    pub taylor: Vec<usize>,
    /// Nodes across the radius of the 3-D (`taylor3d`) runs of the study.
    pub taylor3d: Vec<usize>,
    /// Particles across the radius of the sensitivity, Table 1 and stability runs.
    pub resolution: f64,
    /// Resolution of the test 7 time histories and maps.
    pub figures: f64,
    /// Wall-clock budget of one stability case, seconds.
    pub wall_budget: f64,
}

impl Plan {
    fn new(quick: bool) -> Self {
        if quick {
            Plan {
                quick,
                noh: vec![100, 200, 400],
                taylor: vec![4, 6, 8],
                taylor3d: vec![3],
                resolution: 6.0,
                figures: 8.0,
                wall_budget: 120.0,
            }
        } else {
            Plan {
                quick,
                noh: vec![100, 200, 400, 800, 1600, 3200],
                taylor: vec![8, 10, 15, 20, 31, 41, 61],
                taylor3d: vec![3, 4, 6],
                resolution: 20.0,
                figures: 20.0,
                wall_budget: 7200.0,
            }
        }
    }
}

/// A table: written as CSV and shown in the Markdown report.
#[derive(Debug, Clone)]
pub struct Table {
    /// File stem of the CSV file.
    pub name: String,
    /// Column names.
    pub header: Vec<String>,
    /// Rows of formatted cells.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new(name: &str, header: &[&str]) -> Self {
        Table {
            name: name.to_string(),
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row.
    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.header.len(), "{}", self.name);
        self.rows.push(row);
    }

    /// Writes `DIR/<name>.csv`.
    pub fn write_csv(&self, dir: &Path) -> Result<()> {
        let path = dir.join(format!("{}.csv", self.name));
        meshless_impact::files::write_whole(&path, |o| {
            let mut w = csv::Writer::from_writer(o);
            w.write_record(&self.header)?;
            for r in &self.rows {
                w.write_record(r)?;
            }
            w.flush()
        })
    }

    /// The table in Markdown, with a link to its CSV file.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        let esc = |c: &str| c.replace('|', "\\|");
        let _ = writeln!(s, "| {} |", self.header.join(" | "));
        let _ = writeln!(s, "|{}", "---|".repeat(self.header.len()));
        for r in &self.rows {
            let cells: Vec<String> = r.iter().map(|c| esc(c)).collect();
            let _ = writeln!(s, "| {} |", cells.join(" | "));
        }
        let _ = writeln!(s, "\n(CSV: [{0}.csv]({0}.csv))\n", self.name);
        s
    }
}

/// Writes one progress line to stderr. A closed or full stderr loses the
/// line and nothing else: progress never stops or panics a report.
macro_rules! progress {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}
pub(crate) use progress;

/// Formats a number with `d` significant digits (scientific when very small or large).
pub(crate) fn sig(v: f64, d: usize) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-3..6).contains(&mag) {
        return format!("{:.*e}", d.saturating_sub(1), v);
    }
    let decimals = (d as i32 - 1 - mag).max(0) as usize;
    format!("{v:.decimals$}")
}

/// Formats a signed percentage with two decimals.
pub(crate) fn pct(v: f64, reference: f64) -> String {
    format!("{:+.2}%", 100.0 * (v - reference) / reference)
}

/// Markdown being assembled, with the tables and figures written beside it.
pub(crate) struct Doc<'a> {
    pub dir: &'a Path,
    pub text: String,
    pub files: Vec<String>,
}

impl Doc<'_> {
    /// Writes the table's CSV and appends its Markdown.
    pub fn table(&mut self, t: &Table) -> Result<()> {
        t.write_csv(self.dir)?;
        self.files.push(format!("{}.csv", t.name));
        self.text.push_str(&t.markdown());
        Ok(())
    }

    /// Draws a line plot and appends the image link.
    pub fn lines(&mut self, file: &str, ax: plot::Axes, series: &[plot::Series]) -> Result<()> {
        plot::lines(&self.dir.join(file), ax, series)?;
        self.image(file, ax.title);
        Ok(())
    }

    /// Appends an image link to a figure already written.
    pub fn image(&mut self, file: &str, alt: &str) {
        self.files.push(file.to_string());
        let _ = writeln!(self.text, "![{alt}]({file})\n");
    }

    /// Appends a paragraph.
    pub fn para(&mut self, s: &str) {
        self.text.push_str(s);
        self.text.push_str("\n\n");
    }
}

/// What was written.
#[derive(Debug, Clone)]
pub struct Report {
    /// Files written, relative to the output directory (index.md last).
    pub files: Vec<String>,
    /// Wall time of the whole report, seconds.
    pub wall_s: f64,
}

/// A short description of the machine: CPU model, cores, memory, OS.
pub fn machine() -> String {
    let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
    let cpu = read("/proc/cpuinfo")
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split(':').nth(1))
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mem = read("/proc/meminfo")
        .lines()
        .find(|l| l.starts_with("MemTotal"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kb| kb.parse::<f64>().ok())
        .map_or_else(
            || "unknown memory".into(),
            |kb| format!("{:.0} GiB", kb / 1048576.0),
        );
    format!(
        "{cpu}, {cores} cores available, {mem}, {} {}",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

/// Runs every study and writes the report into `opts.out`.
pub fn generate(opts: &ReportOptions) -> Result<Report> {
    let start = Instant::now();
    let plan = Plan::new(opts.quick);
    let dir = opts.out.as_path();
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut doc = Doc {
        dir,
        text: String::new(),
        files: Vec::new(),
    };
    let command = format!(
        "meshless-impact report --out {}{}",
        dir.display(),
        if opts.quick { " --quick" } else { "" }
    );
    let _ = write!(
        doc.text,
        "# Verification report: error against run time, sensitivity, stability\n\n\
         Generated by `{command}` (meshless-impact {}, an optimised build) on: {}.\n\n\
         Physics digest: `{}` (`meshless-impact report --digest` prints the code's: the \
         bits of small runs of every solver; when it differs from this one, the code \
         no longer gives these figures and the report must be generated again).\n\n\
         Mode: **{}**. Every number below was measured by that command; each table \
         is also a CSV file in this directory and each figure an SVG file. \
         References: Batra & Zhang (2008), J. Comput. Phys. 227:1962 (\"the paper\"), \
         House et al. (1995) as tabulated in its Table 1.\n\n\
         Wall times: the convergence runs (sections 1-2) run one at a time and each \
         uses every core, so their wall times are comparable with each other. The \
         sensitivity, Table 1 and stability cases run side by side and share the \
         cores: their wall times are indicative only.\n\n",
        meshless_impact::VERSION,
        machine(),
        digest::format(digest::physics_digest()?),
        if opts.quick {
            "quick (coarse resolutions and a reduced stability matrix, for the tests)"
        } else {
            "full"
        }
    );
    convergence::noh(&plan, &mut doc)?;
    let (taylor, figure_run) = convergence::taylor(&plan, &mut doc)?;
    convergence::taylor3d(&plan, &mut doc, &taylor)?;
    figures::test7(&plan, &mut doc, figure_run)?;
    profiles::aisi310(&plan, &mut doc)?;
    sensitivity::smoothing(&plan, &mut doc)?;
    sensitivity::table1(&plan, &mut doc)?;
    stability::matrix(&plan, &mut doc)?;
    benchmarks::run(&plan, &mut doc)?;
    penetration::damage(&plan, &mut doc)?;
    penetration::ballistic_limit(&plan, &mut doc)?;
    let wall_s = start.elapsed().as_secs_f64();
    let _ = writeln!(doc.text, "---\n\nWhole report: {wall_s:.1} s wall time.");
    let index = dir.join("index.md");
    meshless_impact::files::write_whole_bytes(&index, doc.text.as_bytes())?;
    doc.files.push("index.md".into());
    Ok(Report {
        files: doc.files,
        wall_s,
    })
}
