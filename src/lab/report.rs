//! `collide validate`: every experiment, then one report (`index.html`, `report.md`) with
//! the verdict table, each check against its expectation and tolerance, the plots, the
//! machine, the version and the seed.

use super::{Check, EXPERIMENTS, ExperimentError, ExperimentResult, Options};
use crate::run::output::write_atomic;
use std::fmt::Write as _;

/// The numerics self-check (the edge-case reference) as an experiment-like result.
pub fn numerics(options: &Options) -> ExperimentResult {
    let report = quadratic::reference::check_all();
    ExperimentResult {
        name: "numerics".into(),
        dimension: 2,
        quick: options.quick(),
        size: options.size,
        seed: options.seed,
        parameters: serde_json::json!({ "cases": report.cases }),
        data: serde_json::json!({ "report": report.text }),
        checks: vec![Check::within(
            "edge-case reference cases disagreeing with the exact answers",
            report.failures as f64,
            0.0,
            0.0,
            0.0,
            "exact: the stored answers are proved by the big-integer oracle",
        )],
        plots: Vec::new(),
    }
}

/// A description of this machine: OS, architecture, CPU model, cores.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    format!("{} {}, {cpu}, {cores} cores", std::env::consts::OS, std::env::consts::ARCH)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

fn expectation(c: &Check) -> String {
    c.expectation(3)
}

/// Writes `report.md` and `index.html` for these results into `options.out`.
pub fn write_report(results: &[ExperimentResult], options: &Options) -> Result<(), ExperimentError> {
    let passed = results.iter().all(ExperimentResult::passed);
    let header = format!(
        "collide {} · {} · seed {} · {} · {}",
        env!("CARGO_PKG_VERSION"),
        options.size.label(),
        options.seed,
        machine(),
        if passed { "ALL CHECKS PASS" } else { "SOME CHECKS FAIL" }
    );
    let mut md =
        format!("# collide validation report\n\n{header}\n\n| experiment | checks | verdict |\n|---|---|---|\n");
    for r in results {
        let ok = r.checks.iter().filter(|c| c.pass).count();
        writeln!(md, "| {} | {ok}/{} | {} |", r.slug(), r.checks.len(), if r.passed() { "PASS" } else { "FAIL" })
            .unwrap();
    }
    let mut html = format!(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>collide validation</title>\
         <style>body{{font-family:sans-serif;max-width:1100px;margin:auto}}td,th{{padding:3px 8px;border-bottom:1px solid #ddd}}\
         .pass{{color:#176b1a}}.fail{{color:#b00020;font-weight:bold}}svg{{max-width:100%;height:auto}}</style></head><body>\
         <h1>collide validation report</h1><p>{}</p><table><tr><th>experiment</th><th>checks</th><th>verdict</th></tr>",
        escape(&header)
    );
    for r in results {
        let ok = r.checks.iter().filter(|c| c.pass).count();
        let (class, verdict) = if r.passed() { ("pass", "PASS") } else { ("fail", "FAIL") };
        write!(
            html,
            "<tr><td><a href=\"#{0}\">{0}</a></td><td>{ok}/{1}</td><td class=\"{class}\">{verdict}</td></tr>",
            r.slug(),
            r.checks.len()
        )
        .unwrap();
    }
    html.push_str("</table>");
    for r in results {
        writeln!(md, "\n## {}\n\n| check | measured | error | expected | verdict | why this tolerance |\n|---|---|---|---|---|---|", r.slug())
            .unwrap();
        write!(
            html,
            "<h2 id=\"{0}\">{0}</h2><table><tr><th>check</th><th>measured</th><th>error</th><th>expected</th><th>verdict</th><th>why this tolerance</th></tr>",
            r.slug()
        )
        .unwrap();
        for c in &r.checks {
            let verdict = if c.pass { "PASS" } else { "FAIL" };
            writeln!(
                md,
                "| {} | {} | {:.2e} | {} | {verdict} | {} |",
                c.name,
                super::check::number(c.measured),
                c.error,
                expectation(c),
                c.why
            )
            .unwrap();
            write!(
                html,
                "<tr><td>{}</td><td>{}</td><td>{:.2e}</td><td>{}</td><td class=\"{}\">{verdict}</td><td>{}</td></tr>",
                escape(&c.name),
                super::check::number(c.measured),
                c.error,
                escape(&expectation(c)),
                verdict.to_lowercase(),
                escape(&c.why)
            )
            .unwrap();
        }
        html.push_str("</table>");
        for plot in &r.plots {
            writeln!(md, "\n![{plot}]({}/{plot})", r.slug()).unwrap();
            let path = ExperimentResult::dir(&options.out, &r.slug()).join(plot);
            let svg = std::fs::read_to_string(&path).map_err(crate::run::rundir::at(&path))?;
            // Inline: the page is self-contained.
            write!(html, "<figure>{}</figure>", svg.trim_start_matches("<?xml version=\"1.0\" encoding=\"UTF-8\"?>"))
                .unwrap();
        }
    }
    html.push_str("</body></html>\n");
    let out = &options.out;
    std::fs::create_dir_all(out).map_err(crate::run::rundir::at(out))?;
    write_atomic(&out.join("report.md"), md.as_bytes())?;
    write_atomic(&out.join("index.html"), html.as_bytes())?;
    Ok(())
}

/// The experiments that take longest at report size (two minutes or more each on two cores),
/// which [`validate`] starts first.
const LONGEST: [&str; 3] = ["jamming", "equation_of_state", "structure"];

/// Runs the numerics check and every experiment in both dimensions (disks, then spheres),
/// `jobs` experiments at a time (each is single-threaded but `jamming`, and independent of
/// the others: the results are the same for any `jobs`, in the same order), writes their
/// results and the report, and returns the results (`progress` hears a line as each
/// experiment starts, `running <slug> …`, and as it ends, `<slug>: passed in <s> s` — wall
/// time, which no result holds). The first error, in that order, is returned once every
/// experiment has ended.
pub fn validate(
    options: &Options,
    jobs: usize,
    progress: impl Fn(&str) + Sync,
) -> Result<Vec<ExperimentResult>, ExperimentError> {
    let work: Vec<(Options, &str, super::Experiment)> = [2, 3]
        .into_iter()
        .flat_map(|dimension| {
            EXPERIMENTS
                .iter()
                .map(move |&(name, experiment)| (Options { dimension, ..options.clone() }, name, experiment))
        })
        .collect();
    // The longest experiments start first, so that no worker is left with one of them at the
    // end while the others idle (at report size on two cores, started in list order, the
    // last minute and a half ran one experiment alone). The results keep the list's order.
    let mut order: Vec<usize> = (0..work.len()).collect();
    order.sort_by_key(|&k| !LONGEST.contains(&work[k].1));
    let done = super::in_parallel(work.len(), jobs, |k| {
        let (options, name, experiment) = &work[order[k]];
        let slug = options.slug(name);
        progress(&format!("running {slug} …"));
        let start = std::time::Instant::now();
        let result = experiment(options)?;
        result.write(&options.out)?;
        progress(&format!(
            "{slug}: {} in {:.0} s",
            if result.passed() { "passed" } else { "FAILED" },
            start.elapsed().as_secs_f64()
        ));
        Ok(result)
    })?;
    let mut results = vec![numerics(options)];
    let mut done: Vec<(usize, ExperimentResult)> = order.into_iter().zip(done).collect();
    done.sort_by_key(|(k, _)| *k);
    results.extend(done.into_iter().map(|(_, r)| r));
    write_report(&results, options)?;
    Ok(results)
}
