//! Properties under generated input (proptest, fixed seeds): mutated configurations, mutated
//! checkpoints (as they are, and sealed again so that their state is what gets judged) and
//! random JSON lines never panic, always end within a bound of events, always write strict
//! JSON, and every rejection is an error of one short line.
//!
//! 8 000 cases in all by default (1 500 configurations, 500 + 2 000 checkpoints, 4 000
//! streams of JSON lines); `COLLIDE_FUZZ_CASES=N` runs N cases of each of the four
//! properties instead (the long mode: `COLLIDE_FUZZ_CASES=25000` makes 10⁵ in all).

use crate::common::{self, BASE};
use collide::query::numbers::NumberFormat;
use collide::query::{Query, answer_lines};
use collide::run::{Checkpoint, Config, Discard, Limits, Run, Saved, Sink, Status};
use proptest::prelude::*;
use proptest::test_runner::{Config as ProptestConfig, RngAlgorithm, TestRng, TestRunner};
use std::cell::Cell;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

/// Values a mutation puts in: edges of every type the configuration takes, and wrong types.
const VALUES: &[&str] = &[
    "0",
    "-1",
    "1",
    "3",
    "100",
    "2000",
    "20000",
    "9223372036854775807",
    "-9223372036854775808",
    "0.0",
    "-0.0",
    "0.5",
    "0.9",
    "0.95",
    "1e-300",
    "1e300",
    "5e-324",
    "nan",
    "inf",
    "-inf",
    "1e-9",
    "2.0",
    "1e3",
    "1e-6",
    "0.3",
    "0.7",
    "\"wall\"",
    "\"periodic\"",
    "\"mirror\"",
    "\"random\"",
    "\"triangular\"",
    "\"square\"",
    "\"maxwell\"",
    "\"fixed-speed\"",
    "\"\"",
    "true",
    "[]",
    "[1.0]",
    "[10.0, 10.0]",
    "[1.0, 5.0]",
    "[0.9, 400.0]",
    "[1.0000000000000002, 3.0]",
    "[\"wall\", \"periodic\"]",
    "[\"wall\"]",
    "{}",
    "[[1]]",
];

const KEYS: &[&str] = &[
    "seed",
    "packing_fraction",
    "size",
    "aspect",
    "boundary",
    "count",
    "radius",
    "mass",
    "placement",
    "velocities",
    "kT",
    "collisions",
    "time",
    "sample_interval",
    "blocks",
    "trajectory_every",
    "checkpoint_every",
    "colour",
];

fn cases(default: u32) -> u32 {
    std::env::var("COLLIDE_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn runner(cases: u32) -> TestRunner {
    let config = ProptestConfig { cases, failure_persistence: None, ..ProptestConfig::default() };
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

/// Limits that keep every generated run small: its setup and its events are bounded.
fn limits() -> Limits {
    Limits {
        max_particles: 3000,
        max_samples: 20_000,
        max_collisions: 1e9,
        memory: Some(1 << 31),
        watchdog_events: 4096,
        max_projected_events: 1e9,
    }
}

/// The most events a generated run processes.
const EVENTS: u64 = 3000;

/// A sink that asks the run to stop after [`EVENTS`] events.
struct Budget<'a> {
    events: u64,
    stop: &'a AtomicBool,
}

impl Sink<2> for Budget<'_> {
    type Error = ();
    fn event(&mut self, _: &Run<2>, _: &collide::engine::Outcome<2>) -> Result<(), ()> {
        self.events += 1;
        if self.events >= EVENTS {
            self.stop.store(true, Ordering::Relaxed);
        }
        Ok(())
    }
}

/// An error message as the user sees it: one line, short.
fn short(message: &str) -> Result<(), TestCaseError> {
    prop_assert!(!message.contains('\n'), "more than one line: {message}");
    prop_assert!(message.len() <= 1200, "{} bytes: {}", message.len(), &message[..200]);
    Ok(())
}

/// Strict JSON ([`common::strict_json`]), as a property.
fn strict_json(text: &str) -> Result<(), TestCaseError> {
    prop_assert!(common::strict_json(text), "not strict JSON: {}", &text[..text.len().min(300)]);
    Ok(())
}

/// Counts a run that was refused or admitted (and exercises it): the generators must reach
/// both sides, or they test half of the property.
fn judge(
    run: Result<Run<2>, impl std::fmt::Display>,
    refused: &Cell<u32>,
    ran: &Cell<u32>,
) -> Result<(), TestCaseError> {
    match run {
        Ok(run) => {
            ran.set(ran.get() + 1);
            exercise(run)
        }
        Err(e) => {
            refused.set(refused.get() + 1);
            short(&e.to_string())
        }
    }
}

