//! `continuum hardcases`: the numerical hard-case suite (`tests/hard_cases/`)
//! through every algorithm, precision and viewport, at the origin and far from
//! it. Prints a table case × algorithm → violations (or the JSON report) and
//! exits with status 1 on any violation within the documented limits.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use continuum_hardcases::{self as hardcases, Check, SuiteReport};
use serde_json::json;

use std::fmt::Write;

use crate::{CliError, write_stdout};

#[derive(Args, Debug)]
pub struct HardcasesArgs {
    /// Print the whole report (every checked render) as JSON.
    #[arg(long)]
    json: bool,
    /// Folder of case files [default: the repository's tests/hard_cases].
    #[arg(long)]
    cases: Option<PathBuf>,
    /// Run only these cases (names of files without .toml), comma-separated.
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
}

pub fn run(args: &HardcasesArgs) -> Result<bool, CliError> {
    let dir = args
        .cases
        .clone()
        .unwrap_or_else(hardcases::default_cases_dir);
    let mut cases =
        hardcases::load_cases(&dir).map_err(|e| CliError::Usage(format!("--cases: {e}")))?;
    if !args.only.is_empty() {
        if let Some(bad) = args
            .only
            .iter()
            .find(|n| !cases.iter().any(|c| &c.name == *n))
        {
            let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
            return Err(CliError::Usage(format!(
                "--only: no case '{bad}' in {}; cases are: {}",
                dir.display(),
                names.join(", ")
            )));
        }
        cases.retain(|c| args.only.contains(&c.name));
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.threads {
        pool = pool.num_threads(t as usize);
    }
    let pool = pool.build().context("building the thread pool")?;
    let report = pool
        .install(|| hardcases::run_suite(&cases))
        .map_err(|e| CliError::Usage(format!("--cases: {e}")))?;
    let failed = report
        .checks
        .iter()
        .any(|c| c.violations.total() > 0 && !hardcases::beyond_limit(c));
    if args.json {
        let doc = json!({
            "cases_dir": dir.display().to_string(),
            "f32_offset_limit": hardcases::F32_OFFSET_LIMIT,
            "passed": !failed,
            "cases": report.cases,
            "table": table_json(&report),
            "checks": report.checks,
            "not_run": report.not_run.iter().map(|(a, why)| json!({ "algorithm": a, "reason": why })).collect::<Vec<_>>(),
        });
        let text = serde_json::to_string_pretty(&doc).context("encoding JSON")?;
        write_stdout(&(text + "\n"))?;
    } else {
        write_stdout(&table_text(&report))?;
    }
    Ok(!failed)
}

/// Column of a check: the algorithm, with its precision unless f32.
fn column(c: &Check) -> String {
    hardcases::variant_name(c.algorithm, c.precision)
}

/// Per case and column: violations within the limits, and beyond them.
fn tally(report: &SuiteReport) -> BTreeMap<(String, String), (u64, u64)> {
    let mut cells = BTreeMap::new();
    for c in &report.checks {
        let cell: &mut (u64, u64) = cells.entry((c.case.clone(), column(c))).or_default();
        if hardcases::beyond_limit(c) {
            cell.1 += c.violations.total();
        } else {
            cell.0 += c.violations.total();
        }
    }
    cells
}

fn columns() -> Vec<String> {
    hardcases::variants_of_all()
        .into_iter()
        .filter(|(a, _)| continuum::unavailable(*a).is_none())
        .map(|(a, p)| hardcases::variant_name(a, p))
        .collect()
}

fn table_json(report: &SuiteReport) -> serde_json::Value {
    let cells = tally(report);
    let rows: Vec<serde_json::Value> = report
        .cases
        .iter()
        .map(|case| {
            let counts: serde_json::Map<String, serde_json::Value> = columns()
                .into_iter()
                .filter_map(|col| {
                    let (within, beyond) = cells.get(&(case.name.clone(), col.clone()))?;
                    Some((col, json!({ "violations": within, "beyond_limit": beyond })))
                })
                .collect();
            json!({ "case": case.name, "columns": counts })
        })
        .collect();
    serde_json::Value::Array(rows)
}

fn offset_text(o: Option<f64>) -> String {
    o.map_or("none".into(), |v| {
        if v == 0.0 {
            "0".into()
        } else {
            format!("{v:.0e}")
        }
    })
}

/// The table case × algorithm → violations, the column legend and the first
/// violations, as text.
fn table_text(report: &SuiteReport) -> String {
    let mut out = String::new();
    let cells = tally(report);
    let cols = columns();
    writeln!(
        out,
        "violations per case and algorithm (0 = every invariant holds; +N = N beyond a documented limit: the case's [limits], or f32 beyond an offset of {:.0e}):",
        hardcases::F32_OFFSET_LIMIT
    ).ok();
    write!(out, "{:<22}", "case").ok();
    for (k, _) in cols.iter().enumerate() {
        write!(out, " {:>4}", format!("c{k}")).ok();
    }
    writeln!(
        out,
        "   f32 first violation   f64 holds   fixed/gpu first violation"
    )
    .ok();
    for case in &report.cases {
        write!(out, "{:<22}", case.name).ok();
        for col in &cols {
            let text = match cells.get(&(case.name.clone(), col.clone())) {
                None => "-".to_string(),
                Some((0, 0)) => "0".to_string(),
                Some((w, 0)) => w.to_string(),
                Some((0, b)) => format!("+{b}"),
                Some((w, b)) => format!("{w}+{b}"),
            };
            write!(out, " {text:>4}").ok();
        }
        writeln!(
            out,
            "   {:<21} {:<11} {}",
            offset_text(case.f32_first_violation),
            if case.f64_holds { "yes" } else { "no" },
            offset_text(case.snapped_first_violation)
        )
        .ok();
    }
    writeln!(out).ok();
    for (k, col) in cols.iter().enumerate() {
        writeln!(out, "c{k:<3} {col}").ok();
    }
    for (a, why) in &report.not_run {
        writeln!(out, "not run on this machine: {a} ({why})").ok();
    }
    let mut limits: Vec<(&str, String, &str)> = report
        .checks
        .iter()
        .filter_map(|c| Some((c.case.as_str(), column(c), c.limit.as_deref()?)))
        .collect();
    limits.dedup();
    if !limits.is_empty() {
        writeln!(out).ok();
        writeln!(out, "documented limits:").ok();
        for (case, col, why) in limits {
            writeln!(out, "  {case} {col}: {why}").ok();
        }
    }
    let shown: Vec<&Check> = report
        .checks
        .iter()
        .filter(|c| c.violations.total() > 0 && !hardcases::beyond_limit(c))
        .take(12)
        .collect();
    if !shown.is_empty() {
        writeln!(out).ok();
        writeln!(out, "first violations:").ok();
        for c in shown {
            writeln!(
                out,
                "  {} {} {} offset {} {}: {:?} — {}",
                c.case,
                c.camera,
                c.viewport,
                offset_text(Some(c.offset)),
                column(c),
                c.violations,
                c.example.as_deref().unwrap_or("")
            )
            .ok();
        }
    }
    out
}
