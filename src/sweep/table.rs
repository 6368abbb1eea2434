//! The sweep's table: one row per task, from whatever has finished.
//!
//! `results.csv` has the columns `task`, `status` (`finished`, `failed`, `interrupted`,
//! `missing`), the varied keys in the factors' order, then every scalar of the tasks'
//! `summary.json` in the order a summary writes them — nested tables flattened with `_`
//! (`max_overlap_fraction`, `events_by_kind_pair`, `compression_packing_fraction`), each wall's
//! pressure as `wall_pressure_<axis>_<side>` and its `_error` —, and `error` last. Numbers are
//! written as the summaries hold them (shortest round-trip decimals: read back, they are the
//! same doubles); a task without a summary leaves its cells empty. `results.json` holds the
//! same rows as objects. `results.svg` draws `[plot] y` (with its `_error` column as error
//! bars, when there is one) against `[plot] x`, one series for each combination of the other
//! varied values.

use super::task::{self, State};
use super::{Sweep, SweepError, Task};
use crate::lab::plot::{Chart, Series, draw};
use crate::run::rundir::write_atomic;
use serde_json::{Map, Value as Json};
use std::path::{Path, PathBuf};
use toml::Value;

/// One task's row.
#[derive(Clone, Debug)]
pub struct Row {
    /// The task.
    pub index: usize,
    /// Its directory, relative to the sweep's.
    pub dir: String,
    /// What its files say.
    pub state: State,
    /// Its varied values.
    pub parameters: Vec<(String, Value)>,
    /// Its summary's scalars, flattened (empty without a summary).
    pub results: Vec<(String, Json)>,
}

/// What [`collect`] wrote and found.
#[derive(Clone, Debug)]
pub struct Collected {
    /// Every task's row.
    pub rows: Vec<Row>,
    /// The summary columns, in order.
    pub columns: Vec<String>,
    /// The files written.
    pub files: Vec<PathBuf>,
    /// Why there is no SVG, when there is none.
    pub no_plot: Option<String>,
}

impl Collected {
    /// The tasks in `state`'s kind (compared by [`State::name`]).
    pub fn with(&self, name: &str) -> Vec<&Row> {
        self.rows.iter().filter(|r| r.state.name() == name).collect()
    }

    /// Whether every task finished.
    pub fn complete(&self) -> bool {
        self.rows.iter().all(|r| r.state == State::Finished)
    }
}

/// Reads every task's directory under `out` and writes `results.csv`, `results.json` and
/// `results.svg` there (each whole, or not at all).
pub fn collect(sweep: &Sweep, tasks: &[Task], out: &Path) -> Result<Collected, SweepError> {
    let n = tasks.len();
    let mut rows = Vec::with_capacity(n);
    let mut columns: Vec<String> = Vec::new();
    for t in tasks {
        let dir = task::dir(out, t, n);
        let state = task::state(&dir, t);
        let results = match state {
            State::NotFinished => Vec::new(),
            _ => std::fs::read(dir.join("summary.json"))
                .ok()
                .and_then(|b| serde_json::from_slice::<Json>(&b).ok())
                .map(|s| flatten(&s))
                .unwrap_or_default(),
        };
        for (k, _) in &results {
            if !columns.contains(k) {
                columns.push(k.clone());
            }
        }
        rows.push(Row {
            index: t.index,
            dir: format!("tasks/{}", t.dir_name(n)),
            state,
            parameters: t.parameters.clone(),
            results,
        });
    }
    // A summary scalar named like a varied key (`seed`, `dimension`) echoes it: one column.
    let keys = sweep.keys();
    columns.retain(|c| !keys.contains(c));
    let mut files = Vec::new();
    let csv_path = out.join("results.csv");
    write_atomic(&csv_path, csv(&keys, &columns, &rows).as_bytes())?;
    files.push(csv_path);
    let json_path = out.join("results.json");
    write_atomic(&json_path, json(sweep, &keys, &rows).as_bytes())?;
    files.push(json_path);
    let svg_path = out.join("results.svg");
    let no_plot = match chart(sweep, &columns, &rows) {
        Ok(chart) => {
            // Drawn beside, then renamed: a reader never sees half a picture.
            let tmp = out.join(format!(".results.svg.{}.tmp", std::process::id()));
            let drawn = draw(&chart, &tmp)
                .map_err(|e| e.to_string())
                .and_then(|()| std::fs::rename(&tmp, &svg_path).map_err(|e| format!("{}: {e}", svg_path.display())));
            match drawn {
                Ok(()) => {
                    files.push(svg_path);
                    None
                }
                Err(e) => {
                    let _ = std::fs::remove_file(&tmp);
                    Some(e)
                }
            }
        }
        Err(why) => Some(why),
    };
    Ok(Collected { rows, columns, files, no_plot })
}