fn both_sides(refused: Cell<u32>, ran: Cell<u32>) {
    let (refused, ran) = (refused.get(), ran.get());
    eprintln!("refused {refused}, ran {ran}");
    assert!(refused > 50 && ran > 50, "refused {refused}, ran {ran}");
}

/// Runs a run that was admitted: a bounded number of events, then the summary and the
/// checkpoint must be strict JSON, and the checkpoint must be accepted again.
fn exercise(mut run: Run<2>) -> Result<(), TestCaseError> {
    let stop = AtomicBool::new(false);
    let mut budget = Budget { events: 0, stop: &stop };
    let status = run.advance(&stop, &mut budget).expect("the budget never fails");
    prop_assert!(budget.events <= EVENTS, "{} events", budget.events);
    prop_assert!(matches!(status, Status::Complete | Status::Interrupted | Status::Stalled | Status::TooManySamples));
    strict_json(&serde_json::to_string(&run.summary()).expect("a summary serialises"))?;
    let text = run.checkpoint(0).to_json();
    strict_json(&text)?;
    let again = Checkpoint::<2>::from_json(text.as_bytes())
        .map_err(|e| TestCaseError::fail(format!("own checkpoint refused: {e}")))?;
    Run::resume_with_limits(again, limits())
        .map_err(|e| TestCaseError::fail(format!("own checkpoint refused: {e}")))?;
    Ok(())
}

/// The base configuration with mutations: `(kind, which, what)` each.
fn mutate(mutations: &[(u32, u32, u32)]) -> String {
    let mut lines: Vec<String> = BASE.lines().map(str::to_string).collect();
    for &(kind, which, what) in mutations {
        let n = lines.len().max(1);
        let value = VALUES[what as usize % VALUES.len()];
        let with_values: Vec<usize> = (0..lines.len()).filter(|&k| lines[k].contains(" = ")).collect();
        let valued = with_values.get(which as usize % with_values.len().max(1)).copied();
        match kind % 6 {
            0 | 1 => {
                if let Some(k) = valued {
                    let key = lines[k].split(" = ").next().unwrap().to_string();
                    lines[k] = format!("{key} = {value}");
                }
            }
            // A number scaled, keeping its type: mostly still valid, sometimes out of range.
            2 => {
                if let Some(k) = valued {
                    let (key, old) = lines[k].split_once(" = ").map(|(a, b)| (a.to_string(), b.to_string())).unwrap();
                    let factor = [0.5, 2.0, 10.0, 0.1, 1.5, 100.0, 0.01][what as usize % 7];
                    let new = if let Ok(i) = old.parse::<i64>() {
                        Some(((i as f64 * factor).round() as i64).to_string())
                    } else {
                        old.parse::<f64>().ok().map(|x| format!("{:?}", x * factor))
                    };
                    if let Some(new) = new {
                        lines[k] = format!("{key} = {new}");
                    }
                }
            }
            3 => {
                lines.remove(which as usize % n);
            }
            4 => {
                let key = KEYS[what as usize / VALUES.len() % KEYS.len()];
                lines.insert(which as usize % (n + 1), format!("{key} = {value}"));
            }
            _ => {
                let headers = ["[box]", "[[species]]", "[init]", "[run]", "[output]", "[equilibration]", "[other]"];
                lines.insert(which as usize % (n + 1), headers[what as usize % headers.len()].to_string());
            }
        }
    }
    lines.join("\n") + "\n"
}

#[test]
fn mutated_configurations_are_refused_clearly_or_run() {
    let strategy = prop::collection::vec((any::<u32>(), any::<u32>(), any::<u32>()), 1..3);
    let (refused, ran) = (Cell::new(0u32), Cell::new(0u32));
    runner(cases(1500))
        .run(&strategy, |mutations| {
            let text = mutate(&mutations);
            let config = match Config::parse(&text, "fuzz.toml") {
                Ok(config) => config,
                Err(e) => {
                    refused.set(refused.get() + 1);
                    return short(&e.to_string());
                }
            };
            judge(Run::with_limits(config, limits()), &refused, &ran)
        })
        .unwrap();
    both_sides(refused, ran);
}