/// A summary's scalars, nested tables flattened with `_`; the configuration (the task's
/// `config.toml` holds it) and lists left out, but for the walls' pressures.
pub fn flatten(summary: &Json) -> Vec<(String, Json)> {
    let mut out = Vec::new();
    let Json::Object(map) = summary else { return out };
    for (key, value) in map {
        match (key.as_str(), value) {
            ("config" | "status" | "warnings", _) => {}
            ("wall_pressures", Json::Array(walls)) => {
                for wall in walls {
                    let (axis, side) =
                        (wall.get("axis").map(|a| a.to_string()), wall.get("side").and_then(Json::as_str));
                    if let (Some(axis), Some(side)) = (axis, side) {
                        for (field, name) in [("pressure", ""), ("error", "_error")] {
                            if let Some(v) = wall.get(field) {
                                out.push((format!("wall_pressure_{axis}_{side}{name}"), v.clone()));
                            }
                        }
                    }
                }
            }
            _ => scalars(key, value, &mut out),
        }
    }
    out
}

fn scalars(prefix: &str, value: &Json, out: &mut Vec<(String, Json)>) {
    match value {
        Json::Object(map) => {
            for (k, v) in map {
                scalars(&format!("{prefix}_{k}"), v, out);
            }
        }
        Json::Array(_) => {}
        scalar => out.push((prefix.to_string(), scalar.clone())),
    }
}

/// A varied value as a cell: strings bare, everything else as TOML writes it.
fn parameter_text(value: &Value) -> String {
    match value {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// A result as a cell: strings bare, numbers as the summary wrote them, null empty.
fn result_text(value: &Json) -> String {
    match value {
        Json::String(s) => s.clone(),
        Json::Null => String::new(),
        other => other.to_string(),
    }
}

/// RFC 4180 quoting where a cell needs it.
fn cell(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_string() }
}

fn error_of(row: &Row) -> String {
    match &row.state {
        State::Failed(e) => e.clone(),
        _ => String::new(),
    }
}

fn csv(keys: &[String], columns: &[String], rows: &[Row]) -> String {
    let mut header = vec!["task".to_string(), "status".to_string()];
    header.extend(keys.iter().cloned());
    header.extend(columns.iter().cloned());
    header.push("error".into());
    let mut text = header.iter().map(|h| cell(h)).collect::<Vec<_>>().join(",") + "\n";
    for row in rows {
        let mut cells = vec![row.index.to_string(), row.state.name().to_string()];
        cells.extend(row.parameters.iter().map(|(_, v)| cell(&parameter_text(v))));
        for column in columns {
            let value = row.results.iter().find(|(k, _)| k == column).map(|(_, v)| result_text(v)).unwrap_or_default();
            cells.push(cell(&value));
        }
        cells.push(cell(&error_of(row)));
        text += &(cells.join(",") + "\n");
    }
    text
}

fn json(sweep: &Sweep, keys: &[String], rows: &[Row]) -> String {
    let tasks: Vec<Json> = rows
        .iter()
        .map(|row| {
            let mut o = Map::new();
            o.insert("task".into(), row.index.into());
            o.insert("dir".into(), row.dir.clone().into());
            o.insert("status".into(), row.state.name().into());
            o.insert("parameters".into(), task::parameters_json(&row.parameters).into());
            o.insert("results".into(), row.results.iter().cloned().collect::<Map<String, Json>>().into());
            let error = error_of(row);
            o.insert("error".into(), if error.is_empty() { Json::Null } else { error.into() });
            Json::Object(o)
        })
        .collect();
    let mut o = Map::new();
    o.insert("sweep".into(), sweep.source.clone().into());
    o.insert("parameters".into(), keys.to_vec().into());
    o.insert("plot".into(), serde_json::json!({ "x": sweep.plot.x, "y": sweep.plot.y }));
    o.insert("tasks".into(), tasks.into());
    serde_json::to_string_pretty(&Json::Object(o)).expect("serialises") + "\n"
}

/// A number from a TOML value (integers and floats).
fn number(value: &Value) -> Option<f64> {
    match value {
        Value::Integer(i) => Some(*i as f64),
        Value::Float(x) => Some(*x),
        _ => None,
    }
}

/// The chart of `[plot]`, or why there is none.
fn chart(sweep: &Sweep, columns: &[String], rows: &[Row]) -> Result<Chart, String> {
    let (x, y) = (&sweep.plot.x, &sweep.plot.y);
    if x.is_empty() {
        return Err("nothing is varied, so there is nothing to plot against".into());
    }
    if !columns.contains(y) {
        return Err(if columns.is_empty() {
            "no task has finished yet".into()
        } else {
            format!("[plot] y = \"{y}\" is not a column of the results (they are: {})", columns.join(", "))
        });
    }
    let error_column = format!("{y}_error");
    let has_errors = columns.contains(&error_column);
    // One series for each combination of the other varied values, in the tasks' order.
    // (label, points, errors)
    type Group = (String, Vec<(f64, f64)>, Vec<f64>);
    let mut series: Vec<Group> = Vec::new();
    for row in rows.iter().filter(|r| r.state == State::Finished) {
        let Some(xv) = row.parameters.iter().find(|(k, _)| k == x).and_then(|(_, v)| number(v)) else {
            return Err(format!("[plot] x = \"{x}\" takes values that are not numbers"));
        };
        let get = |name: &str| row.results.iter().find(|(k, _)| k == name).and_then(|(_, v)| v.as_f64());
        let Some(yv) = get(y) else { continue };
        let label =
            row.parameters.iter().filter(|(k, _)| k != x).map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>();
        let label = if label.is_empty() { y.clone() } else { label.join(", ") };
        let at = match series.iter().position(|(l, ..)| *l == label) {
            Some(at) => at,
            None => {
                series.push((label, Vec::new(), Vec::new()));
                series.len() - 1
            }
        };
        series[at].1.push((xv, yv));
        series[at].2.push(get(&error_column).unwrap_or(0.0));
    }
    // The legend goes where the data are not: to the left when y rises with x.
    let points = || series.iter().flat_map(|(_, p, _)| p.iter().copied());
    let leftmost = points().min_by(|a, b| a.0.total_cmp(&b.0));
    let rightmost = points().max_by(|a, b| a.0.total_cmp(&b.0));
    let rises = matches!((leftmost, rightmost), (Some(l), Some(r)) if r.1 > l.1);
    let series = series
        .into_iter()
        .map(
            |(label, points, errors)| {
                if has_errors { Series::errors(&label, points, errors) } else { Series::points(&label, points) }
            },
        )
        .collect();
    Ok(Chart {
        title: format!("{y} against {x}"),
        x_label: x.clone(),
        y_label: if has_errors { format!("{y} (± one standard error)") } else { y.clone() },
        series,
        legend_left: rises,
    })
}