/// The base checkpoint: the base configuration without outputs, 5 000 collisions into
/// production.
fn base_checkpoint() -> &'static serde_json::Value {
    static CHECKPOINT: OnceLock<serde_json::Value> = OnceLock::new();
    CHECKPOINT.get_or_init(|| {
        let config = Config::parse(BASE, "base").unwrap();
        let mut run = Run::<2>::with_limits(config, limits()).unwrap();
        let Ok(_) = run.equilibrate(&mut Discard);
        /// Asks the run to stop once production has 5 000 collisions.
        struct Five<'a>(&'a AtomicBool);
        impl Sink<2> for Five<'_> {
            type Error = std::convert::Infallible;
            fn event(&mut self, run: &Run<2>, _: &collide::engine::Outcome<2>) -> Result<(), Self::Error> {
                if run.collisions() >= 5000 {
                    self.0.store(true, Ordering::Relaxed);
                }
                Ok(())
            }
        }
        let stop = AtomicBool::new(false);
        let Ok(_) = run.advance(&stop, &mut Five(&stop));
        assert_eq!(run.collisions(), 5000);
        serde_json::from_str(&run.checkpoint(0).to_json()).unwrap()
    })
}

/// JSON values a checkpoint mutation puts in.
fn json_value(what: u32) -> serde_json::Value {
    let values = [
        "0",
        "-1",
        "1",
        "5",
        "99",
        "100",
        "4294967295",
        "1e300",
        "-1e300",
        "1e-300",
        "0.5",
        "-0.5",
        "31.5",
        "null",
        "true",
        "\"\"",
        "\"wall\"",
        "\"inf\"",
        "\"Nothing\"",
        "\"Rebuild\"",
        "[]",
        "[0, 0]",
        "[1e150, 0]",
        "[0.5, 0.5]",
        "{}",
        "{\"Pair\": {\"partner\": 3, \"partner_events\": 0}}",
        "{\"Wall\": {\"axis\": 1, \"upper\": true}}",
        "\"equilibration\"",
        "\"production\"",
        "[[0, 0]]",
    ];
    serde_json::from_str(values[what as usize % values.len()]).unwrap()
}

/// Every leaf of `value`, as JSON pointers.
fn leaves(value: &serde_json::Value, at: String, out: &mut Vec<String>) {
    match value {
        serde_json::Value::Array(items) => {
            for (k, v) in items.iter().enumerate() {
                leaves(v, format!("{at}/{k}"), out);
            }
        }
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                leaves(v, format!("{at}/{k}"), out);
            }
        }
        _ => out.push(at),
    }
}

fn mutate_checkpoint(mutations: &[(u32, u32, u32)]) -> serde_json::Value {
    let mut value = base_checkpoint().clone();
    for &(kind, which, what) in mutations {
        let mut all = Vec::new();
        leaves(&value, String::new(), &mut all);
        let pointer = &all[which as usize % all.len()];
        if std::env::var_os("COLLIDE_FUZZ_TRACE").is_some() {
            eprintln!("mutation {kind} {what} at {pointer}");
        }
        match kind % 3 {
            // A leaf's parent removed: an entry of a list, or a key.
            0 => {
                let (parent, key) = pointer.rsplit_once('/').unwrap();
                match value.pointer_mut(parent) {
                    Some(serde_json::Value::Array(items)) => {
                        items.remove(key.parse::<usize>().unwrap());
                    }
                    Some(serde_json::Value::Object(map)) => {
                        map.remove(key);
                    }
                    _ => {}
                }
            }
            // A number nudged by an ulp either way, or scaled.
            1 => {
                if let Some(x) = value.pointer(pointer).and_then(serde_json::Value::as_f64) {
                    let y = match what % 4 {
                        0 => f64::from_bits(x.to_bits() + 1),
                        1 => f64::from_bits(x.to_bits().saturating_sub(1)),
                        2 => x * 1.5,
                        _ => -x,
                    };
                    if let Some(n) = serde_json::Number::from_f64(y) {
                        *value.pointer_mut(pointer).unwrap() = serde_json::Value::Number(n);
                    }
                }
            }
            _ => *value.pointer_mut(pointer).unwrap() = json_value(what),
        }
    }
    value
}

#[test]
fn mutated_checkpoints_are_refused_by_their_digest() {
    let strategy = prop::collection::vec((any::<u32>(), any::<u32>(), any::<u32>()), 1..3);
    let saved: Saved<2> = serde_json::from_value(base_checkpoint()["run"].clone()).unwrap();
    let original = serde_json::to_string(&saved).unwrap();
    runner(cases(500))
        .run(&strategy, |mutations| {
            let value = mutate_checkpoint(&mutations);
            match Checkpoint::<2>::from_json(serde_json::to_string(&value).unwrap().as_bytes()) {
                Err(e) => short(&e.to_string()),
                // Accepted only when the mutation changed nothing that is read back.
                Ok(checkpoint) => {
                    prop_assert_eq!(serde_json::to_string(&checkpoint.run).unwrap(), original.clone());
                    Ok(())
                }
            }
        })
        .unwrap();
}

#[test]
fn resealed_mutated_checkpoints_are_refused_clearly_or_run() {
    let strategy = prop::collection::vec((any::<u32>(), any::<u32>(), any::<u32>()), 1..3);
    let (refused, ran) = (Cell::new(0u32), Cell::new(0u32));
    runner(cases(2000))
        .run(&strategy, |mutations| {
            let value = mutate_checkpoint(&mutations);
            let Ok(saved) = serde_json::from_value::<Saved<2>>(value["run"].clone()) else {
                refused.set(refused.get() + 1);
                return Ok(());
            };
            judge(Run::resume_with_limits(Checkpoint::seal(saved), limits()), &refused, &ran)
        })
        .unwrap();
    both_sides(refused, ran);
}

/// A random request line: random bytes, or an object of known and unknown keys with values
/// of every kind.
fn request(kind: u32, keys: &[(u32, u32)], bytes: &[u8]) -> Vec<u8> {
    if kind % 4 == 0 {
        return bytes.iter().copied().filter(|&b| b != b'\n').collect();
    }
    let names = ["id", "a", "b", "c", "r1", "v1", "R1", "r2", "v2", "R2", "x"];
    let values = [
        "1",
        "1E5",
        "-0",
        "0.1",
        "1e308",
        "1e-320",
        "1e999",
        "\"0x1p-1074\"",
        "\"-0x1.8p+1\"",
        "\"nan\"",
        "\"inf\"",
        "null",
        "true",
        "[0, 0]",
        "[1, 0]",
        "[3, 0]",
        "[0, 0, 0]",
        "[\"0x1p-1074\", 0]",
        "[1e300, 1e300]",
        "[]",
        "{}",
        "\"abc\"",
        "[1, [2]]",
        "0.5",
        "-1",
        "2",
    ];
    let fields: Vec<String> = keys
        .iter()
        .map(|&(k, v)| format!("\"{}\": {}", names[k as usize % names.len()], values[v as usize % values.len()]))
        .collect();
    let mut line = format!("{{{}}}", fields.join(", ")).into_bytes();
    if kind % 4 == 1 && !bytes.is_empty() {
        // A byte changed somewhere: broken syntax, or broken UTF-8.
        let at = bytes[0] as usize % line.len();
        line[at] = bytes[bytes.len() - 1];
        line.retain(|&b| b != b'\n');
    }
    line
}

#[test]
fn random_json_lines_are_answered_in_strict_json_or_refused_by_line() {
    let line = (
        any::<u32>(),
        prop::collection::vec((any::<u32>(), any::<u32>()), 0..9),
        prop::collection::vec(any::<u8>(), 0..40),
    );
    let strategy = (any::<bool>(), prop::collection::vec(line, 1..6), any::<bool>());
    runner(cases(4000))
        .run(&strategy, |(contact, lines, hex)| {
            let mut input = Vec::new();
            for (kind, keys, bytes) in &lines {
                input.extend(request(*kind, keys, bytes));
                input.push(b'\n');
            }
            let query = if contact { Query::ContactTime } else { Query::Roots };
            let format = if hex { NumberFormat::Hex } else { NumberFormat::Shortest };
            let (mut out, mut err) = (Vec::new(), Vec::new());
            let failed = answer_lines(query, input.as_slice(), &mut out, &mut err, format).unwrap();
            let out = String::from_utf8(out).expect("output is UTF-8");
            let err = String::from_utf8(err).expect("messages are UTF-8");
            for line in out.lines() {
                strict_json(line)?;
            }
            for line in err.lines() {
                prop_assert!(line.starts_with("line "), "{line}");
                short(line)?;
            }
            let blank = |bytes: &[u8]| std::str::from_utf8(bytes).is_ok_and(|l| l.trim().is_empty());
            let requests = lines.iter().filter(|(kind, keys, bytes)| !blank(&request(*kind, keys, bytes))).count();
            prop_assert_eq!(out.lines().count() + failed, requests);
            prop_assert_eq!(err.lines().count(), failed);
            Ok(())
        })
        .unwrap();
}
